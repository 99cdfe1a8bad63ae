/* scene.h -- simulated Ping360 scenes (pool, open water): echo model and ground truth, shared by sonar-sim and sonar-feed. */
#ifndef SONARD_SCENE_H
#define SONARD_SCENE_H

#include <stdint.h>
#include <stdio.h>

#define SCENE_MAX_OBJ 8
#define SCENE_MAX_WALL 4

struct scene_object {
    const char *id;
    double x, y, r;  /* metres at first_sweep */
    double vx, vy;   /* metres per sweep */
    double strength; /* peak echo, grey levels */
    int first_sweep; /* present from this sweep on */
};

struct scene_wall {
    double x0, y0, x1, y1;
};

struct scene {
    const char *name;
    double range_m; /* the recording's range */
    int samples, sweeps, step;
    struct scene_wall wall[SCENE_MAX_WALL];
    int nwall;
    struct scene_object obj[SCENE_MAX_OBJ];
    int nobj;
};

/* xorshift64*: the same stream on every machine. */
struct scene_rng {
    uint64_t s;
};

/* Fills s for "pool" or "open"; returns 0, or -1 for an unknown name. */
int scene_make(struct scene *s, const char *name);

/* Where object k is at a sweep; returns 0 if it is not there yet. */
int scene_object_at(const struct scene *s, int k, int sweep, double *x, double *y);

/*
 * One beam: angle in gradians, n samples over range_m metres (sample i at (i + 0.5) range_m / n),
 * as the scene looks during the given sweep. Uses and advances g.
 */
void scene_beam(const struct scene *s, int sweep, int angle, double range_m, int n, struct scene_rng *g, uint8_t *out);

/* The truth file: {"scene","range_m","samples","beams_per_sweep","sweeps":[{"sweep","objects":[...]}]}. */
int scene_write_truth(FILE *f, const struct scene *s, int sweeps);

double scene_uniform(struct scene_rng *g);

#endif
