/* test_kmeans.c -- seeding, Lloyd on hand-made blobs, weights, skipped points, determinism, Lloyd kept inside parts, the pruned search against a plain one. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "sonar/kmeans.h"

static void test_two_blobs(void **state)
{
    struct sonar_point p[8] = {{0, 0, 1}, {10, 0, 1}, {0, 10, 1}, {10, 10, 1},
                               {1000, 1000, 1}, {1010, 1000, 1}, {1000, 1010, 1}, {1010, 1010, 1}};
    struct sonar_xy c[2];
    uint8_t l[8];
    int i;
    (void)state;
    assert_int_equal(sonar_kmeans_seed(p, 8, c, 2), 2);
    assert_int_equal(c[0].x, 0);
    assert_int_equal(c[1].x, 1010); /* farthest from (0, 0) */
    assert_true(sonar_kmeans_lloyd(p, 8, l, c, 2, 10) >= 1);
    for (i = 0; i < 4; i++) {
        assert_int_equal(l[i], 0);
        assert_int_equal(l[i + 4], 1);
    }
    assert_int_equal(c[0].x, 5);
    assert_int_equal(c[0].y, 5);
    assert_int_equal(c[1].x, 1005);
    assert_true(sonar_kmeans_inertia(p, 8, l, c) == 8 * 50.0);
}

static void test_weights_and_skips(void **state)
{
    struct sonar_point p[3] = {{0, 0, 3}, {100, 0, 1}, {5000, 5000, 0}};
    struct sonar_xy c[1] = {{7, 7}};
    uint8_t l[3];
    (void)state;
    assert_true(sonar_kmeans_lloyd(p, 3, l, c, 1, 5) >= 1);
    assert_int_equal(c[0].x, 25); /* (0*3 + 100*1) / 4 */
    assert_int_equal(c[0].y, 0);
    assert_int_equal(l[2], SONAR_KMEANS_SKIP);
    /* seeding ignores weight-0 points and stops at the distinct points */
    assert_int_equal(sonar_kmeans_seed(p, 3, c, 1), 1);
    {
        struct sonar_point same[3] = {{4, 4, 1}, {4, 4, 2}, {4, 4, 1}};
        struct sonar_xy c3[3];
        assert_int_equal(sonar_kmeans_seed(same, 3, c3, 3), 1);
    }
    assert_int_equal(sonar_kmeans_lloyd(p, 3, l, c, 0, 5), SONAR_ERR_ARG);
    assert_int_equal(sonar_kmeans_lloyd(p, 3, l, c, 1, 0), SONAR_ERR_ARG);
}

static void test_empty_cluster_keeps_centre(void **state)
{
    struct sonar_point p[2] = {{0, 0, 1}, {2, 0, 1}};
    struct sonar_xy c[2] = {{1, 0}, {100000, 100000}};
    uint8_t l[2];
    (void)state;
    assert_true(sonar_kmeans_lloyd(p, 2, l, c, 2, 3) >= 1);
    assert_int_equal(c[1].x, 100000);
    assert_int_equal(l[0], 0);
    assert_int_equal(l[1], 0);
}

/* Coordinates beyond SONAR_KMEANS_MAX_COORD are refused, so the int32 differences cannot overflow. */
static void test_coordinates_bounded(void **state)
{
    struct sonar_point p[2] = {{0, 0, 1}, {SONAR_KMEANS_MAX_COORD, -SONAR_KMEANS_MAX_COORD, 1}};
    struct sonar_xy c[2] = {{0, 0}, {10, 10}};
    uint8_t labels[2] = {0, 0}, part[2] = {0, 0};
    (void)state;
    assert_true(sonar_kmeans_lloyd(p, 2, labels, c, 2, 5) > 0); /* at the bound: fine */
    p[1].x = SONAR_KMEANS_MAX_COORD + 1;
    assert_int_equal(sonar_kmeans_seed(p, 2, c, 2), SONAR_ERR_ARG);
    assert_int_equal(sonar_kmeans_lloyd(p, 2, labels, c, 2, 5), SONAR_ERR_ARG);
    assert_int_equal(sonar_kmeans_lloyd_within(p, 2, labels, c, part, 2, 5), SONAR_ERR_ARG);
    p[1].w = 0; /* an unweighted point is ignored, wherever it is */
    labels[0] = labels[1] = 0;
    assert_true(sonar_kmeans_lloyd_within(p, 2, labels, c, part, 2, 5) > 0);
    c[1].y = -SONAR_KMEANS_MAX_COORD - 1; /* and so is a centre out of bounds refused */
    assert_int_equal(sonar_kmeans_lloyd(p, 2, labels, c, 2, 5), SONAR_ERR_ARG);
}

static void test_deterministic_and_bounded(void **state)
{
    static struct sonar_point p[3000];
    struct sonar_xy a[6], b[6];
    static uint8_t la[3000], lb[3000];
    int i, ra, rb;
    (void)state;
    srand(5);
    for (i = 0; i < 3000; i++) {
        p[i].x = (i % 6) * 3000 + rand() % 900;
        p[i].y = (i % 6) * -2000 + rand() % 900;
        p[i].w = 1u + (unsigned)(rand() % 5);
    }
    assert_int_equal(sonar_kmeans_seed(p, 3000, a, 6), 6);
    assert_int_equal(sonar_kmeans_seed(p, 3000, b, 6), 6);
    ra = sonar_kmeans_lloyd(p, 3000, la, a, 6, 10);
    rb = sonar_kmeans_lloyd(p, 3000, lb, b, 6, 10);
    assert_in_range(ra, 1, 10);
    assert_int_equal(ra, rb);
    assert_memory_equal(la, lb, sizeof(la));
    assert_memory_equal(a, b, sizeof(a));
    /* the six blobs come out whole: every blob's points share one label */
    for (i = 6; i < 3000; i++)
        assert_int_equal(la[i], la[i % 6]);
}

static void test_within_parts(void **state)
{
    /*
     * Part 0: a long bar from x = 0 to 900 (a wall); part 1: a small blob at x = 1000, 100 from
     * the bar's end. Free Lloyd lets the blob's centre take the bar's far end; within parts it
     * cannot, and the bar's two centres cut it in two.
     */
    struct sonar_point p[11];
    struct sonar_xy c[3] = {{450, 0}, {900, 0}, {1000, 0}}, f[3];
    const uint8_t part[3] = {0, 0, 1};
    uint8_t l[11], lf[11];
    int i;
    (void)state;
    for (i = 0; i < 10; i++) {
        p[i].x = i * 100;
        p[i].y = 0;
        p[i].w = 1;
        l[i] = 0;
    }
    p[10].x = 1000;
    p[10].y = 0;
    p[10].w = 1;
    l[10] = 2;
    memcpy(f, c, sizeof(f));
    assert_true(sonar_kmeans_lloyd(p, 11, lf, f, 3, 10) >= 1);
    assert_int_equal(lf[9], 2); /* free: the blob's centre steals x = 900 */
    assert_true(sonar_kmeans_lloyd_within(p, 11, l, c, part, 3, 10) >= 2);
    for (i = 0; i < 10; i++)
        assert_int_equal(l[i], i < 6 ? 0 : 1); /* the bar in two; x = 500 is a tie, to the lower index */
    assert_int_equal(l[10], 2);
    assert_int_equal(c[2].x, 1000);
    assert_int_equal(c[0].x, 250);
    assert_int_equal(c[1].x, 750);
    /* one centre per part: only the parts' means */
    {
        struct sonar_xy one[2] = {{0, 0}, {5000, 5000}};
        const uint8_t pp[2] = {7, 9};
        for (i = 0; i < 11; i++)
            l[i] = i < 10 ? 0 : 1;
        assert_true(sonar_kmeans_lloyd_within(p, 11, l, one, pp, 2, 10) >= 1);
        assert_int_equal(one[0].x, 450);
        assert_int_equal(one[1].x, 1000);
    }
    l[3] = 5; /* an entry label beyond k */
    assert_int_equal(sonar_kmeans_lloyd_within(p, 11, l, c, part, 3, 10), SONAR_ERR_ARG);
    p[3].w = 0; /* ...is fine on a skipped point, which comes back SKIP */
    l[3] = 5;
    assert_true(sonar_kmeans_lloyd_within(p, 11, l, c, part, 3, 10) >= 1);
    assert_int_equal(l[3], SONAR_KMEANS_SKIP);
    assert_int_equal(sonar_kmeans_lloyd_within(p, 11, l, c, NULL, 3, 10), SONAR_ERR_ARG);
}

/* The plain Lloyd the pruned search must equal: every centre of the point's part, lowest index on ties. */
static int64_t ref_d2(const struct sonar_point *p, const struct sonar_xy *c)
{
    int64_t dx = (int64_t)p->x - c->x, dy = (int64_t)p->y - c->y;
    return dx * dx + dy * dy;
}

static int32_t ref_mean(int64_t sum, uint64_t w)
{
    int64_t half = (int64_t)(w / 2u);
    return (int32_t)(sum >= 0 ? (sum + half) / (int64_t)w : -((-sum + half) / (int64_t)w));
}

static int ref_lloyd(const struct sonar_point *pts, int n, uint8_t *labels, struct sonar_xy *c, const uint8_t *part,
                     int k, int iterations)
{
    int it, i, j;
    for (it = 0; it < iterations; it++) {
        int64_t sx[64] = {0}, sy[64] = {0};
        uint64_t sw[64] = {0};
        int changed = 0;
        for (i = 0; i < n; i++) {
            int best = -1;
            int64_t bd = 0;
            if (pts[i].w == 0)
                continue;
            for (j = 0; j < k; j++) {
                int64_t d;
                if (part != NULL && labels[i] != SONAR_KMEANS_SKIP && part[j] != part[labels[i]])
                    continue;
                d = ref_d2(&pts[i], &c[j]);
                if (best < 0 || d < bd) {
                    bd = d;
                    best = j;
                }
            }
            changed += best != labels[i];
            labels[i] = (uint8_t)best;
            sx[best] += (int64_t)pts[i].x * pts[i].w;
            sy[best] += (int64_t)pts[i].y * pts[i].w;
            sw[best] += pts[i].w;
        }
        for (j = 0; j < k; j++)
            if (sw[j] > 0) {
                c[j].x = ref_mean(sx[j], sw[j]);
                c[j].y = ref_mean(sy[j], sw[j]);
            }
        if (changed == 0 && (it > 0 || part == NULL))
            return it + 1;
    }
    return iterations;
}

static void test_pruned_search_equals_plain(void **state)
{
    /*
     * Clustered and uniform points on a coarse grid (many exact ties), k = 1..20 (beyond 16 the
     * search is the plain one), free and within parts, 1..25 rounds: labels, centres and rounds
     * all equal, whatever the pruned search, the kept sums and the skipped centres leave out.
     */
    static struct sonar_point p[400];
    static uint8_t l[400], lr[400];
    struct sonar_xy c[20], cr[20];
    uint8_t part[20];
    int trial;
    (void)state;
    srand(5);
    for (trial = 0; trial < 600; trial++) {
        int n = 1 + rand() % 400, k = 1 + rand() % 20, within = trial % 2, i, j, got, want, rounds = 1 + rand() % 25;
        int grid = trial % 3 == 0 ? 1 : 50;
        for (i = 0; i < n; i++) {
            int blob = rand() % 4;
            p[i].x = (blob * 3000 + rand() % 2000) / grid * grid;
            p[i].y = (blob % 2 * 2000 + rand() % 2000) / grid * grid;
            p[i].w = rand() % 8 == 0 ? 0u : (uint32_t)(1 + rand() % 5);
        }
        for (j = 0; j < k; j++) {
            c[j].x = p[rand() % n].x;
            c[j].y = p[rand() % n].y;
            part[j] = (uint8_t)(within ? rand() % 3 : 0);
        }
        for (i = 0; i < n; i++) {
            /* entry labels: a centre of a random part present */
            l[i] = (uint8_t)(rand() % k);
        }
        memcpy(cr, c, sizeof(c));
        memcpy(lr, l, sizeof(l));
        if (within) {
            for (i = 0; i < n; i++)
                if (p[i].w == 0)
                    lr[i] = SONAR_KMEANS_SKIP;
            got = sonar_kmeans_lloyd_within(p, (uint16_t)n, l, c, part, (uint8_t)k, (uint8_t)rounds);
            want = ref_lloyd(p, n, lr, cr, part, k, rounds);
        } else {
            memset(lr, SONAR_KMEANS_SKIP, sizeof(lr));
            got = sonar_kmeans_lloyd(p, (uint16_t)n, l, c, (uint8_t)k, (uint8_t)rounds);
            want = ref_lloyd(p, n, lr, cr, NULL, k, rounds);
        }
        assert_int_equal(got, want);
        for (i = 0; i < n; i++)
            assert_int_equal(l[i], lr[i]);
        for (j = 0; j < k; j++) {
            assert_int_equal(c[j].x, cr[j].x);
            assert_int_equal(c[j].y, cr[j].y);
        }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_two_blobs),
        cmocka_unit_test(test_weights_and_skips),
        cmocka_unit_test(test_empty_cluster_keeps_centre),
        cmocka_unit_test(test_coordinates_bounded),
        cmocka_unit_test(test_deterministic_and_bounded),
        cmocka_unit_test(test_within_parts),
        cmocka_unit_test(test_pruned_search_equals_plain),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
