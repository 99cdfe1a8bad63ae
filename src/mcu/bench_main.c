/* bench_main.c -- the co-processor bench image: the core's per-beam step and per-sweep detection on synthetic sweeps, timed by the board clock; under QEMU -icount shift=0 one instruction is one ns, so the figures are instruction counts. Results as text on UART0. RAM: one sweep of samples (N x beams) plus the stages. */
#include <string.h>

#include "board.h"
#include "sonar/background.h"
#include "sonar/cfar.h"
#include "sonar/detector.h"
#include "sonar/tracker.h"
#include "sonar/median.h"
#include "sonar/pipeline.h"
#include "sonar/scan.h"
#include "detector_internal.h"
#include "../../tools/bench/tracker_scene.h"

#ifndef BENCH_BEAMS
#define BENCH_BEAMS 400
#endif
#ifndef BENCH_N
#define BENCH_N 1200
#endif
#define INSN_PER_US 1000u /* -icount shift=0: one instruction per ns of virtual time */

struct bench {
    uint8_t sweep[BENCH_BEAMS][BENCH_N];
    uint8_t filt[BENCH_N], fg[BENCH_N];
    struct sonar_background bg;
    struct sonar_detector det;
    struct sonar_detections out;
    uint32_t rng;
};

static uint32_t next(struct bench *b)
{
    b->rng = b->rng * 1664525u + 1013904223u;
    return b->rng >> 8;
}

/* Speckle ((a^2 + b^2) >> 7), a static wall and 20 moving 9 x 21 blobs, as tools/bench/bench.c makes them. */
static void make_sweep(struct bench *b, int s)
{
    int i, j, k;
    for (i = 0; i < BENCH_BEAMS; i++)
        for (j = 0; j < BENCH_N; j++) {
            uint32_t a = next(b) % 64u, c = next(b) % 64u;
            b->sweep[i][j] = (uint8_t)((a * a + c * c) >> 7);
            if (j >= BENCH_N * 3 / 4 + i / 8 && j < BENCH_N * 3 / 4 + 10 + i / 8)
                b->sweep[i][j] = (uint8_t)(120u + next(b) % 60u);
        }
    for (k = 0; k < 20; k++) {
        int bi = (k * 19 + s * 11) % (BENCH_BEAMS - 9), bj = 50 + (k * 41 + s * 3) % (BENCH_N - 300);
        for (i = bi; i < bi + 9; i++)
            for (j = bj; j < bj + 21; j++)
                b->sweep[i][j] = (uint8_t)(150u + next(b) % 100u);
    }
}

static void put(const char *s)
{
    size_t n = strlen(s), k = 0;
    while (k < n) {
        k += board_uart_write(BOARD_UART_SONAR, (const uint8_t *)s + k, n - k);
        board_uart_pump();
    }
}

static void put_num(const char *key, uint64_t v)
{
    char buf[48], d[24];
    int i = 0, k;
    do {
        d[i++] = (char)('0' + (int)(v % 10u));
        v /= 10u;
    } while (v > 0);
    for (k = 0; key[k] != '\0' && k < 30; k++)
        buf[k] = key[k];
    buf[k++] = ' ';
    while (i > 0)
        buf[k++] = d[--i];
    buf[k++] = '\n';
    buf[k] = '\0';
    put(buf);
}

/* The tracker's sweep (tools/bench/tracker_scene.h, as the host bench times it): 32 tracks, 16 detections; in a
   walled site (SONAR_TRK_MAX_WALLS walls about it) when walls. */
static int64_t tracker_us(int walls)
{
    static struct sonar_tracker tk;
    struct sonar_tracker_config tc;
    struct sonar_tracker_obs ob[16];
    struct sonar_tracker_sweep sw;
    int64_t t0;
    sonar_tracker_defaults(&tc);
    if (bench_tracker_scene(&tk, &tc, ob, &sw) != 0 || (walls && bench_tracker_walls(&tk) != 0))
        return -1;
    t0 = board_micros();
    if (sonar_tracker_update(&tk, ob, 16, &sw) != SONAR_OK)
        return -1;
    return board_micros() - t0;
}

/* The same sweep and each track's activity look after it (tracker_scene.h: every track's two windows full). */
static int64_t tracker_activity_us(void)
{
    static struct sonar_tracker tk;
    static struct sonar_activity act;
    static uint8_t row[1200];
    struct sonar_tracker_config tc;
    struct sonar_tracker_obs ob[16];
    struct sonar_tracker_sweep sw;
    int64_t t0;
    sonar_tracker_defaults(&tc);
    if (bench_tracker_scene(&tk, &tc, ob, &sw) != 0 || bench_activity_scene(&act, &tk, row) != 0)
        return -1;
    t0 = board_micros();
    if (sonar_tracker_update(&tk, ob, 16, &sw) != SONAR_OK)
        return -1;
    sonar_activity_look(&act, &tk, sw.utime, 0.0f, 60.0f, 0);
    return board_micros() - t0;
}

/* sonard's default detector settings with the study's global threshold (mean + k std): the step before the CFAR. */
static struct sonar_detector_config det_cfg(void)
{
    struct sonar_pipeline_config p;
    sonar_pipeline_defaults(&p);
    p.detector.threshold_mode = SONAR_DET_GLOBAL;
    return p.detector;
}

/*
 * sonard's default per-beam step through the pipeline (median, auto background in place, the CFAR
 * over each beam and its neighbours, runs), over beams 1 .. BENCH_BEAMS - 1 of the fifth sweep:
 * beam 0 ends the previous sweep (detection and tracking, timed apart). Returns the time, or -1.
 */
static int64_t pipeline_us(struct bench *b)
{
    static struct sonar_pipeline pipe;
    static struct sonar_background pipe_bg;
    static struct sonar_activity pipe_act; /* the tracks' echo windows, as the firmware holds them */
    static struct sonar_pipeline_config pc;
    int64_t t0 = 0;
    int s, i;
    sonar_pipeline_defaults(&pc);
    if (sonar_pipeline_init(&pipe, &pipe_bg, &pc) != SONAR_OK || sonar_activity_init(&pipe_act) != SONAR_OK)
        return -1;
    sonar_pipeline_set_activity(&pipe, &pipe_act);
    for (s = 0; s < 5; s++) {
        make_sweep(b, s);
        for (i = 0; i < BENCH_BEAMS; i++) {
            struct sonar_beam beam;
            beam.utime = ((int64_t)s * BENCH_BEAMS + i) * 20000;
            beam.angle = (uint16_t)(i * 400 / BENCH_BEAMS);
            beam.n = BENCH_N;
            beam.range_m = 20.0f;
            beam.samples = b->sweep[i];
            beam.gain = 0;
            if (i == 1)
                t0 = board_micros();
            if (sonar_pipeline_push(&pipe, &beam) < 0)
                return -1;
        }
    }
    return board_micros() - t0;
}

/*
 * The default step's stages one by one, as the pipeline runs them (the CFAR over the beam, the
 * one before and the one after), over the fifth sweep: out[0] the auto background, out[1] the
 * block sums, out[2] the CFAR, out[3] the runs. Returns 0, or -1.
 */
static int default_stages(struct bench *b, int64_t out[4])
{
    static struct sonar_background bg;
    static struct sonar_detector det;
    static uint16_t sums[2][SONAR_CFAR_MAX_BLOCKS];
    static uint8_t on[SONAR_CFAR_MAX_BLOCKS];
    struct sonar_pipeline_config pc;
    int s, i;
    sonar_pipeline_defaults(&pc);
    if (sonar_background_init(&bg, &pc.background) != SONAR_OK || sonar_detector_init(&det, &pc.detector) != SONAR_OK)
        return -1;
    for (s = 0; s < 5; s++) {
        make_sweep(b, s);
        out[0] = out[1] = out[2] = out[3] = 0;
        for (i = 0; i < BENCH_BEAMS; i++) {
            int64_t a, g, u, c;
            uint16_t angle = (uint16_t)(i * 400 / BENCH_BEAMS);
            if (sonar_median_1d(b->sweep[i], b->filt, BENCH_N, 5) != SONAR_OK)
                return -1;
            a = board_micros();
            if (sonar_background_apply_keep(&bg, angle, b->filt, b->filt, BENCH_N, NULL, 0) != SONAR_OK)
                return -1;
            g = board_micros();
            if (sonar_cfar_sums(b->filt, BENCH_N, sums[i & 1]) < 0)
                return -1;
            u = board_micros();
            if (sonar_cfar_blocks_sums(&pc.detector.cfar, sums[(i + 1) & 1], sums[i & 1], sums[(i + 1) & 1], BENCH_N,
                                       on, NULL) < 0)
                return -1;
            c = board_micros();
            if (sonar_detector_add_blocks(&det, angle, b->filt, on, BENCH_N, 20.0f, 0) != SONAR_OK)
                return -1;
            out[0] += g - a;
            out[1] += u - g;
            out[2] += c - u;
            out[3] += board_micros() - c;
        }
        if (sonar_detector_end(&det, &b->out) < 0)
            return -1;
    }
    return 0;
}

/*
 * The scan planner's worst call: follow mode round a full circle at 1 gradian a step (a 400-beam
 * grid), SONAR_SCAN_MAX_TARGETS targets each with the widest window, after a turn. Returns the
 * mean us of 400 calls, or -1.
 */
static int64_t scan_us(void)
{
    static struct sonar_scan sc;
    struct sonar_scan_config c;
    struct sonar_scan_target t[SONAR_SCAN_MAX_TARGETS];
    int64_t now = 0, t0;
    int i;
    memset(&c, 0, sizeof(c));
    c.mode = SONAR_SCAN_FOLLOW;
    c.full_circle = 1;
    c.step = 1;
    c.ping_us = 39400;
    c.revisit_s = 1.5f;
    for (i = 0; i < SONAR_SCAN_MAX_TARGETS; i++) {
        t[i].angle = (float)(i * 25);
        t[i].half_width = 40.0f;
    }
    if (sonar_scan_init(&sc, &c) != SONAR_OK)
        return -1;
    for (i = 0; i < 400; i++, now += 45400)
        (void)sonar_scan_next(&sc, t, SONAR_SCAN_MAX_TARGETS, now);
    t0 = board_micros();
    for (i = 0; i < 400; i++, now += 45400)
        (void)sonar_scan_next(&sc, t, SONAR_SCAN_MAX_TARGETS, now);
    return (board_micros() - t0) / 400;
}

/* The typical sweep's figures: per-beam stages (us over the sweep) and the detection at its end. */
struct typical {
    int64_t beam_us, det_us, t_med, t_bg, t_add;
    int count;
};

/* Two sweeps seed the background, one sets the threshold; the fourth is timed. 0, or the exit code. */
static int typical_sweeps(struct bench *b, struct typical *ty)
{
    int64_t t0;
    int s, i;
    for (s = 0; s < 4; s++) {
        make_sweep(b, s);
        ty->t_med = ty->t_bg = ty->t_add = 0;
        t0 = board_micros();
        for (i = 0; i < BENCH_BEAMS; i++) {
            /* Each stage timed too; the clock reads (tens of instructions) are inside the total. */
            int64_t a = board_micros(), m, g;
            if (sonar_median_1d(b->sweep[i], b->filt, BENCH_N, 5) != SONAR_OK)
                return 2;
            m = board_micros();
            if (sonar_background_apply(&b->bg, (uint16_t)(i * 400 / BENCH_BEAMS), b->filt, b->fg, BENCH_N) != SONAR_OK)
                return 2;
            g = board_micros();
            if (sonar_detector_add(&b->det, (uint16_t)(i * 400 / BENCH_BEAMS), b->fg, BENCH_N, 20.0f, 0) != SONAR_OK)
                return 2;
            ty->t_med += m - a;
            ty->t_bg += g - m;
            ty->t_add += board_micros() - g;
        }
        ty->beam_us = board_micros() - t0;
        t0 = board_micros();
        if (sonar_detector_end(&b->det, &b->out) < 0)
            return 3;
        ty->det_us = board_micros() - t0;
        ty->count = b->out.count;
    }
    return 0;
}

/* The last sweep again under the detector's worst case: the run table full, every rule on, wide groups cut into the most pieces. */
static int worst_sweep_in(struct bench *b, const struct sonar_detector_config *dc)
{
    int i;
    if (sonar_detector_init(&b->det, dc) != SONAR_OK)
        return 4;
    for (i = 0; i < BENCH_BEAMS; i++)
        if (sonar_detector_add(&b->det, (uint16_t)(i * 400 / BENCH_BEAMS), b->sweep[i], BENCH_N, 20.0f, 0) != SONAR_OK)
            return 5;
    return 0;
}

/* The worst case whole (*worst_us), then stage by stage in sonar_detector_end's order, each put. 0, or the exit code. */
static int worst_sweep(struct bench *b, int64_t *worst_us)
{
    struct sonar_detector_config dc = det_cfg();
    struct sonar_xy c[SONAR_MAX_CLUSTERS], at;
    struct sonar_det_cluster cl[SONAR_MAX_CLUSTERS];
    uint8_t part[SONAR_MAX_CLUSTERS], k, j;
    uint16_t groups;
    struct sonar_detection o;
    int64_t t0, t1, t2, t3, t4;
    int r;
    dc.min_threshold = 0;
    dc.threshold_k = 0.0f;
    dc.max_clusters = SONAR_MAX_CLUSTERS;
    dc.max_extent_m = 1.0f;
    dc.split_points = 1;
    dc.max_aspect = 2.0f;
    dc.min_range_m = 0.5f;
    dc.track_m = 1.0f;
    dc.track_points = 1;
    if ((r = worst_sweep_in(b, &dc)) != 0)
        return r;
    put_num("worst_runs", b->det.nruns);
    t0 = board_micros();
    if (sonar_detector_end(&b->det, &b->out) < 0)
        return 6;
    *worst_us = board_micros() - t0;
    if ((r = worst_sweep_in(b, &dc)) != 0)
        return r + 3;
    t1 = board_micros();
    sonar_det_join(&b->det);
    t2 = board_micros();
    k = sonar_det_seed(&b->det, c, part, &groups);
    t3 = board_micros();
    if (sonar_kmeans_lloyd_within(b->det.pts, b->det.nruns, b->det.labels, c, part, k, b->det.cfg.iterations) < 0)
        return 9;
    t4 = board_micros();
    sonar_det_clusters(&b->det, k, cl);
    for (j = 0; j < k; j++)
        (void)sonar_det_accept(&b->det, j, &cl[j], 1, &o, &at);
    put_num("worst_insn_link", (uint64_t)(t2 - t1) * INSN_PER_US);
    put_num("worst_insn_seed_and_cut", (uint64_t)(t3 - t2) * INSN_PER_US);
    put_num("worst_insn_kmeans", (uint64_t)(t4 - t3) * INSN_PER_US);
    put_num("worst_insn_rules_hulls", (uint64_t)(board_micros() - t4) * INSN_PER_US);
    put_num("worst_clusters", k);
    return 0;
}

int main(void)
{
    static struct bench b; /* main's own */
    struct sonar_background_config bc = {SONAR_BACKGROUND_PER_ANGLE, 2, 1, 8};
    struct sonar_detector_config dc = det_cfg();
    struct typical ty;
    int64_t worst_us = 0, tu, tw, ta, su, tp, st[4];
    int r;
    board_init();
    b.rng = 42;
    if (sonar_background_init(&b.bg, &bc) != SONAR_OK || sonar_detector_init(&b.det, &dc) != SONAR_OK)
        return 1;
    if ((r = typical_sweeps(&b, &ty)) != 0 || (r = worst_sweep(&b, &worst_us)) != 0)
        return r;
    if ((tu = tracker_us(0)) < 0 || (tw = tracker_us(1)) < 0 || (ta = tracker_activity_us()) < 0 || (su = scan_us()) < 0)
        return 5;
    put_num("insn_tracker_sweep", (uint64_t)tu * INSN_PER_US);
    put_num("insn_tracker_walls_sweep", (uint64_t)tw * INSN_PER_US);
    put_num("insn_tracker_activity_sweep", (uint64_t)ta * INSN_PER_US);
    put_num("insn_scan_call", (uint64_t)su * INSN_PER_US);
    put_num("beams", BENCH_BEAMS);
    put_num("samples", BENCH_N);
    put_num("insn_per_beam_global", (uint64_t)ty.beam_us * INSN_PER_US / BENCH_BEAMS);
    put_num("insn_per_beam_median5", (uint64_t)ty.t_med * INSN_PER_US / BENCH_BEAMS);
    put_num("insn_per_beam_background", (uint64_t)ty.t_bg * INSN_PER_US / BENCH_BEAMS);
    put_num("insn_per_beam_stats_runs", (uint64_t)ty.t_add * INSN_PER_US / BENCH_BEAMS);
    put_num("insn_sweep_detect_typical", (uint64_t)ty.det_us * INSN_PER_US);
    put_num("typical_detections", (uint64_t)ty.count);
    put_num("worst_detections", b.out.count);
    put_num("insn_sweep_detect_worst", (uint64_t)worst_us * INSN_PER_US);
    if ((tp = pipeline_us(&b)) < 0)
        return 10;
    put_num("insn_per_beam", (uint64_t)tp * INSN_PER_US / (BENCH_BEAMS - 1));
    if (default_stages(&b, st) != 0)
        return 11;
    put_num("insn_per_beam_auto_background", (uint64_t)st[0] * INSN_PER_US / BENCH_BEAMS);
    put_num("insn_per_beam_cfar_sums", (uint64_t)st[1] * INSN_PER_US / BENCH_BEAMS);
    put_num("insn_per_beam_cfar", (uint64_t)st[2] * INSN_PER_US / BENCH_BEAMS);
    put_num("insn_per_beam_cfar_runs", (uint64_t)st[3] * INSN_PER_US / BENCH_BEAMS);
    put_num("stack_used_bytes", board_stack_used());
    put("done\n");
    while (board_uart_pending(BOARD_UART_SONAR) > 0)
        board_uart_pump();
    board_exit(0);
    return 0;
}
