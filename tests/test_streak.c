/* test_streak.c -- interference streaks: a few streaked beams in quiet water are counted and left out (no object, nothing learnt); a whole sweep of them gives no object; a beam after a jump is never judged; the rule alone, share by share. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "sonar/pipeline.h"
#include "sonar/streak.h"

#define N 400
#define STEP 4

static struct sonar_pipeline pipe_;
static struct sonar_background bg_;
static struct sonar_pipeline_config cfg_;
static unsigned objects, sweeps;
static uint32_t rng = 12345u;

static void on_sweep(void *user, const struct sonar_detections *d)
{
    uint8_t i;
    (void)user;
    sweeps++;
    for (i = 0; i < d->count; i++)
        objects += d->det[i].kind == SONAR_DET_OBJECT;
}

/* Quiet water: speckle 5..12, the near 20 samples zeroed as some recorders do. */
static void water(uint8_t *s)
{
    int i;
    for (i = 0; i < N; i++) {
        rng = rng * 1103515245u + 12345u;
        s[i] = i < 20 ? 0 : (uint8_t)(5u + (rng >> 16) % 8u);
    }
}

/* One turn at STEP gradians, 25 ms a beam; streak(a): whether the beam at a is interference (level 90..150 along it). */
static void turn(int64_t *t, int (*streak)(int))
{
    uint8_t s[N];
    struct sonar_beam b;
    int a, i;
    for (a = 0; a < 400; a += STEP) {
        water(s);
        if (streak != NULL && streak(a))
            for (i = 20; i < N; i++)
                s[i] = (uint8_t)(90 + (i * 7) % 60);
        b.utime = *t;
        b.angle = (uint16_t)a;
        b.n = N;
        b.range_m = 10.0f;
        b.samples = s;
        b.gain = -1;
        assert_int_equal(sonar_pipeline_push(&pipe_, &b), SONAR_OK);
        *t += 25000;
    }
}

static int three_beams(int a) { return a >= 100 && a < 100 + 3 * STEP; }
static int every_beam(int a) { (void)a; return 1; }

/* A fresh pipeline after four turns of quiet water (its background learnt); objects counted from here. */
static void start(int64_t *t)
{
    int k;
    sonar_pipeline_defaults(&cfg_);
    cfg_.track = 0;
    cfg_.on_sweep = on_sweep;
    assert_int_equal(sonar_pipeline_init(&pipe_, &bg_, &cfg_), SONAR_OK);
    for (k = 0; k < 4; k++)
        turn(t, NULL);
    assert_int_equal(sonar_pipeline_interference_beams(&pipe_), 0);
    objects = sweeps = 0;
}

static void test_streaks_left_out(void **state)
{
    int64_t t = 1000000;
    (void)state;
    start(&t);
    turn(&t, three_beams);
    turn(&t, NULL); /* ends the streaked turn */
    assert_int_equal(sonar_pipeline_interference_beams(&pipe_), 3);
    assert_int_equal(objects, 0);
    /* Nothing learnt: the same streaks again are streaks again, not background. */
    turn(&t, three_beams);
    turn(&t, NULL);
    assert_int_equal(sonar_pipeline_interference_beams(&pipe_), 6);
    assert_int_equal(objects, 0);
}

/* A streaked beam next to one as lit (its reference) is no streak: the rule compares with the beam before. */
static void test_no_streak_beside_a_lit_beam(void **state)
{
    int64_t t = 1000000;
    (void)state;
    start(&t);
    pipe_.streak.ref256 = 256;
    pipe_.streak.have_ref = 1;
    objects = 0;
    {
        uint8_t s[N];
        struct sonar_beam b = {0, 100, N, 10.0f, s, -1};
        int i;
        water(s);
        for (i = 20; i < N; i++)
            s[i] = (uint8_t)(90 + (i * 7) % 60);
        b.utime = t;
        pipe_.streak.last_angle = 96;
        pipe_.streak.last_us = t - 25000;
        assert_int_equal(sonar_pipeline_push(&pipe_, &b), SONAR_OK);
    }
    assert_int_equal(sonar_pipeline_interference_beams(&pipe_), 0);
}

/*
 * A whole turn of interference after quiet water: no object. Its first SONAR_STREAK_MAX_RUN beams are
 * streaks; after them the lit water is taken as the water changing (streak.h) and learnt.
 */
static void test_sweep_of_interference(void **state)
{
    int64_t t = 1000000;
    (void)state;
    start(&t);
    turn(&t, every_beam);
    turn(&t, NULL);
    assert_int_equal(sonar_pipeline_interference_beams(&pipe_), SONAR_STREAK_MAX_RUN);
    assert_int_equal(objects, 0);
}

/* The rule alone: a beam after a jump is the reference, never a streak; a neighbour twice as lit is. */
static void test_rule(void **state)
{
    struct sonar_streak s;
    int i;
    (void)state;
    sonar_streak_init(&s);
    assert_int_equal(sonar_streak_judge(&s, 100, 0, 300, 380), 0);           /* first beam: no neighbour */
    assert_int_equal(sonar_streak_judge(&s, 104, 25000, 300, 380), 0);       /* as lit as the one before */
    sonar_streak_init(&s);
    assert_int_equal(sonar_streak_judge(&s, 100, 0, 20, 380), 0);
    assert_int_equal(sonar_streak_judge(&s, 104, 25000, 300, 380), 1);       /* 79 % against 5 % */
    assert_int_equal(sonar_streak_judge(&s, 108, 50000, 300, 380), 1);       /* the reference stays the quiet one */
    assert_int_equal(sonar_streak_judge(&s, 112, 75000, 250, 380), 0);       /* 66 %: under three quarters */
    assert_int_equal(sonar_streak_judge(&s, 200, 100000, 300, 380), 0);      /* a jump: no neighbour */
    assert_int_equal(sonar_streak_judge(&s, 204, 3000000, 300, 380), 0);     /* 3 s later: no neighbour */
    assert_int_equal(sonar_streak_judge(&s, 208, 3025000, -1, 380), 0);      /* no model: never */
    assert_int_equal(sonar_streak_judge(&s, 212, 3050000, 10, 10), 0);       /* too short to judge */
    assert_int_equal(s.beams, 2);
    /* A run longer than streaks come: the fifth lit beam in a row is the water changing, and the reference. */
    sonar_streak_init(&s);
    assert_int_equal(sonar_streak_judge(&s, 0, 0, 20, 380), 0);
    for (i = 1; i <= SONAR_STREAK_MAX_RUN; i++)
        assert_int_equal(sonar_streak_judge(&s, (uint16_t)i, 25000 * i, 360, 380), 1);
    assert_int_equal(sonar_streak_judge(&s, (uint16_t)i, 25000 * i, 360, 380), 0);
    assert_int_equal(sonar_streak_judge(&s, (uint16_t)(i + 1), 25000 * (i + 1), 360, 380), 0);
    {
        uint8_t z[5] = {0, 0, 3, 0, 1};
        assert_int_equal(sonar_streak_from(z, 5), 2);
        assert_int_equal(sonar_streak_from(z, 2), 2);
    }
}

/* The count against the model (SIMD on ARMv7E-M and x86-64, lanes elsewhere) is a plain count wherever the share can matter: every start and pattern (the model's length is the beam's). */
static void test_standing_counts(void **state)
{
    int64_t t = 0;
    uint8_t in[N];
    const uint8_t *model;
    uint16_t n, from, i, angle = 100;
    unsigned p;
    (void)state;
    start(&t);
    model = bg_.cell[(unsigned)angle * SONAR_MAX_ANGLES / SONAR_GRAD_TURN];
    for (p = 0; p < 14; p++)
        for (n = N; n <= N; n++)
            for (from = 0; from < 120; from = (uint16_t)(from + 7)) {
                int want = 0, got;
                for (i = 0; i < n; i++) {
                    unsigned lit = p < 4 ? (i * (p + 1u)) % 8u < p * 2u : (i / (p + 1u)) % 3u != 0u;
                    int at = model[i] + 8 + (int)((i * 7u + p) % 5u) - 2; /* the margin's edge: -2 .. +2 about it */
                    in[i] = (uint8_t)(lit ? (model[i] > 200 ? 255 : model[i] + 40) : model[i] / 2);
                    if (p == 12) /* at the margin, and saturating past 255 */
                        in[i] = (uint8_t)(at > 255 ? 255 : at);
                    else if (p == 13) /* below the margin itself */
                        in[i] = (uint8_t)(i % 9u);
                }
                for (i = from; i < n; i++)
                    want += (unsigned)in[i] > (unsigned)model[i] + 8u;
                got = sonar_streak_standing(&bg_, angle, in, n, from, 8);
                /* Exact where the share can matter (3/8 of the length or more); below it, still below it. */
                if (16u * SONAR_STREAK_RATIO * (unsigned)want >= SONAR_STREAK_16 * (unsigned)(n - from))
                    assert_int_equal(got, want);
                else
                    assert_true(got <= want && got >= 0);
            }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_streaks_left_out),
        cmocka_unit_test(test_no_streak_beside_a_lit_beam),
        cmocka_unit_test(test_sweep_of_interference),
        cmocka_unit_test(test_rule),
        cmocka_unit_test(test_standing_counts),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
