/* test_detector.c -- grouping sets k, k-means stays inside groups and cuts wide ones, the rules (size, beams, range, aspect, extent), tracking, wrap, offset, limits, and the CFAR threshold against the global one. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>
#include <math.h>

#include "sonar/detector.h"
#include "sonar/geometry.h"

#define N 600
#define RANGE 12.0f

static struct sonar_detector det;
static struct sonar_detections out;
static uint8_t fg[400][N];

static struct sonar_detector_config cfg(void)
{
    struct sonar_detector_config c;
    memset(&c, 0, sizeof(c));
    c.threshold_k = 3.0f;
    c.min_threshold = 16;
    c.max_clusters = 8;
    c.iterations = 10;
    c.join_beams = 2;
    c.min_points = 20;
    c.join_m = 0.15f;
    return c;
}

/* A blob of level v over angles [a0, a1] (mod 400) and samples [s0, s1]. */
static void blob(int a0, int a1, int s0, int s1, uint8_t v)
{
    int a, s;
    for (a = a0; a <= a1; a++)
        for (s = s0; s <= s1; s++)
            fg[(a + 400) % 400][s] = v;
}

static int run_sweep(const struct sonar_detector_config *c)
{
    int a;
    assert_int_equal(sonar_detector_init(&det, c), SONAR_OK);
    for (a = 0; a < 400; a++)
        assert_int_equal(sonar_detector_add(&det, (uint16_t)a, fg[a], N, RANGE, 1000 * a), SONAR_OK);
    return sonar_detector_end(&det, &out);
}

/* The same at every fourth gradian (100 beams of 4 gradians). */
static int run_coarse_sweep(const struct sonar_detector_config *c)
{
    int a;
    assert_int_equal(sonar_detector_init(&det, c), SONAR_OK);
    for (a = 0; a < 400; a += 4)
        assert_int_equal(sonar_detector_add(&det, (uint16_t)a, fg[a], N, RANGE, 1000 * a), SONAR_OK);
    return sonar_detector_end(&det, &out);
}

static void expect_at(const struct sonar_detection *d, double angle, double sample)
{
    double x, y;
    sonar_frame_to_xy(angle, 0, sonar_geometry_sample_range((uint16_t)sample, N, RANGE) + 0.5 * RANGE / N * (sample - floor(sample)) * 2, &x, &y);
    assert_true(fabs(d->x_m - x) < 0.03);
    assert_true(fabs(d->y_m - y) < 0.03);
}

static void test_separate_objects_separate_detections(void **state)
{
    struct sonar_detector_config c = cfg();
    (void)state;
    memset(fg, 0, sizeof(fg));
    blob(50, 54, 200, 219, 150); /* 5 x 20 cells */
    blob(60, 64, 200, 219, 120); /* same range, 6 beams away: separate */
    blob(300, 310, 400, 409, 200);
    assert_int_equal(run_sweep(&c), 3);
    assert_int_equal(out.groups, 3);
    assert_int_equal(out.det[0].points, 110);
    expect_at(&out.det[0], 305, 404.5);
    assert_int_equal(out.det[1].points, 100);
    assert_true(fabs(out.det[1].mean_intensity - 150.0f) < 1e-3 || fabs(out.det[1].mean_intensity - 120.0f) < 1e-3);
    assert_true(out.det[0].area_m2 > 0.0f);
    assert_int_equal(out.beams, 400);
}

static void test_one_object_stays_whole(void **state)
{
    struct sonar_detector_config c = cfg();
    (void)state;
    memset(fg, 0, sizeof(fg));
    blob(100, 160, 300, 305, 90); /* an arc 61 beams wide: one wall-like object */
    blob(120, 120, 306, 312, 90); /* touching bump */
    c.max_clusters = 8;
    assert_int_equal(run_sweep(&c), 1);
    assert_int_equal(out.det[0].points, 61 * 6 + 7);
    /* its hull spans the arc: about 61 * 0.9 degrees at ~6 m */
    assert_true(out.det[0].area_m2 > 0.1f);
}

static void test_small_groups_dropped_and_cap(void **state)
{
    struct sonar_detector_config c = cfg();
    (void)state;
    memset(fg, 0, sizeof(fg));
    blob(10, 12, 100, 104, 200);  /* 15 cells: noise */
    blob(30, 35, 100, 119, 200);  /* 120 */
    blob(80, 84, 100, 119, 200);  /* 100 */
    assert_int_equal(run_sweep(&c), 2);
    assert_int_equal(out.groups, 2);
    c.max_clusters = 1;
    assert_int_equal(run_sweep(&c), 1);
    /* the second group is not swallowed into the first: its hull stays small */
    assert_int_equal(out.det[0].points, 120);
    assert_true(out.det[0].area_m2 < 0.2f);
    assert_int_equal(out.groups, 2);
}

static void test_wrap_joins_across_zero(void **state)
{
    struct sonar_detector_config c = cfg();
    (void)state;
    memset(fg, 0, sizeof(fg));
    blob(397, 402, 250, 259, 180); /* angles 397..399 and 0..2 */
    assert_int_equal(run_sweep(&c), 1);
    assert_int_equal(out.det[0].points, 60);
    assert_true(out.det[0].x_m > 0.0f);
    assert_true(fabs(out.det[0].y_m) < 0.05f);
}

static void test_angle_offset_rotates(void **state)
{
    struct sonar_detector_config c = cfg();
    float x0, y0;
    (void)state;
    memset(fg, 0, sizeof(fg));
    blob(40, 44, 100, 119, 200);
    assert_int_equal(run_sweep(&c), 1);
    x0 = out.det[0].x_m;
    y0 = out.det[0].y_m;
    c.angle_offset = 100.0f; /* 90 degrees */
    assert_int_equal(run_sweep(&c), 1);
    assert_true(fabs(out.det[0].x_m + y0) < 1e-3);
    assert_true(fabs(out.det[0].y_m - x0) < 1e-3);
    assert_true(fabs(out.det[0].bearing_deg - sonar_frame_bearing_deg(-y0, x0)) < 0.01);
}

static void test_threshold_uses_previous_sweep(void **state)
{
    struct sonar_detector_config c = cfg();
    int a, s;
    (void)state;
    memset(fg, 0, sizeof(fg));
    for (a = 0; a < 400; a++)
        for (s = 0; s < N; s++)
            fg[a][s] = (uint8_t)((a * 7 + s * 13) % 41); /* spread 0..40: mean 20, std ~11.8 */
    assert_int_equal(run_sweep(&c), 0);
    /* first sweep: its own statistics so far; floor(20 + 3 * 11.8) = 55 > 40: nothing passes */
    assert_int_equal(out.threshold, 55);
    assert_int_equal(out.runs, 0);
    /* a second sweep of zeros uses the first sweep's statistics, not its own */
    memset(fg, 0, sizeof(fg));
    for (a = 0; a < 400; a++)
        assert_int_equal(sonar_detector_add(&det, (uint16_t)a, fg[a], N, RANGE, 0), SONAR_OK);
    assert_int_equal(det.threshold, 55);
    assert_int_equal(sonar_detector_end(&det, &out), 0);
}

static void test_run_overflow_counted(void **state)
{
    struct sonar_detector_config c = cfg();
    int a, s;
    (void)state;
    memset(fg, 0, sizeof(fg));
    for (a = 0; a < 400; a++)
        for (s = 0; s < N; s += 2)
            fg[a][s] = 250; /* isolated cells: 300 runs a beam */
    c.min_threshold = 100;
    c.threshold_k = 0.0f;
    /* every kept cell is within join_m of the next: one group */
    assert_int_equal(run_sweep(&c), 1);
    assert_int_equal(out.runs, SONAR_MAX_RUNS);
    assert_int_equal(out.det[0].points, SONAR_MAX_RUNS);
    assert_int_equal(out.runs_dropped, 400u * 300u - SONAR_MAX_RUNS);
}

static void test_min_beams_and_max_extent(void **state)
{
    struct sonar_detector_config c = cfg();
    (void)state;
    memset(fg, 0, sizeof(fg));
    blob(20, 20, 100, 159, 200);  /* one beam, 60 cells: a zero-area line */
    blob(100, 104, 100, 119, 200); /* 5 beams, ~0.2 m */
    blob(200, 230, 500, 503, 200); /* a 31-beam arc at 10 m: ~4.9 m wide */
    /* At 1-gradian steps the 2-degree beams overlap: no reflector lights one beam alone, so that one is a fragment. */
    assert_int_equal(run_sweep(&c), 2);
    c.min_beams = 6;
    assert_int_equal(run_sweep(&c), 1);
    /* At 4-gradian steps (3.6 degrees) they do not: one beam is a reflector's whole echo, and kept. */
    c.min_beams = 0;
    assert_int_equal(run_coarse_sweep(&c), 3);
    c.min_beams = 2;
    assert_int_equal(run_coarse_sweep(&c), 2);
    assert_int_equal(run_sweep(&c), 2);
    c.max_extent_m = 3.0f;
    /* The arc is wider than any object: reported after the objects, as structure. */
    assert_int_equal(run_sweep(&c), 2);
    assert_int_equal(out.det[0].points, 100);
    assert_int_equal(out.det[0].kind, SONAR_DET_OBJECT);
    assert_int_equal(out.det[1].points, 31 * 4);
    assert_int_equal(out.det[1].kind, SONAR_DET_STRUCTURE);
    c.max_extent_m = -1.0f;
    assert_int_equal(sonar_detector_init(&det, &c), SONAR_ERR_ARG);
}

/* Adds the 400 beams of fg as the next sweep, without a new init, and ends it. */
static int next_sweep(void)
{
    int a;
    for (a = 0; a < 400; a++)
        assert_int_equal(sonar_detector_add(&det, (uint16_t)a, fg[a], N, RANGE, 1000 * a), SONAR_OK);
    return sonar_detector_end(&det, &out);
}

static void test_kmeans_stays_inside_groups(void **state)
{
    struct sonar_detector_config c = cfg();
    int i;
    (void)state;
    memset(fg, 0, sizeof(fg));
    /*
     * A wall arc at 6 m over 61 beams, and a small object 0.2 m nearer at the arc's middle: two
     * groups, but the arc's centroid (on its chord, ~5.8 m) lies on the object. Free Lloyd would
     * hand the object's centre the middle of the wall; inside groups each keeps its own cells.
     */
    blob(100, 160, 300, 305, 90);
    blob(128, 132, 280, 289, 150);
    assert_int_equal(run_sweep(&c), 2);
    assert_int_equal(out.det[0].points, 61 * 6);
    assert_int_equal(out.det[1].points, 50);
    assert_true(fabs(out.det[1].mean_intensity - 150.0f) < 1e-3);
    for (i = 0; i < 2; i++)
        assert_true(out.det[i].points == 50 || out.det[i].area_m2 > 0.5f);
}

static void test_split_cuts_wide_group(void **state)
{
    struct sonar_detector_config c = cfg();
    int i;
    (void)state;
    memset(fg, 0, sizeof(fg));
    /* Two 5 x 20 objects at 6 m, 45 beams (~4.2 m) apart, joined by a faint one-sample bridge. */
    blob(100, 104, 300, 319, 200);
    blob(145, 149, 300, 319, 200);
    blob(105, 144, 310, 310, 60);
    c.max_extent_m = 3.0f;
    assert_int_equal(run_sweep(&c), 1); /* one group 4.2 m wide: structure, not an object */
    assert_int_equal(out.det[0].kind, SONAR_DET_STRUCTURE);
    assert_int_equal(out.groups, 1);
    c.split_points = 60;
    assert_int_equal(run_sweep(&c), 2); /* cut in three; the bridge's middle piece is too small */
    for (i = 0; i < 2; i++) {
        assert_int_equal(out.det[i].kind, SONAR_DET_OBJECT);
        assert_true(out.det[i].points >= 100 && out.det[i].points < 130);
        assert_true(out.det[i].area_m2 < 0.5f);
    }
    assert_true(out.det[0].bearing_deg < 90.0f * 104.0f / 100.0f + 2.0f || out.det[1].bearing_deg < 90.0f * 104.0f / 100.0f + 2.0f);
    assert_true(out.det[0].bearing_deg > 90.0f * 145.0f / 100.0f - 2.0f || out.det[1].bearing_deg > 90.0f * 145.0f / 100.0f - 2.0f);
    c.split_points = 300; /* pieces need more cells than either object has */
    assert_int_equal(run_sweep(&c), 0);
    c.split_points = 60;
    c.max_extent_m = 0.0f; /* no width limit: nothing to cut, the group stays whole */
    assert_int_equal(run_sweep(&c), 1);
    assert_int_equal(out.det[0].points, 2 * 100 + 40);
}

/* Walls and ropes: a thin line wider than max_extent_m is never cut into object-sized pieces, a line with an object on it is. */
static void test_lines_are_not_cut(void **state)
{
    struct sonar_detector_config c = cfg();
    int i;
    (void)state;
    memset(fg, 0, sizeof(fg));
    blob(100, 160, 300, 305, 120); /* a wall: 61 beams at 6 m (~5.7 m), 6 samples (0.12 m) deep */
    c.max_extent_m = 3.0f;
    c.split_points = 60;
    assert_int_equal(run_sweep(&c), 1);
    assert_int_equal(out.det[0].kind, SONAR_DET_STRUCTURE);
    assert_int_equal(out.det[0].points, 61 * 6);
    /* A person against it: 8 beams 30 samples (0.6 m) deep, a bulge on an eighth of the wall's beams. */
    blob(126, 133, 276, 305, 160);
    assert_int_equal(run_sweep(&c), 4); /* the person, and the wall's pieces as structure */
    assert_int_equal(out.det[0].kind, SONAR_DET_OBJECT);
    for (i = 1; i < 4; i++)
        assert_int_equal(out.det[i].kind, SONAR_DET_STRUCTURE);
    assert_true(out.det[0].bearing_deg > 90.0f * 126.0f / 100.0f - 2.0f && out.det[0].bearing_deg < 90.0f * 133.0f / 100.0f + 2.0f);
    /* Without the cut, the whole of it is structure. */
    c.split_points = 0;
    assert_int_equal(run_sweep(&c), 1);
    assert_int_equal(out.det[0].kind, SONAR_DET_STRUCTURE);
}

/* Structure never takes an object's place: objects first (max_clusters of them), structure in the room left. */
static void test_structure_after_objects(void **state)
{
    struct sonar_detector_config c = cfg();
    int a, i;
    (void)state;
    memset(fg, 0, sizeof(fg));
    c.max_extent_m = 2.0f;
    c.max_clusters = SONAR_MAX_CLUSTERS;
    for (a = 0; a < 6; a++) /* six walls: 21 beams at 9 m (~3 m), larger than any object */
        blob(a * 60, a * 60 + 20, 450, 453, 100);
    for (a = 0; a < 10; a++) /* ten objects */
        blob(a * 39 + 25, a * 39 + 27, 200, 209, (uint8_t)(150 + a));
    assert_int_equal(run_sweep(&c), SONAR_MAX_CLUSTERS);
    for (i = 0; i < SONAR_MAX_CLUSTERS; i++)
        assert_int_equal(out.det[i].kind, i < 10 ? SONAR_DET_OBJECT : SONAR_DET_STRUCTURE);
    /* Fewer object slots: the objects still come first, and structure takes what is left. */
    c.max_clusters = 4;
    assert_int_equal(run_sweep(&c), 4); /* the four largest groups are walls: seeded first, all structure */
    assert_int_equal(out.det[0].kind, SONAR_DET_STRUCTURE);
}

/* The cells' area in square metres: the same object is the same area at 1200 or 600 samples. */
static void test_min_area(void **state)
{
    struct sonar_detector_config c = cfg();
    (void)state;
    memset(fg, 0, sizeof(fg));
    /* 5 beams of 1 gradian x 20 samples of 2 cm at 6.2 m: 100 x 0.0157 rad x 6.2 m x 0.02 m = 0.195 m^2 */
    blob(100, 104, 300, 319, 200);
    c.min_area_m2 = 0.19f;
    assert_int_equal(run_sweep(&c), 1);
    c.min_area_m2 = 0.2f;
    assert_int_equal(run_sweep(&c), 0);
    c.min_area_m2 = -0.1f;
    assert_int_equal(sonar_detector_init(&det, &c), SONAR_ERR_ARG);
    c.min_area_m2 = (float)SONAR_DET_AREA_MAX + 1.0f;
    assert_int_equal(sonar_detector_init(&det, &c), SONAR_ERR_ARG);
}

/*
 * The resolution floor: a cluster must cover a point target's footprint at its range (the sample's depth times
 * the beam's 2 degrees). Cells 1 gradian wide are under half of one: one beam's run is not an echo, three beams'
 * is; near the sonar a small object passes where 0.05 m^2 would drop it.
 */
static void test_min_footprints(void **state)
{
    struct sonar_detector_config c = cfg();
    (void)state;
    c.min_points = 1;
    c.min_footprints = 1.0f;
    memset(fg, 0, sizeof(fg));
    blob(100, 100, 300, 300, 200); /* one cell: 0.0157 rad x 6 m x 0.02 m, under 0.0349 rad x 6 m x 0.02 m */
    assert_int_equal(run_sweep(&c), 0);
    memset(fg, 0, sizeof(fg));
    blob(100, 102, 300, 300, 200); /* three beams, 1 sample: 3 x 0.0157 = 0.047 rad of the 0.0349 */
    assert_int_equal(run_sweep(&c), 1);
    memset(fg, 0, sizeof(fg));
    blob(100, 104, 30, 39, 200); /* 5 beams x 10 samples at 0.7 m: 0.0011 m^2, 0.002 of the footprints' worth */
    assert_int_equal(run_sweep(&c), 1);
    c.min_area_m2 = 0.05f; /* an absolute floor drops it */
    assert_int_equal(run_sweep(&c), 0);
    c.min_area_m2 = 0.0f;
    c.min_footprints = -1.0f;
    assert_int_equal(sonar_detector_init(&det, &c), SONAR_ERR_ARG);
    c.min_footprints = (float)SONAR_DET_FOOTPRINTS_MAX + 1.0f;
    assert_int_equal(sonar_detector_init(&det, &c), SONAR_ERR_ARG);
}

static void test_min_range_and_aspect(void **state)
{
    struct sonar_detector_config c = cfg();
    (void)state;
    memset(fg, 0, sizeof(fg));
    blob(20, 24, 40, 59, 200);    /* 5 x 20 at ~1 m */
    blob(100, 104, 200, 219, 200); /* 5 x 20 at ~4 m: along 0.4 m, across ~0.31 m */
    blob(200, 201, 300, 399, 200); /* a radial streak at 6-8 m: along 2 m, across ~0.22 m */
    assert_int_equal(run_sweep(&c), 3);
    c.min_range_m = 2.0f;
    assert_int_equal(run_sweep(&c), 2);
    c.max_aspect = 2.0f;
    assert_int_equal(run_sweep(&c), 1);
    assert_int_equal(out.det[0].points, 100);
    assert_true(out.det[0].range_m > 3.9f && out.det[0].range_m < 4.5f);
    c.max_aspect = 0.05f;
    assert_int_equal(sonar_detector_init(&det, &c), SONAR_ERR_ARG);
    c.max_aspect = 0.0f;
    c.min_range_m = -1.0f;
    assert_int_equal(sonar_detector_init(&det, &c), SONAR_ERR_ARG);
}

static void test_tracking_confirms_with_fewer_cells(void **state)
{
    struct sonar_detector_config c = cfg();
    int pass;
    (void)state;
    for (pass = 0; pass < 2; pass++) {
        c.track_m = pass ? 1.0f : 0.0f;
        c.track_points = 10;
        memset(fg, 0, sizeof(fg));
        blob(100, 104, 200, 219, 150); /* sweep 1: a clear object at 4 m */
        assert_int_equal(run_sweep(&c), 1);
        memset(fg, 0, sizeof(fg));
        blob(101, 103, 205, 208, 150); /* sweep 2: 12 cells where it was... */
        blob(300, 302, 205, 208, 150); /* ...and 12 cells where nothing was */
        if (!pass) {
            assert_int_equal(next_sweep(), 0); /* no tracking: both below min_points */
            continue;
        }
        assert_int_equal(next_sweep(), 1);
        assert_int_equal(out.det[0].points, 12);
        assert_true(out.det[0].bearing_deg < 100.0f);
        /* sweep 3: the tracked object moved 0.4 m along the beam: still inside the gate */
        memset(fg, 0, sizeof(fg));
        blob(101, 103, 225, 228, 150);
        assert_int_equal(next_sweep(), 1);
        /* sweep 4: a jump of 2 m leaves the gate */
        memset(fg, 0, sizeof(fg));
        blob(101, 103, 325, 328, 150);
        assert_int_equal(next_sweep(), 0);
    }
    c.track_m = 1.0f;
    c.track_points = 0;
    assert_int_equal(sonar_detector_init(&det, &c), SONAR_ERR_ARG);
}

/* Brute force: every pair of runs within lb beams (round the turn) that touch, O(runs^2). */
struct brun {
    int beam, s, e; /* samples [s, e] */
    int parent, size;
};
static struct brun br[SONAR_MAX_RUNS];

static int bfind(int i)
{
    while (br[i].parent != i)
        i = br[i].parent;
    return i;
}

static int cmp_int_desc(const void *a, const void *b)
{
    return *(const int *)b - *(const int *)a;
}

static void test_linking_matches_brute_force(void **state)
{
    int trial;
    (void)state;
    srand(11);
    for (trial = 0; trial < 60; trial++) {
        struct sonar_detector_config c = cfg();
        int n = 0, i, j, k, a, want[SONAR_MAX_RUNS], got[SONAR_MAX_CLUSTERS], nw = 0;
        uint32_t gap;
        memset(fg, 0, sizeof(fg));
        for (k = 0; k < 40; k++) { /* objects */
            int a0 = rand() % 400, s0 = rand() % (N - 40);
            blob(a0, a0 + rand() % 6, s0, s0 + rand() % 30, 200);
        }
        for (k = 0; k < 600; k++) /* speckle */
            fg[rand() % 400][rand() % N] = 200;
        c.threshold_k = 0.0f;
        c.min_threshold = 100;
        c.join_beams = (uint8_t)(1 + rand() % 4);
        c.join_m = (float)(rand() % 31) / 100.0f;
        c.min_points = 25;
        c.max_clusters = SONAR_MAX_CLUSTERS;
        c.iterations = 1;
        (void)run_sweep(&c);
        /* the same runs, by hand */
        for (a = 0; a < 400; a++)
            for (i = 0; i < N; i++)
                if (fg[a][i] > 100) {
                    for (j = i; j + 1 < N && fg[a][j + 1] > 100; j++)
                        ;
                    br[n].beam = a;
                    br[n].s = i;
                    br[n].e = j;
                    br[n].parent = n;
                    br[n].size = 0;
                    n++;
                    i = j;
                }
        assert_true(n <= SONAR_MAX_RUNS);
        assert_int_equal(out.runs, n);
        gap = (uint32_t)((double)c.join_m * N / (double)RANGE);
        for (i = 0; i < n; i++)
            for (j = 0; j < i; j++) {
                int db = abs(br[i].beam - br[j].beam);
                int lo = br[i].s > br[j].s ? br[i].s : br[j].s, hi = br[i].e < br[j].e ? br[i].e : br[j].e;
                if ((db <= c.join_beams || 400 - db <= c.join_beams) && lo <= hi + 1 + (int)gap) {
                    int ri = bfind(i), rj = bfind(j);
                    if (ri != rj)
                        br[ri].parent = rj;
                }
            }
        for (i = 0; i < n; i++)
            br[bfind(i)].size += br[i].e - br[i].s + 1;
        for (i = 0; i < n; i++)
            if (bfind(i) == i && br[i].size >= c.min_points)
                want[nw++] = br[i].size;
        assert_int_equal(out.groups, nw);
        /* up to SONAR_MAX_CLUSTERS groups, each one detection of exactly its cells */
        qsort(want, (size_t)nw, sizeof(int), cmp_int_desc);
        for (i = 0; i < out.count; i++)
            got[i] = (int)out.det[i].points;
        if (nw <= SONAR_MAX_CLUSTERS) {
            assert_int_equal(out.count, nw);
            assert_memory_equal(got, want, (size_t)nw * sizeof(int));
        }
    }
}

static void test_bad_input(void **state)
{
    struct sonar_detector_config c = cfg();
    uint8_t b[4] = {0};
    (void)state;
    assert_int_equal(sonar_detector_init(&det, &c), SONAR_OK);
    assert_int_equal(sonar_detector_add(&det, 400, b, 4, 1.0f, 0), SONAR_ERR_ARG);
    /* Beyond SONAR_DET_DISTANCE_MAX metres the run centres would leave the bounded mm grid. */
    assert_int_equal(sonar_detector_add(&det, 0, b, 4, (float)SONAR_DET_DISTANCE_MAX + 1.0f, 0), SONAR_ERR_ARG);
    assert_int_equal(sonar_detector_add(&det, 0, b, 4, 0.0f, 0), SONAR_ERR_ARG);
    assert_int_equal(sonar_detector_add(&det, 0, b, 4, 1.0f, 0), SONAR_OK);
    assert_int_equal(sonar_detector_add(&det, 1, b, 3, 1.0f, 0), SONAR_ERR_STATE);
    assert_int_equal(sonar_detector_add(&det, 1, b, 4, 2.0f, 0), SONAR_ERR_STATE);
    c.max_clusters = 0;
    assert_int_equal(sonar_detector_init(&det, &c), SONAR_ERR_ARG);
    c = cfg();
    c.join_m = 11.0f;
    assert_int_equal(sonar_detector_init(&det, &c), SONAR_ERR_ARG);
}

/*
 * Speckle that grows toward the sonar (up to 0..59 at the sonar, tapering to 0..14 at 3 m and
 * beyond) and a faint object (level 28) at 9 m: the global mean + 3 std, raised by the near
 * speckle, misses it, and lowered enough to find it the near speckle comes through as objects; the
 * CFAR, which compares each window with the noise along its own beam, finds it alone.
 */
static void test_cfar_follows_the_noise_along_range(void **state)
{
    struct sonar_detector_config c = cfg();
    uint32_t r = 12345u;
    int a, i, k, got, found;
    double ox, oy;
    (void)state;
    memset(fg, 0, sizeof(fg));
    for (a = 0; a < 400; a++)
        for (i = 0; i < N; i++) {
            r ^= r << 13;
            r ^= r >> 17;
            r ^= r << 5;
            fg[a][i] = (uint8_t)(r % (uint32_t)(i < 150 ? 60 - 45 * i / 150 : 15)); /* tapering to 3 m, like ring-down */
        }
    /* Early in the sweep, so that the near speckle's runs at the lowered threshold do not use up SONAR_MAX_RUNS first. */
    blob(4, 8, 440, 470, 28);
    sonar_frame_to_xy(6.0, 0.0, 455.5 * RANGE / N, &ox, &oy);
    for (k = 0; k < 2; k++) /* the global threshold is the previous sweep's */
        got = run_sweep(&c);
    for (found = 0, i = 0; i < got; i++)
        found |= hypot(out.det[i].x_m - ox, out.det[i].y_m - oy) < 0.3;
    assert_false(found);
    c.threshold_k = 1.0f;
    for (k = 0; k < 2; k++)
        got = run_sweep(&c);
    for (found = 0, i = 0; i < got; i++)
        found |= hypot(out.det[i].x_m - ox, out.det[i].y_m - oy) < 0.3;
    assert_true(found);
    assert_true(got >= 2); /* and the near speckle with it */
    c.threshold_mode = SONAR_DET_CFAR;
    c.cfar.cut = 1;
    c.cfar.guard = 1;
    c.cfar.train = 4;
    c.cfar.rank16 = 8;
    c.cfar.scale = 2.5f;
    c.cfar.floor = 8;
    got = run_sweep(&c);
    assert_int_equal(got, 1);
    expect_at(&out.det[0], 6.0, 455.0);
    assert_int_equal(out.threshold, 8); /* the CFAR floor is what the sweep reports */
    /* Its config is checked when CFAR is on, and not otherwise. */
    c.cfar.train = 0;
    assert_int_equal(sonar_detector_init(&det, &c), SONAR_ERR_ARG);
    assert_string_equal(sonar_detector_config_check(&c), "cfar.train: 1..8 blocks");
    c.threshold_mode = SONAR_DET_GLOBAL;
    assert_null(sonar_detector_config_check(&c));
    c.threshold_mode = 2;
    assert_string_equal(sonar_detector_config_check(&c), "threshold_mode: global or cfar");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_separate_objects_separate_detections),
        cmocka_unit_test(test_one_object_stays_whole),
        cmocka_unit_test(test_small_groups_dropped_and_cap),
        cmocka_unit_test(test_wrap_joins_across_zero),
        cmocka_unit_test(test_angle_offset_rotates),
        cmocka_unit_test(test_threshold_uses_previous_sweep),
        cmocka_unit_test(test_run_overflow_counted),
        cmocka_unit_test(test_min_beams_and_max_extent),
        cmocka_unit_test(test_kmeans_stays_inside_groups),
        cmocka_unit_test(test_split_cuts_wide_group),
        cmocka_unit_test(test_lines_are_not_cut),
        cmocka_unit_test(test_structure_after_objects),
        cmocka_unit_test(test_min_area),
        cmocka_unit_test(test_min_footprints),
        cmocka_unit_test(test_min_range_and_aspect),
        cmocka_unit_test(test_tracking_confirms_with_fewer_cells),
        cmocka_unit_test(test_linking_matches_brute_force),
        cmocka_unit_test(test_bad_input),
        cmocka_unit_test(test_cfar_follows_the_noise_along_range),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
