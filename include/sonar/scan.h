/* scan.h -- the scan planner: the next angle for the head, a plain sweep or passes that look at every tracked target and at the sector's grid in turns, within a staleness bound, planned with the head's travel time; RAM: sizeof(struct sonar_scan) = 1 704 B, 4 B a gradian. */
#ifndef SONAR_SCAN_H
#define SONAR_SCAN_H

#include <stdint.h>

#include "sonar/err.h"
#include "sonar/frame.h"
#include "sonar/ping360.h"

enum sonar_scan_mode {
    SONAR_SCAN_SWEEP = 0, /* the sector in order, as the driver steps it: full turns, or back and forth */
    SONAR_SCAN_FOLLOW = 1 /* round and round, pinging the targets' windows every pass and the grid in turns */
};

#define SONAR_SCAN_GRAD_US SONAR_P360_GRAD_US /* the head's travel, us a gradian: the driver's timing model's */
#define SONAR_SCAN_MAX_HALF 25      /* a target's window spans at most +-25 gradians */
#define SONAR_SCAN_REVISIT_MAX_S 60 /* revisit_s and surveil_s: at most a minute */
#define SONAR_SCAN_MAX_TARGETS 16   /* targets the planner reads a call; more are ignored (counted) */

struct sonar_scan_config {
    uint8_t mode;         /* enum sonar_scan_mode */
    uint16_t start_angle; /* gradians 0..399 */
    uint16_t stop_angle;  /* gradians 0..399, != start; a sector runs start -> stop going up (mod 400) */
    uint8_t full_circle;  /* 1: full turns from start_angle (stop ignored) */
    uint8_t step;         /* gradians a beam, 1..50 */
    uint32_t ping_us;     /* a ping without the head's travel: 19.4 ms + 2R/c + the transfer; 1..10^7 us */
    float revisit_s;      /* follow: the revisit wanted, 0.2..60 s; looks later than it are counted */
    float surveil_s;      /* follow: no angle of the sector's grid unvisited for longer; 0: twice a plain
                             sweep; else at least a plain sweep, at most SONAR_SCAN_REVISIT_MAX_S */
};

/* A target to revisit: its bearing predicted now and how far either side it may be. */
struct sonar_scan_target {
    float angle;      /* head gradians [0, 400) */
    float half_width; /* gradians >= 0: its uncertainty; the window is clipped to two steps or 8 gradians either side
                         (at most SONAR_SCAN_MAX_HALF), and the windows together to a quarter of the grid's pings */
};

struct sonar_scan_counters {
    uint32_t target_pings;   /* pings chosen for a target's window */
    uint32_t surveil_pings;  /* pings chosen for the grid (its turn, its bound, or nothing else to do) */
    uint32_t targets_dropped; /* targets past SONAR_SCAN_MAX_TARGETS, or outside the sector, over all calls */
    uint32_t late_looks;      /* window pings at angles left longer than revisit_s */
};

struct sonar_scan {
    struct sonar_scan_config cfg;
    struct sonar_scan_counters counters;
    uint32_t seen_ms[SONAR_GRAD_TURN]; /* ms after t0 of the last ping at each gradian; 0: never */
    int64_t t0;                        /* us: the first call, less 1 ms */
    uint32_t surveil_us;               /* the staleness bound in use */
    uint32_t sweep_us;                 /* modelled time of a plain sweep of the sector */
    uint16_t head;                     /* the angle given last */
    uint16_t pos, span;                /* sweep mode: gradians from start_angle; the sector's length */
    int64_t window_us;                 /* follow: the targets' windows' pings a pass, as last marked, us */
    uint32_t pass;                     /* follow: passes so far (turns, or one-way sector passes) */
    int64_t last_call;                 /* follow: the time of the call before, us */
    uint16_t prev;                     /* follow: the angle given before head */
    uint16_t k;                        /* follow: a grid beam is pinged every k-th pass (1: every pass) */
    uint16_t slow_q8;                  /* follow: beams' times over the model's, averaged, 1/256 (256..1024) */
    uint16_t travelled;                /* follow: gradians moved in the current turn */
    uint8_t ntargets;                  /* follow: targets read in the last call (at most SONAR_SCAN_MAX_TARGETS) */
    uint16_t window_left;              /* follow: window pings this pass may still take (its reserve) */
    int8_t dir;                        /* +1 / -1: the way the head is going */
    uint8_t started;
};

/* NULL when cfg is valid, else a static "field: rule" string naming the first bad field. cfg must not be NULL. */
const char *sonar_scan_config_check(const struct sonar_scan_config *cfg);

/* Copies cfg and starts the plan at start_angle, nothing yet visited. Returns SONAR_OK or SONAR_ERR_ARG. */
SONAR_CHECK int sonar_scan_init(struct sonar_scan *s, const struct sonar_scan_config *cfg);

/*
 * The angle (gradians 0..399, inside the sector) to ping next at now (us, monotonic; an earlier
 * value is taken as the last one), recorded as pinged then. Sweep mode: the driver's order;
 * targets unused (may be NULL). Follow mode: the head keeps going one way round a circle (to a
 * sector's end and back), travelling past what needs no ping and pinging (a) every target's window
 * (the step-spaced angles within its half-width, at most SONAR_SCAN_MAX_HALF, of its bearing) once
 * a pass, and (b) grid beam j (a plain sweep's beams) on every k-th pass, k the most that keeps a
 * grid angle within surveil_s with the targets' windows counted (k = 1 is a plain sweep), plus any
 * beam that would otherwise pass surveil_s before its turn. A pass is a turn of travel (2.4 s)
 * and its pings: that, not revisit_s, sets how often a target is looked at; looks later than
 * revisit_s are counted (late_looks). Targets past SONAR_SCAN_MAX_TARGETS or outside the sector
 * are counted and ignored. O(targets x window + the walk to the next ping) a call, 400 B of stack.
 */
uint16_t sonar_scan_next(struct sonar_scan *s, const struct sonar_scan_target *targets, unsigned n, int64_t now);

/* Modelled time in us from a ping at angle from to one at angle to: the travel (6 ms a gradian) and a ping. */
uint32_t sonar_scan_cost_us(const struct sonar_scan *s, uint16_t from, uint16_t to);

#endif
