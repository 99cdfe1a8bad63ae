/* bench.c -- per-stage speed of the core on a 400 x 1200 sweep, with memcpy of the same bytes as the yardstick; writes the data for bench_opencv. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "sonar/background.h"
#include "sonar/detector.h"
#include "sonar/hull.h"
#include "sonar/kmeans.h"
#include "sonar/median.h"
#include "sonar/obstacle.h"
#include "sonar/pipeline.h"
#include "sonar/scan.h"
#include "sonar/survey.h"
#include "sonar/tracker.h"
#include "tracker_scene.h"

#define BEAMS 400
#define N 1200
#define REPS 41
#define SWEEPS 4

static uint8_t sweeps[SWEEPS][BEAMS][N];
#define sweep sweeps[0]
static uint8_t filt[N], fg[N], copy[BEAMS][N];
static struct sonar_background bg, bg_alone; /* the pipeline's, and one for timing the stage alone */
static struct sonar_background bg_world;      /* the world grid of a moving sonar */
static struct sonar_obstacle obstacles;       /* the OBSTACLE_DISTANCE map */
static struct sonar_detector det;
static struct sonar_detections out, worst_out;
static struct sonar_pipeline pipe; /* sonard's defaults, beam by beam */
static struct sonar_background pipe_bg;
static struct sonar_activity pipe_act; /* its tracks' echo windows, as sonard holds them */
static struct sonar_pipeline pipe_sv; /* the same, judged against a survey of the site */
static struct sonar_background pipe_sv_bg;
static struct sonar_survey_rec rec;   /* the survey's recording (3.4 MB, the host's) ... */
static struct sonar_survey sv;        /* ... and its use: the level in the background, the spread here */
static struct sonar_survey_spread spread;
static struct sonar_detector sv_det;  /* the recording's scratch for the structure */
static struct sonar_detection sv_places[SONAR_MAX_CLUSTERS], sv_found[SONAR_MAX_CLUSTERS];
static uint8_t sv_img[SONAR_BGFILE_MAX];

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + (double)t.tv_nsec * 1e-9;
}

static int cmpd(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static double median_of(double *v, int n)
{
    qsort(v, (size_t)n, sizeof(double), cmpd);
    return v[n / 2];
}

/*
 * A pipeline's per-beam step, us: 8 sweeps to warm, then REPS sweeps timed (t, REPS of them), the
 * median. Beam 0 of each sweep is pushed untimed: it ends the previous sweep (detection, tracking).
 */
static double pipeline_step_us(struct sonar_pipeline *p, double *t, int *sink)
{
    int r, i;
    for (r = 0; r < 8 + REPS; r++) {
        double t0 = 0.0;
        for (i = 0; i < BEAMS; i++) {
            struct sonar_beam b = {(int64_t)(r * BEAMS + i) * 20000, (uint16_t)i, N, 20.0f, sweeps[r % SWEEPS][i], 0};
            if (i == 1)
                t0 = now();
            *sink += sonar_pipeline_push(p, &b);
        }
        if (r >= 8)
            t[r - 8] = (now() - t0) / (BEAMS - 1) * 1e6;
    }
    return median_of(t, REPS);
}

/*
 * Sonar-like sweeps: fresh speckle ((a^2 + b^2) >> 7, as in algorithms.md) every sweep, a static
 * wall, and 20 bright 9 x 21 blobs that move between sweeps, so the background has a steady
 * state and the foreground has objects, like a real scene.
 */
static void make_sweeps(void)
{
    int s, i, j, k;
    srand(42);
    for (s = 0; s < SWEEPS; s++) {
        for (i = 0; i < BEAMS; i++)
            for (j = 0; j < N; j++) {
                int a = rand() % 64, b = rand() % 64;
                sweeps[s][i][j] = (uint8_t)((a * a + b * b) >> 7);
                if (j >= 900 + i / 8 && j < 910 + i / 8)
                    sweeps[s][i][j] = (uint8_t)(120 + rand() % 60);
            }
        for (k = 0; k < 20; k++) {
            int bi = (k * 19 + s * 11) % (BEAMS - 9), bj = 50 + (k * 41 + s * 3) % (N - 300);
            for (i = bi; i < bi + 9; i++)
                for (j = bj; j < bj + 21; j++)
                    sweeps[s][i][j] = (uint8_t)(150 + rand() % 100);
        }
    }
}

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : "/tmp";
    double t_med[REPS], t_step[REPS], t_cpy[REPS], t_det[REPS], t_km[REPS], t_bg[REPS], t_st[REPS], t_2d[REPS];
    static struct sonar_median2d m2d;
    struct sonar_background_config bc = {SONAR_BACKGROUND_PER_ANGLE, 2, 1, 8};
    struct sonar_pipeline_config defaults;
    struct sonar_detector_config dc;
    static struct sonar_point pts[5000];
    static uint8_t labels[5000];
    static struct sonar_xy hp[5000], hull[10000];
    struct sonar_xy c[6];
    char path[512];
    FILE *f;
    int r, i, j, sink = 0;
    unsigned worst_runs = 0;

    sonar_pipeline_defaults(&defaults);
    /* The detector with the study's global threshold (mean + 3 std): the run table fills as it did before the CFAR. */
    dc = defaults.detector;
    dc.threshold_mode = SONAR_DET_GLOBAL;
    make_sweeps();
    snprintf(path, sizeof(path), "%s/bench_sweep.bin", dir);
    f = fopen(path, "wb");
    if (f == NULL || fwrite(sweep, 1, sizeof(sweep), f) != sizeof(sweep) || fclose(f) != 0) {
        perror(path);
        return 1;
    }
    if (sonar_background_init(&bg, &bc) != SONAR_OK || sonar_background_init(&bg_alone, &bc) != SONAR_OK ||
        sonar_detector_init(&det, &dc) != SONAR_OK)
        return 1;
    /* Warm the background past its seeding so the steady-state path is what gets timed. */
    for (r = 0; r < 8; r++)
        for (i = 0; i < BEAMS; i++) {
            if (sonar_median_1d(sweeps[r % SWEEPS][i], filt, N, 5) != SONAR_OK ||
                sonar_background_apply(&bg, (uint16_t)i, filt, fg, N) != SONAR_OK ||
                sonar_detector_add(&det, (uint16_t)i, fg, N, 20.0f, 0) != SONAR_OK)
                return 1;
            if (i == BEAMS - 1 && sonar_detector_end(&det, &out) < 0)
                return 1;
        }
    for (r = 0; r < REPS; r++) {
        double t0 = now(), t1, t2, t3, t4, t5;
        for (i = 0; i < BEAMS; i++)
            sink += sonar_median_1d(sweep[i], filt, N, 5) + filt[7];
        t1 = now();
        /* The per-beam step before the CFAR: median, per-angle background, global threshold and runs. */
        for (i = 0; i < BEAMS; i++) {
            sink += sonar_median_1d(sweeps[r % SWEEPS][i], filt, N, 5);
            sink += sonar_background_apply(&bg, (uint16_t)i, filt, fg, N);
            sink += sonar_detector_add(&det, (uint16_t)i, fg, N, 20.0f, 0);
        }
        t2 = now();
        sink += sonar_detector_end(&det, &out);
        t3 = now();
        for (i = 0; i < BEAMS; i++)
            memcpy(copy[i], sweep[i], N);
        sink += copy[r][r];
        t4 = now();
        /* A separate model: feeding sweep 0 to the pipeline's would teach it sweep 0's objects. */
        for (i = 0; i < BEAMS; i++)
            sink += sonar_background_apply(&bg_alone, (uint16_t)i, sweep[i], fg, N);
        t5 = now();
        t_med[r] = (t1 - t0) / (BEAMS * N) * 1e9;
        t_step[r] = (t2 - t1) / BEAMS * 1e6;
        t_st[r] = (t3 - t2) * 1e3;
        t_cpy[r] = (t4 - t3) / BEAMS * 1e6;
        t_bg[r] = (t5 - t4) / BEAMS * 1e6;
    }
    /*
     * The per-beam step of sonard's defaults through the pipeline: median, auto background in
     * place, CFAR over each beam and its neighbours (one beam late), runs. Beam 0 of each sweep is
     * pushed untimed: it ends the previous sweep (detection and tracking, timed above).
     */
    {
        double t_pipe[REPS];
        if (sonar_pipeline_init(&pipe, &pipe_bg, &defaults) != SONAR_OK || sonar_activity_init(&pipe_act) != SONAR_OK)
            return 1;
        sonar_pipeline_set_activity(&pipe, &pipe_act);
        printf("beam_step_us %.4f\n", pipeline_step_us(&pipe, t_pipe, &sink));
    }
    /*
     * The same step with a site survey in use (survey.h): each cell judged against its level and
     * spread instead of learnt, and each beam looked at for the survey's fit. The survey is of these
     * sweeps, recorded beam by beam after the median as the pipeline records it (no tracks: nothing refuses it).
     */
    {
        double t_sv[REPS], t_load;
        struct sonar_bgfile_meta m;
        const char *why = NULL;
        uint8_t np = 0;
        int32_t len;
        sonar_survey_rec_init(&rec);
        for (r = 0; r < 2 * SWEEPS; r++) {
            for (i = 0; i < BEAMS; i++)
                if (sonar_median_1d(sweeps[r % SWEEPS][i], filt, N, defaults.median) != SONAR_OK ||
                    sonar_survey_rec_beam(&rec, (uint16_t)i, filt, N, 20.0f, 0, (int64_t)(r * BEAMS + i) * 20000) != SONAR_OK)
                    return 1;
            if (sonar_survey_rec_sweep(&rec, NULL, 0) != SONAR_OK)
                return 1;
        }
        memset(&m, 0, sizeof(m));
        m.mode = defaults.background.mode;
        m.median = defaults.median;
        m.sound_mm_s = 1500000u;
        len = sonar_survey_rec_image(&rec, &m, &defaults.detector, &sv_det, sv_found, &np, sv_img, sizeof(sv_img));
        if (len < 0 || sonar_pipeline_init(&pipe_sv, &pipe_sv_bg, &defaults) != SONAR_OK)
            return 1;
        sonar_survey_init(&sv, &spread, sv_places);
        sonar_pipeline_set_survey(&pipe_sv, &sv);
        t_load = now();
        if (sonar_pipeline_load_background(&pipe_sv, sv_img, (size_t)len, &why) != SONAR_OK) {
            fprintf(stderr, "bench: the survey: %s\n", why != NULL ? why : "?");
            return 1;
        }
        printf("survey_load_ms %.3f\n", (now() - t_load) * 1e3);
        printf("beam_step_survey_us %.4f\n", pipeline_step_us(&pipe_sv, t_sv, &sink));
        /* Timed in use, not given up along the way (then the plain background would have been timed). */
        printf("beam_step_survey_in_use %d\n", sonar_pipeline_survey(&pipe_sv)->state == SONAR_SURVEY_IN_USE);
        {
            /* The file with the spread against the same file without (a learnt model's): what the spread costs. */
            struct sonar_bgfile_layout lo;
            if (sonar_bgfile_layout(N, (uint8_t)(sv.meta.flags & ~SONAR_BGFILE_SPREAD), np, &lo) != SONAR_OK)
                return 1;
            printf("survey_file_bytes %ld %u\n", (long)len, (unsigned)lo.size);
            printf("survey_ram_bytes %u %u\n", (unsigned)sizeof(pipe_sv_bg.cell), (unsigned)sizeof(spread));
        }
    }
    /* The study's 2-D filter: 5 x 5 over the sweep, row by row through the delay line. */
    for (r = 0; r < REPS; r++) {
        struct sonar_median_row meta = {0, 0, 0}, om;
        double t0 = now();
        if (sonar_median2d_init(&m2d, 5) != SONAR_OK)
            return 1;
        for (i = 0; i < BEAMS; i++)
            sink += sonar_median2d_push(&m2d, sweep[i], N, &meta, filt, &om);
        while (sonar_median2d_flush(&m2d, filt, &om) == 1)
            sink++;
        t_2d[r] = (now() - t0) / (BEAMS * N) * 1e9;
    }
    /* A sweep that fills the run table, with every rule on and wide groups cut into the most
       pieces: the detector's worst case. */
    for (r = 0; r < REPS; r++) {
        struct sonar_detector_config worst = dc;
        double t0;
        worst.min_threshold = 0;
        worst.threshold_k = 0.0f;
        worst.max_clusters = SONAR_MAX_CLUSTERS;
        worst.max_extent_m = 1.0f;
        worst.split_points = 1;
        worst.max_aspect = 2.0f;
        worst.min_range_m = 0.5f;
        worst.track_m = 1.0f;
        worst.track_points = 1;
        if (sonar_detector_init(&det, &worst) != SONAR_OK)
            return 1;
        for (i = 0; i < BEAMS; i++)
            sink += sonar_detector_add(&det, (uint16_t)i, sweep[i], N, 20.0f, 0);
        worst_runs = det.nruns;
        t0 = now();
        sink += sonar_detector_end(&det, &worst_out);
        t_det[r] = (now() - t0) * 1e3;
    }
    /* 5000 points in 6 Gaussian blobs (mm); written for the OpenCV run on the same points. */
    srand(7);
    for (i = 0; i < 5000; i++) {
        double u1 = (rand() + 1.0) / (RAND_MAX + 2.0), u2 = (rand() + 1.0) / (RAND_MAX + 2.0);
        double g = sqrt(-2 * log(u1)), th = 6.283185307179586 * u2;
        pts[i].x = (int32_t)((i % 6) * 4000 + 600 * g * cos(th));
        pts[i].y = (int32_t)((i % 3) * 5000 + 600 * g * sin(th));
        pts[i].w = 1;
    }
    snprintf(path, sizeof(path), "%s/bench_points.bin", dir);
    f = fopen(path, "wb");
    if (f == NULL || fwrite(pts, sizeof(pts[0]), 5000, f) != 5000 || fclose(f) != 0) {
        perror(path);
        return 1;
    }
    for (r = 0; r < REPS; r++) {
        double t0 = now();
        int k = sonar_kmeans_seed(pts, 5000, c, 6);
        sink += sonar_kmeans_lloyd(pts, 5000, labels, c, (uint8_t)k, 10);
        for (j = 0; j < k; j++) {
            int m = 0;
            for (i = 0; i < 5000; i++)
                if (labels[i] == j) {
                    hp[m].x = pts[i].x;
                    hp[m].y = pts[i].y;
                    m++;
                }
            if (m > 0)
                sink += sonar_hull_build(hp, (uint16_t)m, hull, 10000);
        }
        t_km[r] = (now() - t0) * 1e3;
    }
    /* The tracker: tracker_scene.h's sweep, 32 tracks and 16 detections, from the same saved state each time. */
    {
        static struct sonar_tracker tk0, tk;
        struct sonar_tracker_config tc;
        struct sonar_tracker_obs ob[16];
        struct sonar_tracker_sweep tsw;
        double t_trk[REPS];
        int rep, cv;
        /* Twice: sonard's tracker, then the one before the IMM (near constant velocity alone, each sweep final). */
        for (cv = 0; cv < 2; cv++) {
            sonar_tracker_defaults(&tc);
            tc.imm = (uint8_t)!cv;
            tc.defer = (uint8_t)!cv;
            if (bench_tracker_scene(&tk0, &tc, ob, &tsw) != 0)
                return 1;
            for (r = 0; r < REPS; r++) {
                double t0 = now();
                for (rep = 0; rep < 200; rep++) {
                    memcpy(&tk, &tk0, sizeof(tk));
                    sink += sonar_tracker_update(&tk, ob, 16, &tsw);
                }
                t_trk[r] = (now() - t0) / 200 * 1e6;
            }
            printf("tracker_sweep%s_us %.3f\n", cv ? "_cv" : "", median_of(t_trk, REPS));
            if (cv)
                break;
            printf("tracker_tracks %d\n", (int)tk0.n);
            printf("tracker_alternatives %d %d\n", (int)tk0.nalt, (int)tk.nalt);
            {
                /* The same sweep in a walled site (tracker_scene.h): SONAR_TRK_MAX_WALLS walls about it. */
                static struct sonar_tracker tkw;
                memcpy(&tkw, &tk0, sizeof(tkw));
                if (bench_tracker_walls(&tkw) != 0)
                    return 1;
                for (r = 0; r < REPS; r++) {
                    double t0 = now();
                    for (rep = 0; rep < 200; rep++) {
                        memcpy(&tk, &tkw, sizeof(tk));
                        sink += sonar_tracker_update(&tk, ob, 16, &tsw);
                    }
                    t_trk[r] = (now() - t0) / 200 * 1e6;
                }
                printf("tracker_walls_sweep_us %.3f\n", median_of(t_trk, REPS));
            }
            {
                /* The same sweep and the activity's look after it (every track's two windows full), less the copy of
                   the activity's saved state that each repetition needs. */
                static struct sonar_activity act0, act;
                static uint8_t row[1200];
                double t_act[REPS], t_cp[REPS];
                if (bench_activity_scene(&act0, &tk0, row) != 0)
                    return 1;
                for (r = 0; r < REPS; r++) {
                    double t0 = now(), t1;
                    for (rep = 0; rep < 200; rep++) {
                        memcpy(&tk, &tk0, sizeof(tk));
                        memcpy(&act, &act0, sizeof(act));
                        sink += sonar_tracker_update(&tk, ob, 16, &tsw);
                        sonar_activity_look(&act, &tk, tsw.utime, 0.0f, 60.0f, 0);
                    }
                    t1 = now();
                    for (rep = 0; rep < 200; rep++) {
                        memcpy(&act, &act0, sizeof(act));
                        sink += act.s[rep % SONAR_ACT_SLOTS].looks;
                    }
                    t_act[r] = (t1 - t0) / 200 * 1e6;
                    t_cp[r] = (now() - t1) / 200 * 1e6;
                }
                printf("tracker_activity_sweep_us %.3f\n", median_of(t_act, REPS) - median_of(t_cp, REPS));
            }
        }
    }
    /* The scan planner's worst call: follow round a full circle at 1 gradian a step (a 400-beam
       grid), the most targets it reads, each with the widest window. */
    {
        static struct sonar_scan sc;
        struct sonar_scan_config scfg;
        struct sonar_scan_target tg[SONAR_SCAN_MAX_TARGETS];
        double t_sc[REPS];
        int64_t tnow = 0;
        int k2, rep;
        memset(&scfg, 0, sizeof(scfg));
        scfg.mode = SONAR_SCAN_FOLLOW;
        scfg.full_circle = 1;
        scfg.step = 1;
        scfg.ping_us = 39400;
        scfg.revisit_s = 1.5f;
        for (k2 = 0; k2 < SONAR_SCAN_MAX_TARGETS; k2++) {
            tg[k2].angle = (float)(k2 * 25);
            tg[k2].half_width = 40.0f;
        }
        if (sonar_scan_init(&sc, &scfg) != SONAR_OK)
            return 1;
        for (rep = 0; rep < 400; rep++, tnow += 45400)
            sink += sonar_scan_next(&sc, tg, SONAR_SCAN_MAX_TARGETS, tnow);
        for (r = 0; r < REPS; r++) {
            double t0 = now();
            for (rep = 0; rep < 400; rep++, tnow += 45400)
                sink += sonar_scan_next(&sc, tg, SONAR_SCAN_MAX_TARGETS, tnow);
            t_sc[r] = (now() - t0) / 400 * 1e6;
        }
        printf("scan_call_us %.3f\n", median_of(t_sc, REPS));
    }
    /*
     * A moving sonar: each beam into the world grid, the vehicle 1 cm further north and 0.3
     * degrees further round each beam (0.5 m/s and 30 degrees/s at 20 ms a beam); and each beam
     * into the OBSTACLE_DISTANCE map. Both per beam, over the same sweep.
     */
    {
        struct sonar_background_config wc = {SONAR_BACKGROUND_PER_ANGLE, 2, 1, 8};
        struct sonar_obstacle_config oc;
        double t_w[REPS], t_o[REPS];
        long k = 0;
        sonar_obstacle_defaults(&oc);
        if (sonar_background_init(&bg_world, &wc) != SONAR_OK || sonar_obstacle_init(&obstacles, &oc) != SONAR_OK)
            return 1;
        for (r = 0; r < REPS; r++) {
            double t0 = now(), t1;
            for (i = 0; i < BEAMS; i++, k++) {
                struct sonar_bg_ray ray = {0.01 * (double)k, 0.0, 0.9 * i + 0.3 * (double)k, 1.2, 20.0f, 0.5f};
                sink += sonar_background_apply_world(&bg_world, &ray, sweep[i], fg, N);
            }
            t1 = now();
            for (i = 0; i < BEAMS; i++)
                sink += sonar_obstacle_beam(&obstacles, (int64_t)k * 20000 + i * 20000, 0.9f * (float)i, NULL, sweep[i], N, 20.0f);
            t_w[r] = (t1 - t0) / BEAMS * 1e6;
            t_o[r] = (now() - t1) / BEAMS * 1e6;
        }
        printf("world_background_beam_us %.3f\n", median_of(t_w, REPS));
        printf("obstacle_beam_us %.3f\n", median_of(t_o, REPS));
        /* One message's map from a full ring of world points: a sweep with the vehicle's poses, then 200 maps. */
        {
            uint16_t d[SONAR_OBS_SECTORS], mn, mx;
            double t_m[REPS];
            int64_t t = (int64_t)k * 20000 + 100000000;
            for (i = 0; i < BEAMS + SONAR_MAX_OBS_ECHOES; i++, t += 20000) {
                struct sonar_pose q = {t, 0.01f * (float)i, 0.0f, 0.3f * (float)i};
                sink += sonar_obstacle_beam(&obstacles, t, 0.9f * (float)(i % BEAMS), &q, sweep[i % BEAMS], N, 20.0f);
            }
            for (r = 0; r < REPS; r++) {
                struct sonar_pose q = {t, 0.01f * (float)i, 0.0f, 0.3f * (float)i};
                double t0 = now();
                for (j = 0; j < 200; j++) {
                    sonar_obstacle_map(&obstacles, t, 9600000, &q, d, &mn, &mx);
                    sink += d[j % SONAR_OBS_SECTORS];
                }
                t_m[r] = (now() - t0) / 200 * 1e6;
            }
            printf("obstacle_map_us %.3f\n", median_of(t_m, REPS));
            printf("obstacle_map_echoes %u\n", (unsigned)obstacles.count);
        }
    }
    printf("median5_ns_per_sample %.4f\n", median_of(t_med, REPS));
    printf("median5x5_ns_per_sample %.4f\n", median_of(t_2d, REPS));
    printf("beam_step_global_us %.4f\n", median_of(t_step, REPS));
    printf("memcpy_beam_us %.5f\n", median_of(t_cpy, REPS));
    printf("background_beam_us %.4f\n", median_of(t_bg, REPS));

    printf("sweep_detect_ms %.4f\n", median_of(t_st, REPS));
    printf("sweep_detect_objects %d\n", (int)out.count);
    printf("sweep_detect_worst_ms %.4f\n", median_of(t_det, REPS));
    printf("sweep_detect_worst_runs %d\n", (int)worst_runs);
    printf("kmeans_hull_5000_ms %.4f\n", median_of(t_km, REPS));
    printf("sink %d\n", sink & 1);
    return 0;
}
