/* test_scan.c -- the scan planner on the device's timing model, simulated: sweep order as the driver's, and follow mode's bounds (no grid angle left beyond surveil_s, whatever the targets), its travel (one way round a circle) and its revisits against a plain sweep's. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "sonar/scan.h"

static struct sonar_scan s;
static double slow = 1.0; /* the link and host: each beam this many times the model's */

/* 15 m, 1500 m/s: 19.4 ms + 2R/c = 39.4 ms a ping; 4 gradians a step (a 6.3 s turn). */
static void config(struct sonar_scan_config *c, uint8_t mode)
{
    memset(c, 0, sizeof(*c));
    c->mode = mode;
    c->full_circle = 1;
    c->step = 4;
    c->ping_us = 39400;
    c->revisit_s = 1.5f;
}

static void test_config_checked(void **state)
{
    struct sonar_scan_config c;
    (void)state;
    config(&c, SONAR_SCAN_FOLLOW);
    assert_null(sonar_scan_config_check(&c));
    c.step = 0;
    assert_non_null(strstr(sonar_scan_config_check(&c), "step"));
    config(&c, SONAR_SCAN_FOLLOW);
    c.revisit_s = 0.1f;
    assert_non_null(strstr(sonar_scan_config_check(&c), "revisit_s"));
    config(&c, SONAR_SCAN_FOLLOW);
    c.surveil_s = -1.0f;
    assert_non_null(strstr(sonar_scan_config_check(&c), "surveil_s"));
    config(&c, SONAR_SCAN_FOLLOW);
    c.full_circle = 0;
    c.start_angle = c.stop_angle = 10;
    assert_non_null(strstr(sonar_scan_config_check(&c), "stop_angle"));
    config(&c, SONAR_SCAN_FOLLOW);
    c.ping_us = 0;
    assert_non_null(strstr(sonar_scan_config_check(&c), "ping_us"));
    config(&c, 7);
    assert_non_null(strstr(sonar_scan_config_check(&c), "mode"));
    assert_int_equal(sonar_scan_init(&s, &c), SONAR_ERR_ARG);
    assert_int_equal(sonar_scan_init(NULL, &c), SONAR_ERR_ARG);
}

/* Sweep mode steps as the driver does: full turns, or back and forth. */
static void test_sweep_order(void **state)
{
    static const uint16_t sector[] = {100, 105, 110, 115, 120, 115, 110, 105, 100, 105, 110};
    struct sonar_scan_config c;
    int64_t t = 0;
    int i;
    (void)state;
    config(&c, SONAR_SCAN_SWEEP);
    c.start_angle = 398;
    assert_int_equal(sonar_scan_init(&s, &c), SONAR_OK);
    for (i = 0; i < 300; i++, t += 63400)
        assert_int_equal(sonar_scan_next(&s, NULL, 0, t), (398 + 4 * i) % 400);
    config(&c, SONAR_SCAN_SWEEP);
    c.full_circle = 0;
    c.step = 5;
    c.start_angle = 100;
    c.stop_angle = 120;
    assert_int_equal(sonar_scan_init(&s, &c), SONAR_OK);
    for (i = 0; i < (int)(sizeof(sector) / sizeof(sector[0])); i++, t += 63400)
        assert_int_equal(sonar_scan_next(&s, NULL, 0, t), sector[i]);
}

static int cmp64(const void *a, const void *b)
{
    int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return x < y ? -1 : x > y;
}

struct run {
    int64_t p95[SONAR_SCAN_MAX_TARGETS + 4]; /* per target: 95th percentile of the time between looks, us */
    int ng[SONAR_SCAN_MAX_TARGETS + 4];      /* looks counted */
    int64_t unvisited;                       /* longest a grid angle went unpinged after its first ping, us (INT64_MAX: one never was) */
    int outside;                             /* pings outside the sector */
    int64_t travel;                          /* gradians the head moved */
    double seconds;
};

/*
 * Runs the plan for `seconds` on the timing model, n targets starting at start[] and moving at
 * `rate` gradians a second with half-width hw. A look at a target: a ping within half a step of its
 * bearing; looks in the same pass (closer than two pings) count as one.
 */
static void simulate(const struct sonar_scan_config *c, const float *start, unsigned n, float rate, float hw,
                     double seconds, struct run *r)
{
    static int64_t gaps[SONAR_SCAN_MAX_TARGETS + 4][256];
    static int64_t last_seen[400];
    struct sonar_scan_target tg[SONAR_SCAN_MAX_TARGETS + 4];
    int64_t t = 0, last[SONAR_SCAN_MAX_TARGETS + 4];
    int span = c->full_circle ? 400 : (c->stop_angle + 400 - c->start_angle) % 400, g;
    unsigned i;
    uint16_t prev = c->start_angle;
    memset(r, 0, sizeof(*r));
    r->seconds = seconds;
    assert_int_equal(sonar_scan_init(&s, c), SONAR_OK);
    for (i = 0; i < n; i++)
        last[i] = -1;
    memset(last_seen, 0, sizeof(last_seen));
    while (t < (int64_t)(seconds * 1e6)) {
        uint16_t a;
        for (i = 0; i < n; i++) {
            tg[i].angle = fmodf(start[i] + rate * (float)t * 1e-6f + 400.0f, 400.0f);
            tg[i].half_width = hw;
        }
        a = sonar_scan_next(&s, tg, n, t);
        r->travel += (int64_t)(sonar_scan_cost_us(&s, prev, a) - c->ping_us) / SONAR_SCAN_GRAD_US;
        t += (int64_t)(slow * (double)sonar_scan_cost_us(&s, prev, a));
        prev = a;
        if (!c->full_circle && (a + 400 - c->start_angle) % 400 > span)
            r->outside++;
        last_seen[a] = t;
        for (i = 0; i < n; i++) {
            float d = fabsf(fmodf(tg[i].angle - (float)a + 600.0f, 400.0f) - 200.0f);
            if (d <= (float)c->step * 0.5f + 0.01f) {
                if (last[i] >= 0 && t - last[i] > 2 * (int64_t)c->ping_us && t > 20000000 && r->ng[i] < 256)
                    gaps[i][r->ng[i]++] = t - last[i];
                last[i] = t;
            }
        }
        /* From each angle's first ping on (the first coverage takes k passes), and all pinged by 2 bounds. */
        for (g = 0; g <= span && g < 400; g += c->step) {
            int64_t seen = last_seen[(c->start_angle + g) % 400], u = t - seen;
            if (seen == 0 && t > 2 * (int64_t)s.surveil_us)
                r->unvisited = INT64_MAX;
            if (seen > 0 && u > r->unvisited)
                r->unvisited = u;
        }
    }
    for (i = 0; i < n; i++) {
        r->p95[i] = INT64_MAX;
        if (r->ng[i] == 0)
            continue;
        qsort(gaps[i], (size_t)r->ng[i], sizeof(int64_t), cmp64);
        r->p95[i] = gaps[i][(r->ng[i] * 95) / 100];
    }
}

/* The grid's bound holds whatever the targets: none, one, four, eight, more than the planner reads, wide ones. */
static void test_follow_keeps_the_bound(void **state)
{
    static const float spread[20] = {0, 20, 40, 60, 80, 100, 120, 140, 160, 180, 200, 220, 240, 260, 280, 300, 320, 340, 360, 380};
    static const unsigned counts[] = {0, 1, 4, 8, 20};
    struct sonar_scan_config c;
    struct run r;
    unsigned i;
    (void)state;
    for (i = 0; i < sizeof(counts) / sizeof(counts[0]); i++) {
        config(&c, SONAR_SCAN_FOLLOW);
        simulate(&c, spread, counts[i], 3.0f, 4.0f, 120.0, &r);
        if (r.unvisited > (int64_t)s.surveil_us)
            fail_msg("%u targets: an angle unvisited %.2f s > %.2f s", counts[i], (double)r.unvisited * 1e-6,
                     (double)s.surveil_us * 1e-6);
        simulate(&c, spread, counts[i], 0.0f, 400.0f, 120.0, &r); /* uncertain over the whole circle */
        assert_true(r.unvisited <= (int64_t)s.surveil_us);
    }
    assert_int_equal(s.counters.targets_dropped > 0, 1); /* 20 > SONAR_SCAN_MAX_TARGETS: the rest counted */
}

/* A link or host slower than the model (30 % a beam): the passes are measured, the bound still kept. */
static void test_follow_slow_link(void **state)
{
    static const float four[4] = {20, 120, 220, 320};
    struct sonar_scan_config c;
    struct run r;
    (void)state;
    config(&c, SONAR_SCAN_FOLLOW);
    slow = 1.3;
    simulate(&c, four, 4, 3.0f, 4.0f, 120.0, &r);
    slow = 1.0;
    assert_true(s.slow_q8 > 300);
    if (r.unvisited > (int64_t)s.surveil_us)
        fail_msg("slow link: an angle unvisited %.2f s > %.2f s", (double)r.unvisited * 1e-6, (double)s.surveil_us * 1e-6);
}

/* Round a circle the head keeps one way: a turn of travel a pass, never back and forth. */
static void test_follow_travels_one_way(void **state)
{
    static const float four[4] = {20, 120, 220, 320};
    struct sonar_scan_config c;
    struct run r;
    (void)state;
    config(&c, SONAR_SCAN_FOLLOW);
    simulate(&c, four, 4, 0.0f, 4.0f, 120.0, &r);
    assert_true(s.pass > 10);
    assert_true(r.travel <= (int64_t)(s.pass + 1) * 400);
}

/* What follow mode gains over a plain sweep (6.3 s a look): a quarter with one target, a sixth with four; its floor: a turn of travel (2.4 s) and its pings. */
static void test_follow_revisits_sooner(void **state)
{
    static const float one[1] = {150}, four[4] = {20, 120, 220, 320};
    struct sonar_scan_config c;
    struct run sweep, follow;
    unsigned i;
    (void)state;
    config(&c, SONAR_SCAN_SWEEP);
    simulate(&c, one, 1, 0.0f, 4.0f, 120.0, &sweep);
    assert_true(sweep.p95[0] > 6000000 && sweep.p95[0] < 6600000);
    config(&c, SONAR_SCAN_FOLLOW);
    simulate(&c, one, 1, 0.0f, 4.0f, 120.0, &follow);
    assert_true(follow.p95[0] < sweep.p95[0] * 3 / 4);
    assert_true(follow.p95[0] > 2400000);
    simulate(&c, four, 4, 3.0f, 4.0f, 120.0, &follow);
    for (i = 0; i < 4; i++)
        assert_true(follow.p95[i] < sweep.p95[0] * 5 / 6);
}

/* In a sector: never outside it, the bound kept, targets outside it ignored (counted), one gradian wide. */
static void test_follow_in_a_sector(void **state)
{
    static const float at[3] = {130, 250, 350};
    struct sonar_scan_config c;
    struct run r;
    (void)state;
    config(&c, SONAR_SCAN_FOLLOW);
    c.full_circle = 0;
    c.step = 2;
    c.start_angle = 100;
    c.stop_angle = 300;
    simulate(&c, at, 3, 0.0f, 4.0f, 120.0, &r);
    assert_int_equal(r.outside, 0);
    assert_int_equal(r.ng[2], 0);
    assert_true(r.ng[0] > 10 && r.ng[1] > 10);
    assert_true(r.unvisited <= (int64_t)s.surveil_us);
    assert_true(s.counters.targets_dropped > 0);
    c.start_angle = 399;
    c.stop_angle = 0; /* one gradian, across 0 */
    simulate(&c, at, 1, 0.0f, 30.0f, 30.0, &r);
    assert_int_equal(r.outside, 0);
    assert_true(r.unvisited <= (int64_t)s.surveil_us);
}

/* A clock that goes back is taken as the last time: nothing is older than it was. */
static void test_clock_back(void **state)
{
    static const struct sonar_scan_target t = {100.0f, 4.0f};
    struct sonar_scan_config c;
    int i;
    (void)state;
    config(&c, SONAR_SCAN_FOLLOW);
    assert_int_equal(sonar_scan_init(&s, &c), SONAR_OK);
    for (i = 0; i < 200; i++)
        assert_true(sonar_scan_next(&s, &t, 1, 1000000 - i * 1000) < 400);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_config_checked),
        cmocka_unit_test(test_sweep_order),
        cmocka_unit_test(test_follow_keeps_the_bound),
        cmocka_unit_test(test_follow_slow_link),
        cmocka_unit_test(test_follow_travels_one_way),
        cmocka_unit_test(test_follow_revisits_sooner),
        cmocka_unit_test(test_follow_in_a_sector),
        cmocka_unit_test(test_clock_back),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
