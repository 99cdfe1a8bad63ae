/* test_structure.c -- the structure rule's places: an echo there from the first look that stands is structure after structure_s and not before; one that came in later, or comes and goes, never is; forgetting, eviction, restart and bad input. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "sonar/structure.h"

#define SWEEP_US 4000000 /* a sweep every 4 s */

static struct sonar_structure s;

static struct sonar_structure_obs at(float x, float y, uint8_t first_look, int sweep)
{
    struct sonar_structure_obs o;
    o.x_m = x;
    o.y_m = y;
    o.radius_m = 0.4f;
    o.utime = (int64_t)sweep * SWEEP_US;
    o.first_look = first_look;
    return o;
}

/* One sweep with the given detections; returns how many are structure, is[] for each. */
static int sweep(const struct sonar_structure_obs *o, uint8_t n, int k, uint8_t *is)
{
    return sonar_structure_sweep(&s, o, n, (int64_t)k * SWEEP_US + 1000, is);
}

static void test_first_look_that_stands_is_structure_after_structure_s(void **state)
{
    uint8_t is[2];
    int k;
    (void)state;
    assert_int_equal(sonar_structure_init(&s, 30.0f), SONAR_OK);
    for (k = 0; k < 12; k++) {
        /* The ladder: there at the first look (sweeps 0-1), then seen where the background has learnt. */
        struct sonar_structure_obs o = at(-0.5f + 0.05f * (float)(k % 3), 8.0f, k < 2, k);
        int r = sweep(&o, 1, k, is);
        /* 30 s is sweep 7.5: structure from sweep 8 on, an object before: static since start once seen 3 times. */
        assert_int_equal(r, k >= 8 ? 1 : 0);
        assert_int_equal(is[0], k >= 8 ? SONAR_DET_STRUCTURE : k >= 2 ? SONAR_DET_STATIC_START : SONAR_DET_OBJECT);
    }
    assert_int_equal(sonar_structure_count(&s), 1);
    assert_int_equal(s.promoted, 1);
    assert_int_equal(s.detections, 4);
}

/* A reload's new angle offset turns the places with the frame: the ladder, turned 90 degrees, is still structure there. */
static void test_turned_with_the_frame(void **state)
{
    uint8_t is[1];
    int k;
    (void)state;
    assert_int_equal(sonar_structure_init(&s, 10.0f), SONAR_OK);
    for (k = 0; k < 6; k++) {
        struct sonar_structure_obs o = at(0.0f, 8.0f, k < 2, k);
        assert_true(sweep(&o, 1, k, is) >= 0);
    }
    assert_int_equal(is[0], 1);
    sonar_structure_turn(&s, 90.0f); /* 8 m to starboard becomes 8 m astern */
    {
        struct sonar_structure_obs o = at(-8.0f, 0.0f, 0, k);
        assert_int_equal(sweep(&o, 1, k, is), 1);
        assert_int_equal(is[0], 1);
    }
    {
        struct sonar_structure_obs o = at(0.0f, 8.0f, 0, k + 1); /* where it was: nothing learnt there now */
        assert_int_equal(sweep(&o, 1, k + 1, is), 0);
    }
}

static void test_what_came_in_later_is_never_structure(void **state)
{
    uint8_t is[1];
    int k;
    (void)state;
    assert_int_equal(sonar_structure_init(&s, 10.0f), SONAR_OK);
    for (k = 0; k < 40; k++) {
        /* A diver who swam in and stopped: first seen where the background knew the water. */
        struct sonar_structure_obs o = at(3.0f, 3.0f, 0, k);
        assert_int_equal(sweep(&o, 1, k, is), 0);
        assert_int_equal(is[0], SONAR_DET_OBJECT); /* nor static since start */
    }
    assert_int_equal(sonar_structure_count(&s), 0);
    assert_int_equal(s.n, 0); /* not even a place: nothing that came in later is kept */
}

static void test_comes_and_goes_is_never_structure(void **state)
{
    uint8_t is[1];
    int k;
    (void)state;
    assert_int_equal(sonar_structure_init(&s, 10.0f), SONAR_OK);
    for (k = 0; k < 40; k++) {
        /* Seen at the first look, then one sweep in three (a swimmer's lane crossing it): it did not stand there. */
        struct sonar_structure_obs o = at(2.0f, -4.0f, k < 2, k);
        if (k < 2 || (k >= 4 && k % 3 == 1)) {
            assert_int_equal(sweep(&o, 1, k, is), 0);
            assert_int_equal(is[0], SONAR_DET_OBJECT); /* it did not stand there since the first look */
        } else
            assert_int_equal(sweep(NULL, 0, k, is), 0);
    }
    assert_int_equal(sonar_structure_count(&s), 0);
}

/* Off (no survey, --structure-s 0): never structure, but what stood since the first look says so: static since start. */
static void test_off_means_never(void **state)
{
    uint8_t is[1];
    int k;
    (void)state;
    assert_int_equal(sonar_structure_init(&s, 0.0f), SONAR_OK);
    for (k = 0; k < 100; k++) {
        struct sonar_structure_obs o = at(1.0f, 1.0f, 1, k);
        assert_int_equal(sweep(&o, 1, k, is), 0);
        assert_int_equal(is[0], k >= SONAR_PLACE_MIN_SEEN - 1 ? SONAR_DET_STATIC_START : SONAR_DET_OBJECT);
    }
    assert_int_equal(s.promoted, 0);
}

static void test_forgotten_evicted_restarted(void **state)
{
    struct sonar_structure_obs o[SONAR_MAX_CLUSTERS];
    uint8_t is[SONAR_MAX_CLUSTERS], i;
    int k;
    (void)state;
    assert_int_equal(sonar_structure_init(&s, 10.0f), SONAR_OK);
    /* A structure place, then silence for minutes: kept (its echo is learnt; if it returns it is still structure). */
    for (k = 0; k < 5; k++) {
        o[0] = at(5.0f, 0.0f, 1, k);
        assert_true(sweep(o, 1, k, is) >= 0);
    }
    assert_int_equal(sonar_structure_count(&s), 1);
    o[0] = at(1.0f, 1.0f, 1, 5); /* a place seen once */
    assert_true(sweep(o, 1, 5, is) >= 0);
    assert_int_equal(s.n, 2);
    assert_true(sweep(NULL, 0, 5 + (SONAR_PLACE_FORGET_S * 1000000 / SWEEP_US) + 1, is) >= 0);
    assert_int_equal(s.n, 1); /* the one seen once is forgotten, the structure kept */
    o[0] = at(5.2f, 0.1f, 0, 200);
    assert_int_equal(sweep(o, 1, 200, is), 1);
    /* A full table evicts the place seen longest ago that is not structure, never the structure. */
    for (k = 0; k < SONAR_MAX_PLACES + 4; k++) {
        o[0] = at(-20.0f + 2.0f * (float)(k / 8), 2.0f * (float)(k % 8), 1, 201);
        o[0].utime += k;
        assert_true(sonar_structure_sweep(&s, o, 1, (int64_t)201 * SWEEP_US + k, is) >= 0);
    }
    assert_int_equal(s.n, SONAR_MAX_PLACES);
    assert_true(s.evicted >= 4);
    assert_int_equal(sonar_structure_count(&s), 1);
    /* The background restarted: nothing it learnt is structure any more. */
    sonar_structure_restart(&s);
    assert_int_equal(s.n, 0);
    assert_int_equal(s.restarts, 1);
    for (i = 0; i < SONAR_MAX_CLUSTERS; i++)
        o[i] = at((float)i, 0.0f, 0, 300);
    assert_int_equal(sweep(o, SONAR_MAX_CLUSTERS, 300, is), 0);
}

static void test_bad_input(void **state)
{
    struct sonar_structure_obs o[2];
    uint8_t is[SONAR_MAX_CLUSTERS + 1];
    (void)state;
    assert_int_equal(sonar_structure_init(&s, 0.5f), SONAR_ERR_ARG);
    assert_int_equal(sonar_structure_init(&s, (float)SONAR_STRUCTURE_S_MAX + 1.0f), SONAR_ERR_ARG);
    assert_int_equal(sonar_structure_init(&s, NAN), SONAR_ERR_ARG);
    assert_int_equal(sonar_structure_init(NULL, 10.0f), SONAR_ERR_ARG);
    assert_int_equal(sonar_structure_init(&s, 10.0f), SONAR_OK);
    assert_int_equal(sonar_structure_tune(&s, -1.0f), SONAR_ERR_ARG);
    assert_true(s.structure_s == 10.0f);
    o[0] = at(1.0f, 1.0f, 1, 0);
    o[1] = at(NAN, 1.0f, 1, 0);
    assert_int_equal(sweep(o, 2, 0, is), SONAR_ERR_ARG);
    assert_int_equal(s.n, 0); /* nothing changed */
    o[1] = at(1.0f, INFINITY, 1, 0);
    assert_int_equal(sweep(o, 2, 0, is), SONAR_ERR_ARG);
    assert_int_equal(sonar_structure_sweep(&s, o, SONAR_MAX_CLUSTERS + 1, 0, is), SONAR_ERR_ARG);
    assert_int_equal(sonar_structure_sweep(&s, NULL, 1, 0, is), SONAR_ERR_ARG);
    assert_int_equal(sonar_structure_sweep(&s, o, 1, 0, NULL), SONAR_ERR_ARG);
    assert_int_equal(s.n, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_first_look_that_stands_is_structure_after_structure_s),
        cmocka_unit_test(test_what_came_in_later_is_never_structure),
        cmocka_unit_test(test_turned_with_the_frame),
        cmocka_unit_test(test_comes_and_goes_is_never_structure),
        cmocka_unit_test(test_off_means_never),
        cmocka_unit_test(test_forgotten_evicted_restarted),
        cmocka_unit_test(test_bad_input),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
