/* test_kmeans.c -- seeding, Lloyd on hand-made blobs, weights, skipped points, determinism, Lloyd kept inside parts. */
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

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_two_blobs),
        cmocka_unit_test(test_weights_and_skips),
        cmocka_unit_test(test_empty_cluster_keeps_centre),
        cmocka_unit_test(test_coordinates_bounded),
        cmocka_unit_test(test_deterministic_and_bounded),
        cmocka_unit_test(test_within_parts),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
