/* tracker.h -- tracks with persistent IDs across sweeps: interacting multiple models (moving, manoeuvring, resting), a Mahalanobis gate, an optimal assignment deferred by a sweep, confirmation by M of N hits or by probability of existence, predictions turned at the site's walls (tracker_walls.c); RAM: sizeof(struct sonar_track) = 184 B a track (SONAR_MAX_TRACKS), sizeof(struct sonar_tracker) = 11 680 B (the walls SONAR_TRK_MAX_WALLS * 48 = 768 B of it, the pair cost cache SONAR_MAX_CLUSTERS * SONAR_MAX_TRACKS * 4 = 2 048 B of it); stack of an update ~3.5 KB. */
#ifndef SONAR_TRACKER_H
#define SONAR_TRACKER_H

#include <stdint.h>

#include "sonar/clutter.h"
#include "sonar/config.h"
#include "sonar/err.h"
#include "sonar/pose.h"

/*
 * Each track is x = (px, vx, py, vy) in metres and m/s in the frame of its detections (the sonar
 * frame), estimated by an interacting multiple model filter (IMM) of three Kalman filters: near
 * constant velocity (white acceleration noise accel_mps2), a manoeuvre (manoeuvre_mps2: a turn,
 * a start, a stop) and rest (no velocity, the position wandering at SONAR_TRK_REST_MPS). Both
 * axes see the same measurement noise, so each model keeps one 2 x 2 covariance for both
 * (position, cross, velocity): exact for each model, and a quarter of the arithmetic; the
 * combined estimate averages the two axes' spread. Each detection carries its own time (the beam
 * that saw its centroid), so a track is predicted to the moment it was seen, not to the end of
 * the sweep.
 */

enum sonar_track_model_kind { SONAR_TRK_CV = 0, SONAR_TRK_MANOEUVRE = 1, SONAR_TRK_REST = 2, SONAR_TRK_MODELS = 3 };

/* What a track is doing, from its models' probabilities at its last hit. */
enum sonar_track_mode {
    SONAR_TRACK_MOVING = 0,  /* near constant velocity is the likeliest model */
    SONAR_TRACK_TURNING = 1, /* the manoeuvre model is */
    SONAR_TRACK_RESTING = 2  /* the rest model is */
};

/* What a track is over its life. */
enum sonar_track_kind {
    SONAR_TRACK_KIND_NEW = 0,       /* not yet enough looks to say (fewer than SONAR_TRK_KIND_HITS hits) */
    SONAR_TRACK_KIND_MOVING = 1,    /* it has moved, and moves now */
    SONAR_TRACK_KIND_RESTING = 2,   /* it moved once and stands still now (the pool watcher's case) */
    SONAR_TRACK_KIND_STILL = 3,     /* never moved since first seen, over SONAR_TRK_KIND_HITS hits or more: still, not
                                       structure (only the site's survey says what is; its structure is not tracked) */
    SONAR_TRACK_KIND_STATIC_START = 4 /* never moved, on what has stood there since the first look (structure.h): with no
                                         survey it cannot be told from the site; it stays a track */
};

enum sonar_track_state {
    SONAR_TRACK_TENTATIVE = 0, /* not yet M hits in the last N sweeps it was visible in */
    SONAR_TRACK_CONFIRMED = 1, /* hit this sweep */
    SONAR_TRACK_COASTING = 2   /* confirmed, then not hit (missed, or out of view): running on its prediction */
};

#define SONAR_TRK_ACCEL_MAX 10   /* accel_mps2: 0.001..10 */
#define SONAR_TRK_MEAS_MAX 10    /* meas_m: 0.01..10 */
#define SONAR_TRK_SPEED_MAX 20   /* speed0_mps: 0.01..20 */
#define SONAR_TRK_GATE_MAX 100   /* gate: 1..100 */
#define SONAR_TRK_WINDOW_MAX 8   /* 1 <= confirm_m <= confirm_n <= 8 */
#define SONAR_TRK_MAX_DT_MAX 600 /* max_dt_s: 1..600 */
#define SONAR_TRK_COORD_MAX 1000 /* detections beyond +-1000 m on an axis are refused as absurd */
/* A track of two hits or more pairs only with a detection it reaches at 3 x its speed + 0.3 m/s (+ 3 meas_m). */
#define SONAR_TRK_TURN_SPEEDUP 3.0f
#define SONAR_TRK_TURN_FROM_REST 0.3f
/* A track has moved when its filtered position leaves a disc of this radius about where it last moved, metres.
   (Structure, an echo there from the first look that never moved, is not tracked: structure.h.) */
#define SONAR_TRK_STILL_M 0.3f
#define SONAR_TRK_LEFT_ONCE 2u /* sonar_track.moved: left its disc on its last hit, not yet on two */
/* The rest model's position wander, m/s per root second (a floating body bobbing): variance grows REST^2 x dt. */
#define SONAR_TRK_REST_MPS 0.05f
/* A swimmer's centre turns this far out from a wall (half a body length; tracker_walls.c), metres. */
#define SONAR_TRK_WALL_TURN_M 0.5f
/* A wall's line runs on this far past the ends seen of it (metres): a survey sees a wall only as far as its beams
   reach, and a swimmer turning at its end is a body's width wide. */
#define SONAR_TRK_WALL_END_M 1.0f
/* Hits before a track that never moved is called structure (enum sonar_track_kind). */
#define SONAR_TRK_KIND_HITS 4

/*
 * A track's probability of existence (the integrated PDA's, Musicki et al., with the one detection
 * the assignment gives it; tracker_exist.c). Each look it survives with SONAR_TRK_EXIST_SURVIVE;
 * a miss where it was in view multiplies the odds by 1 - P_D P_G; a hit by 1 - P_D (P_G - g / rho),
 * g the detection's likelihood under its models (per m^2) and rho the clutter density there
 * (clutter.h): a detection where clutter is rare is good evidence, one where it flickers every look
 * is little. P_D is the track's own (its hits over its looks, starting from SONAR_TRK_EXIST_PD),
 * so a faint far swimmer seen every other look is not ended by the looks that miss it.
 */
#define SONAR_TRK_EXIST_BIRTH 0.5f    /* a new track's, from one detection nothing else explains */
#define SONAR_TRK_EXIST_CONFIRM 0.9f  /* confirmed at or above */
#define SONAR_TRK_EXIST_ALARM 0.97f   /* established at or above: alarms only on such tracks (activity.h) */
#define SONAR_TRK_EXIST_DOUBT 0.5f    /* a confirmed track hit below it is tentative again, until it earns CONFIRM */
#define SONAR_TRK_EXIST_END 0.1f      /* a confirmed track below it ends ... */
#define SONAR_TRK_EXIST_END_NEW 0.05f /* ... a tentative one below this */
#define SONAR_TRK_EXIST_SURVIVE 0.98f /* the chance a real object is still there a look later */
#define SONAR_TRK_EXIST_PD 0.9f       /* a new track's chance to be detected when in view; 0.5 .. 0.95 as it learns its own */
#define SONAR_TRK_EXIST_PG 0.99f      /* the chance its detection falls inside the gate */

struct sonar_tracker_config {
    float accel_mps2;     /* acceleration noise std, m/s^2, 0.001..10 */
    float manoeuvre_mps2; /* acceleration noise std of the manoeuvre model, m/s^2, 0..10; not above accel_mps2: as the moving one */
    float meas_m;         /* detection position std per axis, m, 0.01..10 */
    float speed0_mps;     /* velocity std of a new track, m/s, 0.01..20 */
    float max_speed_mps;  /* no pair implies a move faster than this from the track's last state (+ 3 meas_m), m/s,
                             0 (off) or 0.1..20: a one-hit track's velocity gate spans metres, this bounds it */
    float gate;           /* Mahalanobis d^2 a detection may be from a prediction (chi-square, 2 dof: 9.21 = 99%), 1..100 */
    uint8_t confirm_m;    /* hits ...                                           */
    uint8_t confirm_n;    /* ... in the last N sweeps the track was visible in confirm it; 1 <= M <= N <= 8 */
    uint8_t max_misses;   /* visible sweeps in a row without a hit that delete a confirmed track, 1..127;
                             twice as many sweeps without a hit, in view or not, also do */
    float max_dt_s;       /* longest prediction step, s, 1..600; longer gaps are counted and clipped */
    uint8_t imm;          /* 1: the three models; 0: near constant velocity alone */
    uint8_t defer;        /* 1: keep the likeliest other assignments of a sweep and let the next look decide
                             (IDs may then be revised, each revision said); 0: each sweep's assignment is final */
    uint8_t existence;    /* 1: confirmed and ended by probability of existence (SONAR_TRK_EXIST_*); 0: confirmed
                             by confirm_m of confirm_n hits and ended after max_misses misses (sonard before issue 51) */
    uint8_t walls;        /* 1: predictions turn at the site's walls (sonar_tracker_set_walls); 0: they never do */
};

/*
 * One model of a track's IMM, held mixed: the model's starting state for the next step (its own
 * estimate blended with the others' by the probabilities of changing model), and p its prior
 * probability for that step. Rest keeps vx = vy = pb = pc = 0.
 */
struct sonar_track_model {
    float px, py, vx, vy; /* m, m/s, the tracker's frame */
    float pa, pb, pc;     /* per-axis covariance, as the track's */
    float p;              /* prior probability of this model for the next step, 0..1; the three sum to 1 */
};

struct sonar_track {
    uint32_t id;         /* 1, 2, ... in birth order; never reused in a tracker's life */
    uint8_t state;       /* enum sonar_track_state */
    uint8_t history;     /* bit k: hit k visible sweeps ago */
    uint8_t seen;        /* visible sweeps in history, <= confirm_n */
    int8_t det;          /* index of the detection used this sweep, -1 if none */
    uint16_t age;        /* sweeps since birth (saturating) */
    uint16_t hits;       /* detections used (saturating) */
    uint16_t misses;     /* visible sweeps in a row without a hit */
    uint8_t unseen;      /* sweeps in a row without a hit, in view or not (saturating) */
    uint8_t size_dm;     /* its last detection's radius, decimetres (sonar_tracker_obs.size_m; saturating at 25.5 m) */
    int64_t utime;       /* us since the epoch: the time of the state below */
    float px, py, vx, vy; /* m, m/s, in the tracker's frame (world: north, east) */
    float pa, pb, pc;    /* per-axis covariance: position m^2, cross m^2/s, velocity m^2/s^2 */
    float ax, ay;        /* where it last moved: its filtered position then (same frame as px, py) */
    uint32_t still_ms;   /* ms it had stood still at utime: since it last moved more than SONAR_TRK_STILL_M, or was born */
    uint8_t mode;        /* enum sonar_track_mode at its last hit */
    uint8_t kind;        /* enum sonar_track_kind */
    uint8_t moved;       /* 1 once it has moved more than SONAR_TRK_STILL_M from where it was born, on two hits
                            in a row; SONAR_TRK_LEFT_ONCE after the first of them; else 0 */
    uint8_t mu[SONAR_TRK_MODELS]; /* the models' probabilities at its last hit, 0..255 (255 = 1) */
    uint8_t chance;      /* 1: this sweep's detection came in the second chance (tracker.c), under its models' own gates */
    uint8_t activity;    /* enum sonar_activity_kind (activity.h), set after each look; 0 unknown */
    uint8_t alarms;      /* SONAR_ALARM_* bits (activity.h) */
    int8_t echo_corr;    /* its echo's look-to-look correlation x 100, averaged (activity.h); -128: none */
    uint16_t looks;      /* sweeps it was in view or hit (saturating): its own P_D is hits over these */
    uint8_t exists;      /* 1 once its existence reached SONAR_TRK_EXIST_ALARM, until it falls below SONAR_TRK_EXIST_DOUBT */
    uint16_t near_walls; /* this update: bit k, wall[k] within its models' reach by the sweep's last detection (tracker_walls.c) */
    float existence;     /* probability it is a real object, 0..1 (SONAR_TRK_EXIST_*) */
    float lik;           /* this sweep's detection's likelihood under its models, per m^2 (0: none) */
    struct sonar_track_model m[SONAR_TRK_MODELS]; /* the IMM, mixed for the next step; px .. pc above combine them */
};

/* One detection handed to the tracker. */
struct sonar_tracker_obs {
    float x_m, y_m; /* metres, in the tracks' frame */
    int64_t utime;  /* us since the epoch: when it was seen */
    float size_m;   /* its radius (centroid to farthest hull vertex), metres, 0..100; kept by the track, else unused */
};

/* What the sweep looked at: a track outside it is neither hit nor missed. */
struct sonar_tracker_sweep {
    int64_t utime;        /* us since the epoch of the sweep's last beam */
    uint16_t beams;       /* 0: an empty sweep, counted and otherwise ignored */
    const uint8_t *cover; /* 400-bit map (50 bytes, bit a % 8 of byte a / 8) of the gradians scanned, in
                             the tracks' frame; NULL: everywhere */
    float min_range_m, max_range_m; /* the ranges scanned (a track predicted inside min_range is out of view) */
    float origin_x, origin_y; /* the sonar's position at utime in the tracks' frame (0, 0 in the body frame) */
    struct sonar_clutter *clutter; /* the site's clutter map about origin: its look taken over cover and the ranges
                                      first (what the last sweep taught), then each track's evidence judged against
                                      it and the detections tentative tracks took taught to it; NULL: the floor
                                      density everywhere, nothing taught */
};

/*
 * Another assignment of one sweep, kept until the next look decides: it changes two tracks (by
 * ID) and holds their states had it been chosen. id[0] lost a detection to id[1] (id[1] took
 * it, or the two swapped theirs); absent: under it id[0] was never born (id[1] took its first
 * detection).
 */
struct sonar_trk_alt {
    float delta;                /* its cost above the assignment published, -2 ln of a likelihood ratio, >= 0 */
    uint32_t id[2];
    uint8_t absent;             /* 1: id[0] does not exist under it */
    int8_t born_det;            /* the detection id[0] was born from, until its ID is known; -1 */
    struct sonar_track t[2];    /* id[0]'s and id[1]'s states under it */
};

/* A revision of the IDs published the sweep before: the track published as from is to (0: withdrawn, it was not there). */
struct sonar_track_revision {
    uint32_t from, to;
};

struct sonar_tracker {
    struct sonar_tracker_config cfg;
    struct sonar_track t[SONAR_MAX_TRACKS];
    uint8_t n;               /* live tracks, t[0 .. n) in birth order */
    uint32_t next_id;
    int64_t last_utime;      /* latest detection or sweep time seen */
    uint32_t sweeps;         /* non-empty sweeps */
    uint32_t bad_detections; /* NaN, infinite or beyond SONAR_TRK_COORD_MAX: refused */
    uint32_t clock_back;     /* sweeps whose time ran backwards (tracks re-timed, nothing predicted back) */
    uint32_t clock_gaps;     /* predictions clipped at max_dt_s */
    uint32_t empty_sweeps;   /* sweeps with zero beams */
    uint32_t overflow;       /* detections that found no free track */
    uint32_t dropped;        /* detections past SONAR_MAX_CLUSTERS in one update: not read */
    uint32_t out_of_order;   /* detections older than the last sweep (used; nothing is predicted backwards) */
    uint32_t deleted;        /* tracks ended */
    uint32_t manoeuvres;     /* hits after which the manoeuvre model was the likeliest (a turn, a start, a stop) */
    uint8_t world;           /* the tracks' frame: 1 world (north, east), 0 body; see sonar_tracker_reframe */
    uint32_t reframes;       /* changes of frame */
    uint8_t nalt;            /* alternatives of the last sweep kept for the next look */
    struct sonar_trk_alt alt[SONAR_TRK_HYPOTHESES - 1];
    uint8_t nrev;            /* revisions this update made of the IDs published after the last one */
    struct sonar_track_revision rev[2];
    uint32_t revisions;      /* updates that revised the last sweep's IDs */
    uint32_t hyp_overflow;   /* alternatives within reach that did not fit: that sweep's assignment was final for them */
    /*
     * An update's scratch, here rather than on its stack (static RAM is counted; the stack is the
     * co-processor's small bank): each pair's cost under the combined gate, computed once an update
     * (the passes, the alternatives and the next look's decision all read it); known bit k of row d:
     * cost[d][k] holds detection d's cost for track slot k.
     */
    float wall[SONAR_TRK_MAX_WALLS][4]; /* x0, y0, x1, y1 of each wall, metres in the tracks' frame */
    uint8_t nwalls;          /* wall[0 .. nwalls) (sonar_tracker_set_walls) */
    float wall_box[4][SONAR_TRK_MAX_WALLS]; /* each wall's box: least x, most x, least y, most y (a row each: compared
                                               a track against them all at once) */
    float turn[SONAR_TRK_MAX_WALLS][4]; /* this update: each wall's line where a swimmer turns (tracker_walls.c) ... */
    uint32_t turnable;       /* ... bit k: wall k has one (it has a length, and the sonar is off its line) */
    const struct sonar_tracker_obs *cache_obs;
    const struct sonar_tracker_sweep *cur_sw; /* the sweep being updated (its clutter map and origin), else NULL */
    uint64_t cache_known[SONAR_MAX_CLUSTERS];
    float cache_cost[SONAR_MAX_CLUSTERS][SONAR_MAX_TRACKS];
};

/* Largest assignment sonar_tracker_assign solves: rows <= cols <= this. */
#define SONAR_ASSIGN_MAX (SONAR_MAX_CLUSTERS + SONAR_MAX_TRACKS)

/* NULL when cfg is valid, else a static "field: rule" string naming the first bad field. */
const char *sonar_tracker_config_check(const struct sonar_tracker_config *cfg);

/* sonard's defaults: 0.05 m/s^2, manoeuvres 0.5 m/s^2, 0.15 m, 1 m/s, gate 9.21, 2 of 3, 3 misses, 120 s, deferred. */
void sonar_tracker_defaults(struct sonar_tracker_config *cfg);

/*
 * The site's walls (a survey's lines, say) as n segments x0, y0, x1, y1 (metres, the tracks' frame),
 * copied; n 0 clears them. A model whose straight prediction would cross a wall, seen from the
 * sonar's side, also predicts the turn: its path reflected about the wall, its speed kept; each
 * detection is judged against whichever of the two explains it better, so a wall that is a lane rope
 * costs a swimmer who dives under it nothing. A track beyond a wall is never turned back in.
 * Kept by sonar_tracker_tune, emptied by sonar_tracker_init. Returns SONAR_OK; SONAR_ERR_ARG (tk
 * NULL, seg NULL with n > 0, or a coordinate not finite or beyond SONAR_TRK_COORD_MAX; nothing
 * changed) or SONAR_ERR_SPACE (n over SONAR_TRK_MAX_WALLS: the first SONAR_TRK_MAX_WALLS kept).
 */
SONAR_CHECK int sonar_tracker_set_walls(struct sonar_tracker *tk, const float (*seg)[4], unsigned n);

/* Validates cfg (copied) and empties the tracker; IDs start at 1. Returns SONAR_OK or SONAR_ERR_ARG. */
SONAR_CHECK int sonar_tracker_init(struct sonar_tracker *tk, const struct sonar_tracker_config *cfg);

/* Changes the settings in place, keeping the tracks. Returns SONAR_OK or SONAR_ERR_ARG (nothing changed). */
SONAR_CHECK int sonar_tracker_tune(struct sonar_tracker *tk, const struct sonar_tracker_config *cfg);

/*
 * One sweep's detections (the first SONAR_MAX_CLUSTERS of n are read, the rest dropped and
 * counted; obs may be NULL when n is 0): the last sweep's alternatives read first (deferred
 * association: the IDs it published may be revised, sonar_tracker_revisions); predicts every
 * track's models to each detection's time, gates, assigns at least total cost (-2 ln of the
 * models' mixture likelihood a pair, more than a gated pair of one model costs to start a new
 * track instead), offers what is left to the confirmed tracks that found nothing under each of
 * their models' own gates (a second assignment), keeps the likeliest other assignments for the
 * next look, updates, confirms, coasts, deletes, and starts tentative tracks from the detections
 * left over; each track's existence moved by its hit or miss (sw's clutter map, whose look it takes
 * first). A track's det is its detection's index in obs. Bad detections and full tables are
 * counted, never fatal. Returns SONAR_OK, or SONAR_ERR_ARG (tk or sw NULL, obs NULL with n > 0, or
 * sw's clutter map with a max_range_m it cannot take: nothing changed).
 */
SONAR_CHECK int sonar_tracker_update(struct sonar_tracker *tk, const struct sonar_tracker_obs *obs, unsigned n,
                                     const struct sonar_tracker_sweep *sw);

/*
 * Seconds t has stood still at utime (us since the epoch): since its filtered position last moved
 * more than SONAR_TRK_STILL_M, or since its birth; 0 when utime is earlier. A pool watcher's alarm
 * on a person who stopped moving reads this.
 */
float sonar_track_still_s(const struct sonar_track *t, int64_t utime);

/* Position of t predicted to utime (us; earlier than t->utime gives t's own), metres. */
void sonar_tracker_predict(const struct sonar_track *t, int64_t utime, float *x_m, float *y_m);

/*
 * Moves every track into the other frame at pose p (to_world 1: body -> world, 0: world -> body):
 * positions through sonar_pose_to_world / _to_body, velocities turned by p's yaw; the per-axis
 * covariances do not change under a rotation. Sets tk->world to to_world and counts a reframe
 * when it changed (nothing happens when the tracks are already in that frame).
 */
void sonar_tracker_reframe(struct sonar_tracker *tk, const struct sonar_pose *p, int to_world);

/*
 * The sonar's output frame turned by deg degrees clockwise (a reload's new angle offset): body-frame
 * tracks turn about the sonar, world-frame ones about the vehicle at pose at (positions, where they
 * last moved, velocities), so they stay on the objects the turned beams will now place there. A
 * world-frame tracker with at NULL is left as it is (no pose: nowhere to turn about).
 */
void sonar_tracker_turn(struct sonar_tracker *tk, float deg, const struct sonar_pose *at);

/* Live tracks (t[0 .. n) in birth order), one of them (i < that), and the frame they are in (1: world). */
unsigned sonar_tracker_count(const struct sonar_tracker *tk);
const struct sonar_track *sonar_tracker_track(const struct sonar_tracker *tk, unsigned i);
int sonar_tracker_world(const struct sonar_tracker *tk);

/* "tentative", "confirmed", "coasting", or "?" for anything else. */
const char *sonar_track_state_str(int state);

/* "moving", "turning", "resting" (enum sonar_track_mode), or "?". */
const char *sonar_track_mode_str(int mode);

/*
 * After sonar_tracker_update: the update's detections (by index, n of them) that stand where something
 * has stood since the first look (SONAR_DET_STATIC_START): each track hit by one that never moved is
 * of kind SONAR_TRACK_KIND_STATIC_START. O(tracks).
 */
void sonar_tracker_static_start(struct sonar_tracker *tk, const uint8_t *is_static, unsigned n);

/* "new", "moving", "resting", "still", "static since start" (enum sonar_track_kind), or "?". */
const char *sonar_track_kind_str(int kind);

/*
 * The revisions the last update made of the IDs published after the update before it (*n of
 * them, 0 or 2): the tracks published then as from are to (0: that track was not there). A
 * consumer that keeps the last sweep's tracks relabels them; one that wants no revisions reads
 * each sweep one sweep late, after them.
 */
const struct sonar_track_revision *sonar_tracker_revisions(const struct sonar_tracker *tk, unsigned *n);

/*
 * A copy of the tracker as it was after one sweep, made what a consumer one sweep late reads:
 * next's revisions (next: the same tracker after the following update) applied to its IDs, each
 * track published as from now to, one withdrawn (to 0) removed, and its own revisions cleared (a
 * late reader sees none). kept[i] (SONAR_MAX_TRACKS entries) = where track i of the result was
 * before, for whatever else is indexed by track. Returns the tracks left.
 */
unsigned sonar_tracker_relabel(struct sonar_tracker *copy, const struct sonar_tracker *next, uint8_t *kept);

/*
 * Marks in cover (50 bytes, cleared first) the gradians a sweep's beams scanned: each beam's own
 * gradian and those between consecutive beams up to max_gap apart (a larger gap is a jump, not
 * scanned), all shifted by offset gradians (the output frame) and taken modulo 400.
 */
void sonar_tracker_cover(uint8_t *cover, const uint16_t *angles, uint16_t n, uint16_t max_gap, int offset);

/*
 * Minimum-cost assignment of rows to distinct columns (Hungarian, O(rows^2 cols)): cost is
 * rows x cols, row-major; 1 <= rows <= cols <= SONAR_ASSIGN_MAX. row_col[i] = the column of row
 * i. Ties go the same way on every platform. Returns SONAR_OK or SONAR_ERR_ARG.
 */
SONAR_CHECK int sonar_tracker_assign(const float *cost, uint8_t rows, uint8_t cols, int8_t *row_col);

#endif
