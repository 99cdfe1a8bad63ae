/* test_detector_stages.c -- the detector's stages one at a time through detector_internal.h: runs and threshold, linking, grouping and cutting (the cuts against a plain reference), rules and emission; and the frame vocabulary they share. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>
#include <math.h>

#include "detector_internal.h"
#include "sonar/frame.h"

#define N 100
#define RANGE 10.0f

static struct sonar_detector det;
static uint8_t beam[N];

static struct sonar_detector_config cfg(void)
{
    struct sonar_detector_config c;
    memset(&c, 0, sizeof(c));
    c.threshold_k = 0.0f;
    c.min_threshold = 16; /* T = 16 with k = 0 over a dark sweep */
    c.max_clusters = 8;
    c.iterations = 10;
    c.join_beams = 1;
    c.min_points = 4;
    c.join_m = 0.0f;
    return c;
}

/* Adds beam at angle a with cells [s0, s1] at level v (0 elsewhere). */
static void add(uint16_t a, int s0, int s1, uint8_t v)
{
    int i;
    memset(beam, 0, sizeof(beam));
    for (i = s0; i <= s1; i++)
        beam[i] = v;
    assert_int_equal(sonar_detector_add(&det, a, beam, N, RANGE, 1000 + a), SONAR_OK);
}

static void test_frame_vocabulary(void **state)
{
    double x, y;
    (void)state;
    assert_int_equal(sonar_frame_delta(399, 0), 1);
    assert_int_equal(sonar_frame_delta(0, 399), -1);
    assert_int_equal(sonar_frame_delta(0, 200), -200);
    assert_int_equal(sonar_frame_delta(10, 30), 20);
    assert_int_equal(sonar_frame_delta(410, 5), -5); /* inputs taken mod 400 */
    assert_int_equal(sonar_frame_gap(399, 1), 2);
    assert_int_equal(sonar_frame_gap(0, 200), 200);
    assert_int_equal(sonar_frame_gap(0, 201), 199);
    assert_true(fabs(sonar_frame_rad(100) - SONAR_PI / 2) < 1e-15);
    assert_true(fabs(sonar_frame_deg(SONAR_PI) - 180.0) < 1e-12);
    sonar_frame_to_xy(100, 0, 2.0, &x, &y);
    assert_true(fabs(x) < 1e-12 && fabs(y - 2.0) < 1e-12);
    assert_true(fabs(sonar_frame_bearing_deg(0.0, -1.0) - 270.0) < 1e-12);
    assert_true(sonar_frame_bearing_deg(0.0, 0.0) == 0.0);
}

static void test_runs_threshold_and_polar(void **state)
{
    struct sonar_detector_config c = cfg();
    struct sonar_xy p;
    (void)state;
    assert_int_equal(sonar_detector_init(&det, &c), SONAR_OK);
    add(100, 10, 19, 50);
    add(101, 90, 99, 17); /* a run that ends at the last sample */
    assert_int_equal(det.nruns, 2);
    assert_int_equal(det.runs[0].beam, 0);
    assert_int_equal(det.runs[0].start, 10);
    assert_int_equal(det.pts[0].w, 10);
    assert_int_equal(det.runs[0].sum, 500);
    assert_int_equal(det.runs[1].start, 90);
    assert_int_equal(det.pts[1].w, 10);
    assert_int_equal(det.threshold, 16);
    /* The run's centre: samples 10..19 of 100 over 10 m are 1.0..2.0 m, centre 1.5 m, at 90 degrees. */
    assert_true(abs(det.pts[0].x) <= 1);
    assert_true(abs(det.pts[0].y - 1500) <= 1);
    p = sonar_det_polar_mm(&det, 0, 2u * 49u + 1u); /* sample 49's centre at angle 0: 4.95 m on +x */
    assert_int_equal(p.x, 4950);
    assert_int_equal(p.y, 0);
    p = sonar_det_polar_mm(&det, 300, 2u * 49u + 1u);
    assert_true(abs(p.x) <= 1 && p.y == -4950);
    /* Geometry must not change within a sweep; angles stay 0..399. */
    assert_int_equal(sonar_detector_add(&det, 102, beam, N / 2, RANGE, 0), SONAR_ERR_STATE);
    assert_int_equal(sonar_detector_add(&det, 400, beam, N, RANGE, 0), SONAR_ERR_ARG);
}

static void test_link_by_beams_and_gap(void **state)
{
    struct sonar_detector_config c = cfg();
    (void)state;
    c.join_beams = 1;
    c.join_m = 0.3f; /* 3 samples at 10 m / 100 */
    assert_int_equal(sonar_detector_init(&det, &c), SONAR_OK);
    add(10, 10, 14, 40);               /* run 0 */
    add(11, 17, 20, 40);               /* run 1: 2 samples' gap from run 0: linked */
    add(12, 40, 44, 40);               /* run 2: far in range: not linked */
    add(13, 0, -1, 0);                 /* an empty beam: linking counts beams of the sweep, not gradians */
    add(14, 40, 44, 40);               /* run 3: two beams after run 2 with join_beams 1: not linked */
    add(15, 36, 41, 40);               /* run 4: overlaps run 3 in range, next beam */
    memset(beam, 0, sizeof(beam));
    beam[30] = beam[31] = 40;          /* run 5: 4 samples short of run 4 (gap 3): only through run 6 */
    beam[33] = beam[34] = 40;          /* run 6: 1 sample from run 4 and from run 5 */
    assert_int_equal(det.nruns, 5);
    assert_int_equal(sonar_detector_add(&det, 16, beam, N, RANGE, 0), SONAR_OK);
    sonar_det_join(&det);
    assert_int_equal(sonar_det_find(det.runs, 1), sonar_det_find(det.runs, 0));
    assert_int_not_equal(sonar_det_find(det.runs, 2), sonar_det_find(det.runs, 1));
    assert_int_not_equal(sonar_det_find(det.runs, 3), sonar_det_find(det.runs, 2));
    assert_int_equal(sonar_det_find(det.runs, 3), sonar_det_find(det.runs, 4)); /* adjacent beams, touching */
    assert_int_equal(sonar_det_find(det.runs, 6), sonar_det_find(det.runs, 4)); /* beam 16's run 6: to beam 15's */
    assert_int_equal(sonar_det_find(det.runs, 5), sonar_det_find(det.runs, 6)); /* run 5: to its neighbour */
    c.join_m = 0.0f;
    assert_int_equal(sonar_detector_init(&det, &c), SONAR_OK);
    add(10, 10, 14, 40);
    add(11, 17, 20, 40); /* no gap allowed now */
    sonar_det_join(&det);
    assert_int_not_equal(sonar_det_find(det.runs, 1), sonar_det_find(det.runs, 0));
}

static void test_seed_keeps_largest_groups_and_cuts_wide_ones(void **state)
{
    struct sonar_detector_config c = cfg();
    struct sonar_xy centres[SONAR_MAX_CLUSTERS];
    uint8_t part[SONAR_MAX_CLUSTERS];
    uint16_t groups;
    uint8_t k;
    int a;
    (void)state;
    c.max_clusters = 2;
    c.min_points = 10;
    assert_int_equal(sonar_detector_init(&det, &c), SONAR_OK);
    add(50, 10, 29, 40);  /* 20 cells */
    add(60, 50, 55, 40);  /* 6 cells: noise */
    add(70, 60, 89, 40);  /* 30 cells */
    add(80, 10, 21, 40);  /* 12 cells: beyond max_clusters */
    sonar_det_join(&det);
    k = sonar_det_seed(&det, centres, part, &groups);
    assert_int_equal(groups, 3);       /* groups big enough to seed */
    assert_int_equal(k, 2);            /* the two largest */
    assert_int_equal(det.labels[2], 0); /* the 30-cell group gets centre 0 */
    assert_int_equal(det.labels[0], 1);
    assert_int_equal(det.labels[1], SONAR_KMEANS_SKIP);
    assert_int_equal(det.labels[3], SONAR_KMEANS_SKIP);
    assert_int_equal(det.pts[3].w, 0);
    /* A wall 100 gradians wide at 5 m is ~7.8 m across: with max_extent 2 m it gets a centre per metre. */
    c = cfg();
    c.max_extent_m = 2.0f;
    c.split_points = 5;
    c.join_beams = 1;
    assert_int_equal(sonar_detector_init(&det, &c), SONAR_OK);
    for (a = 50; a < 150; a++)
        add((uint16_t)a, 48, 52, 40);
    sonar_det_join(&det);
    k = sonar_det_seed(&det, centres, part, &groups);
    assert_int_equal(groups, 1);
    assert_true(k >= 7 && k <= SONAR_MAX_CLUSTERS);
    for (a = 0; a < k; a++)
        assert_int_equal(part[a], 0); /* every centre belongs to the one group */
}

/* The plain cut the seeding must equal: every run end on the box, every run rescanned for each new centre. */
static int64_t ref_d2(struct sonar_xy a, int32_t x, int32_t y)
{
    int64_t dx = (int64_t)a.x - x, dy = (int64_t)a.y - y;
    return dx * dx + dy * dy;
}

/* Is group j a line (detector.h): each beam's first to last cell of it, deeper than SONAR_DET_LINE_M on at most 2/16 of its beams? */
static int ref_line(const struct sonar_detector *d, uint8_t j)
{
    uint16_t b, i, beams = 0, thick = 0;
    uint32_t line = (uint32_t)((double)SONAR_DET_LINE_M * (double)d->n / (double)d->range_m) + 1u;
    for (b = 0; b < d->beams; b++) {
        uint32_t lo = UINT32_MAX, hi = 0;
        for (i = 0; i < d->nruns; i++)
            if (d->pts[i].w > 0 && d->labels[i] == j && d->runs[i].beam == b) {
                lo = d->runs[i].start < lo ? d->runs[i].start : lo;
                hi = d->runs[i].start + d->pts[i].w - 1u > hi ? d->runs[i].start + d->pts[i].w - 1u : hi;
            }
        if (lo == UINT32_MAX)
            continue;
        beams++;
        thick = (uint16_t)(thick + (hi - lo + 1u > line));
    }
    return 8u * thick <= beams;
}

static uint8_t ref_cut(struct sonar_detector *d, struct sonar_xy *c, uint8_t *part, uint8_t k)
{
    uint8_t ng = k, j;
    for (j = 0; j < ng; j++) {
        int32_t x0 = INT32_MAX, x1 = INT32_MIN, y0 = INT32_MAX, y1 = INT32_MIN, width;
        int64_t lim = (int64_t)((double)d->cfg.max_extent_m * 1000.0), piece = lim / 2 > 0 ? lim / 2 : 1, want, have;
        int32_t far = -1;
        int64_t far_d = 0;
        uint16_t i;
        for (i = 0; i < d->nruns; i++) {
            int e;
            if (d->pts[i].w == 0 || d->labels[i] != j)
                continue;
            for (e = 0; e < 2; e++) {
                struct sonar_xy p = sonar_det_polar_mm(d, d->angles[d->runs[i].beam],
                                                       2u * (d->runs[i].start + (e ? d->pts[i].w - 1u : 0u)) + 1u);
                x0 = p.x < x0 ? p.x : x0;
                x1 = p.x > x1 ? p.x : x1;
                y0 = p.y < y0 ? p.y : y0;
                y1 = p.y > y1 ? p.y : y1;
            }
        }
        width = x1 - x0 > y1 - y0 ? x1 - x0 : y1 - y0;
        if (width <= lim || ref_line(d, j))
            continue;
        want = (width + piece - 1) / piece;
        for (i = 0; i < d->nruns; i++)
            if (d->pts[i].w > 0 && d->labels[i] == j && ref_d2(c[j], d->pts[i].x, d->pts[i].y) > far_d) {
                far_d = ref_d2(c[j], d->pts[i].x, d->pts[i].y);
                far = i;
            }
        for (have = 1; have < want && k < SONAR_MAX_CLUSTERS && far >= 0; have++) {
            c[k].x = d->pts[far].x;
            c[k].y = d->pts[far].y;
            far = -1;
            far_d = 0;
            for (i = 0; i < d->nruns; i++) {
                int64_t dk, dl;
                if (d->pts[i].w == 0 || d->labels[i] >= k || part[d->labels[i]] != j)
                    continue;
                dk = ref_d2(c[k], d->pts[i].x, d->pts[i].y);
                dl = ref_d2(c[d->labels[i]], d->pts[i].x, d->pts[i].y);
                if (dk < dl) {
                    d->labels[i] = k;
                    dl = dk;
                }
                if (dl > far_d) {
                    far_d = dl;
                    far = i;
                }
            }
            part[k] = j;
            k++;
        }
    }
    return k;
}

static void test_cuts_equal_plain_ones(void **state)
{
    /*
     * Random sweeps of blobs and speckle at ranges up to the bound: the seeding's cuts (widths from
     * each beam's end cells, only the centres a new one can take runs from rescanned) give the
     * labels, centres and parts of the plain cut, which boxes every run end and rescans every run.
     * Beams and samples within the build's grid (the STM32F405's is smaller).
     */
    static struct sonar_detector plain;
    static uint8_t b[600];
    int trial;
    (void)state;
    srand(11);
    for (trial = 0; trial < 150; trial++) {
        struct sonar_detector_config c = cfg();
        struct sonar_xy cg[SONAR_MAX_CLUSTERS], cr[SONAR_MAX_CLUSTERS];
        uint8_t pg[SONAR_MAX_CLUSTERS], pr[SONAR_MAX_CLUSTERS], kg, kr;
        uint16_t groups;
        int nb = 10 + rand() % (SONAR_MAX_SWEEP_BEAMS < 200 ? SONAR_MAX_SWEEP_BEAMS - 10 : 190),
            n = 50 + rand() % (SONAR_MAX_SAMPLES < 600 ? SONAR_MAX_SAMPLES - 50 : 550), blobs = 1 + rand() % 10, i, s;
        float range = trial == 0 ? (float)SONAR_DET_DISTANCE_MAX : 1.0f + (float)(rand() % 1000) / 10.0f;
        c.max_clusters = (uint8_t)(1 + rand() % SONAR_MAX_CLUSTERS);
        c.min_points = (uint16_t)(1 + rand() % 10);
        c.join_beams = (uint8_t)(1 + rand() % 3);
        c.max_extent_m = range / (float)(2 + rand() % 40);
        c.split_points = 1;
        assert_int_equal(sonar_detector_init(&det, &c), SONAR_OK);
        for (s = 0; s < nb; s++) {
            memset(b, 0, sizeof(b));
            for (i = 0; i < blobs; i++) {
                int at = (i * 7919 + trial * 104729) % n, len = 1 + (i * 31 + trial) % (n / 4 + 1), j;
                if ((s + i * 13) % (nb / (i + 1) + 1) > nb / 3)
                    continue;
                for (j = at; j < at + len && j < n; j++)
                    b[j] = (uint8_t)(rand() % 4 ? 40 : 0);
            }
            for (i = 0; i < n / 40; i++)
                b[rand() % n] = 40;
            assert_int_equal(sonar_detector_add(&det, (uint16_t)(s * 400 / nb), b, (uint16_t)n, range, s), SONAR_OK);
        }
        sonar_det_join(&det);
        memcpy(&plain, &det, sizeof(det));
        kg = sonar_det_seed(&det, cg, pg, &groups);
        plain.cfg.max_extent_m = 0.0f; /* groups only: the reference cuts them */
        kr = sonar_det_seed(&plain, cr, pr, &groups);
        plain.cfg.max_extent_m = c.max_extent_m;
        kr = ref_cut(&plain, cr, pr, kr);
        assert_int_equal(kg, kr);
        assert_memory_equal(det.labels, plain.labels, det.nruns);
        for (i = 0; i < kg; i++) {
            assert_int_equal(cg[i].x, cr[i].x);
            assert_int_equal(cg[i].y, cr[i].y);
            assert_int_equal(pg[i], pr[i]);
        }
    }
}

static void test_emit_rules_and_detection(void **state)
{
    struct sonar_detector_config c = cfg();
    struct sonar_xy centres[SONAR_MAX_CLUSTERS], at;
    struct sonar_detection o;
    struct sonar_det_cluster cl;
    uint8_t part[SONAR_MAX_CLUSTERS];
    uint16_t groups;
    int a;
    (void)state;
    assert_int_equal(sonar_detector_init(&det, &c), SONAR_OK);
    for (a = 0; a < 5; a++)
        add((uint16_t)a, 40, 49, 60); /* 5 beams x 10 cells at 4..5 m around angle 2 */
    sonar_det_join(&det);
    assert_int_equal(sonar_det_seed(&det, centres, part, &groups), 1);
    sonar_det_clusters(&det, 1, &cl);
    assert_int_equal(cl.nbeams, 5);
    assert_int_equal(cl.rlo, 40);
    assert_int_equal(cl.rhi, 49);
    assert_int_equal(sonar_det_accept(&det, 0, &cl, 0, &o, &at), 1);
    assert_int_equal(o.points, 50);
    assert_true(fabs(o.mean_intensity - 60.0f) < 1e-6);
    assert_true(fabs(o.range_m - 4.5f) < 0.02);
    assert_true(fabs(o.bearing_deg - 1.8f) < 0.05);
    assert_true(o.hull_count >= 4 && o.area_m2 > 0.0f);
    assert_true(abs(at.x - 4498) < 5);
    /* The same cluster against each rule. */
    det.cfg.min_range_m = 5.0f;
    assert_int_equal(sonar_det_accept(&det, 0, &cl, 0, &o, &at), 0);
    det.cfg.min_range_m = 0.0f;
    det.cfg.min_beams = 6;
    assert_int_equal(sonar_det_accept(&det, 0, &cl, 0, &o, &at), 0);
    det.cfg.min_beams = 0;
    det.cfg.max_extent_m = 0.5f; /* ~1.1 m along the diagonal: structure, not an object */
    assert_int_equal(sonar_det_accept(&det, 0, &cl, 0, &o, &at), 2);
    assert_int_equal(o.kind, SONAR_DET_STRUCTURE);
    det.cfg.max_extent_m = 0.0f;
    det.cfg.max_aspect = 0.5f;   /* 1 m along, ~0.28 m across */
    assert_int_equal(sonar_det_accept(&det, 0, &cl, 0, &o, &at), 0);
    det.cfg.max_aspect = 0.0f;
    det.cfg.split_points = 60;
    assert_int_equal(sonar_det_accept(&det, 0, &cl, 1, &o, &at), 0); /* a cut piece needs split_points cells */
    assert_int_equal(sonar_det_accept(&det, 0, &cl, 0, &o, &at), 1); /* a whole group does not */
    assert_int_equal(o.kind, SONAR_DET_OBJECT);
    /* Its beams' depth: 10 cells of 10 cm, not a line at 0.3 m; a cut piece that is a line is a piece of wall. */
    assert_int_equal(cl.thick, 5);
    det.cfg.split_points = 0;
    cl.thick = 0;
    assert_int_equal(sonar_det_accept(&det, 0, &cl, 1, &o, &at), 2);
    assert_int_equal(sonar_det_accept(&det, 0, &cl, 0, &o, &at), 1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_frame_vocabulary),
        cmocka_unit_test(test_runs_threshold_and_polar),
        cmocka_unit_test(test_link_by_beams_and_gap),
        cmocka_unit_test(test_seed_keeps_largest_groups_and_cuts_wide_ones),
        cmocka_unit_test(test_cuts_equal_plain_ones),
        cmocka_unit_test(test_emit_rules_and_detection),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
