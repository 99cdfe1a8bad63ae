/* test_detector_walls.c -- walls in one look (a thin line, a line in pieces), a buoy before a wall, a wall's echoes behind it (weaker: echo; stronger: object; off the wall's beams: object), and a wall behind a nearer, stronger one. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>
#include <math.h>

#include "sonar/detector.h"
#include "sonar/pipeline.h"

#define N 600
#define RANGE 12.0f /* 2 cm a sample */

static struct sonar_detector det;
static struct sonar_detections out;
static uint8_t fg[400][N];

/* sonard's default rules (3.5 m extent, aspect 2, a point target's footprint) with the global threshold. */
static struct sonar_detector_config cfg(void)
{
    struct sonar_pipeline_config p;
    sonar_pipeline_defaults(&p);
    p.detector.threshold_mode = SONAR_DET_GLOBAL;
    return p.detector;
}

/* A blob of level v over angles [a0, a1] and samples [s0, s1]. */
static void blob(int a0, int a1, int s0, int s1, uint8_t v)
{
    int a, s;
    for (a = a0; a <= a1; a++)
        for (s = s0; s <= s1; s++)
            fg[a][s] = v;
}

static int run_sweep(void)
{
    struct sonar_detector_config c = cfg();
    int a;
    assert_int_equal(sonar_detector_init(&det, &c), SONAR_OK);
    for (a = 0; a < 400; a++)
        assert_int_equal(sonar_detector_add(&det, (uint16_t)a, fg[a], N, RANGE, 1000 * a), SONAR_OK);
    return sonar_detector_end(&det, &out);
}

/* Detections of kind k. */
static int count(int k)
{
    int i, n = 0;
    for (i = 0; i < out.count; i++)
        n += out.det[i].kind == k;
    return n;
}

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

/* A wall 1.2 m long, 0.1 m thick, at 3 m: structure in one look, though shorter than max_extent_m. A person-sized echo stays an object. */
static void test_wall_in_one_look(void **state)
{
    (void)state;
    memset(fg, 0, sizeof(fg));
    blob(100, 125, 150, 154, 150); /* 26 gradians at 3 m: 1.2 m; 5 samples */
    blob(200, 210, 150, 174, 150); /* a person: 0.5 m across, 0.5 m deep */
    assert_int_equal(run_sweep(), 2);
    assert_int_equal(count(SONAR_DET_STRUCTURE), 1);
    assert_int_equal(count(SONAR_DET_OBJECT), 1);
    assert_int_equal(out.det[0].kind, SONAR_DET_OBJECT); /* objects first */
    assert_true(out.det[0].bearing_deg > 170.0f);
    /* As thick as a person (0.5 m): not a line, an object (and a blob of that size is not wider than 3.5 m). */
    memset(fg, 0, sizeof(fg));
    blob(100, 125, 150, 174, 150);
    assert_int_equal(run_sweep(), 1);
    assert_int_equal(out.det[0].kind, SONAR_DET_OBJECT);
    /* Short: a 0.4 m thin echo (a pipe, a float) is an object. */
    memset(fg, 0, sizeof(fg));
    blob(100, 108, 150, 154, 150);
    assert_int_equal(run_sweep(), 1);
    assert_int_equal(out.det[0].kind, SONAR_DET_OBJECT);
}

/* A wall returned in patches: thin pieces in one line are one wall; two buoys side by side are not. */
static void test_wall_in_pieces(void **state)
{
    int a;
    (void)state;
    memset(fg, 0, sizeof(fg));
    for (a = 0; a < 4; a++) /* four pieces of 0.3 m with gaps of 0.15 m (3 gradians at 3 m) */
        blob(100 + a * 10, 106 + a * 10, 150, 153, 150);
    assert_int_equal(run_sweep(), 4);
    assert_int_equal(count(SONAR_DET_STRUCTURE), 4);
    memset(fg, 0, sizeof(fg));
    blob(100, 106, 150, 153, 150);
    blob(110, 116, 150, 153, 150); /* two pieces: 0.75 m end to end, but... */
    blob(150, 156, 150, 153, 150); /* ...a third far off (1.6 m away) joins neither */
    assert_int_equal(run_sweep(), 3);
    assert_int_equal(count(SONAR_DET_STRUCTURE), 2);
    assert_int_equal(count(SONAR_DET_OBJECT), 1);
    /* Two buoys (0.2 m across and deep) 0.1 m apart: 0.55 m end to end, shorter than a wall: objects. */
    memset(fg, 0, sizeof(fg));
    blob(100, 104, 150, 159, 150);
    blob(107, 111, 150, 159, 150);
    assert_int_equal(run_sweep(), 2);
    assert_int_equal(count(SONAR_DET_OBJECT), 2);
}

/* A 0.2 m buoy 0.6 m before a wall: the wall is structure, the buoy an object. */
static void test_buoy_before_wall(void **state)
{
    (void)state;
    memset(fg, 0, sizeof(fg));
    blob(100, 130, 150, 154, 150); /* the wall at 3 m, 1.45 m long */
    blob(113, 117, 120, 129, 150); /* the buoy at 2.4 m: 0.2 m across and deep */
    assert_int_equal(run_sweep(), 2);
    assert_int_equal(kind_at(3.05f), SONAR_DET_STRUCTURE);
    assert_int_equal(kind_at(2.5f), SONAR_DET_OBJECT);
}

/* Echoes of a wall at 2 m: weaker copies at 4 and 6 m on its beams are its echo; a stronger one is an object; one off its beams too. */
static void test_wall_echoes(void **state)
{
    (void)state;
    memset(fg, 0, sizeof(fg));
    blob(100, 140, 100, 104, 160); /* the wall at 2 m, 1.3 m long */
    blob(112, 118, 200, 209, 60);  /* at twice its range, weaker */
    blob(122, 127, 300, 309, 40);  /* at three times */
    assert_int_equal(run_sweep(), 3);
    assert_int_equal(kind_at(2.05f), SONAR_DET_STRUCTURE);
    assert_int_equal(kind_at(4.1f), SONAR_DET_WALL_ECHO);
    assert_int_equal(kind_at(6.1f), SONAR_DET_WALL_ECHO);
    assert_int_equal(count(SONAR_DET_OBJECT), 0);
    /* Stronger than the wall: not its echo (a person beyond a rope taken for a wall). */
    blob(112, 118, 200, 209, 200);
    assert_int_equal(run_sweep(), 3);
    assert_int_equal(kind_at(4.1f), SONAR_DET_OBJECT);
    assert_int_equal(out.det[0].kind, SONAR_DET_OBJECT); /* the object first, before structure and echoes */
    /* On beams the wall does not cover: an object. */
    memset(fg, 0, sizeof(fg));
    blob(100, 140, 100, 104, 160);
    blob(160, 166, 200, 209, 60);
    assert_int_equal(run_sweep(), 2);
    assert_int_equal(kind_at(4.1f), SONAR_DET_OBJECT);
    /* The echo of the wall is a wall itself (as long): behind the nearer, stronger wall it is its echo. */
    memset(fg, 0, sizeof(fg));
    blob(100, 140, 100, 104, 160);
    blob(110, 130, 200, 203, 60);
    assert_int_equal(run_sweep(), 2);
    assert_int_equal(kind_at(2.05f), SONAR_DET_STRUCTURE);
    assert_int_equal(kind_at(4.05f), SONAR_DET_WALL_ECHO);
}

/* No wall, no echo: the same blobs without the wall are objects. */
static void test_no_wall_no_echo(void **state)
{
    (void)state;
    memset(fg, 0, sizeof(fg));
    blob(112, 118, 200, 209, 60);
    blob(122, 127, 300, 309, 40);
    assert_int_equal(run_sweep(), 2);
    assert_int_equal(count(SONAR_DET_OBJECT), 2);
    assert_string_equal(sonar_det_kind_str(SONAR_DET_WALL_ECHO), "wall echo");
    assert_false(sonar_det_kind_tracked(SONAR_DET_WALL_ECHO));
    assert_false(sonar_det_kind_tracked(SONAR_DET_STRUCTURE));
    assert_true(sonar_det_kind_tracked(SONAR_DET_STATIC_START));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_wall_in_one_look),
        cmocka_unit_test(test_wall_in_pieces),
        cmocka_unit_test(test_buoy_before_wall),
        cmocka_unit_test(test_wall_echoes),
        cmocka_unit_test(test_no_wall_no_echo),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
