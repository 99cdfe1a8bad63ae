/* wallfit.c -- what a moving sonar's world makes of a scene's walls: the world-frame background's grid fitted across each wall, and the OBSTACLE_DISTANCE map's sectors against the walls as the vehicle moves, with its world memory and without. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "app.h"
#include "posefile.h"
#include "sonar/obstacle.h"
#include "source_replay.h"

#define MAX_WALLS 8

static int64_t mono_ns(void *u)
{
    struct timespec t;
    (void)u;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (int64_t)t.tv_sec * 1000000000 + t.tv_nsec;
}

static int64_t wall_us(void *u)
{
    (void)u;
    return mono_ns(NULL) / 1000;
}

/*
 * Along the normal through (n, e) of a wall with unit normal (nn, ne): the model-weighted
 * centroid of the cells above half the largest, within +-1 m. Returns the offset from (n, e) in
 * metres, or NAN when nothing there was seen.
 */
static double fit(const struct sonar_background *bg, double n, double e, double nn, double ne, int *peak)
{
    double step = (double)bg->cell_m / 4.0, s, sw = 0.0, swx = 0.0;
    uint8_t m, seen, mx = 0;
    for (s = -1.0; s <= 1.0; s += step)
        if (sonar_background_world_at(bg, n + s * nn, e + s * ne, &m, &seen) && m > mx)
            mx = m;
    *peak = mx;
    if (mx < 40)
        return NAN;
    for (s = -1.0; s <= 1.0; s += step)
        if (sonar_background_world_at(bg, n + s * nn, e + s * ne, &m, &seen) && m >= mx / 2) {
            sw += m;
            swx += m * s;
        }
    return swx / sw;
}

/* Distance along the unit ray (ux, uy) from (n, e) to a wall; < 0 if missed. */
static double ray_wall(double n, double e, double ux, double uy, const double *w)
{
    double x0 = w[0] - n, y0 = w[1] - e, ex = w[2] - w[0], ey = w[3] - w[1], den = ux * ey - uy * ex, t, s;
    if (fabs(den) < 1e-12)
        return -1.0;
    t = (x0 * ey - y0 * ex) / den;
    s = (x0 * uy - y0 * ux) / den;
    return t > 0.0 && s >= 0.0 && s <= 1.0 ? t : -1.0;
}

/* The obstacle map's check: two maps fed the filtered beams, one with the poses (world memory), one without. */
struct probe {
    struct app_sink sink;
    struct sonar_obstacle with, without;
    const double (*walls)[4];
    int nw;
    int64_t next_us, start_us;
    long n[2], within[2];
    double abs_err[2];
};

static int probe_beam(void *self, const struct app_beam *b)
{
    struct probe *p = self;
    struct sonar_pose q = {b->utime, b->north_m, b->east_m, b->yaw_deg};
    float bearing = (float)b->angle * 0.9f;
    int k, m;
    if (sonar_obstacle_beam(&p->with, b->utime, bearing, b->has_pose ? &q : NULL, b->samples, b->n, b->range_m) != SONAR_OK ||
        sonar_obstacle_beam(&p->without, b->utime, bearing, NULL, b->samples, b->n, b->range_m) != SONAR_OK)
        return HOST_ERR_IO;
    if (p->start_us == 0)
        p->start_us = b->utime;
    /* Once a second after the first two sweeps (the floor's warm-up): every sector with an echo against the walls from here. */
    if (!b->has_pose || b->utime < p->start_us + 13000000 || b->utime < p->next_us)
        return HOST_OK;
    p->next_us = b->utime + 1000000;
    for (m = 0; m < 2; m++) {
        uint16_t d[SONAR_OBS_SECTORS], mn, mx;
        sonar_obstacle_map(m == 0 ? &p->with : &p->without, b->utime, 7600000, m == 0 ? &q : NULL, d, &mn, &mx);
        for (k = 0; k < SONAR_OBS_SECTORS; k++) {
            double best = -1.0, a;
            int w;
            if (d[k] == SONAR_OBS_UNKNOWN || d[k] > mx)
                continue;
            for (a = -2.5; a <= 2.5; a += 0.1) {
                double th = ((double)k * 5.0 + a + (double)b->yaw_deg) * 3.14159265358979323846 / 180.0;
                for (w = 0; w < p->nw; w++) {
                    double t = ray_wall(b->north_m, b->east_m, cos(th), sin(th), p->walls[w]);
                    if (t > 0.0 && (best < 0.0 || t < best))
                        best = t;
                }
            }
            if (best < 0.0 || best > (double)mx / 100.0)
                continue;
            p->n[m]++;
            p->within[m] += fabs((double)d[k] / 100.0 - best) <= 0.1;
            p->abs_err[m] += fabs((double)d[k] / 100.0 - best);
        }
    }
    return HOST_OK;
}

int main(int argc, char **argv)
{
    static struct probe probe;
    struct sonar_obstacle_config oc;
    static struct app app;
    static struct source_replay rp;
    static struct posefile pf;
    struct sonar_pipeline_config c;
    struct app_clock clk = {mono_ns, wall_us, NULL};
    double walls[MAX_WALLS][4], all2 = 0.0;
    int nw = 0, i, nall = 0;
    const char *csv = NULL, *pose = NULL;
    char err[300];
    for (i = 1; i + 1 < argc; i += 2) {
        if (strcmp(argv[i], "--replay") == 0)
            csv = argv[i + 1];
        else if (strcmp(argv[i], "--pose") == 0)
            pose = argv[i + 1];
        else if (strcmp(argv[i], "--wall") == 0 && nw < MAX_WALLS &&
                 sscanf(argv[i + 1], "%lf,%lf,%lf,%lf", &walls[nw][0], &walls[nw][1], &walls[nw][2], &walls[nw][3]) == 4)
            nw++;
        else
            break;
    }
    if (csv == NULL || pose == NULL || nw == 0 || i < argc) {
        fprintf(stderr, "usage: sonar-wallfit --replay FILE.csv --pose POSE.csv --wall N0,E0,N1,E1 [--wall ...]\n");
        return 2;
    }
    sonar_pipeline_defaults(&c);
    if (app_init(&app, &c, NULL, NULL, &clk, 1500.0f, 0, err, sizeof(err)) != HOST_OK ||
        source_replay_open(&rp, csv, -1.0, 1500.0, err, sizeof(err)) != HOST_OK ||
        posefile_open(&pf, pose, err, sizeof(err)) != HOST_OK) {
        fprintf(stderr, "sonar-wallfit: %s\n", err);
        return 2;
    }
    rp.pose = &pf;
    sonar_obstacle_defaults(&oc);
    if (sonar_obstacle_init(&probe.with, &oc) != SONAR_OK || sonar_obstacle_init(&probe.without, &oc) != SONAR_OK)
        return 2;
    probe.walls = (const double(*)[4])walls;
    probe.nw = nw;
    probe.sink.name = "probe";
    probe.sink.self = &probe;
    probe.sink.stages = 1u << SONAR_STAGE_MEDIAN;
    probe.sink.beam = probe_beam;
    if (app_add_sink(&app, &probe.sink) != HOST_OK)
        return 2;
    (void)source_replay_run(&rp, &app, stderr);
    if (!app.pipe.bg.world) {
        fprintf(stderr, "sonar-wallfit: the background is not in the world frame (no pose?)\n");
        return 1;
    }
    printf("grid cell %.3f m, range cell %.4f m\n", (double)app.pipe.bg.cell_m, (double)(app.pipe.range_m / (float)app.pipe.n));
    for (i = 0; i < nw; i++) {
        double dn = walls[i][2] - walls[i][0], de = walls[i][3] - walls[i][1], len = sqrt(dn * dn + de * de), s;
        double nn = -de / len, ne = dn / len, sum = 0.0, sum2 = 0.0;
        int k = 0, tried = 0;
        /* Every 0.2 m, a metre clear of the corners (where two walls meet, the fit mixes them). */
        for (s = 1.0; s <= len - 1.0; s += 0.2) {
            int peak;
            double off = fit(&app.pipe.bg, walls[i][0] + s * dn / len, walls[i][1] + s * de / len, nn, ne, &peak);
            tried++;
            if (isnan(off))
                continue;
            sum += off;
            sum2 += off * off;
            k++;
        }
        all2 += sum2;
        nall += k;
        printf("wall %d (%.1f,%.1f)-(%.1f,%.1f): %d of %d points seen, offset mean %+.4f m, rms %.4f m\n", i, walls[i][0],
               walls[i][1], walls[i][2], walls[i][3], k, tried, k ? sum / k : 0.0, k ? sqrt(sum2 / k) : 0.0);
    }
    printf("all walls: %d points, rms %.4f m\n", nall, nall ? sqrt(all2 / nall) : 0.0);
    for (i = 0; i < 2; i++)
        printf("OBSTACLE_DISTANCE map %s: %ld sectors with a wall echo checked once a second, %.1f %% within 0.1 m "
               "of the nearest wall in the sector, mean |error| %.3f m\n",
               i == 0 ? "with the poses (world memory)" : "without (the sonar frame as seen)", probe.n[i],
               probe.n[i] ? 100.0 * (double)probe.within[i] / (double)probe.n[i] : 0.0,
               probe.n[i] ? probe.abs_err[i] / (double)probe.n[i] : 0.0);
    posefile_close(&pf);
    source_replay_close(&rp);
    return nall > 0 ? 0 : 1;
}
