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
        s->obj[0] = (struct scene_object){"gate_post_left", 5.0, 2.0, 0.10, 0, 0, 170, 2};
        s->obj[1] = (struct scene_object){"gate_post_right", 5.0, 3.6, 0.10, 0, 0, 170, 2};
        s->obj[2] = (struct scene_object){"buoy", -3.0, -2.0, 0.25, 0.35, 0.1, 190, 3};
        s->nobj = 3;
    } else if (strcmp(name, "open") == 0) {
        /* Open water: no walls, objects there from the first ping. */
        s->sweeps = 4;
        s->obj[0] = (struct scene_object){"gate_post", 4.0, 1.0, 0.10, 0, 0, 170, 0};
        s->obj[1] = (struct scene_object){"buoy", -2.0, 3.0, 0.25, 0.3, 0.0, 190, 0};
        s->obj[2] = (struct scene_object){"diver", 1.0, -6.0, 0.30, 0.0, 0.4, 150, 0};
        s->nobj = 3;
    } else {
        return -1;
    }
    return 0;
}

int scene_object_at(const struct scene *s, int k, int sweep, double *x, double *y)
{
    const struct scene_object *o = &s->obj[k];
    int d = sweep - o->first_sweep;
    *x = o->x + o->vx * d;
    *y = o->y + o->vy * d;
    return sweep >= o->first_sweep;
}

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

void scene_beam(const struct scene *s, int sweep, int angle, double range_m, int n, struct scene_rng *g, uint8_t *out)
{
    double th = angle * PI / 200.0, ux = cos(th), uy = sin(th);
    double sig_beam = 0.85 * PI / 180.0; /* 2 degree beam: Gaussian sigma of the two-way pattern */
    double wall_d = -1.0, wall_cos = 1.0;
    double buf[1200];
    int i, k;
    if (n > 1200)
        n = 1200;
    for (k = 0; k < s->nwall; k++) {
        double c, d = ray_wall(&s->wall[k], ux, uy, &c);
        if (d > 0.0 && (wall_d < 0.0 || d < wall_d)) {
            wall_d = d;
            wall_cos = c;
        }
    }
    for (i = 0; i < n; i++) {
        double r = (i + 0.5) * range_m / n;
        double sigma = 7.0 + 22.0 * exp(-r / 2.0);
        double v = sigma * rayleigh(g) + 230.0 * exp(-r / 0.12);
        if (wall_d > 0.0) {
            double tanv = sqrt(1.0 - wall_cos * wall_cos) / (wall_cos > 0.05 ? wall_cos : 0.05);
            double sr = 0.04 + fmin(0.4, wall_d * 0.0175 * tanv);
            double a = 70.0 * sqrt(wall_cos) + 50.0;
            v += a * exp(-0.5 * pow((r - wall_d) / sr, 2.0)) * (0.6 + 0.8 * scene_uniform(g));
            if (r > wall_d + 2.0 * sr)
                v *= 0.3;
        }
        buf[i] = v;
    }
    for (k = 0; k < s->nobj; k++) {
        const struct scene_object *o = &s->obj[k];
        double ox, oy, d, phi, delta, alpha, e, gain, near, far;
        if (!scene_object_at(s, k, sweep, &ox, &oy))
            continue;
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


int scene_write_truth(FILE *f, const struct scene *s, int sweeps)
{
    int sweep, k;
    fprintf(f, "{\"scene\":\"%s\",\"range_m\":%.3f,\"samples\":%d,\"beams_per_sweep\":%d,\"sweeps\":[", s->name,
            s->range_m, s->samples, 400 / s->step);
    for (sweep = 0; sweep < sweeps; sweep++) {
        int first = 1;
        fprintf(f, "%s{\"sweep\":%d,\"objects\":[", sweep ? "," : "", sweep);
        for (k = 0; k < s->nobj; k++) {
            double x, y;
            if (!scene_object_at(s, k, sweep, &x, &y))
                continue;
            fprintf(f, "%s{\"id\":\"%s\",\"x\":%.3f,\"y\":%.3f,\"radius\":%.3f}", first ? "" : ",", s->obj[k].id, x, y,
                    s->obj[k].r);
            first = 0;
        }
        fputs("]}", f);
    }
    fputs("]}\n", f);
    return ferror(f) ? -1 : 0;
}
