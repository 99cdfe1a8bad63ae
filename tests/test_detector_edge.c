/* test_detector_edge.c -- the water's boundary in one look: an oblique wall's piece cut by the sector and a prop is structure; a buoy before a wall, at the sector's end, and a person beside a rope stay objects; a faint patch just behind a wall is its tail. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>
#include <math.h>

#include "sonar/cfar.h"
#include "sonar/detector.h"
#include "sonar/edge.h"
#include "sonar/pipeline.h"

#define N 600
#define RANGE 5.0f /* 8.3 mm a sample */
#define BEAMS 100  /* a sector of 100 gradians at 1 gradian */
#define NEAR 60    /* the ring-down: 0.5 m */

static struct sonar_detector det;
static struct sonar_detections out;
static uint8_t raw[BEAMS][N];

/* Quiet water everywhere. */
static void water(void) { memset(raw, 10, sizeof(raw)); }

/* An echo of level v on beam b over samples [s0, s0 + depth), and the shadow behind it to the range's end. */
static void echo(int b, int s0, int depth, uint8_t v)
{
    int s;
    for (s = s0; s < N; s++)
        raw[b][s] = s < s0 + depth ? v : 3;
}

/*
 * One sweep of the sector as sonard's pipeline gives it to the detector: each beam's samples (the
 * background has learnt nothing: a first look), samples [h0, h1) of each hidden from the detector as
 * the shadow's level (as a CFAR whose training blocks are all wall passes none of it) and, with edges,
 * each beam's leading edge, found on all its samples. Returns the count.
 */
static int run_sweep_hiding(int edges, int h0, int h1)
{
    struct sonar_pipeline_config p;
    int a;
    sonar_pipeline_defaults(&p);
    p.detector.threshold_mode = SONAR_DET_GLOBAL;
    assert_int_equal(sonar_detector_init(&det, &p.detector), SONAR_OK);
    for (a = 0; a < BEAMS; a++) {
        uint8_t top, seen[N];
        uint16_t sums[SONAR_CFAR_MAX_BLOCKS], e;
        assert_true(sonar_cfar_sums(raw[a], N, sums) >= 0);
        e = sonar_edge_leading(raw[a], sums, NEAR, N, &top);
        memcpy(seen, raw[a], N);
        memset(seen + h0, 3, (size_t)(h1 - h0));
        assert_int_equal(sonar_detector_add(&det, (uint16_t)(150 + a), seen, N, RANGE, 30000 * a), SONAR_OK);
        if (edges)
            sonar_detector_set_edge(&det, e, top);
    }
    return sonar_detector_end(&det, &out);
}

static int run_sweep(int edges) { return run_sweep_hiding(edges, 0, 0); }

/* The detection nearest range r metres, its kind. */
static int kind_at(float r)
{
    int i, best = -1;
    for (i = 0; i < out.count; i++)
        if (best < 0 || fabsf(out.det[i].range_m - r) < fabsf(out.det[best].range_m - r))
            best = i;
    assert_true(best >= 0 && fabsf(out.det[best].range_m - r) < 0.3f);
    return out.det[best].kind;
}

/*
 * An oblique wall, its return 0.33 m deep on each beam (the beam meets it over a stretch of range), cut by
 * the sector's first beam, then hidden by a prop nearer on ten beams, then running on: the piece at the
 * sector's end is too short and too thick for a line, yet it is the wall the edge runs on from.
 */
static void oblique_wall(void)
{
    int b;
    water();
    for (b = 0; b < 10; b++)
        echo(b, 560 - 6 * b, 40, 150);
    for (b = 10; b < 20; b++)
        echo(b, 300, 24, 200); /* the prop: 0.2 m deep, 0.4 m across at 2.5 m */
    for (b = 20; b < 70; b++)
        echo(b, 560 - 6 * b, 40, 150);
}

/* Detections of kind k; and the kind of the one of pts cells. */
static int count(int k)
{
    int i, n = 0;
    for (i = 0; i < out.count; i++)
        n += out.det[i].kind == k;
    return n;
}

static int kind_of(uint32_t pts)
{
    int i;
    for (i = 0; i < out.count; i++)
        if (out.det[i].points == pts)
            return out.det[i].kind;
    fail();
    return -1;
}

static void test_wall_cut_by_the_sector(void **state)
{
    (void)state;
    oblique_wall();
    /* Without the edges: all three are objects (the piece 0.75 m by 0.3 m; the rest of the wall is too thick
       for a line and too short for the oblique rule). */
    assert_int_equal(run_sweep(0), 3);
    assert_int_equal(count(SONAR_DET_OBJECT), 3);
    /* With them: the edge runs on from the piece behind the prop along the wall: both are structure, the prop
       stays an object. */
    assert_int_equal(run_sweep(1), 3);
    assert_int_equal(kind_of(10 * 40), SONAR_DET_STRUCTURE);
    assert_int_equal(kind_of(50 * 40), SONAR_DET_STRUCTURE);
    assert_int_equal(kind_of(10 * 24), SONAR_DET_OBJECT);
}

/* A 0.2 m buoy 0.6 m before a wall takes the edge on its own beams: it jumps back to the wall on both sides. */
static void test_buoy_before_wall(void **state)
{
    int b;
    (void)state;
    water();
    for (b = 20; b < 80; b++)
        echo(b, 480, 6, 150); /* the wall at 4 m, 4 m long */
    for (b = 45; b < 51; b++)
        echo(b, 408, 24, 200); /* the buoy at 3.4 m */
    assert_int_equal(run_sweep(1), 3);
    assert_int_equal(kind_at(3.5f), SONAR_DET_OBJECT);
    assert_int_equal(out.det[0].kind, SONAR_DET_OBJECT);
    assert_int_equal(out.det[1].kind, SONAR_DET_STRUCTURE);
    /* At the sector's end, the wall beside it on one side only: still an object. */
    water();
    for (b = 6; b < 80; b++)
        echo(b, 480, 6, 150);
    for (b = 0; b < 6; b++)
        echo(b, 408, 24, 200);
    assert_int_equal(run_sweep(1), 2);
    assert_int_equal(kind_at(3.5f), SONAR_DET_OBJECT);
    assert_int_equal(kind_at(4.0f), SONAR_DET_STRUCTURE);
}

/* A person beside a faint lane rope (too faint to be detected, but the edge on its beams) at the same range: an object. */
static void test_person_beside_rope(void **state)
{
    int b;
    (void)state;
    memset(raw, 2, sizeof(raw));
    for (b = 10; b < 61; b++)
        echo(b, 300, 3, 14); /* the rope at 2.5 m, below the detector's floor */
    for (b = 61; b < 67; b++)
        echo(b, 296, 48, 200); /* a person: 0.4 m deep */
    assert_int_equal(run_sweep(1), 1);
    assert_int_equal(out.det[0].kind, SONAR_DET_OBJECT);
}

/*
 * A wall's piece seen between two props, the wall running on beyond the second one, where its first two beams
 * out are fainter than half (speckle, the wall's aspect): the faint beams are bridged and the piece is
 * structure; the props stay objects.
 */
static void test_faint_beam_bridged(void **state)
{
    int b;
    (void)state;
    water();
    for (b = 20; b < 30; b++)
        echo(b, 300, 24, 200); /* prop A at 2.5 m */
    for (b = 30; b < 40; b++)
        echo(b, 560 - 3 * b, 40, 150); /* the piece, 0.33 m deep: no line of its own */
    for (b = 40; b < 50; b++)
        echo(b, 250, 24, 200); /* prop B, at 2.1 m: not in line with A */
    for (b = 50; b < 90; b++)
        echo(b, 560 - 3 * b, 40, b == 50 || b == 51 ? 60 : 150);
    assert_true(run_sweep(1) >= 3);
    assert_int_equal(kind_of(10 * 40), SONAR_DET_STRUCTURE);
    assert_int_equal(count(SONAR_DET_OBJECT), 2);
    assert_int_equal(kind_at(2.1f), SONAR_DET_OBJECT);
    assert_int_equal(kind_at(2.5f), SONAR_DET_OBJECT);
}

/*
 * A straight wall 2.5 m away, square to beam 20: its range grows as 1 / cos along the sweep. A piece of it
 * far along (beams 55-72, where the range climbs 3.6 samples a beam at its start, 5.3 on average) is seen
 * between two props; behind the first, the wall runs on flatter. Looked for where the piece's own end
 * points, it is found and the piece is structure; along the piece's mean slope it would be 0.25 m off.
 */
static void test_wall_bends_along_the_sweep(void **state)
{
    int b;
    (void)state;
    water();
    for (b = 0; b < 85; b++)
        echo(b, (int)(300.0 / cos((b - 20) * 3.14159265358979 / 200.0) + 0.5), 40, 150);
    for (b = 45; b < 55; b++)
        echo(b, 200, 24, 200); /* prop A at 1.7 m */
    for (b = 73; b < 85; b++)
        echo(b, 250, 24, 200); /* prop B at 2.1 m; beyond it the wall is out of range */
    assert_true(run_sweep(1) >= 3);
    assert_int_equal(kind_of(18 * 40), SONAR_DET_STRUCTURE);
    assert_int_equal(kind_at(1.7f), SONAR_DET_OBJECT);
    assert_int_equal(kind_at(2.1f), SONAR_DET_OBJECT);
}

/*
 * A wall at 2.5 m (level 250 on beams 10-89) that the detector does not see, as when the CFAR's training
 * blocks are all wall (its edge is found all the same), and on six beams just behind it a patch v strong
 * s0.. s0 + 7. Returns the count.
 */
static int tail(int s0, uint8_t v)
{
    int a, s;
    water();
    for (a = 10; a < 90; a++)
        echo(a, 296, 8, 250);
    for (a = 47; a < 53; a++)
        for (s = s0; s < s0 + 8; s++)
            raw[a][s] = v;
    return run_sweep_hiding(1, 296, 304);
}

/* The patch a tenth of the wall, 0.25 m behind it, is the wall's tail; a quarter as strong, or 0.7 m behind, it is an object. */
static void test_tail_behind_wall(void **state)
{
    (void)state;
    assert_int_equal(tail(326, 25), 0);
    assert_int_equal(tail(326, 64), 1);
    assert_int_equal(out.det[0].kind, SONAR_DET_OBJECT);
    assert_int_equal(tail(380, 25), 1);
    assert_int_equal(out.det[0].kind, SONAR_DET_OBJECT);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_wall_cut_by_the_sector),
        cmocka_unit_test(test_buoy_before_wall),
        cmocka_unit_test(test_person_beside_rope),
        cmocka_unit_test(test_faint_beam_bridged),
        cmocka_unit_test(test_wall_bends_along_the_sweep),
        cmocka_unit_test(test_tail_behind_wall),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
