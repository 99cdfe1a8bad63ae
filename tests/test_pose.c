/* test_pose.c -- the pose ring: order, jumps, bad values, thinning, wrap-around of the ring and of yaw, interpolation, staleness, body <-> world. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <math.h>

#include <cmocka.h>

#include "sonar/pose.h"

static struct sonar_pose_ring ring;

static void init(void)
{
    struct sonar_pose_limits lim;
    sonar_pose_limits_default(&lim);
    assert_int_equal(sonar_pose_init(&ring, &lim), SONAR_OK);
}

static struct sonar_pose P(int64_t t, float n, float e, float yaw)
{
    struct sonar_pose p;
    p.utime = t;
    p.north_m = n;
    p.east_m = e;
    p.yaw_deg = yaw;
    return p;
}

static int push(int64_t t, float n, float e, float yaw)
{
    struct sonar_pose p = P(t, n, e, yaw);
    return sonar_pose_push(&ring, &p);
}

static void test_interpolates_position_and_yaw_the_short_way(void **state)
{
    struct sonar_pose p;
    (void)state;
    init();
    assert_int_equal(push(1000000, 0.0f, 0.0f, 350.0f), SONAR_OK);
    assert_int_equal(push(2000000, 1.0f, -2.0f, 10.0f), SONAR_OK); /* 20 degrees through north */
    assert_int_equal(sonar_pose_at(&ring, 1500000, &p), 1);
    assert_true(fabsf(p.north_m - 0.5f) < 1e-5f);
    assert_true(fabsf(p.east_m + 1.0f) < 1e-5f);
    assert_true(fabsf(p.yaw_deg - 0.0f) < 1e-3f || fabsf(p.yaw_deg - 360.0f) < 1e-3f);
    assert_int_equal(sonar_pose_at(&ring, 1750000, &p), 1);
    assert_true(fabsf(p.yaw_deg - 5.0f) < 1e-3f);
    /* just past either end: the end sample; more than 1 s past: stale */
    assert_int_equal(sonar_pose_at(&ring, 2900000, &p), 1);
    assert_true(fabsf(p.north_m - 1.0f) < 1e-6f);
    assert_int_equal(sonar_pose_at(&ring, 3100000, &p), 0);
    assert_int_equal(sonar_pose_at(&ring, -100000, &p), 0);
    /* a hole longer than 2 s in the middle is stale too */
    assert_int_equal(push(6000000, 1.0f, -2.0f, 10.0f), SONAR_OK);
    assert_int_equal(sonar_pose_at(&ring, 4000000, &p), 0);
    assert_int_equal(sonar_pose_at(&ring, 5500000, &p), 1);
}

static void test_refuses_disorder_jumps_and_bad_values(void **state)
{
    (void)state;
    init();
    assert_int_equal(push(1000000, 0.0f, 0.0f, 0.0f), SONAR_OK);
    assert_int_equal(push(1000000, 0.0f, 0.0f, 0.0f), SONAR_ERR_RANGE);  /* same time */
    assert_int_equal(push(900000, 0.0f, 0.0f, 0.0f), SONAR_ERR_RANGE);   /* backwards */
    assert_int_equal(ring.out_of_order, 2);
    assert_int_equal(push(1500000, 30.0f, 0.0f, 0.0f), SONAR_ERR_RANGE); /* 60 m/s */
    assert_int_equal(push(1500000, 0.0f, 0.0f, 90.0f), SONAR_OK); /* 180 degrees/s is fine ... */
    assert_int_equal(ring.jumps, 1);
    assert_int_equal(push(1700000, 0.0f, 0.0f, 270.0f), SONAR_ERR_RANGE); /* ... 900 degrees/s is not */
    assert_int_equal(ring.jumps, 2);
    assert_int_equal(push(1800000, NAN, 0.0f, 0.0f), SONAR_ERR_RANGE);
    assert_int_equal(push(1800000, 0.0f, INFINITY, 0.0f), SONAR_ERR_RANGE);
    assert_int_equal(push(1800000, 2.0e6f, 0.0f, 0.0f), SONAR_ERR_RANGE);
    assert_int_equal(ring.bad, 3);
    /* after a silence longer than 1 s anything goes: the vehicle moved while nothing was heard */
    assert_int_equal(push(9000000, 300.0f, 0.0f, 180.0f), SONAR_OK);
    assert_int_equal(ring.n, 3);
    /* the same refusals, each said why */
    {
        struct sonar_pose q;
        memset(&q, 0, sizeof(q));
        q.utime = 9000000;
        q.north_m = 300.0f;
        q.yaw_deg = 180.0f;
        assert_string_equal(sonar_pose_push_why(&ring, &q), "not later than the pose before it");
        q.utime = 9100000;
        q.north_m = 330.0f;
        assert_string_equal(sonar_pose_push_why(&ring, &q), "a jump from the pose before it (faster than 50 m/s or 720 deg/s)");
        q.north_m = NAN;
        assert_string_equal(sonar_pose_push_why(&ring, &q), "a value that is not a number or is beyond 10^6 m");
        q.north_m = 300.5f;
        assert_null(sonar_pose_push_why(&ring, &q));
        assert_int_equal(sonar_pose_accepted(&ring), ring.accepted);
        assert_true(sonar_pose_accepted(&ring) >= 4);
    }
    assert_int_equal(sonar_pose_push(NULL, NULL), SONAR_ERR_ARG);
}

static void test_thins_and_wraps_the_ring(void **state)
{
    struct sonar_pose p;
    /* the default spacing, 50 ms, with samples at 50 Hz: every third is kept, 60 ms apart */
    const int64_t gap = 50000, step = 20000, kept = 60000;
    const int total = (SONAR_MAX_POSES + 100) * 3;
    int64_t t = 0;
    int i;
    (void)state;
    init();
    /* At 0.5 m/s north: one sample in two or three is kept, the newest always; the ring wraps. */
    for (i = 0; i < total; i++) {
        t = 1000000 + (int64_t)i * step;
        assert_int_equal(push(t, 0.5f * (float)i * 0.02f, 0.0f, (float)(i % 360)), SONAR_OK);
        assert_true(ring.s[(ring.head + ring.n - 1u) % SONAR_MAX_POSES].utime == t);
    }
    assert_int_equal(ring.n, SONAR_MAX_POSES);
    assert_true(ring.thinned > (uint32_t)total / 2);
    for (i = 1; i + 1 < (int)ring.n; i++) /* stored ones at least min_gap apart, bar the newest */
        assert_true(ring.s[(ring.head + i) % SONAR_MAX_POSES].utime - ring.s[(ring.head + i - 1) % SONAR_MAX_POSES].utime >= gap);
    assert_int_equal(sonar_pose_at(&ring, t - (SONAR_MAX_POSES - 10) * kept, &p), 1);
    assert_true(fabsf(p.north_m - 0.5f * (float)((double)(t - 1000000 - (SONAR_MAX_POSES - 10) * kept) * 1e-6)) < 0.01f);
    assert_int_equal(sonar_pose_at(&ring, t - (SONAR_MAX_POSES + 10) * kept - SONAR_POSE_STALE_US, &p), 0); /* older than the ring */
}

static void test_body_world_round_trip(void **state)
{
    struct sonar_pose p = P(0, 10.0f, -5.0f, 90.0f);
    float n, e, x, y;
    (void)state;
    /* heading east: straight ahead (x) is east, to the right (y) is south */
    sonar_pose_to_world(&p, 2.0f, 0.0f, &n, &e);
    assert_true(fabsf(n - 10.0f) < 1e-5f && fabsf(e + 3.0f) < 1e-5f);
    sonar_pose_to_world(&p, 0.0f, 1.0f, &n, &e);
    assert_true(fabsf(n - 9.0f) < 1e-5f && fabsf(e + 5.0f) < 1e-5f);
    p.yaw_deg = 33.0f;
    sonar_pose_to_world(&p, 3.0f, -4.0f, &n, &e);
    sonar_pose_to_body(&p, n, e, &x, &y);
    assert_true(fabsf(x - 3.0f) < 1e-4f && fabsf(y + 4.0f) < 1e-4f);
}

static void test_limits_checked(void **state)
{
    struct sonar_pose_limits lim;
    (void)state;
    sonar_pose_limits_default(&lim);
    lim.max_speed_mps = 0.0f;
    assert_int_equal(sonar_pose_init(&ring, &lim), SONAR_ERR_ARG);
    sonar_pose_limits_default(&lim);
    lim.min_gap_us = -1;
    assert_int_equal(sonar_pose_init(&ring, &lim), SONAR_ERR_ARG);
    assert_int_equal(sonar_pose_init(NULL, &lim), SONAR_ERR_ARG);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_interpolates_position_and_yaw_the_short_way),
        cmocka_unit_test(test_refuses_disorder_jumps_and_bad_values),
        cmocka_unit_test(test_thins_and_wraps_the_ring),
        cmocka_unit_test(test_body_world_round_trip),
        cmocka_unit_test(test_limits_checked),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
