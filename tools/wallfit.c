/* wallfit.c -- how well the world-frame background rebuilt a scene's walls: replays a recording with its poses, then fits each wall's position across it in the learnt grid. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "app.h"
#include "posefile.h"
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

int main(int argc, char **argv)
{
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
    posefile_close(&pf);
    source_replay_close(&rp);
    return nall > 0 ? 0 : 1;
}
