/* test_activity.c -- track activity: steady and changing echoes, travel, alarms raised and cleared, windows cut by the range end or the sector, restarts, slots full, tracks gone. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "sonar/activity.h"
#include "sonar/frame.h"

#define N 300       /* samples a beam */
#define RANGE 15.0f /* metres */

/* A speckle value for (angle, sample, look): the same each look when look is 0 (a steady reflector). */
static uint8_t speckle(unsigned angle, unsigned i, unsigned look)
{
    uint32_t h = angle * 2654435761u ^ i * 40503u ^ look * 2246822519u;
    h ^= h >> 15;
    h *= 2246822519u;
    h ^= h >> 13;
    return (uint8_t)(h >> 24);
}

/* One look's beams over gradians [a0, a1] every step: steady (look 0) or fresh (look k) echoes. */
static void beams(struct sonar_activity *a, int a0, int a1, int step, unsigned look, uint16_t n, float range, int gain)
{
    uint8_t s[N];
    int g;
    unsigned i;
    for (g = a0; g <= a1; g += step) {
        uint16_t ang = (uint16_t)sonar_frame_wrap(g);
        for (i = 0; i < n; i++)
            s[i] = speckle(ang, i, look);
        sonar_activity_beam(a, ang, s, n, range, gain);
    }
}

/* A tracker holding one track per (x, y), hit this look, confirmed, its existence established. */
static void one(struct sonar_tracker *tk, unsigned k, uint32_t id, float x, float y)
{
    struct sonar_track *t = &tk->t[k];
    t->id = id;
    t->px = x;
    t->py = y;
    t->det = 0;
    t->state = SONAR_TRACK_CONFIRMED;
    t->existence = 1.0f;
    t->exists = 1;
    t->utime = 0;
    t->still_ms = 0;
    if (tk->n <= k)
        tk->n = (uint8_t)(k + 1);
}

static struct sonar_activity act;
static struct sonar_tracker tk;

static void reset(void)
{
    memset(&tk, 0, sizeof(tk));
    assert_int_equal(sonar_activity_init(&act), SONAR_OK);
}

static void test_steady_echo_stands(void **state)
{
    unsigned k;
    (void)state;
    reset();
    one(&tk, 0, 1, 6.0f, 0.0f); /* bearing 0 */
    for (k = 0; k < 5; k++) {
        beams(&act, -20, 20, 1, 0, N, RANGE, 1);
        sonar_activity_look(&act, &tk, 0, 0.0f, 0.0f, 0);
        /* seen, then two windows: a verdict from the third look */
        assert_int_equal(tk.t[0].activity, k < 2 ? SONAR_ACT_UNKNOWN : SONAR_ACT_STANDING);
    }
    assert_int_equal(tk.t[0].echo_corr, 100);
    assert_int_equal(tk.t[0].alarms, 0);
    assert_string_equal(sonar_activity_str(tk.t[0].activity), "standing");
}

/*
 * The same changing echo on a confirmed track whose existence is not established (the water's own
 * echoes hopping into one track): struggling, but no alarm until it is (tracker.h's exists); then
 * at once, its struggle already counted.
 */
static void test_alarm_needs_existence(void **state)
{
    unsigned k, n;
    (void)state;
    reset();
    one(&tk, 0, 7, 0.0f, 5.0f);
    tk.t[0].existence = SONAR_TRK_EXIST_ALARM - 0.05f;
    tk.t[0].exists = 0;
    for (k = 0; k < 5; k++) {
        if (k == 4) {
            tk.t[0].existence = SONAR_TRK_EXIST_ALARM;
            tk.t[0].exists = 1;
        }
        beams(&act, 80, 120, 3, k + 1, N, RANGE, 1);
        sonar_activity_look(&act, &tk, 0, 0.0f, 60.0f, 0);
        (void)sonar_activity_events(&act, &n);
        assert_int_equal(tk.t[0].activity, k < 2 ? SONAR_ACT_UNKNOWN : SONAR_ACT_STRUGGLING);
        assert_int_equal(tk.t[0].alarms, k == 4 ? SONAR_ALARM_STRUGGLE : 0);
        assert_int_equal(n, k == 4 ? 1u : 0u);
    }
}

static void test_changing_echo_struggles_and_alarms(void **state)
{
    unsigned k, n;
    const struct sonar_alarm_event *e;
    (void)state;
    reset();
    one(&tk, 0, 7, 0.0f, 5.0f); /* bearing 90 degrees: gradian 100 */
    for (k = 0; k < 4; k++) {
        beams(&act, 80, 120, 3, k + 1, N, RANGE, 1); /* fresh speckle each look, 3-gradian steps */
        sonar_activity_look(&act, &tk, 0, 0.0f, 0.0f, 0);
        e = sonar_activity_events(&act, &n);
        assert_int_equal(tk.t[0].activity, k < 2 ? SONAR_ACT_UNKNOWN : SONAR_ACT_STRUGGLING);
        /* struggling in 2 of the last 3 looks: the alarm at the fourth look, said once */
        assert_int_equal(tk.t[0].alarms, k == 3 ? SONAR_ALARM_STRUGGLE : 0);
        assert_int_equal(n, k == 3 ? 1u : 0u);
    }
    assert_int_equal(e[0].id, 7);
    assert_int_equal(e[0].alarms, SONAR_ALARM_STRUGGLE);
    assert_int_equal(e[0].was, 0);
    assert_true(e[0].y_m > 4.9f && e[0].y_m < 5.1f);
    assert_true(tk.t[0].echo_corr < 20 && tk.t[0].echo_corr > -20);
    /* The echo goes steady: once the three-look mean passes the threshold it stands, and the alarm clears when fewer than 2 of 3 looks struggled. */
    for (k = 0; k < 6; k++) {
        beams(&act, 80, 120, 3, 0, N, RANGE, 1);
        sonar_activity_look(&act, &tk, 0, 0.0f, 0.0f, 0);
    }
    assert_int_equal(tk.t[0].activity, SONAR_ACT_STANDING);
    assert_int_equal(tk.t[0].alarms, 0);
    /* The track ends with no alarm: nothing to clear. It ends with one: cleared, said as gone. */
    tk.n = 0;
    sonar_activity_look(&act, &tk, 0, 0.0f, 0.0f, 0);
    (void)sonar_activity_events(&act, &n);
    assert_int_equal(n, 0);
}

static void test_gone_clears(void **state)
{
    unsigned k, n;
    const struct sonar_alarm_event *e;
    (void)state;
    reset();
    one(&tk, 0, 3, 0.0f, 5.0f);
    for (k = 0; k < 4; k++) {
        beams(&act, 80, 120, 1, k + 1, N, RANGE, 1);
        sonar_activity_look(&act, &tk, 0, 0.0f, 0.0f, 0);
    }
    assert_int_equal(tk.t[0].alarms, SONAR_ALARM_STRUGGLE);
    tk.n = 0;
    sonar_activity_look(&act, &tk, 0, 0.0f, 0.0f, 0);
    e = sonar_activity_events(&act, &n);
    assert_int_equal(n, 1);
    assert_int_equal(e[0].id, 3);
    assert_int_equal(e[0].alarms, 0);
    assert_int_equal(e[0].was, SONAR_ALARM_STRUGGLE);
    assert_int_equal(e[0].gone, 1);
}

static void test_travel_moves(void **state)
{
    unsigned k;
    (void)state;
    reset();
    for (k = 0; k < 6; k++) {
        one(&tk, 0, 2, 3.0f + 0.6f * (float)k, 0.0f); /* 0.6 m a look: 1.2 m over two */
        beams(&act, -20, 20, 1, 0, N, RANGE, 1);
        sonar_activity_look(&act, &tk, 0, 0.0f, 0.0f, 0);
        assert_int_equal(tk.t[0].activity, k < 2 ? SONAR_ACT_UNKNOWN : SONAR_ACT_MOVING);
    }
    /* Slowing to 0.3 m a look (0.6 m over two): still a swimmer slowing down, half the travel holds it ... */
    for (k = 0; k < 2; k++) {
        one(&tk, 0, 2, tk.t[0].px + 0.3f, 0.0f);
        beams(&act, -20, 20, 1, 0, N, RANGE, 1);
        sonar_activity_look(&act, &tk, 0, 0.0f, 0.0f, 0);
        assert_int_equal(tk.t[0].activity, SONAR_ACT_MOVING);
    }
    /* ... stopping: no longer moving; its window is placed where it stopped and a steady echo stands. */
    for (k = 0; k < 4; k++) {
        beams(&act, -20, 20, 1, 0, N, RANGE, 1);
        sonar_activity_look(&act, &tk, 0, 0.0f, 0.0f, 0);
    }
    assert_int_equal(tk.t[0].activity, SONAR_ACT_STANDING);
}

static void test_still_alarm(void **state)
{
    unsigned k, n;
    const struct sonar_alarm_event *e;
    (void)state;
    reset();
    one(&tk, 0, 4, 6.0f, 0.0f);
    for (k = 0; k < 3; k++) {
        tk.t[0].still_ms = 10000u * k;
        beams(&act, -20, 20, 1, 0, N, RANGE, 1);
        sonar_activity_look(&act, &tk, 0, 0.0f, 15.0f, 0);
        assert_int_equal(tk.t[0].alarms, k >= 2 ? SONAR_ALARM_STILL : 0); /* still 0, 10, 20 s against 15 */
    }
    e = sonar_activity_events(&act, &n);
    assert_int_equal(n, 1);
    assert_int_equal(e[0].alarms, SONAR_ALARM_STILL);
    /* 0: never */
    sonar_activity_look(&act, &tk, 0, 0.0f, 0.0f, 0);
    assert_int_equal(tk.t[0].alarms, 0);
}

static void test_window_cut_is_unknown(void **state)
{
    unsigned k;
    (void)state;
    reset();
    one(&tk, 0, 5, RANGE - 0.2f, 0.0f); /* half its window past the range end */
    one(&tk, 1, 6, 0.0f, 6.0f);         /* at gradian 100, the sector ending at 94 (2 beams of its window) */
    one(&tk, 2, 8, 0.2f, 0.0f);         /* half its window before range 0 */
    for (k = 0; k < 5; k++) {
        beams(&act, -20, 20, 1, k, N, RANGE, 1);
        beams(&act, 60, 94, 1, k, N, RANGE, 1);
        sonar_activity_look(&act, &tk, 0, 0.0f, 0.0f, 0);
        assert_int_equal(tk.t[0].activity, SONAR_ACT_UNKNOWN);
        assert_int_equal(tk.t[0].echo_corr, SONAR_ACT_NO_CORR);
        assert_int_equal(tk.t[1].activity, SONAR_ACT_UNKNOWN);
        assert_int_equal(tk.t[2].activity, SONAR_ACT_UNKNOWN);
    }
    /* Three beams of the window in the sector: enough. */
    reset();
    one(&tk, 0, 6, 0.0f, 6.0f);
    for (k = 0; k < 3; k++) {
        beams(&act, 60, 95, 1, 0, N, RANGE, 1);
        sonar_activity_look(&act, &tk, 0, 0.0f, 0.0f, 0);
    }
    assert_int_equal(tk.t[0].activity, SONAR_ACT_STANDING);
}

static void test_settings_change_restarts(void **state)
{
    (void)state;
    reset();
    one(&tk, 0, 1, 6.0f, 0.0f);
    beams(&act, -20, 20, 1, 0, N, RANGE, 1);
    sonar_activity_look(&act, &tk, 0, 0.0f, 0.0f, 0);
    beams(&act, -20, 20, 1, 0, N, RANGE, 1);
    sonar_activity_look(&act, &tk, 0, 0.0f, 0.0f, 0);
    /* another gain: the window of the look before no longer compares, so no correlation this look */
    beams(&act, -20, 20, 1, 0, N, RANGE, 2);
    sonar_activity_look(&act, &tk, 0, 0.0f, 0.0f, 0);
    assert_int_equal(tk.t[0].echo_corr, SONAR_ACT_NO_CORR);
    assert_int_equal(tk.t[0].activity, SONAR_ACT_UNKNOWN);
    /* another range: the same */
    beams(&act, -20, 20, 1, 0, N, RANGE + 1.0f, 2);
    sonar_activity_look(&act, &tk, 0, 0.0f, 0.0f, 0);
    assert_int_equal(tk.t[0].echo_corr, SONAR_ACT_NO_CORR);
    beams(&act, -20, 20, 1, 0, N, RANGE + 1.0f, 2);
    sonar_activity_look(&act, &tk, 0, 0.0f, 0.0f, 0);
    assert_int_equal(tk.t[0].activity, SONAR_ACT_STANDING);
}

static void test_missed_look_not_correlated(void **state)
{
    unsigned k;
    (void)state;
    reset();
    one(&tk, 0, 1, 6.0f, 0.0f);
    for (k = 0; k < 4; k++) {
        tk.t[0].det = (int8_t)(k == 2 ? -1 : 0); /* missed at the third look: that look and the next are not compared */
        tk.t[0].state = k == 2 ? SONAR_TRACK_COASTING : SONAR_TRACK_CONFIRMED;
        beams(&act, -20, 20, 1, k + 1, N, RANGE, 1);
        sonar_activity_look(&act, &tk, 0, 0.0f, 0.0f, 0);
        assert_int_equal(tk.t[0].echo_corr, SONAR_ACT_NO_CORR);
    }
}

static void test_slots_full_counted(void **state)
{
    unsigned k;
    (void)state;
    reset();
    for (k = 0; k < SONAR_MAX_TRACKS; k++)
        one(&tk, k, k + 1, 3.0f + 0.1f * (float)k, 0.0f);
    sonar_activity_look(&act, &tk, 0, 0.0f, 0.0f, 0);
    assert_int_equal(act.unplaced, SONAR_MAX_TRACKS > SONAR_ACT_SLOTS ? SONAR_MAX_TRACKS - SONAR_ACT_SLOTS : 0);
    for (k = SONAR_ACT_SLOTS; k < SONAR_MAX_TRACKS; k++) {
        assert_int_equal(tk.t[k].activity, SONAR_ACT_UNKNOWN);
        assert_int_equal(tk.t[k].echo_corr, SONAR_ACT_NO_CORR);
    }
    /* A track gone frees its slot for the next one. */
    tk.t[0] = tk.t[tk.n - 1];
    tk.t[0].id = 1000;
    tk.n = 1;
    sonar_activity_look(&act, &tk, 0, 0.0f, 0.0f, 0);
    assert_int_equal(act.unplaced, SONAR_MAX_TRACKS > SONAR_ACT_SLOTS ? SONAR_MAX_TRACKS - SONAR_ACT_SLOTS : 0);
}

static void test_world_frame_no_windows(void **state)
{
    unsigned k;
    (void)state;
    reset();
    one(&tk, 0, 1, 6.0f, 0.0f);
    for (k = 0; k < 4; k++) {
        beams(&act, -20, 20, 1, 0, N, RANGE, 1);
        sonar_activity_look(&act, &tk, 0, 0.0f, 0.0f, 1);
        assert_int_equal(tk.t[0].activity, SONAR_ACT_UNKNOWN);
    }
    assert_int_equal(tk.t[0].echo_corr, SONAR_ACT_NO_CORR);
}

static void test_bad_arguments(void **state)
{
    uint8_t s[4] = {1, 2, 3, 4};
    unsigned n = 9;
    (void)state;
    assert_int_equal(sonar_activity_init(NULL), SONAR_ERR_ARG);
    reset();
    sonar_activity_beam(NULL, 0, s, 4, 1.0f, 0);
    sonar_activity_beam(&act, 400, s, 4, 1.0f, 0); /* ignored: no such gradian */
    sonar_activity_beam(&act, 0, NULL, 4, 1.0f, 0);
    sonar_activity_beam(&act, 0, s, 0, 1.0f, 0);
    assert_int_equal(act.n, 0);
    sonar_activity_look(NULL, &tk, 0, 0.0f, 0.0f, 0);
    assert_null(sonar_activity_events(NULL, &n));
    assert_int_equal(n, 0);
    assert_string_equal(sonar_activity_str(9), "?");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_steady_echo_stands),
        cmocka_unit_test(test_changing_echo_struggles_and_alarms),
        cmocka_unit_test(test_alarm_needs_existence),
        cmocka_unit_test(test_gone_clears),
        cmocka_unit_test(test_travel_moves),
        cmocka_unit_test(test_still_alarm),
        cmocka_unit_test(test_window_cut_is_unknown),
        cmocka_unit_test(test_settings_change_restarts),
        cmocka_unit_test(test_missed_look_not_correlated),
        cmocka_unit_test(test_slots_full_counted),
        cmocka_unit_test(test_world_frame_no_windows),
        cmocka_unit_test(test_bad_arguments),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
