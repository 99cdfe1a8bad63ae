/* test_obstacle.c -- the sector map for OBSTACLE_DISTANCE: noise floor, nearest echo (its leading edge, half a beam off its axis), lines between beams, clear and unknown sectors, passes, ageing, the ring, bad input. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <string.h>

#include <cmocka.h>

#include "sonar/obstacle.h"

#define N 200 /* 10 m: 5 cm a sample */

static struct sonar_obstacle ob;
static const struct sonar_pose *pose_; /* the vehicle's, for beam(); NULL: none */

/* Noise 10..18; a return 150 over samples k to k + 2, its leading edge at k x 5 cm (k < 0: none), and the ring-down in the first 6 samples. */
static void beam(int64_t t, float bearing, int k)
{
    uint8_t s[N];
    int i;
    for (i = 0; i < N; i++)
        s[i] = (uint8_t)(10 + (i * 7 + (int)t / 1000) % 9);
    for (i = 0; i < 6; i++)
        s[i] = 220;
    if (k >= 0)
        for (i = k; i <= k + 2 && i < N; i++)
            s[i] = 150;
    assert_int_equal(sonar_obstacle_beam(&ob, t, bearing, pose_, s, N, 10.0f), SONAR_OK);
}

static void test_sectors(void **state)
{
    struct sonar_obstacle_config c;
    uint16_t d[SONAR_OBS_SECTORS], mn, mx;
    int a, k;
    (void)state;
    sonar_obstacle_defaults(&c);
    assert_int_equal(sonar_obstacle_init(&ob, &c), SONAR_OK);
    /* A full turn of 400 beams, 20 ms apart: a wall at 6 m (from sample 120) between 90 and 180 degrees. */
    for (a = 0; a < 400; a++)
        beam(1000000 + a * 20000, (float)a * 0.9f, (float)a * 0.9f >= 90.0f && (float)a * 0.9f < 180.0f ? 120 : -1);
    for (a = 0; a < 400; a++) /* a second turn: the floor has learnt the noise and the ring-down */
        beam(9000000 + a * 20000, (float)a * 0.9f, (float)a * 0.9f >= 90.0f && (float)a * 0.9f <= 180.0f ? 120 : -1);
    sonar_obstacle_map(&ob, 17000000, 8000000, NULL, d, &mn, &mx);
    assert_int_equal(mn, 50);
    assert_int_equal(mx, 1000);
    for (k = 0; k < SONAR_OBS_SECTORS; k++) {
        if (k >= 19 && k <= 35)
            assert_int_equal(d[k], 600); /* 6 m; the chord to the next beam's echo sags to 6 cos 0.45 = 5.9998 */
        else if (k < 17 || k > 37)
            assert_int_equal(d[k], 1001); /* scanned and clear: max + 1, never the ring-down */
    }
    /* A nearer echo later in the same pass wins; a new pass replaces. */
    beam(16900000, 0.0f, 40);
    beam(16950000, 1.0f, 60);
    sonar_obstacle_map(&ob, 17000000, 8000000, NULL, d, &mn, &mx);
    assert_int_equal(d[0], 200);
    beam(30000000, 0.0f, -1);
    sonar_obstacle_map(&ob, 30000000, 8000000, NULL, d, &mn, &mx);
    assert_int_equal(d[0], 1001);
    /* Older than the age limit: unknown; a bearing wraps into its sector. */
    assert_int_equal(d[20], SONAR_OBS_UNKNOWN);
    beam(30100000, -2.4f, 80);
    sonar_obstacle_map(&ob, 30100000, 8000000, NULL, d, &mn, &mx);
    assert_int_equal(d[0], 400);
    beam(30200000, 357.6f, -1);
    sonar_obstacle_map(&ob, 30200000, 8000000, NULL, d, &mn, &mx);
    assert_int_equal(d[0], 400); /* 357.6 rounds to sector 0 too, and the same pass keeps the echo */
}

static void test_bad_input_and_resets(void **state)
{
    struct sonar_obstacle_config c;
    uint8_t s[N] = {0};
    uint16_t d[SONAR_OBS_SECTORS], mn, mx;
    (void)state;
    sonar_obstacle_defaults(&c);
    c.min_level = 0;
    assert_int_equal(sonar_obstacle_init(&ob, &c), SONAR_ERR_ARG);
    c.min_level = 24;
    c.min_range_m = -1.0f;
    assert_int_equal(sonar_obstacle_init(&ob, &c), SONAR_ERR_ARG);
    c.min_range_m = 0.5f;
    assert_int_equal(sonar_obstacle_init(&ob, &c), SONAR_OK);
    assert_int_equal(sonar_obstacle_beam(&ob, 1, 0.0f, NULL, s, 0, 10.0f), SONAR_ERR_ARG);
    assert_int_equal(sonar_obstacle_beam(&ob, 1, 0.0f, NULL, s, N, 0.0f), SONAR_ERR_ARG);
    assert_int_equal(sonar_obstacle_beam(&ob, 1, (float)(0.0 / 0.0), NULL, s, N, 10.0f), SONAR_ERR_ARG);
    assert_int_equal(sonar_obstacle_beam(&ob, 1, 0.0f, NULL, NULL, N, 10.0f), SONAR_ERR_ARG);
    assert_int_equal(ob.beams, 0);
    sonar_obstacle_map(&ob, 1, 1000000, NULL, d, &mn, &mx);
    assert_int_equal(d[0], SONAR_OBS_UNKNOWN);
    assert_int_equal(mx, 0);
    beam(1000, 0.0f, -1);
    assert_int_equal(sonar_obstacle_beam(&ob, 2000, 5.0f, NULL, s, N, 20.0f), SONAR_OK); /* a new range: afresh */
    sonar_obstacle_map(&ob, 2000, 1000000, NULL, d, &mn, &mx);
    assert_int_equal(d[0], SONAR_OBS_UNKNOWN);
    assert_int_equal(d[1], 2001);
}

/*
 * A vehicle at (10, 20) heading north sees a wall 6 m ahead, then turns to face east and moves 1 m
 * north: the echo, kept as a world point, is now 5 m away on its left (body bearing 270, sector 54),
 * and the clear sectors turn with it; without the pose then, what was kept in the world is left out.
 */
static void test_world_memory(void **state)
{
    struct sonar_obstacle_config c;
    struct sonar_pose p = {0, 10.0f, 20.0f, 0.0f}, now = {0, 11.0f, 20.0f, 90.0f};
    uint16_t d[SONAR_OBS_SECTORS], mn, mx;
    int a;
    (void)state;
    sonar_obstacle_defaults(&c);
    assert_int_equal(sonar_obstacle_init(&ob, &c), SONAR_OK);
    pose_ = &p;
    for (a = 0; a < 800; a++) { /* two turns from astern; the wall only straight ahead, at 6 m (sample 120) */
        int g = (a + 200) % 400;
        beam(1000000 + a * 20000, (float)g * 0.9f, g < 3 || g > 397 ? 120 : -1);
    }
    pose_ = NULL;
    sonar_obstacle_map(&ob, 17000000, 20000000, &p, d, &mn, &mx);
    assert_int_equal(d[0], 600); /* 6 m, and the chords between the three beams */
    assert_int_equal(d[36], 1001);
    sonar_obstacle_map(&ob, 17000000, 20000000, &now, d, &mn, &mx);
    assert_int_equal(d[54], 500); /* 5 m on the left, and the chords */
    assert_int_equal(d[0], 1001);  /* east, where the vehicle now faces: scanned, clear */
    assert_int_equal(d[18], 1001);
    sonar_obstacle_map(&ob, 17000000, 20000000, NULL, d, &mn, &mx);
    assert_int_equal(d[0], SONAR_OBS_UNKNOWN);
    assert_int_equal(d[54], SONAR_OBS_UNKNOWN);
}

/* A map afresh with the defaults, and noise only for a few beams at bearing from 1 s: the floor learns it (an unseeded floor has no echo). */
static void fresh(float bearing)
{
    struct sonar_obstacle_config c;
    int i;
    sonar_obstacle_defaults(&c);
    assert_int_equal(sonar_obstacle_init(&ob, &c), SONAR_OK);
    for (i = 0; i < 8; i++)
        beam(1000000 + i * 20000, bearing, -1);
}

/*
 * A flat wall 4 m ahead (x = 4) seen by beams 4.5 degrees apart, each return starting at the
 * nearest wall inside its 2-degree beam: 4 / cos(|bearing| - 1). Sector 8 (37.5 to 42.5 degrees)
 * holds one beam, at 40.5 degrees, but the wall's nearest point in it is at its edge, 4 / cos 37.5
 * = 5.04 m. Each echo is placed at its beam's edge toward the nearer neighbour (36 -> 35, 40.5 ->
 * 39.5 degrees), on the wall, and the line between them crosses 37.5 degrees there. On the axes
 * (36, 40.5 at the same ranges), the line would cross it at 4.97 m, and the beam at 40.5 would
 * give 5.19 m.
 */
static void wall_x4(int64_t t0)
{
    int a;
    fresh(300.0f);
    for (a = -10; a <= 10; a++) {
        double th = fabs(a * 4.5) > 1.0 ? (fabs(a * 4.5) - 1.0) * 3.14159265358979 / 180.0 : 0.0;
        /* The sample that starts nearest 4 / cos(th). */
        beam(t0 + (a + 10) * 20000, (float)(a * 4.5), (int)floor(4.0 / cos(th) / 0.05 + 0.5));
    }
}

static void test_oblique_wall(void **state)
{
    uint16_t d[SONAR_OBS_SECTORS], mn, mx;
    unsigned k;
    (void)state;
    wall_x4(2000000);
    sonar_obstacle_map(&ob, 3000000, 8000000, NULL, d, &mn, &mx);
    assert_in_range(d[0], 399, 401);       /* straight ahead: 4 m */
    assert_in_range(d[8], 501, 507);       /* 5.04 m at the sector's near edge, not 4.97 or 5.19 */
    assert_in_range(d[72 - 8], 501, 507);  /* and on the other side */
    assert_in_range(d[4], 416, 422);       /* 4 / cos 17.5 = 4.19 m */
    /* The beam holding the foot of the normal has neighbours on both sides: it stays on its axis. */
    k = (ob.head + SONAR_MAX_OBS_ECHOES - 11u) % SONAR_MAX_OBS_ECHOES;
    assert_int_equal(ob.echo[k].side, 0);
    assert_int_equal(ob.echo[(k + 1u) % SONAR_MAX_OBS_ECHOES].side, -1); /* ranges grow: toward the previous beam */
    assert_int_equal(ob.echo[(k + SONAR_MAX_OBS_ECHOES - 1u) % SONAR_MAX_OBS_ECHOES].side, 1);
    /* Every echo point lies on the wall, to the sample (2.5 cm) and float rounding. */
    for (k = 0; k < 21; k++)
        assert_true(fabs(ob.echo[(ob.head + SONAR_MAX_OBS_ECHOES - 21u + k) % SONAR_MAX_OBS_ECHOES].x_m - 4.0) <= 0.026);
}

/*
 * Consecutive beams' echoes are joined only when a surface could run between them: 9 degrees
 * apart at 6 m, the sector between them (5 degrees) holds the line; 6 m then 3 m is two objects,
 * and 12.6 degrees apart is more than SONAR_OBS_LINK_DEG: the sectors between stay unknown.
 */
static void test_linking(void **state)
{
    uint16_t d[SONAR_OBS_SECTORS], mn, mx;
    (void)state;
    fresh(200.0f);
    beam(2000000, 0.0f, 120);   /* 6.00 m */
    beam(2020000, 9.0f, 121);   /* 6.05 m: the wall x = 6 at 8 degrees, the beam's near edge */
    sonar_obstacle_map(&ob, 2100000, 8000000, NULL, d, &mn, &mx);
    assert_int_equal(d[0], 600);
    assert_in_range(d[1], 600, 603); /* the line at 2.5 degrees: 6 / cos 2.5 = 6.006 */
    assert_in_range(d[2], 604, 607); /* the line at 7.5 degrees: 6.052 */

    fresh(200.0f);
    beam(2000000, 0.0f, 120);
    beam(2020000, 9.0f, 60);    /* 3.00 m: something else */
    sonar_obstacle_map(&ob, 2100000, 8000000, NULL, d, &mn, &mx);
    assert_int_equal(d[0], 600); /* no chord: the echo itself */
    assert_int_equal(d[1], SONAR_OBS_UNKNOWN);
    assert_int_equal(d[2], 300);
    assert_int_equal(ob.echo[(ob.head + SONAR_MAX_OBS_ECHOES - 1u) % SONAR_MAX_OBS_ECHOES].side, 0); /* unjoined: on its axis */

    fresh(200.0f);
    beam(2000000, 0.0f, 120);
    beam(2020000, 12.6f, 120);
    sonar_obstacle_map(&ob, 2100000, 8000000, NULL, d, &mn, &mx);
    assert_int_equal(d[1], SONAR_OBS_UNKNOWN);
    assert_int_equal(d[2], SONAR_OBS_UNKNOWN);
    assert_int_equal(d[3], 600);
}

/*
 * More echoes than the ring holds: the oldest makes way. Its sector, which had an echo in its
 * pass, is then unknown (not clear: nothing says it is clear); the sector still being swept
 * keeps its nearest echo among those held.
 */
static void test_ring_overflow(void **state)
{
    uint16_t d[SONAR_OBS_SECTORS], mn, mx;
    int j;
    (void)state;
    fresh(180.0f);
    beam(2000000, 0.0f, 30);
    sonar_obstacle_map(&ob, 2000000, 60000000, NULL, d, &mn, &mx);
    assert_int_equal(d[0], 150);
    /* The echo moves along the beam so the floor does not learn it: 2.00 m at its nearest. */
    for (j = 0; j < SONAR_MAX_OBS_ECHOES + 8; j++)
        beam(2020000 + j * 20000, 180.0f, 40 + 3 * (j % 40));
    assert_int_equal(ob.count, SONAR_MAX_OBS_ECHOES);
    sonar_obstacle_map(&ob, 2020000 + j * 20000, 60000000, NULL, d, &mn, &mx);
    assert_int_equal(d[0], SONAR_OBS_UNKNOWN);
    assert_int_equal(d[36], 200);
}

/*
 * A speckled return with a soft rise, 50 100 140 120 150 60 over samples 99 to 104 above a floor
 * of ~14: its mean level above the floor is ~89, half of it is crossed between samples 99 (36)
 * and 100 (86), at 99.2: 4.98 m. Its peak (sample 103) would say 5.18 m, its centre 5.09 m.
 */
static void test_echo_leading_edge(void **state)
{
    static const uint8_t ret[6] = {50, 100, 140, 120, 150, 60};
    uint16_t d[SONAR_OBS_SECTORS], mn, mx;
    uint8_t s[N];
    int i;
    (void)state;
    fresh(0.0f);
    for (i = 0; i < N; i++)
        s[i] = (uint8_t)(10 + (i * 7) % 9);
    memcpy(&s[99], ret, sizeof(ret));
    assert_int_equal(sonar_obstacle_beam(&ob, 2000000, 180.0f, NULL, s, N, 10.0f), SONAR_OK);
    sonar_obstacle_map(&ob, 2000000, 8000000, NULL, d, &mn, &mx);
    assert_in_range(d[36], 497, 499);
    /* A sharp return, 150 over samples 99 to 101: its edge is sample 99's start, 4.95 m. */
    fresh(0.0f);
    for (i = 0; i < N; i++)
        s[i] = (uint8_t)(10 + (i * 7) % 9);
    memset(&s[99], 150, 3);
    assert_int_equal(sonar_obstacle_beam(&ob, 2000000, 180.0f, NULL, s, N, 10.0f), SONAR_OK);
    sonar_obstacle_map(&ob, 2000000, 8000000, NULL, d, &mn, &mx);
    assert_in_range(d[36], 495, 496);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sectors),
        cmocka_unit_test(test_bad_input_and_resets),
        cmocka_unit_test(test_world_memory),
        cmocka_unit_test(test_oblique_wall),
        cmocka_unit_test(test_linking),
        cmocka_unit_test(test_ring_overflow),
        cmocka_unit_test(test_echo_leading_edge),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
