/* background.h -- per-angle (or per-range) approximate running median of the echo, subtracted and clamped at 0; RAM: sizeof(struct sonar_background) = 481 632 B at the default limits, SONAR_MAX_ANGLES + 1 rows of SONAR_MAX_SAMPLES + 1 B. */
#ifndef SONAR_BACKGROUND_H
#define SONAR_BACKGROUND_H

#include <stdint.h>

#include "sonar/config.h"
#include "sonar/err.h"

enum sonar_background_mode {
    SONAR_BACKGROUND_OFF = 0,       /* foreground = input */
    SONAR_BACKGROUND_PER_ANGLE = 1, /* one model per (angle, range) cell, updated once per visit */
    SONAR_BACKGROUND_RANGE = 2,     /* the study's: one model per range bin, across the beams */
    SONAR_BACKGROUND_AUTO = 3       /* per-angle, with the across-beam model where a row is still warming up
                                       and under tracked objects (sonar_background_apply_keep) */
};

/*
 * Model of each cell b (uint8): the first `warmup` observations are averaged (b += (x - b) / v,
 * rounded, so the first observation seeds it), then b moves `step` levels toward every new
 * observation (McFarlane-Schofield / Frugal-1U), which converges on the median. While a cell is
 * being seeded it reports no foreground. In per-angle mode
 * a cell is observed once per sweep; in range mode once per beam.
 *
 * Sonar speckle is multiplicative (a Rayleigh echo's spread grows with its mean), so a bright
 * static echo such as a wall fluctuates by tens of levels around its median. margin > 0 makes the
 * subtraction a contrast test, x must exceed b by b * margin / 16 before anything is left (a
 * constant-false-alarm-rate rule); margin = 0 is the study's plain subtraction.
 */
#define SONAR_BG_WARMUP_MAX 64 /* warmup 1..64 */
#define SONAR_BG_STEP_MAX 64   /* step 1..64 */
#define SONAR_BG_MARGIN_MAX 64 /* margin 0..64 */

/*
 * Auto mode keeps both models: the per-angle one, and beside it the across-beam one (one row, every
 * beam observes it, seeded over SONAR_BG_ACROSS_WARMUP beams). A row still being seeded is compared
 * with the across-beam model instead of reporting nothing, so objects there from the first ping are
 * found in the first sweep; a seeded row is compared with the larger of the two models (two looks
 * know the water worse than every beam does). Under a tracked object (the keep spans the caller
 * passes, from its tracks) the row takes the across-beam model's level at its first comparison
 * (what the warm-up learnt there was the object) and keeps its value while it is kept: an object
 * that stands still is never learnt, static structure elsewhere still is, and when the object
 * leaves, its place holds the water's level, not its echo.
 */
#define SONAR_BG_ACROSS_WARMUP 8

/* Samples [lo, hi) of a beam: a tracked object's extent along it. */
struct sonar_bg_span {
    uint16_t lo, hi;
};

struct sonar_background_config {
    uint8_t mode;   /* enum sonar_background_mode */
    uint8_t warmup; /* observations averaged to seed a cell, 1..64 */
    uint8_t step;   /* levels per observation after warm-up, 1..64 */
    uint8_t margin; /* contrast margin in 16ths of b, 0..64: fg = max(0, x - b - b * margin / 16) */
};

/*
 * The world frame (a moving sonar, per-angle mode with a pose): the same bytes become a square
 * grid fixed in the world (local NED) of SONAR_BG_GRID two-byte cells a side (the model, 0 =
 * never seen, and its observations), centred on the sonar and scrolling with it as a torus
 * (cells that scroll in are cleared), spanning SONAR_BG_WINDOW ranges: what the vehicle saw
 * half a range behind it is still there when it comes back. A cell is seeded and then follows
 * the same warm-up and step rules as a per-angle one, once per beam whose footprint covers it
 * (the wedge back to the beam before, width_deg), at the range sample over it. A sample is
 * compared with the largest model on the arc of SONAR_BG_LOOK_DEG about its beam, +-
 * SONAR_BG_SLACK_M in range, and with a range profile that every beam updates (the ring-down's
 * tail and the gain curve move with the sonar); it has no foreground while the cell under it
 * was seen fewer than SONAR_BG_MIN_SEEN times. At 400 x 1200: 489 x 489 cells, 9.3 cm at 15 m,
 * 31 cm at 50 m.
 */
#define SONAR_BG_WINDOW 3        /* the grid's side, in ranges */
#define SONAR_BG_LOOK_DEG 4.0    /* the arc a sample is compared over, degrees (the beam is ~2) */
#define SONAR_BG_SLACK_M 0.45f   /* +- range slack of that comparison, metres (at least one cell) */
#define SONAR_BG_MIN_SEEN 3      /* observations before a cell can report foreground */
#define SONAR_BG_GRID_CELLS ((uint32_t)SONAR_MAX_ANGLES * SONAR_MAX_SAMPLES) /* bytes shared with the per-angle model */

struct sonar_bg_ray {
    double north_m, east_m; /* the sonar's position at the beam, local NED, metres (|x| <= 10^6) */
    double bearing_deg;     /* the beam's heading in the world, degrees clockwise from north */
    double width_deg;       /* the beam's share of the scan, degrees (clamped to 0.5..90) */
    float range_m;          /* metres covered by the n samples, (0, 1000] */
    float near_m;           /* samples nearer (ring-down, the mount) are neither modelled nor foreground, >= 0 */
};

struct sonar_background {
    uint8_t cell[SONAR_MAX_ANGLES][SONAR_MAX_SAMPLES];
    uint8_t across[SONAR_MAX_SAMPLES]; /* auto mode: the across-beam model */
    uint8_t visits[SONAR_MAX_ANGLES]; /* observations so far per row, saturating at 255 */
    uint8_t across_visits;            /* observations of across, saturating at 255 */
    uint16_t n;                       /* samples per beam the model holds; 0 = empty */
    uint8_t mode;
    uint8_t warmup;
    uint8_t step;
    uint8_t margin;
    uint8_t world;                    /* 1: cell holds the world grid (sonar_background_apply_world) */
    uint16_t grid;                    /* cells a side */
    float cell_m;                     /* grid cell size, metres */
    float grid_range_m;               /* the range the grid was sized for */
    int32_t wi0, wj0;                 /* world cell index (north, east) of the window's first row, column */
    uint32_t reframes;                /* switches between the per-angle model and the grid (each starts afresh) */
};

/* NULL when cfg is valid, else a static "field: rule" string naming the first bad field. cfg must not be NULL. */
const char *sonar_background_config_check(const struct sonar_background_config *cfg);

/* Validates cfg (copied) and empties the model. Returns SONAR_OK or SONAR_ERR_ARG. */
SONAR_CHECK int sonar_background_init(struct sonar_background *bg, const struct sonar_background_config *cfg);

/* Changes step and margin in place, keeping the model; a new mode or warmup needs init (a fresh
 * model). Returns SONAR_OK or SONAR_ERR_ARG (nothing changed). */
SONAR_CHECK int sonar_background_tune(struct sonar_background *bg, const struct sonar_background_config *cfg);

/* Forgets every cell (e.g. after the range or sample count changed). */
void sonar_background_reset(struct sonar_background *bg);

/*
 * fg[i] = max(0, in[i] - b[i] - b[i] * margin / 16) using the model before this observation, then updates the model.
 * angle: gradians 0..399; n: 1..SONAR_MAX_SAMPLES. A different n than the model holds resets the
 * model first. in and fg may be the same buffer (the pipeline works in place), but not otherwise
 * overlap. Returns SONAR_OK or SONAR_ERR_ARG.
 */
SONAR_CHECK int sonar_background_apply(struct sonar_background *bg, uint16_t angle, const uint8_t *in, uint8_t *fg,
                                       uint16_t n);

/*
 * Whether the row of angle (gradians 0..399) is still being seeded: its next beam's foreground will
 * be the across-beam model's (auto mode) or none (per-angle). 0 in range and off modes and for the
 * world grid.
 */
int sonar_background_seeding(const struct sonar_background *bg, uint16_t angle);


/*
 * sonar_background_apply with the spans of the beam that lie under tracked objects (nkeep of them,
 * keep may be NULL when 0): in auto mode those samples are compared with the across-beam model and
 * their row takes its values (above); other modes ignore them. Returns as sonar_background_apply
 * (SONAR_ERR_ARG also for a span with lo > hi; spans beyond n are clipped).
 */
SONAR_CHECK int sonar_background_apply_keep(struct sonar_background *bg, uint16_t angle, const uint8_t *in, uint8_t *fg,
                                            uint16_t n, const struct sonar_bg_span *keep, uint8_t nkeep);

/*
 * Whether the model has learnt the row of angle (gradians 0..399) past its warm-up, so that what
 * stands out there now came in after the first looks: 1 once its row has been compared with itself
 * (per-angle and auto mode, body frame); 0 while it is seeding or was just seeded, and in other
 * modes and the world grid (no per-angle rows).
 */
int sonar_background_learnt(const struct sonar_background *bg, uint16_t angle);

/*
 * sonar_background_apply_keep with spans to learn at once as well (nlearn of them, learn may be NULL
 * when 0): in per-angle and auto mode, a seeded row's cells under them first rise to the observation
 * where it is brighter (so this look has no foreground there), then the row observes it as usual:
 * structure (a track that never moved, tracker.h) stops standing out at once instead of after a
 * hundred one-level steps. Other modes and seeding rows ignore them.
 * Same returns (SONAR_ERR_ARG also for a learn span with lo > hi).
 */
SONAR_CHECK int sonar_background_apply_spans(struct sonar_background *bg, uint16_t angle, const uint8_t *in, uint8_t *fg,
                                             uint16_t n, const struct sonar_bg_span *keep, uint8_t nkeep,
                                             const struct sonar_bg_span *learn, uint8_t nlearn);

/*
 * The world-frame form of sonar_background_apply for per-angle mode (other modes: as
 * sonar_background_apply, the ray's angle being unused): fg[i] from the grid cell under sample i
 * (0 while that cell was never seen, and inside near_m), then the beam's footprint updates the
 * grid (in and fg may be the same buffer). The first call after per-angle use (or the reverse) starts a fresh model, counted in
 * reframes; so does a new n or range. Returns SONAR_OK or SONAR_ERR_ARG (NULL, n outside
 * 1..SONAR_MAX_SAMPLES, a non-finite or out-of-range field of ray; nothing changed).
 */
SONAR_CHECK int sonar_background_apply_world(struct sonar_background *bg, const struct sonar_bg_ray *ray,
                                             const uint8_t *in, uint8_t *fg, uint16_t n);

/* A tracked object in the world frame whose grid cells are not learnt: its centre and radius, metres. */
struct sonar_bg_disc {
    float north_m, east_m, radius_m;
};

#define SONAR_BG_DISCS_MAX 32 /* discs a beam looks at, at most */

/*
 * sonar_background_apply_world with discs (nkeep of them, keep may be NULL when 0) whose cells the
 * beam does not learn: tracked objects, which stay foreground however long they stand still. Same
 * returns (SONAR_ERR_ARG also for keep NULL with nkeep > 0).
 */
SONAR_CHECK int sonar_background_apply_world_keep(struct sonar_background *bg, const struct sonar_bg_ray *ray,
                                                  const uint8_t *in, uint8_t *fg, uint16_t n,
                                                  const struct sonar_bg_disc *keep, uint8_t nkeep);

/*
 * Reads the world grid at (north_m, east_m): *model (0 = never seen) and *seen (observations,
 * saturating at 255). Returns 1, or 0 when the grid is not in use or the point lies outside its
 * window (both then 0). For maps and for checking what the grid learnt.
 */
int sonar_background_world_at(const struct sonar_background *bg, double north_m, double east_m, uint8_t *model,
                              uint8_t *seen);

#endif
