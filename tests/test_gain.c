/* test_gain.c -- automatic gain: lowered on a saturating sweep, raised on one at the bottom of the scale, held between changes, never back to a setting that saturated (no oscillation), and only from beams at the setting in force. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "sonar/gain.h"

static struct sonar_gain g;

/* A sweep of 100 beams of 600 samples: a noise floor at `floor`, and `bright` samples a beam at 255. */
static int sweep(uint8_t floor, int bright, uint8_t at)
{
    uint8_t b[600];
    int i;
    memset(b, floor, sizeof(b));
    memset(b, 255, (size_t)bright);
    for (i = 0; i < 100; i++)
        sonar_gain_beam(&g, b, 600, at);
    return sonar_gain_sweep_end(&g);
}

static void test_config_checked(void **state)
{
    struct sonar_gain_config c;
    (void)state;
    sonar_gain_defaults(&c);
    assert_null(sonar_gain_config_check(&c));
    c.start = 3;
    assert_non_null(strstr(sonar_gain_config_check(&c), "start"));
    sonar_gain_defaults(&c);
    c.sat_max = 0.0f;
    assert_non_null(strstr(sonar_gain_config_check(&c), "sat_max"));
    assert_int_equal(sonar_gain_init(&g, &c), SONAR_ERR_ARG);
}

/*
 * A scene that saturates at high gain and at normal, not at low, and whose floor at low is at the
 * bottom of the scale: from high it settles at low within two changes and stays there for 20
 * sweeps (the bar keeps it from going back up though the floor asks for it).
 */
static void test_settles_and_stays(void **state)
{
    struct sonar_gain_config c;
    int s, r, changes_at_settle;
    (void)state;
    sonar_gain_defaults(&c);
    c.start = 2;
    assert_int_equal(sonar_gain_init(&g, &c), SONAR_OK);
    assert_int_equal(sweep(40, 30, 2), 1); /* 5 % saturated: lower at once */
    assert_int_equal(sweep(20, 30, 1), -1); /* held: one sweep */
    assert_int_equal(sweep(20, 30, 1), 0);  /* still saturating at normal: low */
    changes_at_settle = (int)g.changes;
    for (s = 0; s < 20; s++) {
        r = sweep(1, 0, g.gain); /* at low: no saturation, the floor at the bottom */
        assert_int_equal(r, -1);
    }
    assert_int_equal((int)g.changes, changes_at_settle);
    assert_int_equal(g.gain, 0);
    /* once the bar has lapsed, the floor raises it again */
    for (s = 0; s < 10 && g.gain == 0; s++)
        (void)sweep(1, 0, g.gain);
    assert_int_equal(g.gain, 1);
    /* ... and when normal saturates again right away, it is barred twice as long */
    (void)sweep(20, 30, 1);
    assert_int_equal(sweep(20, 30, 1), 0);
    assert_int_equal(g.barred_for, 2 * c.memory_sweeps);
}

/* The floor at the bottom raises it a setting at a time, each after the hold; a middling sweep changes nothing. */
static void test_raises_on_the_floor(void **state)
{
    struct sonar_gain_config c;
    (void)state;
    sonar_gain_defaults(&c);
    assert_int_equal(sonar_gain_init(&g, &c), SONAR_OK);
    assert_int_equal(sweep(30, 0, 0), -1);
    assert_int_equal(sweep(2, 0, 0), 1);
    assert_int_equal(sweep(2, 0, 1), -1);
    assert_int_equal(sweep(2, 0, 1), 2);
    assert_int_equal(sweep(0, 0, 2), -1);
    assert_int_equal(sweep(0, 0, 2), -1); /* at the top */
    assert_int_equal(g.last_median, 0);
}

/* Beams taken at another setting (replies from before a change) are not counted; an empty sweep decides nothing. */
static void test_other_setting_ignored(void **state)
{
    struct sonar_gain_config c;
    (void)state;
    sonar_gain_defaults(&c);
    c.start = 1;
    assert_int_equal(sonar_gain_init(&g, &c), SONAR_OK);
    assert_int_equal(sweep(40, 100, 2), -1);
    assert_int_equal(g.gain, 1);
    assert_int_equal(sonar_gain_sweep_end(&g), -1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_config_checked),
        cmocka_unit_test(test_settles_and_stays),
        cmocka_unit_test(test_raises_on_the_floor),
        cmocka_unit_test(test_other_setting_ignored),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
