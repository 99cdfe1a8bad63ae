/* sonar_sim.c -- writes simulated Ping360 sweeps in the study's CSV plus a ground-truth JSON: ring-down, range-dependent speckle, pool walls, objects with beam spreading and shadows. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../src/host/csv.h"

#define PI 3.14159265358979323846
#define MAX_OBJ 8
#define MAX_WALL 4

struct object {
    const char *id;
    double x, y, r;      /* metres at first_sweep */
    double vx, vy;       /* metres per sweep */
    double strength;     /* peak echo, grey levels */
    int first_sweep;     /* present from this sweep on */
};

struct wall {
    double x0, y0, x1, y1;
};

struct scene {
    const char *name;
    double range_m;
    int samples, sweeps, step;
    struct wall wall[MAX_WALL];
    int nwall;
    struct object obj[MAX_OBJ];
    int nobj;
};

struct rng {
    uint64_t s;
};

static double uniform(struct rng *g)
{
    /* xorshift64*: fixed seed, identical streams on every machine */
    g->s ^= g->s >> 12;
    g->s ^= g->s << 25;
    g->s ^= g->s >> 27;
    return ((double)((g->s * 2685821657736338717ull) >> 11) + 0.5) / 9007199254740992.0;
}

static double rayleigh(struct rng *g)
{
    return sqrt(-2.0 * log(uniform(g)));
}

static void make_scene(struct scene *s, const char *name)
{
    memset(s, 0, sizeof(*s));
    s->name = name;
    s->range_m = 12.0;
    s->samples = 1200;
    s->step = 1;
    if (strcmp(name, "pool") == 0) {
        /* A 20 x 12 m pool; the sonar sits off-centre, so some walls are beyond range. */
        struct wall w[4] = {{-6, -5, 14, -5}, {14, -5, 14, 7}, {14, 7, -6, 7}, {-6, 7, -6, -5}};
        memcpy(s->wall, w, sizeof(w));
        s->nwall = 4;
        s->sweeps = 7;
        s->obj[0] = (struct object){"gate_post_left", 5.0, 2.0, 0.10, 0, 0, 170, 2};
        s->obj[1] = (struct object){"gate_post_right", 5.0, 3.6, 0.10, 0, 0, 170, 2};
        s->obj[2] = (struct object){"buoy", -3.0, -2.0, 0.25, 0.35, 0.1, 190, 3};
        s->nobj = 3;
    } else {
        /* Open water: no walls, objects there from the first ping. */
        s->sweeps = 4;
        s->obj[0] = (struct object){"gate_post", 4.0, 1.0, 0.10, 0, 0, 170, 0};
        s->obj[1] = (struct object){"buoy", -2.0, 3.0, 0.25, 0.3, 0.0, 190, 0};
        s->obj[2] = (struct object){"diver", 1.0, -6.0, 0.30, 0.0, 0.4, 150, 0};
        s->nobj = 3;
    }
}

static void obj_at(const struct object *o, int sweep, double *x, double *y)
{
    int k = sweep - o->first_sweep;
    *x = o->x + o->vx * k;
    *y = o->y + o->vy * k;
}

/* Distance along the unit ray (ux, uy) to a wall segment, and |cos| of the incidence; < 0 if missed. */
static double ray_wall(const struct wall *w, double ux, double uy, double *cosinc)
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

static void beam(const struct scene *s, int sweep, int angle, struct rng *g, uint8_t *out)
{
    double th = angle * PI / 200.0, ux = cos(th), uy = sin(th);
    double sig_beam = 0.85 * PI / 180.0; /* 2 degree beam: Gaussian sigma of the two-way pattern */
    double wall_d = -1.0, wall_cos = 1.0;
    double buf[1200];
    int i, k;
    for (k = 0; k < s->nwall; k++) {
        double c, d = ray_wall(&s->wall[k], ux, uy, &c);
        if (d > 0.0 && (wall_d < 0.0 || d < wall_d)) {
            wall_d = d;
            wall_cos = c;
        }
    }
    for (i = 0; i < s->samples; i++) {
        double r = (i + 0.5) * s->range_m / s->samples;
        double sigma = 7.0 + 22.0 * exp(-r / 2.0);
        double v = sigma * rayleigh(g) + 230.0 * exp(-r / 0.12);
        if (wall_d > 0.0) {
            double tanv = sqrt(1.0 - wall_cos * wall_cos) / (wall_cos > 0.05 ? wall_cos : 0.05);
            double sr = 0.04 + fmin(0.4, wall_d * 0.0175 * tanv);
            double a = 70.0 * sqrt(wall_cos) + 50.0;
            v += a * exp(-0.5 * pow((r - wall_d) / sr, 2.0)) * (0.6 + 0.8 * uniform(g));
            if (r > wall_d + 2.0 * sr)
                v *= 0.3;
        }
        buf[i] = v;
    }
    for (k = 0; k < s->nobj; k++) {
        const struct object *o = &s->obj[k];
        double ox, oy, d, phi, delta, alpha, e, gain, near, far;
        if (sweep < o->first_sweep)
            continue;
        obj_at(o, sweep, &ox, &oy);
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
        for (i = 0; i < s->samples; i++) {
            double r = (i + 0.5) * s->range_m / s->samples;
            if (r >= near && r <= far)
                buf[i] += o->strength * gain * (0.75 + 0.5 * uniform(g));
            else if (r > far && delta < alpha)
                buf[i] *= 0.2; /* acoustic shadow behind the object */
        }
    }
    for (i = 0; i < s->samples; i++)
        out[i] = (uint8_t)(buf[i] < 0 ? 0 : buf[i] > 255 ? 255 : floor(buf[i] + 0.5));
}

int main(int argc, char **argv)
{
    const char *scene_name = "pool", *csv_path = NULL, *truth_path = NULL;
    struct scene s;
    struct rng g = {0x9E3779B97F4A7C15ull};
    FILE *csv, *truth;
    uint8_t samples[1200];
    double t = 1728153122.0;
    int i, sweep, a, sweeps = -1;
    for (i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--scene") == 0 && i + 1 < argc)
            scene_name = argv[++i];
        else if (strcmp(argv[i], "--out") == 0 && i + 1 < argc)
            csv_path = argv[++i];
        else if (strcmp(argv[i], "--truth") == 0 && i + 1 < argc)
            truth_path = argv[++i];
        else if (strcmp(argv[i], "--sweeps") == 0 && i + 1 < argc)
            sweeps = atoi(argv[++i]);
        else if (strcmp(argv[i], "--seed") == 0 && i + 1 < argc)
            g.s ^= strtoull(argv[++i], NULL, 0) * 0xBF58476D1CE4E5B9ull;
        else {
            fprintf(stderr,
                    "usage: %s --scene pool|open --out FILE.csv --truth FILE.json [--sweeps N] [--seed S]\n"
                    "  pool: 20 x 12 m pool walls, two gate posts from sweep 2, a moving buoy from sweep 3 (7 sweeps)\n"
                    "  open: open water, a post, a moving buoy and a diver from sweep 0 (4 sweeps)\n"
                    "  12 m range, 1200 samples, 400 beams per sweep; timestamps follow the Ping360 timing model\n",
                    argv[0]);
            return 2;
        }
    }
    if (strcmp(scene_name, "pool") != 0 && strcmp(scene_name, "open") != 0) {
        fprintf(stderr, "sonar_sim: --scene: '%s' is not pool or open\n", scene_name);
        return 2;
    }
    if (csv_path == NULL || truth_path == NULL) {
        fprintf(stderr, "sonar_sim: --out and --truth are required\n");
        return 2;
    }
    make_scene(&s, scene_name);
    if (sweeps > 0)
        s.sweeps = sweeps;
    if ((csv = fopen(csv_path, "w")) == NULL || (truth = fopen(truth_path, "w")) == NULL) {
        perror("sonar_sim");
        return 2;
    }
    fprintf(truth, "{\"scene\":\"%s\",\"range_m\":%.3f,\"samples\":%d,\"beams_per_sweep\":%d,\"sweeps\":[", s.name,
            s.range_m, s.samples, 400 / s.step);
    for (sweep = 0; sweep < s.sweeps; sweep++) {
        int k, first = 1;
        fprintf(truth, "%s{\"sweep\":%d,\"objects\":[", sweep ? "," : "", sweep);
        for (k = 0; k < s.nobj; k++) {
            double x, y;
            if (sweep < s.obj[k].first_sweep)
                continue;
            obj_at(&s.obj[k], sweep, &x, &y);
            fprintf(truth, "%s{\"id\":\"%s\",\"x\":%.3f,\"y\":%.3f,\"radius\":%.3f}", first ? "" : ",", s.obj[k].id, x, y,
                    s.obj[k].r);
            first = 0;
        }
        fputs("]}", truth);
        for (a = 0; a < 400; a += s.step) {
            double sec = floor(t);
            beam(&s, sweep, a, &g, samples);
            csv_write(csv, (int64_t)sec, (uint32_t)((t - sec) * 1e9), (uint16_t)a, samples, (uint16_t)s.samples,
                      s.range_m);
            /* Device timing model (ping.md section 3): 19.4 ms + 6 ms per gradian + 2R/c. */
            t += 0.0194 + 0.006 * s.step + 2.0 * s.range_m / 1500.0;
        }
    }
    fputs("]}\n", truth);
    if (fclose(csv) != 0 || fclose(truth) != 0) {
        perror("sonar_sim");
        return 1;
    }
    return 0;
}
