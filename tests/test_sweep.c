/* test_sweep.c -- sweep boundaries: full-circle wrap, back-and-forth reversal, sector restart, repeats, cap. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "sonar/frame.h"
#include "sonar/sweep.h"

static void test_full_circle_wraps(void **state)
{
    struct sonar_sweep s;
    int a, turn;
    (void)state;
    assert_int_equal(sonar_sweep_init(&s, 20, 400), SONAR_OK);
    for (turn = 0; turn < 3; turn++)
        for (a = 0; a < 400; a += 2) {
            int cut = sonar_sweep_step(&s, (uint16_t)((a + 123) % 400)); /* any start angle, across 399 -> 0 */
            assert_int_equal(cut, a == 0 && turn > 0 ? SONAR_SWEEP_WRAP : SONAR_SWEEP_SAME);
        }
    assert_int_equal(s.index, 2);
    assert_int_equal(s.beams, 200);
}

static void test_back_and_forth_reverses(void **state)
{
    struct sonar_sweep s;
    int a, cuts = 0;
    (void)state;
    assert_int_equal(sonar_sweep_init(&s, 20, 400), SONAR_OK);
    /* pingviewer_noah: 201 -> 251 -> 202 */
    for (a = 201; a <= 251; a++)
        cuts += sonar_sweep_step(&s, (uint16_t)a) != SONAR_SWEEP_SAME;
    assert_int_equal(cuts, 0);
    assert_int_equal(sonar_sweep_step(&s, 250), SONAR_SWEEP_REVERSE);
    for (a = 249; a >= 202; a--)
        assert_int_equal(sonar_sweep_step(&s, (uint16_t)a), SONAR_SWEEP_SAME);
    assert_int_equal(sonar_sweep_step(&s, 203), SONAR_SWEEP_REVERSE);
    assert_int_equal(s.index, 2);
    /* across zero: 390..10 and back */
    assert_int_equal(sonar_sweep_init(&s, 20, 400), SONAR_OK);
    for (a = 390; a <= 410; a += 3)
        assert_int_equal(sonar_sweep_step(&s, (uint16_t)(a % 400)), SONAR_SWEEP_SAME);
    assert_int_equal(sonar_sweep_step(&s, 5), SONAR_SWEEP_REVERSE);
}

static void test_sector_restart_is_a_jump(void **state)
{
    struct sonar_sweep s;
    int a;
    (void)state;
    assert_int_equal(sonar_sweep_init(&s, 20, 400), SONAR_OK);
    for (a = 150; a <= 250; a++)
        assert_int_equal(sonar_sweep_step(&s, (uint16_t)a), SONAR_SWEEP_SAME);
    /* 250 -> 150 is 100 gradians backwards, 0 -> 300 forwards: both jumps */
    assert_int_equal(sonar_sweep_step(&s, 150), SONAR_SWEEP_JUMP);
    assert_int_equal(sonar_sweep_step(&s, 151), SONAR_SWEEP_SAME);
    assert_int_equal(sonar_sweep_step(&s, 300), SONAR_SWEEP_JUMP);
    assert_int_equal(sonar_frame_delta(399, 0), 1);
    assert_int_equal(sonar_frame_delta(0, 399), -1);
    assert_int_equal(sonar_frame_delta(0, 200), -200);
}

/* The frame's wrap and arcs: every start and signed step against a plain walk round the turn. */
static void test_frame_wrap_and_arcs(void **state)
{
    uint8_t cover[SONAR_GRAD_TURN / 8];
    int a, d, g;
    (void)state;
    assert_int_equal(sonar_frame_wrap(-1), 399);
    assert_int_equal(sonar_frame_wrap(-401), 399);
    assert_int_equal(sonar_frame_wrap(800), 0);
    for (a = -400; a < 800; a += 7)
        for (d = -199; d <= 199; d += 3) {
            memset(cover, 0, sizeof(cover));
            sonar_frame_mark_arc(cover, a, a + d);
            for (g = 0; g < (int)SONAR_GRAD_TURN; g++) {
                /* on the arc: g is k steps from a in d's direction, 0 <= k <= |d| */
                int k = sonar_frame_wrap(d < 0 ? a - g : g - a), on = k <= (d < 0 ? -d : d);
                if (((cover[g / 8] >> (g % 8)) & 1) != on)
                    fail_msg("arc from %d by %d: gradian %d %s", a, d, g, on ? "missing" : "marked");
            }
        }
}

static void test_repeats_and_cap(void **state)
{
    struct sonar_sweep s;
    int i;
    (void)state;
    assert_int_equal(sonar_sweep_init(&s, 20, 8), SONAR_OK);
    for (i = 0; i < 8; i++)
        assert_int_equal(sonar_sweep_step(&s, 77), SONAR_SWEEP_SAME); /* a parked head */
    assert_int_equal(sonar_sweep_step(&s, 77), SONAR_SWEEP_FULL);
    assert_int_equal(sonar_sweep_init(&s, 0, 8), SONAR_ERR_ARG);
    assert_int_equal(sonar_sweep_init(&s, 20, 1), SONAR_ERR_ARG);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_full_circle_wraps),
        cmocka_unit_test(test_back_and_forth_reverses),
        cmocka_unit_test(test_sector_restart_is_a_jump),
        cmocka_unit_test(test_repeats_and_cap),
        cmocka_unit_test(test_frame_wrap_and_arcs),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
