/* test_geometry.c -- range, sample period, sample count, transmit duration (with the unit bug peers have), frame. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
#include <math.h>

#include "sonar/geometry.h"

/* Blue Robotics' measured table (ping.md §3): range -> sample_period ticks, transmit us, at 1200 samples. */
static void test_device_table(void **state)
{
    static const struct {
        double range;
        uint16_t ticks, tx;
    } t[] = {{2, 88, 11}, {20, 888, 107}, {50, 2222, 267}};
    unsigned i;
    (void)state;
    for (i = 0; i < 3; i++) {
        uint16_t sp = 0;
        assert_int_equal(sonar_geometry_sample_period(t[i].range, 1200, 1500, &sp), SONAR_OK);
        assert_int_equal(sp, t[i].ticks);
        assert_int_equal(sonar_geometry_transmit_duration(t[i].range, 1500, sp), t[i].tx);
        assert_true(fabs(sonar_geometry_range_m(sp, 1200, 1500) - t[i].range) < 0.03);
    }
}

static void test_max_samples(void **state)
{
    (void)state;
    assert_int_equal(sonar_geometry_max_samples(1.0, 1500), 666); /* ping-viewer#946 "1200 or 666" */
    assert_int_equal(sonar_geometry_max_samples(1.8, 1500), 1200);
    assert_int_equal(sonar_geometry_max_samples(50, 1500), 1200);
    assert_int_equal(sonar_geometry_max_samples(0.2, 1500), 0); /* would need fewer than 200 */
    assert_int_equal(sonar_geometry_max_samples(-1, 1500), 0);
}

static void test_sample_period_limits(void **state)
{
    uint16_t sp = 7;
    (void)state;
    assert_int_equal(sonar_geometry_sample_period(1.0, 1200, 1500, &sp), SONAR_ERR_RANGE); /* 53 ticks < 80 */
    assert_int_equal(sp, 7);
    assert_int_equal(sonar_geometry_sample_period(1000, 200, 1500, &sp), SONAR_ERR_RANGE);
    assert_int_equal(sonar_geometry_sample_period(0, 1200, 1500, &sp), SONAR_ERR_ARG);
    assert_int_equal(sonar_geometry_sample_period(2, 0, 1500, &sp), SONAR_ERR_ARG);
}

/*
 * The 2.5-sample floor in microseconds: at 1 m over 666 samples the period is 80 ticks = 2 us,
 * so the floor is 5 us and 8000 R / c = 5.33 -> 5. At 0.75 m over 200 samples the period is
 * 200 ticks = 5 us: floor 12.5 -> 13 us, above 8000 R / c = 4. Peers compute the floor in
 * seconds (peers.md §0), which makes it 0 and would send 5 us here.
 */
static void test_transmit_floor_units(void **state)
{
    uint16_t sp;
    (void)state;
    assert_int_equal(sonar_geometry_sample_period(1.0, 666, 1500, &sp), SONAR_OK);
    assert_int_equal(sp, 80);
    assert_int_equal(sonar_geometry_transmit_duration(1.0, 1500, sp), 5);
    assert_int_equal(sonar_geometry_sample_period(0.75, 200, 1500, &sp), SONAR_OK);
    assert_int_equal(sp, 200);
    assert_int_equal(sonar_geometry_transmit_duration(0.75, 1500, sp), 13);
    /* the ceiling: min(500, 64 * period) */
    assert_int_equal(sonar_geometry_transmit_duration(60, 1500, 80), 128);
    assert_int_equal(sonar_geometry_transmit_duration(100, 1500, 4000), 500);
}

static void test_frame(void **state)
{
    double x, y;
    (void)state;
    sonar_frame_to_xy(0, 0, 10, &x, &y);
    assert_true(fabs(x - 10) < 1e-9 && fabs(y) < 1e-9);
    sonar_frame_to_xy(100, 0, 10, &x, &y); /* 100 gradians = 90 degrees */
    assert_true(fabs(x) < 1e-9 && fabs(y - 10) < 1e-9);
    sonar_frame_to_xy(100, 100, 2, &x, &y); /* an offset rotates the frame */
    assert_true(fabs(x + 2) < 1e-9 && fabs(y) < 1e-9);
    assert_true(fabs(sonar_frame_bearing_deg(0, -1) - 270.0) < 1e-9);
    assert_true(fabs(sonar_frame_bearing_deg(1, 1) - 45.0) < 1e-9);
    assert_true(fabs(sonar_geometry_sample_range(0, 1200, 12) - 0.005) < 1e-12);
    assert_true(fabs(sonar_geometry_sample_range(1199, 1200, 12) - 11.995) < 1e-9);
    assert_int_equal(sonar_geometry_sample_index(0.005, 1200, 12), 0);
    assert_int_equal(sonar_geometry_sample_index(11.999, 1200, 12), 1199);
    assert_int_equal(sonar_geometry_sample_index(12.0, 1200, 12), -1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_device_table),
        cmocka_unit_test(test_max_samples),
        cmocka_unit_test(test_sample_period_limits),
        cmocka_unit_test(test_transmit_floor_units),
        cmocka_unit_test(test_frame),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
