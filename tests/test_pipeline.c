/* test_pipeline.c -- stage order, sweep cuts and flushes, geometry changes, an object appearing over a static scene, and the same seen from a moving, turning vehicle. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <string.h>

#include <cmocka.h>

#include "sonar/pipeline.h"
#include "sonar/status.h"
#include "view.h"

#define N 300

struct log {
    int stages[4000];
    uint16_t angles[4000];
    int nstage;
    int sweeps;
    uint8_t last_count[16];
    float x[16], y[16];
    uint8_t world[16], det_world[16];
    float north[16], east[16], speed[16]; /* the first detection in the world; the fastest confirmed track */
    uint8_t confirmed[16];
    uint8_t objects[16], structure[16], since[16]; /* detections that are objects (static since start too), structure,
                                                      and objects static since start */
};

static struct sonar_pipeline pipe_;
static struct sonar_background bg_;
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
        uint8_t i;
        for (i = 0; i < d->count; i++) {
            l->objects[l->sweeps] = (uint8_t)(l->objects[l->sweeps] + (d->det[i].kind != SONAR_DET_STRUCTURE));
            l->since[l->sweeps] = (uint8_t)(l->since[l->sweeps] + (d->det[i].kind == SONAR_DET_STATIC_START));
            l->structure[l->sweeps] = (uint8_t)(l->structure[l->sweeps] + (d->det[i].kind == SONAR_DET_STRUCTURE));
        }
        l->last_count[l->sweeps] = d->count;
        l->x[l->sweeps] = d->count ? d->det[0].x_m : 0.0f;
        l->y[l->sweeps] = d->count ? d->det[0].y_m : 0.0f;
        if (pipe_.poses != NULL) {
            static struct msg_view v;
            uint8_t k;
            msg_view_of(&pipe_, &v);
            l->world[l->sweeps] = v.world;
            l->det_world[l->sweeps] = d->count ? v.det_world[0] : 0;
            l->north[l->sweeps] = v.det_north[0];
            l->east[l->sweeps] = v.det_east[0];
            l->speed[l->sweeps] = 0.0f;
            for (k = 0; k < pipe_.trk.n; k++)
                if (pipe_.trk.t[k].state == SONAR_TRACK_CONFIRMED) {
                    float sp;
                    l->confirmed[l->sweeps]++;
                    sp = sqrtf(pipe_.trk.t[k].vx * pipe_.trk.t[k].vx + pipe_.trk.t[k].vy * pipe_.trk.t[k].vy);
                    l->speed[l->sweeps] = sp > l->speed[l->sweeps] ? sp : l->speed[l->sweeps];
                }
        }
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

static void push_at(uint16_t angle, const uint8_t *s, uint16_t n, float range, int64_t utime)
{
    struct sonar_beam b;
    b.utime = utime;
    b.angle = angle;
    b.n = n;
    b.range_m = range;
    b.samples = s;
    b.gain = -1;
    assert_int_equal(sonar_pipeline_push(&pipe_, &b), SONAR_OK);
}

static void push(uint16_t angle, const uint8_t *s, uint16_t n, float range)
{
    push_at(angle, s, n, range, 1000);
}

static void test_stage_order_and_sweeps(void **state)
{
    struct sonar_pipeline_config c;
    uint8_t s[N] = {3}; /* quiet water, not blank: a beam of every sample 0 is skipped (test_blank_beams) */
    int a, i;
    (void)state;
    memset(&lg, 0, sizeof(lg));
    cfg_init(&c);
    assert_int_equal(sonar_pipeline_init(&pipe_, &bg_, &c), SONAR_OK);
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
    uint8_t s[N] = {3}; /* quiet water, not blank: a beam of every sample 0 is skipped (test_blank_beams) */
    int a, i, fgs = 0;
    (void)state;
    memset(&lg, 0, sizeof(lg));
    cfg_init(&c);
    c.median2d = 5;
    assert_int_equal(sonar_pipeline_init(&pipe_, &bg_, &c), SONAR_OK);
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
    uint8_t s[N] = {3}; /* quiet water, not blank: a beam of every sample 0 is skipped (test_blank_beams) */
    (void)state;
    memset(&lg, 0, sizeof(lg));
    cfg_init(&c);
    assert_int_equal(sonar_pipeline_init(&pipe_, &bg_, &c), SONAR_OK);
    push(0, s, N, 10.0f);
    push(1, s, N, 10.0f);
    push(2, s, N, 20.0f);
    assert_int_equal(lg.sweeps, 1);
    assert_int_equal(pipe_.bg->visits[2], 1);
    push(3, s, 200, 20.0f);
    assert_int_equal(lg.sweeps, 2);
    assert_int_equal(pipe_.geometry_changes, 2);
    {
        struct sonar_beam b = {0, 400, N, 10.0f, s, -1};
        assert_int_equal(sonar_pipeline_push(&pipe_, &b), SONAR_ERR_ARG);
        b.angle = 0;
        b.range_m = 0.0f;
        assert_int_equal(sonar_pipeline_push(&pipe_, &b), SONAR_ERR_ARG);
    }
    c.median = 4;
    assert_int_equal(sonar_pipeline_init(&pipe_, &bg_, &c), SONAR_ERR_ARG);
}

/* A change of the beams' gain restarts the background here, in the core: host and co-processor alike; unknown (-1) changes nothing. */
static void test_gain_change_restarts(void **state)
{
    struct sonar_pipeline_config c;
    struct sonar_status st;
    uint8_t s[N] = {3}; /* quiet water, not blank: a beam of every sample 0 is skipped (test_blank_beams) */
    struct sonar_beam b = {0, 0, N, 10.0f, s, 0};
    uint16_t a;
    (void)state;
    memset(&lg, 0, sizeof(lg));
    cfg_init(&c);
    assert_int_equal(sonar_pipeline_init(&pipe_, &bg_, &c), SONAR_OK);
    for (a = 0; a < 3; a++) {
        b.angle = a;
        assert_int_equal(sonar_pipeline_push(&pipe_, &b), SONAR_OK);
    }
    assert_int_equal(pipe_.bg->visits[2], 1);
    b.gain = -1; /* unknown: no change */
    b.angle = 3;
    assert_int_equal(sonar_pipeline_push(&pipe_, &b), SONAR_OK);
    assert_int_equal(pipe_.gain_restarts, 0);
    b.gain = 2;
    b.angle = 4;
    assert_int_equal(sonar_pipeline_push(&pipe_, &b), SONAR_OK);
    assert_int_equal(pipe_.gain_restarts, 1);
    assert_int_equal(pipe_.bg->visits[2], 0); /* learnt afresh at the new gain */
    memset(&st, 0, sizeof(st));
    sonar_status_fill(&st, NULL, &pipe_);
    assert_int_equal(st.acq.gain, 2);
    assert_int_equal(st.acq.background_restarts, 1);
}

/* A beam of every sample 0 (nothing heard) or 255 (saturated) is skipped and counted: no sweep, no background, no detection. */
static void test_blank_beams(void **state)
{
    struct sonar_pipeline_config c;
    struct sonar_status st;
    uint8_t zero[N], full[N], s[N];
    uint16_t a;
    (void)state;
    memset(zero, 0, sizeof(zero));
    memset(full, 255, sizeof(full));
    memset(s, 0, sizeof(s));
    s[N - 1] = 1; /* one sample heard: not blank */
    memset(&lg, 0, sizeof(lg));
    cfg_init(&c);
    assert_int_equal(sonar_pipeline_init(&pipe_, &bg_, &c), SONAR_OK);
    for (a = 0; a < 400; a += 4)
        push(a, a % 8 ? zero : full, N, 10.0f);
    assert_int_equal(sonar_pipeline_finish(&pipe_), SONAR_OK);
    assert_int_equal(lg.sweeps, 0);
    assert_int_equal(lg.nstage, 0);
    assert_int_equal(sonar_pipeline_blank_beams(&pipe_), 100);
    assert_int_equal(pipe_.bg->visits[0], 0);
    push(0, s, N, 10.0f);
    assert_int_equal(lg.nstage, 3);
    assert_int_equal(sonar_pipeline_blank_beams(&pipe_), 100);
    memset(&st, 0, sizeof(st));
    sonar_status_fill(&st, NULL, &pipe_);
    assert_int_equal(st.blank_beams, 100);
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
    assert_int_equal(sonar_pipeline_init(&pipe_, &bg_, &c), SONAR_OK);
    for (turn = 0; turn < 5; turn++)
        for (a = 0; a < 400; a++) {
            for (i = 0; i < N; i++)
                s[i] = (uint8_t)(10 + (i * 31 + a * 17 + turn * 7) % 9);
            for (i = 195; i < 205; i++)
                s[i] = 180;
            if (turn >= 3 && a >= 100 && a <= 104)
                for (i = 100; i < 106; i++) /* 0.3 m deep, as wide: a compact object */
                    s[i] = 200;
            push((uint16_t)a, s, N, 10.0f);
        }
    assert_int_equal(sonar_pipeline_finish(&pipe_), SONAR_OK);
    assert_int_equal(lg.sweeps, 5);
    for (turn = 0; turn < 3; turn++)
        assert_int_equal(lg.last_count[turn], 0);
    for (turn = 3; turn < 5; turn++) {
        assert_int_equal(lg.last_count[turn], 1);
        /* angle 102 gradians (91.8 deg), ~3.4 m */
        assert_true(lg.x[turn] > -0.2f && lg.x[turn] < 0.0f);
        assert_true(lg.y[turn] > 3.2f && lg.y[turn] < 3.6f);
    }
}

/*
 * A vehicle sways north and south by 2 m and yaws by +-30 degrees while the head turns (1 gradian a
 * beam, 50 ms a beam, 20 s a turn). The world holds a wall along east = 6 m and, from the fourth
 * turn, a post at north 3, east -2. In the body frame both move; in the world neither does.
 */
static struct sonar_pose_ring ring_;

static void vehicle(double t, struct sonar_pose *p)
{
    const double pi = 3.14159265358979323846;
    p->utime = (int64_t)(t * 1e6) + 1000000000000;
    p->north_m = (float)(2.0 * sin(2.0 * pi * t / 60.0));
    p->east_m = 0.0f;
    p->yaw_deg = (float)fmod(360.0 + 30.0 * sin(2.0 * pi * t / 40.0), 360.0);
}

static void world_beam(const struct sonar_pose *p, uint16_t angle, int post, uint8_t *s)
{
    const double pi = 3.14159265358979323846, range = 10.0;
    double th = ((double)angle * 0.9 + (double)p->yaw_deg) * pi / 180.0, un = cos(th), ue = sin(th);
    int i;
    for (i = 0; i < N; i++)
        s[i] = (uint8_t)(10 + (i * 31 + angle * 17) % 9);
    if (ue > 0.05) { /* the wall, east = 6 */
        double t = (6.0 - (double)p->east_m) / ue;
        int k = (int)(t / range * N);
        for (i = k - 2; i <= k + 2; i++)
            if (i >= 0 && i < N)
                s[i] = 150;
    }
    if (post) { /* the post, 0.2 m across */
        double dn = 3.0 - (double)p->north_m, de = -2.0 - (double)p->east_m, along = dn * un + de * ue;
        if (along > 0 && fabs(-dn * ue + de * un) < 0.25) {
            int k = (int)(along / range * N);
            for (i = k - 3; i <= k + 3; i++)
                if (i >= 0 && i < N)
                    s[i] = 200;
        }
    }
}

static void run_vehicle(int with_poses, int bare_rules)
{
    struct sonar_pipeline_config c;
    struct sonar_pose_limits lim;
    uint8_t s[N];
    int turn, a;
    memset(&lg, 0, sizeof(lg));
    cfg_init(&c);
    c.detector.min_points = 10;
    if (bare_rules) {
        c.detector.max_extent_m = 0.0f;
        c.detector.max_aspect = 0.0f;
    }
    assert_int_equal(sonar_pipeline_init(&pipe_, &bg_, &c), SONAR_OK);
    sonar_pose_limits_default(&lim);
    assert_int_equal(sonar_pose_init(&ring_, &lim), SONAR_OK);
    if (with_poses)
        sonar_pipeline_set_poses(&pipe_, &ring_);
    for (turn = 0; turn < 6; turn++)
        for (a = 0; a < 400; a++) {
            double t = (turn * 400 + a) * 0.05;
            struct sonar_pose p;
            vehicle(t, &p);
            assert_int_equal(sonar_pose_push(&ring_, &p), SONAR_OK);
            world_beam(&p, (uint16_t)a, turn >= 3, s);
            push_at((uint16_t)a, s, N, 10.0f, p.utime);
        }
    assert_int_equal(sonar_pipeline_finish(&pipe_), SONAR_OK);
    assert_int_equal(lg.sweeps, 6);
}

static void test_moving_vehicle_world_frame(void **state)
{
    int turn;
    (void)state;
    run_vehicle(1, 0);
    assert_int_equal(pipe_.world_sweeps, 6);
    assert_true(pipe_.world_beams == 2400u && pipe_.bg->world);
    /* The wall is background once the grid has seen it; the post is found where it stands. */
    for (turn = 1; turn < 3; turn++)
        assert_int_equal(lg.last_count[turn], 0);
    for (turn = 3; turn < 6; turn++) {
        assert_int_equal(lg.last_count[turn], 1);
        assert_true(lg.world[turn] && lg.det_world[turn]);
        assert_true(fabsf(lg.north[turn] - 3.0f) < 0.3f && fabsf(lg.east[turn] + 2.0f) < 0.3f);
    }
    /* Tracked in the world, the post stands still while the vehicle moves at up to 0.2 m/s and turns. */
    assert_int_equal(lg.confirmed[5], 1);
    assert_true(lg.speed[5] < 0.05f);
}

/* The same beams without the poses: the per-angle model sees the wall move, and finds it. */
static void test_moving_vehicle_body_frame_baseline(void **state)
{
    int turn, found = 0;
    (void)state;
    /* Without the extent and aspect rules, which drop a wall's pieces whatever the background. */
    run_vehicle(0, 1);
    assert_int_equal(pipe_.world_beams, 0);
    for (turn = 2; turn < 6; turn++)
        found += lg.last_count[turn];
    assert_true(found > 3); /* with the poses: the post in turns 3 to 5, nothing else */
}

/* The beam at gradian a of turn: faint speckle; in turn 3 a speck at gradian 50 and an object on 394..398. */
static void speck_beam(uint8_t *s, int turn, int a)
{
    int i;
    for (i = 0; i < N; i++)
        s[i] = (uint8_t)(10 + (i * 31 + a * 17 + turn * 7) % 9);
    if (turn == 3 && a == 50)
        for (i = 150; i < 162; i++)
            s[i] = 90;
    if (turn == 3 && a >= 394)
        for (i = 200; i < 206; i++)
            s[i] = 200;
}

/*
 * The CFAR window across beams, one beam late: over an empty scene learnt for two turns at 2-gradian
 * steps (1.8 degrees: one beam may hold a whole echo), a speck in one beam (gradian 50) is diluted by
 * its neighbours and not found, an object three beams wide at the end of the turn (394..398: the last
 * beam waits for no neighbour, released when the turn ends) is; beams reach the detector in order,
 * each once.
 */
static void test_cfar_across_beams_one_beam_late(void **state)
{
    struct sonar_pipeline_config c;
    uint8_t s[N];
    int turn, a;
    (void)state;
    memset(&lg, 0, sizeof(lg));
    cfg_init(&c);
    c.track = 0;
    c.detector.max_aspect = 0.0f; /* a one-beam speck is also a radial streak: that rule is not the one tested */
    c.detector.min_area_m2 = 0.0f; /* nor is its area (0.03 m^2) */
    assert_int_equal(sonar_pipeline_init(&pipe_, &bg_, &c), SONAR_OK);
    for (turn = 0; turn < 4; turn++)
        for (a = 0; a < 400; a += 2) {
            speck_beam(s, turn, a);
            push((uint16_t)a, s, N, 10.0f);
            /* the detector holds one beam fewer than were pushed this turn */
            assert_int_equal(pipe_.det.beams, a / 2);
        }
    assert_int_equal(sonar_pipeline_finish(&pipe_), SONAR_OK);
    assert_int_equal(lg.sweeps, 4);
    assert_int_equal(lg.last_count[3], 1);
    assert_true(atan2f(lg.y[3], lg.x[3]) < -0.045f && atan2f(lg.y[3], lg.x[3]) > -0.08f); /* 396 gradians */
    /* With the window on each beam alone the speck is found too. */
    memset(&lg, 0, sizeof(lg));
    c.detector.cfar.across = 0;
    assert_int_equal(sonar_pipeline_init(&pipe_, &bg_, &c), SONAR_OK);
    for (turn = 0; turn < 4; turn++)
        for (a = 0; a < 400; a += 2) {
            speck_beam(s, turn, a);
            push((uint16_t)a, s, N, 10.0f);
        }
    assert_int_equal(sonar_pipeline_finish(&pipe_), SONAR_OK);
    assert_int_equal(lg.last_count[3], 2);
}

/*
 * Turn t of the structure scene at 4-gradian steps: speckle; a "ladder" there from the first beam
 * (gradians 100..112, samples 150..169); from turn 4 a "diver" who came in and stands (gradians
 * 300..312, samples 100..119). Both speckled as an echo is.
 */
static void structure_beam(uint8_t *s, int turn, int a)
{
    int i;
    for (i = 0; i < N; i++)
        s[i] = (uint8_t)(10 + (i * 31 + a * 17 + turn * 7) % 9);
    if (a >= 100 && a <= 112)
        for (i = 150; i < 170; i++)
            s[i] = (uint8_t)(110 + (i * 7 + turn * 13 + a) % 40);
    if (turn >= 4 && a >= 300 && a <= 312)
        for (i = 100; i < 120; i++)
            s[i] = (uint8_t)(110 + (i * 11 + turn * 5 + a) % 40);
}

/*
 * Structure learnt as structure (structure.h): what stood there from the first look is an object
 * until structure_s has passed, then structure (flagged, not tracked), then learnt into the
 * background; what came in later stands as long as it likes and stays an object. Turns of 10 s.
 */
static void test_structure_learnt(void **state)
{
    struct sonar_pipeline_config c;
    uint8_t s[N];
    int turn, a, first = -1, k;
    (void)state;
    memset(&lg, 0, sizeof(lg));
    cfg_init(&c);
    c.structure_s = 35.0f;
    assert_int_equal(sonar_pipeline_init(&pipe_, &bg_, &c), SONAR_OK);
    for (turn = 0; turn < 14; turn++)
        for (a = 0; a < 400; a += 4) {
            structure_beam(s, turn, a);
            push_at((uint16_t)a, s, N, 10.0f, (int64_t)turn * 10000000 + (int64_t)a * 25000);
        }
    assert_int_equal(sonar_pipeline_finish(&pipe_), SONAR_OK);
    assert_int_equal(lg.sweeps, 14);
    for (k = 0; k < 14; k++) {
        if (first < 0 && lg.structure[k] > 0)
            first = k;
        /* The diver is an object in every turn from its first on. */
        if (k >= 4)
            assert_true(lg.objects[k] >= 1);
    }
    /* The ladder: an object while structure_s runs (turns 0-3), then structure at 40 s; static since start once it
       has been seen 3 times (turns 2 and 3); the diver, who came in later, never. */
    assert_int_equal(first, 4);
    for (k = 0; k < first; k++) {
        assert_int_equal(lg.objects[k], 1);
        assert_int_equal(lg.since[k], k >= SONAR_PLACE_MIN_SEEN - 1);
    }
    for (k = first; k < 14; k++)
        assert_int_equal(lg.since[k], 0);
    for (k = first; k < 14; k++)
        assert_int_equal(lg.objects[k], 1); /* the diver alone */
    assert_int_equal(sonar_structure_count(&pipe_.st), 1);
    assert_int_equal(pipe_.st.promoted, 1);
    /* Learnt at once: from the next turn on it no longer stands out at all. */
    for (k = first + 1; k < 14; k++)
        assert_int_equal(lg.structure[k], 0);
    /* Not tracked: the one confirmed track is the diver's. */
    for (k = 0; k < pipe_.trk.n; k++)
        if (pipe_.trk.t[k].state != SONAR_TRACK_TENTATIVE)
            assert_true(atan2f(pipe_.trk.t[k].py, pipe_.trk.t[k].px) < -1.0f);
    /* A new range restarts the background and forgets what it had learnt as structure. */
    push(0, s, N, 12.0f);
    assert_int_equal(pipe_.st.n, 0);
    assert_int_equal(pipe_.st.restarts, 1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_structure_learnt),
        cmocka_unit_test(test_stage_order_and_sweeps),
        cmocka_unit_test(test_2d_median_flushes_each_sweep),
        cmocka_unit_test(test_geometry_change_cuts_and_resets),
        cmocka_unit_test(test_gain_change_restarts),
        cmocka_unit_test(test_blank_beams),
        cmocka_unit_test(test_object_over_static_scene),
        cmocka_unit_test(test_cfar_across_beams_one_beam_late),
        cmocka_unit_test(test_moving_vehicle_world_frame),
        cmocka_unit_test(test_moving_vehicle_body_frame_baseline),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
