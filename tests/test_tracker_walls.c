/* test_tracker_walls.c -- the tracker at the site's walls: a turn at a straight wall, past the end seen of one, and at a corner keeps one ID (and loses it without the walls), walls not crossed and no walls change nothing, a track beyond a wall is never turned back in, a wall that is a rope costs a swimmer under it nothing, bad walls refused. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <math.h>

#include <cmocka.h>

#include "sonar/tracker.h"

#define LOOK_S 6.0f
#define TURN 10.0f /* where a centre turns at the walls x = 10.5 and y = 10.5 (SONAR_TRK_WALL_TURN_M out) */

static struct sonar_tracker tk, other;

static const float box[2][4] = {{10.5f, -20.0f, 10.5f, 20.0f}, {-20.0f, 10.5f, 20.0f, 10.5f}};

static void init(struct sonar_tracker *t, unsigned nwalls, int on)
{
    struct sonar_tracker_config c;
    sonar_tracker_defaults(&c);
    c.walls = (uint8_t)on;
    assert_int_equal(sonar_tracker_init(t, &c), SONAR_OK);
    assert_int_equal(sonar_tracker_set_walls(t, box, nwalls), SONAR_OK);
}

/* The mirror of v about a turn line at TURN, when it went past it. */
static float bounce(float v, int walls)
{
    return walls && v > TURN ? 2.0f * TURN - v : v;
}

/*
 * One target seen once a look from (x0, y0) at (vx, vy) m/s for n looks, its path turned at the
 * walls when bounced (each axis at TURN), into t; returns how many distinct track IDs it had.
 */
static unsigned run(struct sonar_tracker *t, float x0, float y0, float vx, float vy, int n, int bounced)
{
    uint32_t ids[16];
    unsigned nid = 0, k;
    int s;
    for (s = 0; s < n; s++) {
        float ts = (float)s * LOOK_S + 3.0f;
        struct sonar_tracker_obs o = {bounce(x0 + vx * ts, bounced), bounce(y0 + vy * ts, bounced),
                                      (int64_t)(ts * 1e6f), 0.3f};
        struct sonar_tracker_sweep sw;
        memset(&sw, 0, sizeof(sw));
        sw.utime = (int64_t)((float)(s + 1) * LOOK_S * 1e6f);
        sw.beams = 400;
        sw.max_range_m = 50.0f;
        assert_int_equal(sonar_tracker_update(t, &o, 1, &sw), SONAR_OK);
        for (k = 0; k < t->n; k++) {
            unsigned i;
            if (t->t[k].det < 0 || t->t[k].state == SONAR_TRACK_TENTATIVE)
                continue;
            for (i = 0; i < nid && ids[i] != t->t[k].id; i++)
                ;
            if (i == nid && nid < 16)
                ids[nid++] = t->t[k].id;
        }
    }
    return nid;
}

/* A swimmer at 1.5 m/s reaching the wall between two looks: one ID with the wall known; without it, another. */
static void test_turn_at_a_wall(void **state)
{
    (void)state;
    init(&tk, 2, 1);
    assert_int_equal(run(&tk, -14.0f, 3.0f, 1.5f, 0.0f, 5, 1), 1u);
    assert_true(tk.t[0].vx < -1.0f); /* it swims back */
    init(&tk, 0, 1);
    assert_true(run(&tk, -14.0f, 3.0f, 1.5f, 0.0f, 5, 1) > 1u);
    init(&tk, 2, 0); /* --track-walls off */
    assert_true(run(&tk, -14.0f, 3.0f, 1.5f, 0.0f, 5, 1) > 1u);
}

/*
 * A wall seen only part way (a survey sees as far as its beams reach): a swimmer turning 0.4 m past the end seen
 * keeps one ID (the line runs on SONAR_TRK_WALL_END_M); one 2.4 m past it is in open water, and is not turned.
 */
static void test_turn_past_the_end_seen(void **state)
{
    static const float part[1][4] = {{10.5f, -20.0f, 10.5f, 2.6f}};
    (void)state;
    init(&tk, 0, 1);
    assert_int_equal(sonar_tracker_set_walls(&tk, part, 1), SONAR_OK);
    assert_int_equal(run(&tk, -14.0f, 3.0f, 1.5f, 0.0f, 5, 1), 1u);
    init(&tk, 0, 1);
    assert_int_equal(sonar_tracker_set_walls(&tk, part, 1), SONAR_OK);
    assert_true(run(&tk, -14.0f, 5.0f, 1.5f, 0.0f, 5, 1) > 1u);
}

/* Into the corner: turned at both walls in one step, one ID. */
static void test_turn_at_a_corner(void **state)
{
    (void)state;
    init(&tk, 2, 1);
    assert_int_equal(run(&tk, -14.0f, -14.0f, 1.5f, 1.5f, 5, 1), 1u);
    assert_true(tk.t[0].vx < 0.0f && tk.t[0].vy < 0.0f);
    init(&tk, 0, 1);
    assert_true(run(&tk, -14.0f, -14.0f, 1.5f, 1.5f, 5, 1) > 1u);
}

/* Whether two trackers hold the same tracks, bit for bit, but for which walls each found near this update. */
static void same_tracks(struct sonar_tracker *a, struct sonar_tracker *b)
{
    unsigned k;
    assert_int_equal(a->n, b->n);
    for (k = 0; k < a->n; k++)
        a->t[k].near_walls = b->t[k].near_walls = 0;
    assert_memory_equal(a->t, b->t, sizeof(a->t[0]) * a->n);
}

/* Walls it never crosses, no walls, and walls set to none: the same tracks, bit for bit. */
static void test_no_walls_change_nothing(void **state)
{
    (void)state;
    init(&tk, 2, 1);
    init(&other, 0, 1);
    (void)run(&tk, -9.0f, -8.0f, 0.4f, 0.3f, 8, 0);
    (void)run(&other, -9.0f, -8.0f, 0.4f, 0.3f, 8, 0);
    same_tracks(&tk, &other);
    init(&tk, 2, 1);
    assert_int_equal(sonar_tracker_set_walls(&tk, NULL, 0), SONAR_OK);
    (void)run(&tk, -14.0f, 3.0f, 1.5f, 0.0f, 5, 1);
    init(&other, 0, 1);
    (void)run(&other, -14.0f, 3.0f, 1.5f, 0.0f, 5, 1);
    same_tracks(&tk, &other);
}

/* Beyond a wall (a reflection, an echo past the pool's edge) coming in through it: never turned back out, as without walls. */
static void test_beyond_a_wall_not_turned(void **state)
{
    (void)state;
    init(&tk, 2, 1);
    init(&other, 0, 1);
    (void)run(&tk, 25.0f, 3.0f, -1.5f, 0.0f, 5, 0);
    (void)run(&other, 25.0f, 3.0f, -1.5f, 0.0f, 5, 0);
    assert_int_equal(tk.n, other.n);
    assert_memory_equal(tk.t, other.t, sizeof(tk.t[0]) * tk.n);
}

/* A lane rope taken for a wall: a swimmer who goes straight under it keeps its ID and state, as without it. */
static void test_rope_costs_nothing(void **state)
{
    (void)state;
    init(&tk, 2, 1);
    init(&other, 0, 1);
    assert_int_equal(run(&tk, -10.0f, 3.0f, 1.5f, 0.0f, 5, 0), run(&other, -10.0f, 3.0f, 1.5f, 0.0f, 5, 0));
    assert_int_equal(tk.n, other.n);
    assert_memory_equal(tk.t, other.t, sizeof(tk.t[0]) * tk.n);
}

static void test_bad_walls(void **state)
{
    float many[SONAR_TRK_MAX_WALLS + 2][4];
    float bad[1][4] = {{0.0f, 0.0f, NAN, 1.0f}};
    unsigned k;
    (void)state;
    init(&tk, 2, 1);
    assert_int_equal(sonar_tracker_set_walls(&tk, (const float(*)[4])bad, 1), SONAR_ERR_ARG);
    assert_int_equal(tk.nwalls, 2); /* nothing changed */
    bad[0][2] = 2.0e3f;
    assert_int_equal(sonar_tracker_set_walls(&tk, (const float(*)[4])bad, 1), SONAR_ERR_ARG);
    assert_int_equal(sonar_tracker_set_walls(&tk, NULL, 3), SONAR_ERR_ARG);
    assert_int_equal(sonar_tracker_set_walls(NULL, box, 1), SONAR_ERR_ARG);
    for (k = 0; k < SONAR_TRK_MAX_WALLS + 2; k++) {
        many[k][0] = (float)k;
        many[k][1] = -1.0f;
        many[k][2] = (float)k;
        many[k][3] = 1.0f;
    }
    assert_int_equal(sonar_tracker_set_walls(&tk, (const float(*)[4])many, SONAR_TRK_MAX_WALLS + 2), SONAR_ERR_SPACE);
    assert_int_equal(tk.nwalls, SONAR_TRK_MAX_WALLS);
    assert_true(tk.wall[SONAR_TRK_MAX_WALLS - 1][0] == (float)(SONAR_TRK_MAX_WALLS - 1));
    /* a wall with no length is kept and never turns anything */
    many[0][2] = many[0][0];
    many[0][3] = many[0][1];
    assert_int_equal(sonar_tracker_set_walls(&tk, (const float(*)[4])many, 1), SONAR_OK);
    assert_int_equal(run(&tk, -10.0f, 3.0f, 1.5f, 0.0f, 3, 0), 1u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_turn_at_a_wall),
        cmocka_unit_test(test_turn_past_the_end_seen),
        cmocka_unit_test(test_turn_at_a_corner),
        cmocka_unit_test(test_no_walls_change_nothing),
        cmocka_unit_test(test_beyond_a_wall_not_turned),
        cmocka_unit_test(test_rope_costs_nothing),
        cmocka_unit_test(test_bad_walls),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
