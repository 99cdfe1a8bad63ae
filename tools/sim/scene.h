/* scene.h -- simulated Ping360 scenes (pool, open water, moving targets): echo model and ground truth, shared by sonar-sim and sonar-feed. */
#ifndef SONARD_SCENE_H
#define SONARD_SCENE_H

#include <stdint.h>
#include <stdio.h>

#define SCENE_MAX_OBJ 8
#define SCENE_MAX_WALL 4
#define SCENE_MAX_WP 20

struct scene_object {
    const char *id;
    double x, y, r;  /* metres at first_sweep */
    double vx, vy;   /* metres per sweep */
    double strength; /* peak echo, grey levels (SCENE_SPECKLE_POOL: its rms amplitude before the noise floor) */
    int first_sweep; /* present from this sweep on */
    /*
     * Timed motion instead (nwp > 0): straight legs between waypoints (seconds since the scene's
     * first beam, metres), present from the first waypoint's time to the last's.
     */
    int nwp;
    double wp_t[SCENE_MAX_WP], wp_x[SCENE_MAX_WP], wp_y[SCENE_MAX_WP];
    unsigned long long fade; /* bit k: no echo at all in sweep k */
    int structure;           /* part of the place (a ladder, a mooring): echoes, but is not in the truth's objects */
};

/*
 * What a person does, as the AquaScan labels say it, and how their echo behaves from look to look
 * (SCENE_SPECKLE_POOL). A standing body is one steady reflector: the same echo pattern look after
 * look, swaying a few centimetres. A struggling one is limbs and splash, several scatterers moving
 * within the body: a fresh pattern every look, its centre jumping up to 0.25 m, never leaving a metre.
 * A swimmer's pattern is fresh every look too (the older scenes' people, whatever they do).
 */
enum scene_act { SCENE_ACT_NONE = 0, SCENE_ACT_MOVING = 1, SCENE_ACT_STANDING = 2, SCENE_ACT_STRUGGLING = 3 };

/*
 * A lane rope (SCENE_SPECKLE_POOL): a line of floats along x = x0 from y0 to y1 that the beam passes
 * through (no shadow), each crossing a short Rayleigh return; it sways across by sway_m with a
 * period, the phase travelling along it, so the background never learns it exactly.
 */
#define SCENE_MAX_ROPE 4
struct scene_rope {
    double x0, y0, y1, strength, sway_m, period_s;
};

struct scene_wall {
    double x0, y0, x1, y1;
};

/*
 * The vehicle carrying the sonar (nwp > 0; else it sits at the origin heading north and the scene's
 * frame is the sonar's): straight legs between waypoints in the world frame (local NED: x north, y
 * east, metres, at seconds since the first beam), and a heading (degrees clockwise from north)
 * turning at yaw_rate_dps, back and forth every yaw_period_s (0: always the same way).
 */
struct scene_vehicle {
    int nwp;
    double wp_t[SCENE_MAX_WP], wp_n[SCENE_MAX_WP], wp_e[SCENE_MAX_WP];
    double yaw0_deg, yaw_rate_dps, yaw_period_s;
};

/*
 * The echo model. SCENE_SPECKLE_SIMPLE: Rayleigh speckle whose level falls with range, ring-down,
 * objects adding a uniform level (the first scenes). SCENE_SPECKLE_POOL: the statistics of the
 * AquaScan pool recordings (tools/eval/speckle_fit.py, docs/results.md section 8): water is a
 * K-distributed amplitude whose shape and mean power follow range (Rayleigh-like near the sonar,
 * spiky far from it), its texture held over 12-sample segments along the beam; objects add a
 * Rayleigh amplitude in power; the device's noise floor is then subtracted and the result clipped
 * at 0, which gives the recordings' zeros (41 % of cells at 2-4 m, 78 % at 12-15 m).
 */
enum scene_speckle {
    SCENE_SPECKLE_SIMPLE = 0,
    SCENE_SPECKLE_POOL = 1
};

/*
 * A transient echo of the water itself (--transients): a patch of surface, bubbles or wake that lasts a few sweeps
 * and drifts, its echo a fresh Rayleigh amplitude each look. Present in sweeps first..first + life - 1, at (x, y) +
 * k (vx, vy) in the k-th of them (metres, the scene's frame; metres a sweep).
 */
#define SCENE_MAX_PATCH 4096
struct scene_patch {
    float x, y, vx, vy, r, strength;
    int first, life;
};

struct scene {
    const char *name;
    int speckle;    /* enum scene_speckle */
    double range_m; /* the recording's range */
    int samples, sweeps, step;
    struct scene_wall wall[SCENE_MAX_WALL];
    int nwall;
    struct scene_object obj[SCENE_MAX_OBJ];
    int act[SCENE_MAX_OBJ]; /* enum scene_act of each object (the truth's "activity"); 0 in the older scenes */
    int nobj;
    struct scene_rope rope[SCENE_MAX_ROPE];
    int nrope;
    int start, stop; /* a sector scanned back and forth, gradians; start == stop: full turns */
    struct scene_vehicle veh;
    struct scene_patch patch[SCENE_MAX_PATCH]; /* the water's transients (scene_transients), npatch of them */
    int npatch;
    /*
     * A tank's acoustics (the "tank" scene; 0 elsewhere): the sound bouncing between a wall and the vehicle
     * comes back at twice and three times the wall's range at echo[0] and echo[1] of the wall's level; and
     * interference streaks, each beam one with probability streak_rate (a streak continues into the next
     * beam with probability SCENE_STREAK_ON), streak_level grey levels added along its length.
     * tools/eval/tank_calib.py measures all four on the RoboSub sweeps (docs/results.md).
     */
    double echo[2];
    double streak_rate, streak_level;
};

#define SCENE_STREAK_ON 0.125 /* two of the 18 streaks on the RoboSub sweeps were two beams wide, none wider */

/* The level a streak adds to beam angle of sweep (0: none), the same for every caller (hashed). */
double scene_streak(const struct scene *s, int sweep, int angle);

/* The scene as it is with nobody in it (--empty): its walls, ropes and structure objects (a ladder) stay. */
void scene_empty(struct scene *s);

/* The vehicle's pose at t seconds since the first beam: north, east (m), yaw (degrees, [0, 360)). */
void scene_vehicle_at(const struct scene *s, double t, double *n, double *e, double *yaw_deg);

/* World (north, east) to the sonar frame at t (identity when the vehicle does not move). */
void scene_to_body(const struct scene *s, double t, double n, double e, double *x, double *y);

/* xorshift64*: the same stream on every machine. */
struct scene_rng {
    uint64_t s;
};

/*
 * Gives a SCENE_SPECKLE_POOL scene the water's transient echoes, as tools/eval/transients.py measures them on the
 * emptied AquaScan sonar4 (born a sweep, how long they last, how far they move, their size and brightness, by range
 * band; docs/results.md section 12), drawn from seed over the scene's sweeps (set them first). Returns 0, or -1 for
 * a scene of the older echo model (nothing given).
 */
int scene_transients(struct scene *s, unsigned long long seed);

/* Fills s for "pool", "open", "moving", "sector", "vehicle", "tank", "occupied", "far", "still", "faces", "faint", "lanes", "laps" or "near"; returns 0, or -1 for an unknown name. */
int scene_make(struct scene *s, const char *name);

/*
 * Where object k is in a sweep at t seconds since the scene's first beam, and its velocity (m/s;
 * 0 for the per-sweep steps of untimed objects). Returns 0 if it is not there then.
 */
int scene_object_at(const struct scene *s, int k, int sweep, double t, double *x, double *y, double *vx, double *vy);

/* The i-th beam's angle of a sweep (full turns: 0, step, ...; sectors: back and forth). Returns -1 past its end. */
int scene_angle(const struct scene *s, int sweep, int i);

/*
 * One beam: angle in gradians, n samples over range_m metres (sample i at (i + 0.5) range_m / n),
 * as the scene looks during the given sweep at t seconds. Uses and advances g.
 */
void scene_beam(const struct scene *s, int sweep, double t, int angle, double range_m, int n, struct scene_rng *g,
                uint8_t *out);

/*
 * Draws the scene's objects, and nothing else of it (no walls, ropes or water), into a recorded beam of
 * real water, in place (sonar-sim --water: the hybrid scenes): the recording's amplitudes taken back
 * above the device's noise floor, the objects' echoes added in power as scene_beam adds them, the floor
 * subtracted again. inout: n <= 1200 samples over range_m metres at angle gradians, during the given
 * sweep at t seconds since the recording's first beam. Uses and advances g. Returns 0, or -1 (inout
 * untouched) when the scene's echo model is not SCENE_SPECKLE_POOL or n is over 1200.
 */
int scene_draw_on(const struct scene *s, int sweep, double t, int angle, double range_m, int n, struct scene_rng *g,
                  uint8_t *inout);

/* What the truth says of one object in one sweep: where it was when a beam crossed it. */
struct scene_seen {
    int present;            /* there and inside the range */
    int visible;            /* present and not faded */
    double t, x, y, vx, vy; /* seconds since the first beam; metres; m/s (the scene's frame) */
    double bx, by;          /* metres in the sonar frame then */
    double d;               /* gradians between that beam and the object's bearing */
};

/*
 * The truth file: {"scene","range_m","samples","beams_per_sweep","walls":[[x0,y0,x1,y1]],"sweeps":[{"sweep","objects":
 * [{"id","x","y","radius","t_us","vx","vy"[,"bx","by"]}],"hidden":[{"id","x","y","t_us"}]}]}: x, y, vx,
 * vy in the scene's frame (the world when the vehicle moves, with bx, by in the sonar's); "objects" are the
 * visible ones (what a detector can find); "hidden" are in range but unseen that sweep (faded, or
 * no beam crossed them), which tracking scores as don't-care. Structure objects (a ladder) are in
 * neither: a detection on one is a false object. seen[sweep * SCENE_MAX_OBJ + k];
 * t0_us: the first beam's time.
 */
int scene_write_truth(FILE *f, const struct scene *s, int sweeps, const struct scene_seen *seen, long long t0_us);

double scene_uniform(struct scene_rng *g);

#endif
