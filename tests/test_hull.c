/* test_hull.c -- monotone chain: collinear and duplicate points, degenerate inputs, random sets checked by brute force. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include <cmocka.h>

#include "sonar/hull.h"

static void test_square_with_collinear_and_duplicates(void **state)
{
    struct sonar_xy p[9] = {{0, 0}, {2, 0}, {4, 0}, {4, 2}, {4, 4}, {2, 4}, {0, 4}, {0, 2}, {4, 4}};
    struct sonar_xy h[18];
    (void)state;
    assert_int_equal(sonar_hull_build(p, 9, h, 18), 4);
    assert_int_equal(h[0].x, 0);
    assert_int_equal(h[0].y, 0);
    assert_int_equal(h[1].x, 4);
    assert_int_equal(h[1].y, 0);
    assert_int_equal(h[2].x, 4);
    assert_int_equal(h[2].y, 4);
    assert_int_equal(h[3].x, 0);
    assert_int_equal(h[3].y, 4);
    assert_true(sonar_hull_area2(h, 4) == 32);
}

static void test_degenerate(void **state)
{
    struct sonar_xy one[1] = {{5, -7}}, same[3] = {{1, 1}, {1, 1}, {1, 1}};
    struct sonar_xy line[4] = {{0, 0}, {3, 3}, {1, 1}, {2, 2}}, h[8];
    (void)state;
    assert_int_equal(sonar_hull_build(one, 1, h, 2), 1);
    assert_int_equal(h[0].y, -7);
    assert_int_equal(sonar_hull_build(same, 3, h, 6), 1);
    assert_int_equal(sonar_hull_build(line, 4, h, 8), 2);
    assert_int_equal(h[0].x, 0);
    assert_int_equal(h[1].x, 3);
    assert_int_equal(sonar_hull_build(line, 4, h, 7), SONAR_ERR_SPACE);
    assert_int_equal(sonar_hull_build(line, 0, h, 8), SONAR_ERR_ARG);
}

static int64_t cross(struct sonar_xy o, struct sonar_xy a, struct sonar_xy b)
{
    return ((int64_t)a.x - o.x) * ((int64_t)b.y - o.y) - ((int64_t)a.y - o.y) * ((int64_t)b.x - o.x);
}

/* Random sets, including huge coordinates: every point inside or on the hull, every turn strictly left. */
static void test_random_against_brute_force(void **state)
{
    static struct sonar_xy p[500], copy[500], h[1000];
    int trial;
    (void)state;
    srand(9);
    for (trial = 0; trial < 200; trial++) {
        int n = 3 + rand() % 400, i, j, k;
        int32_t span = trial % 2 ? 1000000000 : 50;
        for (i = 0; i < n; i++) {
            p[i].x = (int32_t)((rand() % (2 * 1000 + 1)) - 1000) * (span / 1000 ? span / 1000 : 1) / (trial % 2 ? 1 : 20);
            p[i].y = (int32_t)((rand() % (2 * 1000 + 1)) - 1000) * (span / 1000 ? span / 1000 : 1) / (trial % 2 ? 1 : 20);
            copy[i] = p[i];
        }
        k = sonar_hull_build(p, (uint16_t)n, h, 1000);
        assert_true(k >= 1);
        if (k < 3)
            continue;
        for (i = 0; i < k; i++)
            assert_true(cross(h[i], h[(i + 1) % k], h[(i + 2) % k]) > 0);
        for (j = 0; j < n; j++)
            for (i = 0; i < k; i++)
                assert_true(cross(h[i], h[(i + 1) % k], copy[j]) >= 0);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_square_with_collinear_and_duplicates),
        cmocka_unit_test(test_degenerate),
        cmocka_unit_test(test_random_against_brute_force),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
