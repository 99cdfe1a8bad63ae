/* test_clutter.c -- the clutter map: what a look learns and forgets, a burst bounded, the density shrunk toward the site's mean, the floor, a range change, its bytes and damaged bytes refused. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <math.h>

#include <cmocka.h>

#include "sonar/clutter.h"

#define RANGE 15.0f

static struct sonar_clutter map;

/* n looks over everywhere, each teaching k detections at x, y first. */
static void looks(struct sonar_clutter *m, int n, float x, float y, unsigned k)
{
    int i;
    for (i = 0; i < n; i++) {
        sonar_clutter_teach(m, x, y, (float)k);
        assert_int_equal(sonar_clutter_look(m, NULL, 0.0f, RANGE), SONAR_OK);
    }
}

static void test_learns_where_clutter_is(void **state)
{
    float hot, cold, after;
    (void)state;
    sonar_clutter_init(&map);
    assert_true(sonar_clutter_density(&map, 5.0f, 0.0f) == SONAR_CLUTTER_FLOOR); /* nothing learnt */
    looks(&map, 60, 5.0f, 0.0f, 1);
    hot = sonar_clutter_density(&map, 5.0f, 0.0f);
    cold = sonar_clutter_density(&map, -5.0f, 0.0f);
    assert_true(hot > 10.0f * cold);
    /* one detection a look in a cell of about 1.2 m^2 at 5 m: near 1 / area, less its shrinkage */
    assert_true(hot > 0.4f && hot < 1.2f);
    assert_true(map.site > 0.0f);
    /* it forgets: 200 quiet looks and the place is as the rest of the site */
    looks(&map, 200, 5.0f, 0.0f, 0);
    after = sonar_clutter_density(&map, 5.0f, 0.0f);
    assert_true(after < 0.05f * hot);
    assert_int_equal(map.looks, 260u);
    assert_int_equal(map.taught, 59u); /* the first was taught before any look gave the map its range */
}

static void test_burst_is_bounded(void **state)
{
    struct sonar_clutter_summary s;
    (void)state;
    sonar_clutter_init(&map);
    looks(&map, 30, 0.0f, 0.0f, 0);
    /* a wake: 12 detections in one cell on one look teach at most SONAR_CLUTTER_BURST; 200 saturate the cell */
    looks(&map, 1, 3.0f, 3.0f, 12);
    assert_true(fabsf(map.capped - (12.0f - (float)SONAR_CLUTTER_BURST)) < 1e-3f);
    sonar_clutter_summarise(&map, &s);
    assert_true(s.per_look <= (float)SONAR_CLUTTER_BURST / 31.0f * 1.01f);
    assert_true(s.peak > 0.0f && fabsf(s.peak_range_m - 4.22f) < 0.5f);
    /* and it fades: it does not make the place clutter for good */
    looks(&map, 300, 0.0f, 0.0f, 0);
    assert_true(sonar_clutter_density(&map, 3.0f, 3.0f) < 0.02f * s.peak);
}

/* Teaching saturates a cell's pending count (200 detections at once: 15.9 held), in 1/16ths (half a detection: 0.5). */
static void test_teaching_saturates(void **state)
{
    int i;
    (void)state;
    sonar_clutter_init(&map);
    looks(&map, 1, 0.0f, 0.0f, 0);
    for (i = 0; i < 20; i++)
        sonar_clutter_teach(&map, 3.0f, 3.0f, 10.0f);
    assert_int_equal(map.c[4][3].pend, 255);
    sonar_clutter_teach(&map, -3.0f, 3.0f, 0.5f);
    sonar_clutter_teach(&map, -3.0f, 3.0f, -1.0f); /* nothing */
    sonar_clutter_teach(&map, -3.0f, 3.0f, NAN);  /* nothing */
    assert_true(fabsf(map.taught - 200.5f) < 1e-3f); /* counted as given; the cell held 15.9 of them */
    assert_int_equal(sonar_clutter_look(&map, NULL, 0.0f, RANGE), SONAR_OK);
    assert_int_equal(map.c[4][3].pend, 0);
    assert_true(fabsf(map.capped - (255.0f / 16.0f - (float)SONAR_CLUTTER_BURST)) < 1e-3f);
}

static void test_only_what_was_looked_at(void **state)
{
    uint8_t cover[50];
    float before;
    (void)state;
    sonar_clutter_init(&map);
    looks(&map, 20, 5.0f, 0.0f, 1);
    before = sonar_clutter_density(&map, 5.0f, 0.0f);
    /* looks that never reach that sector (gradians 100..199 only) leave its learning alone */
    memset(cover, 0, sizeof(cover));
    memset(cover + 13, 0xff, 11);
    for (int i = 0; i < 20; i++)
        assert_int_equal(sonar_clutter_look(&map, cover, 0.0f, RANGE), SONAR_OK);
    assert_true(fabsf(sonar_clutter_density(&map, 5.0f, 0.0f) - before) < 0.05f * before);
}

static void test_range_change_and_bad_input(void **state)
{
    (void)state;
    sonar_clutter_init(&map);
    looks(&map, 10, 5.0f, 0.0f, 1);
    assert_int_equal(sonar_clutter_look(&map, NULL, 0.0f, 0.05f), SONAR_ERR_ARG);
    assert_int_equal(sonar_clutter_look(NULL, NULL, 0.0f, RANGE), SONAR_ERR_ARG);
    assert_int_equal(sonar_clutter_look(&map, NULL, 0.0f, NAN), SONAR_ERR_ARG);
    assert_int_equal(map.looks, 10u); /* refused looks change nothing */
    assert_int_equal(sonar_clutter_look(&map, NULL, 0.0f, 30.0f), SONAR_OK);
    assert_int_equal(map.resets, 1u);
    assert_true(sonar_clutter_density(&map, 5.0f, 0.0f) == SONAR_CLUTTER_FLOOR);
    sonar_clutter_teach(&map, 100.0f, 0.0f, 5); /* beyond the range: nothing */
    sonar_clutter_teach(NULL, 1.0f, 0.0f, 5);
    assert_true(sonar_clutter_density(NULL, 1.0f, 1.0f) == SONAR_CLUTTER_FLOOR);
    assert_true(sonar_clutter_density(&map, 100.0f, 0.0f) == SONAR_CLUTTER_FLOOR);
}

static void test_bytes_round_trip_and_damage(void **state)
{
    static uint8_t buf[SONAR_CLUTTER_WIRE + 8];
    static struct sonar_clutter back;
    int n;
    (void)state;
    sonar_clutter_init(&map);
    looks(&map, 40, 5.0f, 0.0f, 1);
    looks(&map, 40, -2.0f, 7.0f, 2);
    assert_int_equal(sonar_clutter_encode(&map, buf, 10), SONAR_ERR_SPACE);
    n = sonar_clutter_encode(&map, buf, sizeof(buf));
    assert_int_equal(n, (int)SONAR_CLUTTER_WIRE);
    sonar_clutter_init(&back);
    assert_int_equal(sonar_clutter_decode(&back, buf, (size_t)n), SONAR_OK);
    assert_true(fabsf(back.range_m - map.range_m) < 1e-3f);
    assert_true(fabsf(sonar_clutter_density(&back, 5.0f, 0.0f) - sonar_clutter_density(&map, 5.0f, 0.0f)) < 1e-4f);
    assert_true(fabsf(sonar_clutter_density(&back, -2.0f, 7.0f) - sonar_clutter_density(&map, -2.0f, 7.0f)) < 1e-4f);
    assert_true(fabsf(back.site - map.site) < 1e-6f);
    /* damaged: refused, the map it would have replaced untouched */
    assert_int_equal(sonar_clutter_decode(&back, buf, (size_t)n - 1), SONAR_ERR_LENGTH);
    buf[40] ^= 0x10;
    sonar_clutter_init(&back);
    assert_int_equal(sonar_clutter_decode(&back, buf, (size_t)n), SONAR_ERR_RANGE);
    assert_true(back.range_m == 0.0f && back.looks == 0);
    buf[40] ^= 0x10;
    buf[0] = 'X';
    assert_int_equal(sonar_clutter_decode(&back, buf, (size_t)n), SONAR_ERR_ID);
    assert_int_equal(sonar_clutter_decode(NULL, buf, (size_t)n), SONAR_ERR_ARG);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_learns_where_clutter_is),
        cmocka_unit_test(test_burst_is_bounded),
        cmocka_unit_test(test_teaching_saturates),
        cmocka_unit_test(test_only_what_was_looked_at),
        cmocka_unit_test(test_range_change_and_bad_input),
        cmocka_unit_test(test_bytes_round_trip_and_damage),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
