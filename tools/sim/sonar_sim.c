/* sonar_sim.c -- writes a simulated scene in the study's CSV plus a ground-truth JSON (see scene.h). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stddef.h>

#include "csv.h"
#include "optschema.h"
#include "scene.h"

struct sim_opts {
    const char *scene, *out, *truth, *pose_out;
    long sweeps;
    unsigned long long seed;
    int empty;
};

static int parse_seed(void *base, const char *v, char *err, size_t n)
{
    struct sim_opts *o = base;
    char *end;
    o->seed = strtoull(v, &end, 0);
    if (*v == '\0' || *end != '\0') {
        snprintf(err, n, "--seed: '%s' is not a whole number", v);
        return HOST_ERR_CONFIG;
    }
    return HOST_OK;
}

#define SO(field) offsetof(struct sim_opts, field)
static const struct opt_spec sim_spec[] = {
    {"scene", "NAME", OPT_STR, 0, 0, SO(scene), 0, 0, "pool, open, moving, sector, vehicle, occupied, far, still, faces, faint, lanes, laps, activity or near", "pool",
     "pool: 20 x 12 m walls, two gate posts from sweep 2, a moving buoy from sweep 3 (7 sweeps);\n"
     "open: open water, a post, a moving buoy and a diver from sweep 0 (4 sweeps);\n"
     "moving: 6 targets at 0.05..1.5 m/s crossing, turning, fading, arriving, leaving (14 turns);\n"
     "sector: 5 walkers in a 180-degree sector scanned back and forth (26 passes);\n"
     "vehicle: a 30 x 16 m pool from a vehicle moving at 0.5 m/s and turning at 30 deg/s,\n"
     "posts, a buoy and a diver (18 turns; --pose-out writes its path);\n"
     "occupied, far, still: the AquaScan pool's statistics (a 180-degree sector at 3 gradians,\n"
     "500 samples over 15 m, K-distributed water): five people there from the first ping (two\n"
     "standing, one struggling, one swimming: the truth says which; one faint at 9.5 m) (30\n"
     "passes); four faint targets at 8.5-12.5 m (30 passes); a person who swims for 60 s then\n"
     "floats still for 3 minutes, beside one standing (64 passes);\n"
     "faint: the same statistics, three targets barely above the clutter at 12-14 m (30 passes);\n"
     "lanes: the same statistics, the sonar on the side wall of a 25 x 14.6 m pool (the sector's\n"
     "edges look along it), two swaying lane ropes, a ladder there from the first ping (structure:\n"
     "not in the truth), two swimmers doing lengths and one who swims and then rests (40 passes);\n"
     "laps: the same statistics, full turns at 4 gradians (600 samples over 15 m) from the middle of a\n"
     "16 x 25 m pool: walls all round, two swaying lane ropes, a ladder; three swimmers doing lengths,\n"
     "one standing from the first ping; the truth says their activity (30 turns);\n"
     "activity: the laps pool with the AquaScan labels' three states: a swimmer, one standing (a steady\n"
     "echo, swaying), one struggling (a fresh echo each look, within a metre); truth says each one's (20 turns);\n"
     "near: open water at a 5 m range, three 0.2 m buoys at 0.66, 0.9 and 1.2 m (4 turns)", NULL, NULL},
    {"out", "FILE", OPT_STR, 0, 0, SO(out), 0, 0, "file", NULL, "the study's CSV (12 m, 1200 samples, 400 beams a sweep)", NULL, NULL},
    {"truth", "FILE", OPT_STR, 0, 0, SO(truth), 0, 0, "file", NULL, "ground-truth JSON", NULL, NULL},
    {"pose-out", "FILE", OPT_STR, 0, 0, SO(pose_out), 0, 0, "file", NULL,
     "the vehicle's poses at 10 Hz, utime_us,north_m,east_m,yaw_deg (sonard --pose)", NULL, NULL},
    {"sweeps", "N", OPT_LONG, 0, 0, SO(sweeps), 1, 100000, "sweeps", "the scene's", "sweeps to write", NULL, NULL},
    {"seed", "S", OPT_CUSTOM, 0, 0, 0, 0, 0, "whole number", "0", "speckle random seed", NULL, parse_seed},
    {"empty", NULL, OPT_FLAG, 0, 0, SO(empty), 0, 0, NULL, NULL,
     "the scene without its objects (walls, ropes, structure and water only): a recording of the empty pool, for\n--background-save",
     NULL, NULL},
    {"help", NULL, OPT_ACTION, 0, 0, 0, 0, 0, NULL, NULL, "this text", NULL, NULL},
};

int main(int argc, char **argv)
{
    const struct opt_schema schema = {sim_spec, sizeof(sim_spec) / sizeof(sim_spec[0]), "sonar_sim", NULL, 0};
    struct sim_opts o = {"pool", NULL, NULL, NULL, -1, 0, 0};
    const char *scene_name, *csv_path, *truth_path;
    struct scene s;
    struct scene_rng g = {0x9E3779B97F4A7C15ull};
    FILE *csv, *truth;
    uint8_t samples[1200];
    double t = 1728153122.0, t0 = t;
    struct scene_seen *seen;
    int sweep, a, sweeps, action;
    char err[256];
    struct csv_meta meta;
    if (opt_parse_argv(&schema, argc, argv, &o, NULL, &action, err, sizeof(err)) != HOST_OK || action >= 0) {
        if (action < 0)
            fprintf(stderr, "sonar_sim: %s\n", err);
        fprintf(stderr, "usage: sonar_sim --scene pool|open|moving|sector|vehicle|occupied|far|still|faces|faint|lanes|laps|activity|near --out FILE.csv --truth FILE.json "
                        "[--pose-out FILE.csv] [--sweeps N] [--seed S] [--empty]\n");
        opt_usage(&schema, stderr);
        return action >= 0 ? 0 : 2;
    }
    scene_name = o.scene;
    csv_path = o.out;
    truth_path = o.truth;
    sweeps = (int)o.sweeps;
    g.s ^= o.seed * 0xBF58476D1CE4E5B9ull;
    if (scene_make(&s, scene_name) != 0) {
        fprintf(stderr, "sonar_sim: --scene: '%s' is not pool, open, moving, sector, vehicle, occupied, far, still, faces, faint, lanes, laps, activity or near\n", scene_name);
        return 2;
    }
    if (csv_path == NULL || truth_path == NULL) {
        fprintf(stderr, "sonar_sim: --out and --truth are required\n");
        return 2;
    }
    if (sweeps > 0)
        s.sweeps = sweeps;
    if (o.empty)
        scene_empty(&s);
    if ((csv = fopen(csv_path, "w")) == NULL || (truth = fopen(truth_path, "w")) == NULL) {
        perror("sonar_sim");
        return 2;
    }
    if ((seen = calloc((size_t)s.sweeps * SCENE_MAX_OBJ, sizeof(*seen))) == NULL) {
        perror("sonar_sim");
        return 1;
    }
    meta = csv_meta_none();
    meta.range_m = s.range_m;
    for (sweep = 0; sweep < s.sweeps; sweep++) {
        int i;
        for (i = 0; (a = scene_angle(&s, sweep, i)) >= 0; i++) {
            double sec = floor(t), ts = t - t0;
            int k;
            scene_beam(&s, sweep, ts, a, s.range_m, s.samples, &g, samples);
            csv_write(csv, (int64_t)sec, (uint32_t)((t - sec) * 1e9), (uint16_t)a, samples, (uint16_t)s.samples, &meta);
            /* Truth: each object where it was when the beam nearest its bearing passed. */
            for (k = 0; k < s.nobj; k++) {
                struct scene_seen *v = &seen[sweep * SCENE_MAX_OBJ + k];
                double x, y, vx, vy, bx, by, d;
                int timed = s.obj[k].nwp > 0 || s.veh.nwp > 0; /* a moving sonar may pass a still object by */
                if (!scene_object_at(&s, k, sweep, ts, &x, &y, &vx, &vy))
                    continue;
                scene_to_body(&s, ts, x, y, &bx, &by);
                d = fabs(remainder(atan2(by, bx) * 200.0 / 3.14159265358979323846 - a, 400.0));
                if (v->present && d >= v->d)
                    continue;
                v->present = 1;
                /* Visible only if a beam really crossed it: an object that arrived after the beam
                   passed its bearing is not seen until the next sweep. */
                v->visible = !(timed && (hypot(bx, by) > s.range_m || d > s.step)) && !(sweep < 64 && (s.obj[k].fade >> sweep) & 1u);
                v->t = ts;
                v->x = x;
                v->y = y;
                v->vx = vx;
                v->vy = vy;
                v->bx = bx;
                v->by = by;
                v->d = d;
            }
            /* Device timing model (ping.md section 3): 19.4 ms + 6 ms per gradian + 2R/c. */
            t += 0.0194 + 0.006 * s.step + 2.0 * s.range_m / 1500.0;
        }
    }
    if (o.pose_out != NULL) {
        /* 10 Hz from the first beam to a second past the last, as an autopilot would send it. */
        FILE *pf = fopen(o.pose_out, "w");
        double ts;
        if (pf == NULL) {
            perror("sonar_sim: --pose-out");
            return 2;
        }
        fputs("utime_us,north_m,east_m,yaw_deg\n", pf);
        for (ts = 0.0; ts <= t - t0 + 1.0; ts += 0.1) {
            double n, e, yaw;
            scene_vehicle_at(&s, ts, &n, &e, &yaw);
            fprintf(pf, "%lld,%.4f,%.4f,%.3f\n", (long long)floor((t0 + ts) * 1e6 + 0.5), n, e, yaw);
        }
        if (fclose(pf) != 0) {
            perror("sonar_sim: --pose-out");
            return 1;
        }
    }
    if (scene_write_truth(truth, &s, s.sweeps, seen, (long long)(t0 * 1e6)) != 0) {
        perror("sonar_sim: truth");
        return 1;
    }
    free(seen);
    if (fclose(csv) != 0 || fclose(truth) != 0) {
        perror("sonar_sim");
        return 1;
    }
    return 0;
}
