/* test_pipeline.c -- stage order, sweep cuts and flushes, geometry changes, and an object appearing over a static scene. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "sonar/pipeline.h"

#define N 300

struct log {
    int stages[4000];
    uint16_t angles[4000];
    int nstage;
    int sweeps;
    uint8_t last_count[16];
    float x[16], y[16];
};

static struct sonar_pipeline pipe_;
static struct log lg;

static void on_beam(void *user, int stage, const struct sonar_beam *b)
{
    struct log *l = user;
    if (l->nstage < 4000) {
        l->angles[l->nstage] = b->angle;
        l->stages[l->nstage++] = stage;
    }
}

static void on_sweep(void *user, const struct sonar_detections *d)
{
    struct log *l = user;
    if (l->sweeps < 16) {
        l->last_count[l->sweeps] = d->count;
        l->x[l->sweeps] = d->count ? d->det[0].x_m : 0.0f;
        l->y[l->sweeps] = d->count ? d->det[0].y_m : 0.0f;
    }
    l->sweeps++;
}

static void cfg_init(struct sonar_pipeline_config *c)
{
    sonar_pipeline_defaults(c);
    c->on_beam = on_beam;
    c->on_sweep = on_sweep;
    c->user = &lg;
}

static void push(uint16_t angle, const uint8_t *s, uint16_t n, float range)
{
    struct sonar_beam b;
    b.utime = 1000;
    b.angle = angle;
    b.n = n;
    b.range_m = range;
    b.samples = s;
    assert_int_equal(sonar_pipeline_push(&pipe_, &b), SONAR_OK);
}

static void test_stage_order_and_sweeps(void **state)
{
    struct sonar_pipeline_config c;
    uint8_t s[N] = {0};
    int a, i;
    (void)state;
    memset(&lg, 0, sizeof(lg));
    cfg_init(&c);
    assert_int_equal(sonar_pipeline_init(&pipe_, &c), SONAR_OK);
    for (a = 0; a < 1000; a += 4)
        push((uint16_t)(a % 400), s, N, 10.0f);
    assert_int_equal(lg.sweeps, 2); /* two full turns ended; the third is open */
    assert_int_equal(sonar_pipeline_finish(&pipe_), SONAR_OK);
    assert_int_equal(lg.sweeps, 3);
    assert_int_equal(sonar_pipeline_finish(&pipe_), SONAR_OK); /* nothing open: no empty sweep */
    assert_int_equal(lg.sweeps, 3);
    assert_int_equal(lg.nstage, 3 * 250);
    for (i = 0; i < lg.nstage; i++)
        assert_int_equal(lg.stages[i], i % 3);
}

static void test_2d_median_flushes_each_sweep(void **state)
{
    struct sonar_pipeline_config c;
    uint8_t s[N] = {0};
    int a, i, fgs = 0;
    (void)state;
    memset(&lg, 0, sizeof(lg));
    cfg_init(&c);
    c.median2d = 5;
    assert_int_equal(sonar_pipeline_init(&pipe_, &c), SONAR_OK);
    for (a = 100; a <= 140; a++) /* forward, then back: two sweeps */
        push((uint16_t)a, s, N, 10.0f);
    for (a = 139; a >= 120; a--)
        push((uint16_t)a, s, N, 10.0f);
    assert_int_equal(sonar_pipeline_finish(&pipe_), SONAR_OK);
    assert_int_equal(lg.sweeps, 2);
    for (i = 0; i < lg.nstage; i++)
        if (lg.stages[i] == SONAR_STAGE_FOREGROUND)
            fgs++;
    assert_int_equal(fgs, 41 + 20); /* every beam comes out once, delay line drained at the cut */
}

static void test_geometry_change_cuts_and_resets(void **state)
{
    struct sonar_pipeline_config c;
    uint8_t s[N] = {0};
    (void)state;
    memset(&lg, 0, sizeof(lg));
    cfg_init(&c);
    assert_int_equal(sonar_pipeline_init(&pipe_, &c), SONAR_OK);
    push(0, s, N, 10.0f);
    push(1, s, N, 10.0f);
    push(2, s, N, 20.0f);
    assert_int_equal(lg.sweeps, 1);
    assert_int_equal(pipe_.bg.visits[2], 1);
    push(3, s, 200, 20.0f);
    assert_int_equal(lg.sweeps, 2);
    {
        struct sonar_beam b = {0, 400, N, 10.0f, s};
        assert_int_equal(sonar_pipeline_push(&pipe_, &b), SONAR_ERR_ARG);
        b.angle = 0;
        b.range_m = 0.0f;
        assert_int_equal(sonar_pipeline_push(&pipe_, &b), SONAR_ERR_ARG);
    }
    c.median = 4;
    assert_int_equal(sonar_pipeline_init(&pipe_, &c), SONAR_ERR_ARG);
}

/* A static scene (a wall at sample 200 in every beam) for 3 turns, then an object: only it is found. */
static void test_object_over_static_scene(void **state)
{
    struct sonar_pipeline_config c;
    uint8_t s[N];
    int turn, a, i;
    (void)state;
    memset(&lg, 0, sizeof(lg));
    cfg_init(&c);
    assert_int_equal(sonar_pipeline_init(&pipe_, &c), SONAR_OK);
    for (turn = 0; turn < 5; turn++)
        for (a = 0; a < 400; a++) {
            for (i = 0; i < N; i++)
                s[i] = (uint8_t)(10 + (i * 31 + a * 17 + turn * 7) % 9);
            for (i = 195; i < 205; i++)
                s[i] = 180;
            if (turn >= 3 && a >= 100 && a <= 104)
                for (i = 100; i < 120; i++)
                    s[i] = 200;
            push((uint16_t)a, s, N, 10.0f);
        }
    assert_int_equal(sonar_pipeline_finish(&pipe_), SONAR_OK);
    assert_int_equal(lg.sweeps, 5);
    for (turn = 0; turn < 3; turn++)
        assert_int_equal(lg.last_count[turn], 0);
    for (turn = 3; turn < 5; turn++) {
        assert_int_equal(lg.last_count[turn], 1);
        /* angle 102 gradians (91.8 deg), ~3.6 m */
        assert_true(lg.x[turn] > -0.2f && lg.x[turn] < 0.0f);
        assert_true(lg.y[turn] > 3.4f && lg.y[turn] < 3.8f);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_stage_order_and_sweeps),
        cmocka_unit_test(test_2d_median_flushes_each_sweep),
        cmocka_unit_test(test_geometry_change_cuts_and_resets),
        cmocka_unit_test(test_object_over_static_scene),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
