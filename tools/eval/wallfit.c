/* wallfit.c -- what a moving sonar's world makes of a scene's walls: the world-frame background's grid and the obstacle map's echo points fitted across each wall, and the OBSTACLE_DISTANCE map's sectors against the scene's walls and objects as the vehicle moves, with its world memory and without. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "app.h"
#include "posefile.h"
#include "scene.h"
#include "sonar/obstacle.h"
#include "source_replay.h"

#define MAX_WALLS 8
#define PI 3.14159265358979323846
#define MAP_AGE_US 7600000 /* how old a sector may be: 1.2 sweeps of 6.3 s, as src/host/mav.c asks of the map */

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

/* Distance along the unit ray (ux, uy) from (n, e) to the circle of radius r at (cn, ce); < 0 if missed. */
static double ray_circle(double n, double e, double ux, double uy, double cn, double ce, double r)
{
    double px = cn - n, py = ce - e, along = px * ux + py * uy, miss2 = px * px + py * py - along * along, h;
    if (miss2 > r * r)
        return -1.0;
    h = sqrt(r * r - miss2);
    return along - h > 0.0 ? along - h : along + h > 0.0 ? 0.0 : -1.0;
}

/*
 * The obstacle map's check: two maps fed the filtered beams, one with the poses (world memory),
 * one without. With the scene, its objects are obstacles too, placed where they were when the
 * head last looked their way (what the sonar can know of a moving one).
 */
struct probe {
    struct app_sink sink;
    struct sonar_obstacle with, without;
    const double (*walls)[4];
    int nw;
    const struct scene *scene; /* NULL: walls only */
    int64_t next_us, start_us;
    int sweep, prev_angle;
    int64_t seen_us[SONAR_OBS_SECTORS]; /* by world bearing: the last beam's time, and its sweep */
    int seen_sweep[SONAR_OBS_SECTORS];
    long n[2], within[2], missed[2];
    long on_obj[2], obj_within[2]; /* of n, within: sectors whose nearest obstacle is an object */
    long missed_stale;            /* of missed[0]: beyond the range from where the sonar was at the sector's last pass */
    long nearer[2], farther[2];   /* of n: more than 0.1 m nearer than the obstacle (the safe side), farther */
    long far_obj, far_obj_held;   /* of farther[0]: an object nearest; the map holds an echo within 0.5 m of its centre */
    double abs_err[2];
    long points[2];     /* the map's world echo points within 1 m of a wall, 1 m clear of its ends: all; seen within 30 degrees of its normal */
    double point_sum[2], point_sum2[2];
};

static int world_sector(double deg)
{
    deg = fmod(deg, 360.0);
    deg = deg < 0.0 ? deg + 360.0 : deg;
    return (int)floor(deg / SONAR_OBS_SECTOR_DEG + 0.5) % SONAR_OBS_SECTORS;
}

/*
 * The nearest obstacle along the world ray th (radians) from (n, e); < 0 if none; *object = 1 if
 * it is one of the scene's objects, then at (*on, *oe).
 */
static double nearest(const struct probe *p, double n, double e, double th, int *object, double *on, double *oe)
{
    double best = -1.0, t;
    int w, k, at = world_sector(th * 180.0 / PI);
    *object = 0;
    for (w = 0; w < p->nw; w++)
        if ((t = ray_wall(n, e, cos(th), sin(th), p->walls[w])) > 0.0 && (best < 0.0 || t < best))
            best = t;
    for (k = 0; p->scene != NULL && k < p->scene->nobj && p->seen_us[at] != 0; k++) {
        double x, y, vx, vy, ts = (double)(p->seen_us[at] - p->start_us) / 1e6;
        int sw = p->seen_sweep[at];
        if (!scene_object_at(p->scene, k, sw, ts, &x, &y, &vx, &vy) || (sw < 64 && (p->scene->obj[k].fade >> sw & 1u)))
            continue;
        if ((t = ray_circle(n, e, cos(th), sin(th), x, y, p->scene->obj[k].r)) >= 0.0 && (best < 0.0 || t < best)) {
            best = t;
            *object = 1;
            *on = x;
            *oe = y;
        }
    }
    return best;
}

/* 1 if the world map o holds an echo standing at now_us (as sonar_obstacle_map keeps them) within d metres of (n, e). */
static int holds(const struct sonar_obstacle *o, int64_t now_us, int64_t max_age_us, double n, double e, double d)
{
    uint16_t i;
    for (i = 0; i < o->count; i++) {
        const struct sonar_obstacle_echo *x = &o->echo[i];
        if (x->world && now_us - x->utime <= max_age_us && x->utime >= o->sector[x->sector].pass_us &&
            hypot((double)x->x_m - n, (double)x->y_m - e) <= d)
            return 1;
    }
    return 0;
}

/*
 * *off = the signed distance (m) of (n, e) from the nearest wall within 1 m, a metre clear of its
 * ends, *cosinc = |cos| of the incidence of the ray to it from (vn, ve); returns 0 if none.
 */
static int near_wall(const struct probe *p, double n, double e, double vn, double ve, double *off, double *cosinc)
{
    int w, found = 0;
    for (w = 0; w < p->nw; w++) {
        const double *q = p->walls[w];
        double dn = q[2] - q[0], de = q[3] - q[1], len = sqrt(dn * dn + de * de);
        double s = ((n - q[0]) * dn + (e - q[1]) * de) / len, d = (-(n - q[0]) * de + (e - q[1]) * dn) / len;
        double rn = n - vn, re = e - ve, r = sqrt(rn * rn + re * re);
        if (s < 1.0 || s > len - 1.0 || fabs(d) > 1.0 || (found && fabs(d) >= fabs(*off)))
            continue;
        *off = d;
        *cosinc = r > 0.0 ? fabs(-rn * de + re * dn) / (r * len) : 1.0;
        found = 1;
    }
    return found;
}

/*
 * The nearest obstacle in body sector k (5 degrees, rays 0.1 degree apart) from (n, e) at heading
 * yaw_deg; < 0 if none; *object and (*on, *oe) as nearest() has them for that obstacle.
 */
static double sector_nearest(const struct probe *p, double n, double e, double yaw_deg, int k, int *object, double *on,
                             double *oe)
{
    double best = -1.0, a;
    *object = 0;
    for (a = -2.5; a <= 2.5; a += 0.1) {
        double tn = 0.0, te = 0.0;
        int is_obj;
        double t = nearest(p, n, e, ((double)k * 5.0 + a + yaw_deg) * PI / 180.0, &is_obj, &tn, &te);
        if (t > 0.0 && (best < 0.0 || t < best)) {
            best = t;
            *object = is_obj;
            *on = tn;
            *oe = te;
        }
    }
    return best;
}

/*
 * 1 if body sector k at heading yaw_deg was clear out to range_m from where the sonar was when the
 * head last looked that way (the world memory's "clear" is of that pass; the vehicle moves on).
 */
static int beyond_then(const struct probe *p, int k, double yaw_deg, double range_m)
{
    int at = world_sector((double)k * 5.0 + yaw_deg), obj;
    double vn, ve, yaw, on, oe, best;
    if (p->seen_us[at] == 0)
        return 0;
    scene_vehicle_at(p->scene, (double)(p->seen_us[at] - p->start_us) / 1e6, &vn, &ve, &yaw);
    best = sector_nearest(p, vn, ve, yaw_deg, k, &obj, &on, &oe);
    return best < 0.0 || best > range_m;
}

static int probe_beam(void *self, const struct sonar_record *b)
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
    if ((int)b->angle < p->prev_angle)
        p->sweep++;
    p->prev_angle = b->angle;
    if (b->has_pose) {
        int at = world_sector((double)bearing + (double)b->yaw_deg);
        p->seen_us[at] = b->utime;
        p->seen_sweep[at] = p->sweep;
    }
    if (!b->has_pose || b->utime < p->start_us + 13000000)
        return HOST_OK;
    /*
     * From the third sweep on (the floor's warm-up): the echo before this beam's, as the world map
     * keeps it, against the walls (this beam's echo settles where that one lies in its beam).
     */
    if (p->with.count > 1 &&
        p->with.echo[(p->with.head + SONAR_MAX_OBS_ECHOES - 1u) % SONAR_MAX_OBS_ECHOES].utime == b->utime) {
        const struct sonar_obstacle_echo *e = &p->with.echo[(p->with.head + SONAR_MAX_OBS_ECHOES - 2u) % SONAR_MAX_OBS_ECHOES];
        double off = 0.0, c = 1.0;
        int j;
        if (e->world && e->utime >= p->start_us + 13000000 &&
            near_wall(p, (double)e->x_m, (double)e->y_m, (double)e->ox, (double)e->oy, &off, &c))
            for (j = 0; j < 2; j++)
                if (j == 0 || c >= cos(30.0 * PI / 180.0)) {
                    p->points[j]++;
                    p->point_sum[j] += off;
                    p->point_sum2[j] += off * off;
                }
    }
    /* And once a second, every sector against the nearest obstacle in it from here. */
    if (b->utime < p->next_us)
        return HOST_OK;
    p->next_us = b->utime + 1000000;
    for (m = 0; m < 2; m++) {
        uint16_t d[SONAR_OBS_SECTORS], mn, mx;
        sonar_obstacle_map(m == 0 ? &p->with : &p->without, b->utime, MAP_AGE_US, m == 0 ? &q : NULL, d, &mn, &mx);
        for (k = 0; k < SONAR_OBS_SECTORS; k++) {
            double best, on = 0.0, oe = 0.0, err;
            int obj;
            if (d[k] == SONAR_OBS_UNKNOWN)
                continue;
            best = sector_nearest(p, b->north_m, b->east_m, (double)b->yaw_deg, k, &obj, &on, &oe);
            if (best < 0.0 || best > (double)mx / 100.0)
                continue;
            if (d[k] > mx) {
                p->missed[m]++; /* reported clear with an obstacle in range */
                if (m == 0 && p->scene != NULL)
                    p->missed_stale += beyond_then(p, k, (double)b->yaw_deg, (double)mx / 100.0);
                continue;
            }
            err = (double)d[k] / 100.0 - best;
            p->n[m]++;
            p->within[m] += fabs(err) <= 0.1;
            p->on_obj[m] += obj;
            p->obj_within[m] += obj && fabs(err) <= 0.1;
            p->abs_err[m] += fabs(err);
            p->nearer[m] += err < -0.1;
            if (err > 0.1) {
                /* The unsafe side. An object missed here may still be in the map, its echo a sector over. */
                p->farther[m]++;
                p->far_obj += obj && m == 0;
                p->far_obj_held += obj && m == 0 && holds(&p->with, b->utime, MAP_AGE_US, on, oe, 0.5);
            }
        }
    }
    return HOST_OK;
}

int main(int argc, char **argv)
{
    static struct probe probe;
    struct sonar_obstacle_config oc;
    static struct app_storage mem;
    struct app *app = NULL;
    const struct sonar_pipeline *pipe;
    static struct source_replay rp;
    static struct posefile pf;
    static struct scene scene;
    struct sonar_pipeline_config c;
    struct app_clock clk = {mono_ns, wall_us, NULL};
    double walls[MAX_WALLS][4], all2 = 0.0;
    int nw = 0, i, nall = 0;
    const char *csv = NULL, *pose = NULL, *scene_name = NULL;
    char err[300];
    for (i = 1; i + 1 < argc; i += 2) {
        if (strcmp(argv[i], "--replay") == 0)
            csv = argv[i + 1];
        else if (strcmp(argv[i], "--pose") == 0)
            pose = argv[i + 1];
        else if (strcmp(argv[i], "--scene") == 0)
            scene_name = argv[i + 1];
        else if (strcmp(argv[i], "--wall") == 0 && nw < MAX_WALLS &&
                 sscanf(argv[i + 1], "%lf,%lf,%lf,%lf", &walls[nw][0], &walls[nw][1], &walls[nw][2], &walls[nw][3]) == 4)
            nw++;
        else
            break;
    }
    if (i < argc) {
        fprintf(stderr, "sonar-wallfit: %s: unknown or bad option\n", argv[i]);
        return 2;
    }
    if (scene_name != NULL && scene_make(&scene, scene_name) != 0) {
        fprintf(stderr, "sonar-wallfit: --scene %s: no such scene\n", scene_name);
        return 2;
    }
    /* The scene's walls unless some are given. */
    if (scene_name != NULL && nw == 0)
        for (; nw < scene.nwall; nw++) {
            walls[nw][0] = scene.wall[nw].x0;
            walls[nw][1] = scene.wall[nw].y0;
            walls[nw][2] = scene.wall[nw].x1;
            walls[nw][3] = scene.wall[nw].y1;
        }
    if (csv == NULL || pose == NULL || nw == 0) {
        fprintf(stderr, "usage: sonar-wallfit --replay FILE.csv --pose POSE.csv {--scene NAME | --wall N0,E0,N1,E1 [--wall ...]}\n"
                        "  --scene: its walls, and its objects as obstacles too (sonar-sim's scenes; its recording from the first beam)\n");
        return 2;
    }
    sonar_pipeline_defaults(&c);
    if (app_init(&app, &mem, &c, NULL, NULL, &clk, 0, err, sizeof(err)) != HOST_OK ||
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
    probe.scene = scene_name != NULL ? &scene : NULL;
    probe.prev_angle = -1;
    probe.sink.name = "probe";
    probe.sink.self = &probe;
    probe.sink.stages = 1u << SONAR_STAGE_MEDIAN;
    probe.sink.beam = probe_beam;
    if (app_add_sink(app, &probe.sink) != HOST_OK)
        return 2;
    (void)source_replay_run(&rp, app, stderr);
    pipe = app_pipeline(app);
    if (!pipe->bg->world) {
        fprintf(stderr, "sonar-wallfit: the background is not in the world frame (no pose?)\n");
        return 1;
    }
    printf("grid cell %.3f m, range cell %.4f m\n", (double)pipe->bg->cell_m, (double)(pipe->range_m / (float)pipe->n));
    for (i = 0; i < nw; i++) {
        double dn = walls[i][2] - walls[i][0], de = walls[i][3] - walls[i][1], len = sqrt(dn * dn + de * de), s;
        double nn = -de / len, ne = dn / len, sum = 0.0, sum2 = 0.0;
        int k = 0, tried = 0;
        /* Every 0.2 m, a metre clear of the corners (where two walls meet, the fit mixes them). */
        for (s = 1.0; s <= len - 1.0; s += 0.2) {
            int peak;
            double off = fit(pipe->bg, walls[i][0] + s * dn / len, walls[i][1] + s * de / len, nn, ne, &peak);
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
        printf("obstacle map's world echo points (one a beam, from the third sweep) within 1 m of a wall%s: %ld, offset mean "
               "%+.4f m, rms %.4f m\n", i ? ", seen within 30 degrees of its normal" : "", probe.points[i],
               probe.points[i] ? probe.point_sum[i] / (double)probe.points[i] : 0.0,
               probe.points[i] ? sqrt(probe.point_sum2[i] / (double)probe.points[i]) : 0.0);
    for (i = 0; i < 2; i++) {
        long nw_ = probe.n[i] - probe.on_obj[i], ww = probe.within[i] - probe.obj_within[i];
        printf("OBSTACLE_DISTANCE map %s: %ld sectors with an echo and an obstacle in range checked once a second, %.1f %% "
               "within 0.1 m of the nearest %s in the sector, mean |error| %.3f m; %ld reported clear with one in range\n",
               i == 0 ? "with the poses (world memory)" : "without (the sonar frame as seen)", probe.n[i],
               probe.n[i] ? 100.0 * (double)probe.within[i] / (double)probe.n[i] : 0.0,
               probe.scene != NULL ? "wall or object" : "wall", probe.n[i] ? probe.abs_err[i] / (double)probe.n[i] : 0.0,
               probe.missed[i]);
        if (probe.scene != NULL)
            printf("  of which the nearest is a wall: %ld, %.1f %% within 0.1 m; an object: %ld, %.1f %% within 0.1 m\n", nw_,
                   nw_ ? 100.0 * (double)ww / (double)nw_ : 0.0, probe.on_obj[i],
                   probe.on_obj[i] ? 100.0 * (double)probe.obj_within[i] / (double)probe.on_obj[i] : 0.0);
        printf("  beyond 0.1 m: %ld nearer than the obstacle (the safe side), %ld farther (%.1f %% of the sectors)", probe.nearer[i],
               probe.farther[i], probe.n[i] ? 100.0 * (double)probe.farther[i] / (double)probe.n[i] : 0.0);
        if (probe.scene != NULL && i == 0)
            printf(", %ld of them where an object is nearest (for %ld of those the map holds an echo within 0.5 m of the object)",
                   probe.far_obj, probe.far_obj_held);
        putchar('\n');
        if (probe.scene != NULL && i == 0)
            printf("  reported clear with one in range: %ld of the %ld were beyond the range from where the sonar was at the "
                   "sector's last pass\n", probe.missed_stale, probe.missed[0]);
    }
    posefile_close(&pf);
    source_replay_close(&rp);
    return nall > 0 ? 0 : 1;
}
