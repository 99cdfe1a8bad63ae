/* scene.c -- simulated Ping360 scenes: ring-down, range-dependent speckle, pool walls with shadows, objects with beam spreading; deterministic. */
#define _POSIX_C_SOURCE 200809L
#include "scene.h"

#include <math.h>
#include <string.h>

#define PI 3.14159265358979323846

double scene_uniform(struct scene_rng *g)
{
    /* xorshift64*: fixed seed, identical streams on every machine */
    g->s ^= g->s >> 12;
    g->s ^= g->s << 25;
    g->s ^= g->s >> 27;
    return ((double)((g->s * 2685821657736338717ull) >> 11) + 0.5) / 9007199254740992.0;
}

static double rayleigh(struct scene_rng *g)
{
    return sqrt(-2.0 * log(scene_uniform(g)));
}

int scene_make(struct scene *s, const char *name)
{
    memset(s, 0, sizeof(*s));
    s->name = name;
    s->range_m = 12.0;
    s->samples = 1200;
    s->step = 1;
    if (strcmp(name, "pool") == 0) {
        /* A 20 x 12 m pool; the sonar sits off-centre, so some walls are beyond range. */
        struct scene_wall w[4] = {{-6, -5, 14, -5}, {14, -5, 14, 7}, {14, 7, -6, 7}, {-6, 7, -6, -5}};
        memcpy(s->wall, w, sizeof(w));
        s->nwall = 4;
        s->sweeps = 7;
        s->obj[0] = (struct scene_object){"gate_post_left", 5.0, 2.0, 0.10, 0, 0, 170, 2, 0, {0}, {0}, {0}, 0};
        s->obj[1] = (struct scene_object){"gate_post_right", 5.0, 3.6, 0.10, 0, 0, 170, 2, 0, {0}, {0}, {0}, 0};
        s->obj[2] = (struct scene_object){"buoy", -3.0, -2.0, 0.25, 0.35, 0.1, 190, 3, 0, {0}, {0}, {0}, 0};
        s->nobj = 3;
    } else if (strcmp(name, "open") == 0) {
        /* Open water: no walls, objects there from the first ping. */
        s->sweeps = 4;
        s->obj[0] = (struct scene_object){"gate_post", 4.0, 1.0, 0.10, 0, 0, 170, 0, 0, {0}, {0}, {0}, 0};
        s->obj[1] = (struct scene_object){"buoy", -2.0, 3.0, 0.25, 0.3, 0.0, 190, 0, 0, {0}, {0}, {0}, 0};
        s->obj[2] = (struct scene_object){"diver", 1.0, -6.0, 0.30, 0.0, 0.4, 150, 0, 0, {0}, {0}, {0}, 0};
        s->nobj = 3;
    } else if (strcmp(name, "moving") == 0) {
        /*
         * Open water, full turns at 4 gradians a step (6.3 s a turn at 15 m), 24 turns: two swimmers
         * at 0.5 m/s going to and fro 0.5 m apart (they cross three times), a diver at 1 m/s who turns
         * four times and leaves, a fast one at 1.5 m/s going twice round the sonar (an octagon: 45
         * degrees every 5.6 s), a drifting buoy that fades for two turns and then one, and a late one
         * at 1 m/s who arrives, turns and leaves. The first two turns are the background's warm-up.
         */
        static const struct scene_object o[] = {
            {"swimmer_a", 0, 0, 0.25, 0, 0, 160, 0, 4, {16, 52, 88, 124}, {-9, 9, -9, 9}, {6.25, 6.25, 6.25, 6.25}, 0},
            {"swimmer_b", 0, 0, 0.25, 0, 0, 160, 0, 4, {16, 52, 88, 124}, {9, -9, 9, -9}, {5.75, 5.75, 5.75, 5.75}, 0},
            {"diver", 0, 0, 0.30, 0, 0, 150, 0, 6, {18, 38, 50, 64, 76, 82}, {4, 4, -8, -8, 4, 4}, {-10, 10, 10, -4, -4, -10}, 0},
            {"fast", 0, 0, 0.25, 0, 0, 170, 0, 17,
             {22.0, 27.61, 33.23, 38.84, 44.45, 50.06, 55.68, 61.29, 66.9, 72.51, 78.13, 83.74, 89.35, 94.96, 100.58, 106.19, 111.8},
             {0.0, 7.78, 11.0, 7.78, 0.0, -7.78, -11.0, -7.78, -0.0, 7.78, 11.0, 7.78, 0.0, -7.78, -11.0, -7.78, -0.0},
             {-11.0, -7.78, 0.0, 7.78, 11.0, 7.78, 0.0, -7.78, -11.0, -7.78, -0.0, 7.78, 11.0, 7.78, 0.0, -7.78, -11.0}, 0},
            {"buoy", 0, 0, 0.25, 0, 0, 190, 0, 2, {20, 152}, {-5, -2.5}, {-5, -6.5}, (1ull << 10) | (1ull << 11) | (1ull << 18)},
            {"late", 0, 0, 0.25, 0, 0, 160, 0, 4, {100, 114, 124, 136}, {11, 0, -9, -9}, {-3, -11, -8, 0}, 0},
        };
        s->range_m = 15.0;
        s->samples = 600;
        s->step = 4;
        s->sweeps = 24;
        memcpy(s->obj, o, sizeof(o));
        s->nobj = (int)(sizeof(o) / sizeof(o[0]));
    } else if (strcmp(name, "sector") == 0) {
        /*
         * A 180-degree sector (gradians 100..300, the x < 0 half) scanned back and forth at 2
         * gradians a step (5 s a pass at 15 m), 26 passes: two people crossing at 0.3 m/s who turn
         * back, one at 0.8 m/s who walks out of the sector, one who arrives late, a runner at 1.2 m/s
         * crossing the far side; the first two passes are the background's warm-up.
         */
        static const struct scene_object o[] = {
            {"walker_a", 0, 0, 0.25, 0, 0, 160, 0, 3, {12, 72, 112}, {-4, -4, -4}, {-9, 9, -3}, 0},
            {"walker_b", 0, 0, 0.25, 0, 0, 160, 0, 3, {12, 72, 112}, {-4.5, -4.5, -4.5}, {9, -9, 3}, 0},
            {"leaver", 0, 0, 0.25, 0, 0, 170, 0, 2, {14, 31}, {-8, 5}, {-3, -7}, 0},
            {"late", 0, 0, 0.25, 0, 0, 160, 0, 3, {36, 72, 104}, {-10, -2, -10}, {4, 4, -2}, 0},
            {"runner", 0, 0, 0.25, 0, 0, 170, 0, 2, {64, 78.8}, {-13, 2}, {3, 12.5}, 0},
        };
        s->range_m = 15.0;
        s->samples = 600;
        s->step = 2;
        s->start = 100;
        s->stop = 300;
        s->sweeps = 26;
        memcpy(s->obj, o, sizeof(o));
        s->nobj = (int)(sizeof(o) / sizeof(o[0]));
    } else if (strcmp(name, "vehicle") == 0) {
        /*
         * A 30 x 16 m pool seen from a moving vehicle (issue 11): it goes up and down the pool at
         * 0.5 m/s while its heading swings 180 degrees back and forth at 30 degrees/s; full turns of
         * the head at 4 gradians a step (6.3 s a turn at 15 m), 18 turns. Two posts and a buoy stand
         * still in the world from sweeps 3, 5 and 2; a diver swims at 0.5 m/s from 20 s to 100 s.
         */
        static const struct scene_wall w[4] = {{-15, -8, 15, -8}, {15, -8, 15, 8}, {15, 8, -15, 8}, {-15, 8, -15, -8}};
        static const struct scene_object o[] = {
            {"post_a", 4.0, 5.0, 0.20, 0, 0, 170, 3, 0, {0}, {0}, {0}, 0},
            {"post_b", -5.0, -6.0, 0.20, 0, 0, 170, 5, 0, {0}, {0}, {0}, 0},
            {"buoy", 0.5, 5.5, 0.25, 0, 0, 190, 2, 0, {0}, {0}, {0}, 0},
            {"diver", 0, 0, 0.30, 0, 0, 150, 0, 4, {20, 60, 82, 100}, {10, -10, -10, 0}, {-6, -6, 5, 5}, 0},
        };
        static const struct scene_vehicle v = {6, {0, 32, 40, 72, 80, 120}, {-8, 8, 8, -8, -8, 8}, {-3, -3, 1, 1, -3, -3},
                                               0.0, 30.0, 6.0};
        memcpy(s->wall, w, sizeof(w));
        s->nwall = 4;
        s->range_m = 15.0;
        s->samples = 600;
        s->step = 4;
        s->sweeps = 18;
        memcpy(s->obj, o, sizeof(o));
        s->nobj = (int)(sizeof(o) / sizeof(o[0]));
        s->veh = v;
    } else {
        return -1;
    }
    return 0;
}

void scene_vehicle_at(const struct scene *s, double t, double *n, double *e, double *yaw_deg)
{
    const struct scene_vehicle *v = &s->veh;
    double y;
    int w;
    *n = *e = *yaw_deg = 0.0;
    if (v->nwp == 0)
        return;
    for (w = 0; w + 2 < v->nwp && t > v->wp_t[w + 1]; w++)
        ;
    {
        double dt = v->wp_t[w + 1] - v->wp_t[w], f = dt > 0 ? (t - v->wp_t[w]) / dt : 0.0;
        f = f < 0 ? 0 : f > 1 ? 1 : f;
        *n = v->wp_n[w] + f * (v->wp_n[w + 1] - v->wp_n[w]);
        *e = v->wp_e[w] + f * (v->wp_e[w + 1] - v->wp_e[w]);
    }
    if (v->yaw_period_s > 0) {
        double ph = fmod(t, 2.0 * v->yaw_period_s);
        y = v->yaw0_deg + v->yaw_rate_dps * (ph < v->yaw_period_s ? ph : 2.0 * v->yaw_period_s - ph);
    } else {
        y = v->yaw0_deg + v->yaw_rate_dps * t;
    }
    y = fmod(y, 360.0);
    *yaw_deg = y < 0 ? y + 360.0 : y;
}

void scene_to_body(const struct scene *s, double t, double n, double e, double *x, double *y)
{
    double vn, ve, yaw, c, sn;
    scene_vehicle_at(s, t, &vn, &ve, &yaw);
    c = cos(yaw * PI / 180.0);
    sn = sin(yaw * PI / 180.0);
    /* body = R(-yaw) (world - position) */
    *x = c * (n - vn) + sn * (e - ve);
    *y = -sn * (n - vn) + c * (e - ve);
}

int scene_object_at(const struct scene *s, int k, int sweep, double t, double *x, double *y, double *vx, double *vy)
{
    const struct scene_object *o = &s->obj[k];
    int d = sweep - o->first_sweep, w;
    if (o->nwp == 0) {
        *x = o->x + o->vx * d;
        *y = o->y + o->vy * d;
        *vx = *vy = 0.0;
        return sweep >= o->first_sweep;
    }
    if (t < o->wp_t[0] || t > o->wp_t[o->nwp - 1])
        return 0;
    for (w = 0; w + 2 < o->nwp && t > o->wp_t[w + 1]; w++)
        ;
    {
        double dt = o->wp_t[w + 1] - o->wp_t[w], f = dt > 0 ? (t - o->wp_t[w]) / dt : 0.0;
        *vx = dt > 0 ? (o->wp_x[w + 1] - o->wp_x[w]) / dt : 0.0;
        *vy = dt > 0 ? (o->wp_y[w + 1] - o->wp_y[w]) / dt : 0.0;
        *x = o->wp_x[w] + f * (o->wp_x[w + 1] - o->wp_x[w]);
        *y = o->wp_y[w] + f * (o->wp_y[w + 1] - o->wp_y[w]);
    }
    return 1;
}

int scene_angle(const struct scene *s, int sweep, int i)
{
    int n, a;
    if (s->start == s->stop) {
        a = i * s->step;
        return a < 400 ? a : -1;
    }
    /* Sweep 0 is start..stop; after that each pass leaves out the end it turned at. */
    n = (s->stop - s->start) / s->step + (sweep == 0);
    if (i >= n)
        return -1;
    if (sweep == 0)
        return s->start + i * s->step;
    return sweep % 2 ? s->stop - (i + 1) * s->step : s->start + (i + 1) * s->step;
}

#define HALF_BEAM (1.0 * PI / 180.0) /* the 2-degree beam's half-power half-width */
#define WALL_PULSE_M 0.04             /* a wall's return lasts this past its footprint (the pulse) ... */
#define WALL_TAIL_M 0.05              /* ... then decays over this (reverberation in the wall's roughness) */

/* Distance along the unit ray (ux, uy) to a wall segment, and |cos| of the incidence; < 0 if missed. */
static double ray_wall(const struct scene_wall *w, double ux, double uy, double *cosinc)
{
    double ex = w->x1 - w->x0, ey = w->y1 - w->y0;
    double den = ux * ey - uy * ex;
    double t, s, len;
    if (fabs(den) < 1e-12)
        return -1.0;
    t = (w->x0 * ey - w->y0 * ex) / den;
    s = (w->x0 * uy - w->y0 * ux) / den;
    if (t <= 0.0 || s < 0.0 || s > 1.0)
        return -1.0;
    len = sqrt(ex * ex + ey * ey);
    *cosinc = fabs(ux * ey - uy * ex) / len;
    return t;
}

/* The nearest point of a wall segment (origin-relative) inside the cone th +- hw; < 0 if none. */
static double cone_near(const struct scene_wall *w, double th, double hw)
{
    double best = -1.0, c, ex = w->x1 - w->x0, ey = w->y1 - w->y0, len2 = ex * ex + ey * ey, t, px, py;
    double cand[3][2];
    int k, m = 0;
    for (k = -1; k <= 1; k += 2) {
        double d = ray_wall(w, cos(th + k * hw), sin(th + k * hw), &c);
        if (d > 0.0) {
            cand[m][0] = d * cos(th + k * hw);
            cand[m++][1] = d * sin(th + k * hw);
        }
    }
    /* The foot of the normal from the sonar, and the segment's ends, where the cone holds them. */
    t = len2 > 0.0 ? -(w->x0 * ex + w->y0 * ey) / len2 : 0.0;
    t = t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
    px = w->x0 + t * ex;
    py = w->y0 + t * ey;
    cand[m][0] = px;
    cand[m++][1] = py;
    for (k = 0; k < m; k++) {
        double d = sqrt(cand[k][0] * cand[k][0] + cand[k][1] * cand[k][1]);
        double off = fabs(remainder(atan2(cand[k][1], cand[k][0]) - th, 2.0 * PI));
        if (off <= hw + 1e-9 && (best < 0.0 || d < best))
            best = d;
    }
    return best;
}

/* A wall made relative to the vehicle at (vn, ve). */
static void relative(struct scene_wall *w, double vn, double ve)
{
    w->x0 -= vn;
    w->x1 -= vn;
    w->y0 -= ve;
    w->y1 -= ve;
}

/* Distance from the vehicle at (vn, ve) along bearing th to the first wall, and |cos| of its incidence; < 0 if none. */
static double walls_ray(const struct scene *s, double vn, double ve, double th, double *cosinc)
{
    double best = -1.0, ux = cos(th), uy = sin(th);
    int k;
    for (k = 0; k < s->nwall; k++) {
        struct scene_wall rel = s->wall[k];
        double c, d;
        relative(&rel, vn, ve);
        d = ray_wall(&rel, ux, uy, &c);
        if (d > 0.0 && (best < 0.0 || d < best)) {
            best = d;
            *cosinc = c;
        }
    }
    return best;
}

void scene_beam(const struct scene *s, int sweep, double t, int angle, double range_m, int n, struct scene_rng *g,
                uint8_t *out)
{
    double vn, ve, yaw, th;
    double sig_beam = 0.85 * PI / 180.0; /* 2 degree beam: Gaussian sigma of the two-way pattern */
    double wall_d = -1.0, wall_cos = 1.0, wall_near = -1.0, wall_far = -1.0;
    double buf[1200];
    int i, k;
    /* The ray in the scene's frame: from the vehicle, along the beam turned by its heading. */
    scene_vehicle_at(s, t, &vn, &ve, &yaw);
    th = angle * PI / 200.0 + yaw * PI / 180.0;
    if (n > 1200)
        n = 1200;
    wall_d = walls_ray(s, vn, ve, th, &wall_cos);
    for (k = 0; k < s->nwall; k++) {
        struct scene_wall rel = s->wall[k];
        double d;
        relative(&rel, vn, ve);
        d = cone_near(&rel, th, HALF_BEAM);
        if (d > 0.0 && (wall_near < 0.0 || d < wall_near))
            wall_near = d;
    }
    if (wall_d > 0.0) {
        /* The far side of the footprint: the farther beam edge, on whichever wall each edge meets first. */
        int side;
        wall_far = wall_d;
        for (side = -1; side <= 1; side += 2) {
            double c, e = walls_ray(s, vn, ve, th + side * HALF_BEAM, &c);
            if (e > wall_far && e < wall_d * 1.5)
                wall_far = e;
        }
        if (wall_near < 0.0 || wall_near > wall_d)
            wall_near = wall_d;
    }
    for (i = 0; i < n; i++) {
        double r = (i + 0.5) * range_m / n;
        double sigma = 7.0 + 22.0 * exp(-r / 2.0);
        double v = sigma * rayleigh(g) + 230.0 * exp(-r / 0.12);
        if (wall_d > 0.0) {
            /*
             * Causal, as an echo is: the return starts at the nearest point of wall inside the beam
             * (its half-power edges, or the foot of the normal when the beam holds it) and lasts
             * across the footprint to the far edge, plus the pulse, then decays (reverberation in the
             * wall's roughness); the wall shadows what lies behind.
             */
            double a = 70.0 * sqrt(wall_cos) + 50.0, end = wall_far + WALL_PULSE_M;
            if (r >= wall_near && r <= end)
                v += a * (0.6 + 0.8 * scene_uniform(g));
            else if (r > end)
                v = v * 0.3 + a * exp(-(r - end) / WALL_TAIL_M) * (0.6 + 0.8 * scene_uniform(g));
        }
        buf[i] = v;
    }
    for (k = 0; k < s->nobj; k++) {
        const struct scene_object *o = &s->obj[k];
        double ox, oy, ovx, ovy, d, phi, delta, alpha, e, gain, near, far;
        if (!scene_object_at(s, k, sweep, t, &ox, &oy, &ovx, &ovy) || (sweep < 64 && (o->fade >> sweep) & 1u))
            continue;
        ox -= vn;
        oy -= ve;
        d = sqrt(ox * ox + oy * oy);
        phi = atan2(oy, ox);
        delta = fabs(remainder(th - phi, 2.0 * PI));
        alpha = asin(fmin(1.0, o->r / d));
        e = delta > alpha ? delta - alpha : 0.0;
        gain = exp(-0.5 * (e / sig_beam) * (e / sig_beam));
        if (gain < 0.02)
            continue;
        near = d - o->r;
        far = d + 0.3 * o->r + 0.05;
        for (i = 0; i < n; i++) {
            double r = (i + 0.5) * range_m / n;
            if (r >= near && r <= far)
                buf[i] += o->strength * gain * (0.75 + 0.5 * scene_uniform(g));
            else if (r > far && delta < alpha)
                buf[i] *= 0.2; /* acoustic shadow behind the object */
        }
    }
    for (i = 0; i < n; i++)
        out[i] = (uint8_t)(buf[i] < 0 ? 0 : buf[i] > 255 ? 255 : floor(buf[i] + 0.5));
}


int scene_write_truth(FILE *f, const struct scene *s, int sweeps, const struct scene_seen *seen, long long t0_us)
{
    int sweep, k;
    int beams = 0;
    while (scene_angle(s, 1, beams) >= 0)
        beams++;
    fprintf(f, "{\"scene\":\"%s\",\"range_m\":%.3f,\"samples\":%d,\"beams_per_sweep\":%d,\"walls\":[", s->name,
            s->range_m, s->samples, beams);
    for (k = 0; k < s->nwall; k++)
        fprintf(f, "%s[%.3f,%.3f,%.3f,%.3f]", k ? "," : "", s->wall[k].x0, s->wall[k].y0, s->wall[k].x1, s->wall[k].y1);
    fputs("],\"sweeps\":[", f);
    for (sweep = 0; sweep < sweeps; sweep++) {
        int first = 1;
        fprintf(f, "%s{\"sweep\":%d,\"objects\":[", sweep ? "," : "", sweep);
        for (k = 0; k < s->nobj; k++) {
            const struct scene_seen *v = &seen[sweep * SCENE_MAX_OBJ + k];
            if (!v->visible)
                continue;
            fprintf(f, "%s{\"id\":\"%s\",\"x\":%.3f,\"y\":%.3f,\"radius\":%.3f,\"t_us\":%lld,\"vx\":%.3f,\"vy\":%.3f",
                    first ? "" : ",", s->obj[k].id, v->x, v->y, s->obj[k].r, t0_us + (long long)floor(v->t * 1e6 + 0.5),
                    v->vx, v->vy);
            if (s->veh.nwp > 0)
                fprintf(f, ",\"bx\":%.3f,\"by\":%.3f", v->bx, v->by);
            fputc('}', f);
            first = 0;
        }
        /* There but not seen (faded, or no beam crossed it): a tracker coasting on it is neither right nor wrong. */
        fputs("],\"hidden\":[", f);
        first = 1;
        for (k = 0; k < s->nobj; k++) {
            const struct scene_seen *v = &seen[sweep * SCENE_MAX_OBJ + k];
            if (!v->present || v->visible || hypot(v->bx, v->by) > s->range_m)
                continue;
            fprintf(f, "%s{\"id\":\"%s\",\"x\":%.3f,\"y\":%.3f,\"t_us\":%lld", first ? "" : ",", s->obj[k].id, v->x,
                    v->y, t0_us + (long long)floor(v->t * 1e6 + 0.5));
            if (s->veh.nwp > 0)
                fprintf(f, ",\"bx\":%.3f,\"by\":%.3f", v->bx, v->by);
            fputc('}', f);
            first = 0;
        }
        fputs("]}", f);
    }
    fputs("]}\n", f);
    return ferror(f) ? -1 : 0;
}
