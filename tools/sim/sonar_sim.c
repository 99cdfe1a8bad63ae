/* sonar_sim.c -- writes a simulated scene in the study's CSV plus a ground-truth JSON (see scene.h). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stddef.h>

#include "csv.h"
#include "optschema.h"
#include "scene.h"
#include "sonar/pipeline.h"
#include "sonar/sweep.h"

struct sim_opts {
    const char *scene, *out, *truth, *pose_out, *water;
    long sweeps;
    unsigned long long seed;
    int empty, transients;
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
    {"scene", "NAME", OPT_STR, 0, 0, SO(scene), 0, 0, "pool, open, moving, sector, vehicle, occupied, far, still, faces, faint, lanes, turns, laps, activity or near", "pool",
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
     "turns: the lanes' pool without ropes or ladder: four swimmers doing lengths turned at the end walls\n"
     "(25 m at 1.0 and 1.5 m/s, 5 m at 0.3 and 0.6 m/s), each centre 0.5 m out from the wall (40 passes);\n"
     "laps: the same statistics, full turns at 4 gradians (600 samples over 15 m) from the middle of a\n"
     "16 x 25 m pool: walls all round, two swaying lane ropes, a ladder; three swimmers doing lengths,\n"
     "one standing from the first ping; the truth says their activity (30 turns);\n"
     "activity: the laps pool with the AquaScan labels' three states: a swimmer, one standing (a steady\n"
     "echo, swaying), one struggling (a fresh echo each look, within a metre); truth says each one's (20 turns);\n"
     "near: open water at a 5 m range, three 0.2 m buoys at 0.66, 0.9 and 1.2 m (4 turns);\n"
     "tank: an 8 x 5 m tank from a robot crossing it, a +-45 degree sector at 5 m: walls echoing at\n"
     "twice and three times their range, interference streaks (the truth lists their beams), two buoys\n"
     "and a gate's leg (40 passes; --pose-out writes its path)", NULL, NULL},
    {"out", "FILE", OPT_STR, 0, 0, SO(out), 0, 0, "file", NULL, "the study's CSV (12 m, 1200 samples, 400 beams a sweep)", NULL, NULL},
    {"truth", "FILE", OPT_STR, 0, 0, SO(truth), 0, 0, "file", NULL, "ground-truth JSON", NULL, NULL},
    {"pose-out", "FILE", OPT_STR, 0, 0, SO(pose_out), 0, 0, "file", NULL,
     "the vehicle's poses at 10 Hz, utime_us,north_m,east_m,yaw_deg (sonard --pose)", NULL, NULL},
    {"sweeps", "N", OPT_LONG, 0, 0, SO(sweeps), 1, 100000, "sweeps", "the scene's", "sweeps to write", NULL, NULL},
    {"seed", "S", OPT_CUSTOM, 0, 0, 0, 0, 0, "whole number", "0", "speckle random seed", NULL, parse_seed},
    {"empty", NULL, OPT_FLAG, 0, 0, SO(empty), 0, 0, NULL, NULL,
     "the scene without its objects (walls, ropes, structure and water only): a recording of the empty pool, for\n--background-save",
     NULL, NULL},
    {"transients", NULL, OPT_FLAG, 0, 0, SO(transients), 0, 0, NULL, NULL,
     "the water's transient echoes (surface, bubbles, wakes), as measured on the emptied AquaScan sonar4: born a\n"
     "sweep by range, lasting and drifting, each a fresh echo (scenes with the AquaScan pool's statistics)",
     NULL, NULL},
    {"water", "FILE", OPT_STR, 0, 0, SO(water), 0, 0, "file", NULL,
     "a hybrid scene: the scene's people (not its walls, ropes or water) drawn into a recording of real water\n"
     "(the study's CSV, e.g. one emptied by tools/eval/empty_site.py), beam by beam at its times and angles, its\n"
     "sweeps cut as sonard cuts them; --out keeps the recording's times and metadata; scenes with the AquaScan\n"
     "pool's statistics only (occupied, far, still, faint, lanes, laps, activity)",
     NULL, NULL},
    {"help", NULL, OPT_ACTION, 0, 0, 0, 0, 0, NULL, NULL, "this text", NULL, NULL},
};

/* Truth: each object where it was when the beam nearest its bearing passed (seen: the sweep's row). */
static void note_seen(const struct scene *s, struct scene_seen *seen, int sweep, double ts, int a)
{
    int k;
    for (k = 0; k < s->nobj; k++) {
        struct scene_seen *v = &seen[k];
        double x, y, vx, vy, bx, by, d;
        int timed = s->obj[k].nwp > 0 || s->veh.nwp > 0; /* a moving sonar may pass a still object by */
        if (!scene_object_at(s, k, sweep, ts, &x, &y, &vx, &vy))
            continue;
        scene_to_body(s, ts, x, y, &bx, &by);
        d = fabs(remainder(atan2(by, bx) * 200.0 / 3.14159265358979323846 - a, 400.0));
        if (v->present && d >= v->d)
            continue;
        v->present = 1;
        /* Visible only if a beam really crossed it: an object that arrived after the beam
           passed its bearing is not seen until the next sweep. */
        v->visible = !(timed && (hypot(bx, by) > s->range_m || d > s->step)) && !(sweep < 64 && (s->obj[k].fade >> sweep) & 1u);
        v->t = ts;
        v->x = x;
        v->y = y;
        v->vx = vx;
        v->vy = vy;
        v->bx = bx;
        v->by = by;
        v->d = d;
    }
}

/*
 * The hybrid scene (--water): each row of the recording with the scene's objects drawn in, written to
 * csv; *seen grown a sweep at a time (*nsweeps of them). Returns 0; 2 (said) on a file that cannot be read or
 * drawn on (malformed rows are said and skipped); 1 out of memory.
 */
static int water_scene(struct scene *s, const char *path, long max_sweeps, FILE *csv, struct scene_rng *g,
                       struct scene_seen **seen, int *nsweeps, double *t0)
{
    static struct csv_reader rd;
    static struct csv_row row;
    struct sonar_sweep cut;
    struct sonar_pipeline_config def;
    char err[256];
    int r, have = 0, cap = 0;
    unsigned long bad = 0;
    *nsweeps = 0;
    if (csv_open(&rd, path) != HOST_OK) {
        fprintf(stderr, "sonar_sim: --water %s: %s\n", path, strerror(errno));
        return 2;
    }
    /* Sweeps cut as sonard cuts them by default, so that the truth's sweep k is sonard's. */
    sonar_pipeline_defaults(&def);
    if (sonar_sweep_init(&cut, def.max_step, SONAR_MAX_SWEEP_BEAMS) != SONAR_OK)
        return 1;
    while ((r = csv_next(&rd, &row, err, sizeof(err))) != 0) {
        double t, range_m;
        struct csv_meta meta = csv_meta_none();
        if (r < 0) {
            fprintf(stderr, "sonar_sim: %s:%lu: %s (row skipped)\n", path, rd.line, err);
            bad++;
            continue;
        }
        if (!row.timed) {
            fprintf(stderr, "sonar_sim: --water %s:%lu: the rows have no times; a hybrid scene needs them\n", path, rd.line);
            csv_close(&rd);
            return 2;
        }
        t = (double)row.sec + row.nsec * 1e-9;
        if (!have)
            *t0 = t;
        if (sonar_sweep_step(&cut, row.angle) != SONAR_SWEEP_SAME || !have) {
            if (max_sweeps > 0 && (long)cut.index >= max_sweeps)
                break;
            if ((int)cut.index >= cap) {
                int ncap = cap ? cap * 2 : 64;
                struct scene_seen *m = realloc(*seen, (size_t)ncap * SCENE_MAX_OBJ * sizeof(**seen));
                if (m == NULL) {
                    perror("sonar_sim");
                    csv_close(&rd);
                    return 1;
                }
                memset(m + (size_t)cap * SCENE_MAX_OBJ, 0, (size_t)(ncap - cap) * SCENE_MAX_OBJ * sizeof(*m));
                *seen = m;
                cap = ncap;
            }
            *nsweeps = (int)cut.index + 1;
        }
        have = 1;
        range_m = row.range_m > 0.0 ? row.range_m : s->range_m;
        if (scene_draw_on(s, (int)cut.index, t - *t0, row.angle, range_m, row.n, g, row.samples) != 0) {
            fprintf(stderr, "sonar_sim: --water %s:%lu: %u samples a row; at most 1200 can be drawn on\n", path, rd.line,
                    (unsigned)row.n);
            csv_close(&rd);
            return 2;
        }
        meta.range_m = row.range_m;
        meta.gain = row.gain;
        meta.sample_period = row.sample_period;
        meta.transmit_duration = row.transmit_duration;
        meta.transmit_frequency = row.transmit_frequency;
        meta.speed_of_sound = row.speed_of_sound;
        csv_write(csv, row.sec, row.nsec, row.angle, row.samples, row.n, &meta);
        note_seen(s, &(*seen)[cut.index * SCENE_MAX_OBJ], (int)cut.index, t - *t0, row.angle);
    }
    csv_close(&rd);
    if (!have) {
        fprintf(stderr, "sonar_sim: --water %s: no rows%s\n", path, bad ? " that could be read" : "");
        return 2;
    }
    return 0;
}

/* The simulated scene: its beams written to csv at the device's pace from *t0, *seen one row of objects a sweep; the
   vehicle's poses to pose_out (NULL: none). Returns 0; 2 (said) when pose_out cannot be opened; 1 (said) otherwise. */
static int simulate(struct scene *s, const char *pose_out, FILE *csv, struct scene_rng *g, struct scene_seen **seen,
                    const double *t0)
{
    uint8_t samples[1200];
    double t = *t0;
    int sweep, a;
    struct csv_meta meta;
    if ((*seen = calloc((size_t)s->sweeps * SCENE_MAX_OBJ, sizeof(**seen))) == NULL) {
        perror("sonar_sim");
        return 1;
    }
    meta = csv_meta_none();
    meta.range_m = s->range_m;
    for (sweep = 0; sweep < s->sweeps; sweep++) {
        int i;
        for (i = 0; (a = scene_angle(s, sweep, i)) >= 0; i++) {
            double sec = floor(t), ts = t - *t0;
            scene_beam(s, sweep, ts, a, s->range_m, s->samples, g, samples);
            csv_write(csv, (int64_t)sec, (uint32_t)((t - sec) * 1e9), (uint16_t)a, samples, (uint16_t)s->samples, &meta);
            note_seen(s, &(*seen)[sweep * SCENE_MAX_OBJ], sweep, ts, a);
            /* Device timing model (ping.md section 3): 19.4 ms + 6 ms per gradian + 2R/c. */
            t += 0.0194 + 0.006 * s->step + 2.0 * s->range_m / 1500.0;
        }
    }
    if (pose_out != NULL) {
        /* 10 Hz from the first beam to a second past the last, as an autopilot would send it. */
        FILE *pf = fopen(pose_out, "w");
        double ts;
        if (pf == NULL) {
            perror("sonar_sim: --pose-out");
            return 2;
        }
        fputs("utime_us,north_m,east_m,yaw_deg\n", pf);
        for (ts = 0.0; ts <= t - *t0 + 1.0; ts += 0.1) {
            double n, e, yaw;
            scene_vehicle_at(s, ts, &n, &e, &yaw);
            fprintf(pf, "%lld,%.4f,%.4f,%.3f\n", (long long)floor((*t0 + ts) * 1e6 + 0.5), n, e, yaw);
        }
        if (fclose(pf) != 0) {
            perror("sonar_sim: --pose-out");
            return 1;
        }
    }
    return 0;
}

int main(int argc, char **argv)
{
    const struct opt_schema schema = {sim_spec, sizeof(sim_spec) / sizeof(sim_spec[0]), "sonar_sim", NULL, 0};
    struct sim_opts o = {"pool", NULL, NULL, NULL, NULL, -1, 0, 0, 0};
    const char *scene_name, *csv_path, *truth_path;
    struct scene s;
    struct scene_rng g = {0x9E3779B97F4A7C15ull};
    FILE *csv, *truth;
    double t0 = 1728153122.0;
    struct scene_seen *seen = NULL;
    int sweeps, action, rc;
    char err[256];
    if (opt_parse_argv(&schema, argc, argv, &o, NULL, &action, err, sizeof(err)) != HOST_OK || action >= 0) {
        if (action < 0)
            fprintf(stderr, "sonar_sim: %s\n", err);
        fprintf(stderr, "usage: sonar_sim --scene pool|open|moving|sector|vehicle|tank|occupied|far|still|faces|faint|lanes|turns|laps|activity|near --out FILE.csv --truth FILE.json "
                        "[--pose-out FILE.csv] [--sweeps N] [--seed S] [--transients] [--empty | --water FILE.csv]\n");
        opt_usage(&schema, stderr);
        return action >= 0 ? 0 : 2;
    }
    scene_name = o.scene;
    csv_path = o.out;
    truth_path = o.truth;
    sweeps = (int)o.sweeps;
    g.s ^= o.seed * 0xBF58476D1CE4E5B9ull;
    if (scene_make(&s, scene_name) != 0) {
        fprintf(stderr, "sonar_sim: --scene: '%s' is not pool, open, moving, sector, vehicle, occupied, far, still, faces, faint, lanes, turns, laps, activity or near\n", scene_name);
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
    if (o.water != NULL && s.speckle != SCENE_SPECKLE_POOL) {
        fprintf(stderr, "sonar_sim: --water: scene '%s' is not one with the AquaScan pool's statistics (occupied, far, "
                        "still, faint, lanes, turns, laps or activity); its people cannot be drawn on real water\n", s.name);
        return 2;
    }
    if (o.transients && (o.water != NULL || scene_transients(&s, o.seed) != 0)) {
        fprintf(stderr, "sonar_sim: --transients %s\n", o.water != NULL ? "with --water: the recording's water has its own"
                        : "needs a scene with the AquaScan pool's statistics (occupied, far, still, faint, lanes, turns, laps or activity)");
        return 2;
    }
    if (o.water != NULL && (o.empty || o.pose_out != NULL)) {
        fprintf(stderr, "sonar_sim: --water with %s\n", o.empty ? "--empty: the recording is already the empty water"
                                                                  : "--pose-out: the recording's sonar did not move");
        return 2;
    }
    if ((csv = fopen(csv_path, "w")) == NULL || (truth = fopen(truth_path, "w")) == NULL) {
        perror("sonar_sim");
        return 2;
    }
    if (o.water != NULL) {
        /* Real water carries its own walls and structure: only the scene's people go in. */
        static char name[160];
        const char *base = strrchr(o.water, '/');
        s.nwall = 0;
        s.nrope = 0;
        if ((rc = water_scene(&s, o.water, o.sweeps, csv, &g, &seen, &s.sweeps, &t0)) != 0)
            return rc;
        snprintf(name, sizeof(name), "%s on %s", s.name, base ? base + 1 : o.water);
        s.name = name;
    } else if ((rc = simulate(&s, o.pose_out, csv, &g, &seen, &t0)) != 0) {
        return rc;
    }
    if (scene_write_truth(truth, &s, s.sweeps, seen, (long long)floor(t0 * 1e6 + 0.5)) != 0) {
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
