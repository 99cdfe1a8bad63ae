/* detector.h -- per-sweep object detector: threshold, foreground runs, grouping, k-means, convex hulls; RAM: sizeof(struct sonar_detector) = 27 336 B, mostly 25 B a run (SONAR_MAX_RUNS) and 7 B a beam (SONAR_MAX_SWEEP_BEAMS; config.h). */
#ifndef SONAR_DETECTOR_H
#define SONAR_DETECTOR_H

#include <stdint.h>

#include "sonar/cfar.h"
#include "sonar/config.h"
#include "sonar/err.h"
#include "sonar/hull.h"
#include "sonar/kmeans.h"

/*
 * A beam's foreground cells above the threshold are stored as runs (contiguous samples of one
 * beam). At the end of a sweep, runs that touch (within join_beams beams and join_m metres of
 * range gap) form groups; groups smaller than min_points cells (track_points, when tracking is
 * on) are noise and dropped. Each remaining group (at most max_clusters, the largest first) seeds
 * one k-means centre at its centroid; a group wider than max_extent_m, when split_points is set,
 * seeds one centre per max_extent_m / 2 of its width (farthest-point), so that k-means can cut
 * objects joined by a faint bridge or lying on a wall, unless the group is a line (below: a wall or a
 * rope, never cut). Lloyd's iterations stay inside each group
 * (a wall's centre cannot take an object's runs). Each cluster becomes a detection when it has
 * >= min_points cells (>= track_points within track_m of a detection of the previous sweep) covering
 * >= min_area_m2 square metres and >= min_footprints of a point target's footprint at its range (the
 * sample's depth times the beam's width there: what the sonar resolves, which no echo is smaller than),
 * spans >= min_beams beams (and two or more where the sweep's step is at most half the beam's width:
 * the beams overlap there, so every reflector inside the sector lights two, and a cluster on one beam is
 * a fragment, the CFAR's cut end of a longer return or a speck), lies at >= min_range_m, is no longer
 * along the beam than max_aspect
 * times its width across, and, when cut from a wider group, has >= split_points cells. At most
 * max_clusters detections, the largest first. A cluster that passes every rule but is wider than
 * max_extent_m is structure (a wall, a rope): reported after the objects, kind SONAR_DET_STRUCTURE,
 * in the room they leave in the array (SONAR_MAX_CLUSTERS), and never an object.
 *
 * Threshold, SONAR_DET_GLOBAL: a cell is foreground when its value > T, T = max(min_threshold,
 * floor(mean + k std)) over the foreground cells of the previous sweep (the study's rule, one
 * sweep behind so it can be applied as beams arrive); when there is no previous sweep, or it had
 * no foreground at all (the background was still seeding), over the current sweep's cells seen so
 * far. SONAR_DET_CFAR: a cell is foreground when its value is > 0 and its block passes the
 * range-adaptive test of cfar.h (threshold_k and min_threshold are then unused, and the sweep's
 * reported threshold is the CFAR floor).
 */
enum sonar_det_threshold {
    SONAR_DET_GLOBAL = 0, /* mean + k std of the previous sweep (the study's) */
    SONAR_DET_CFAR = 1    /* order-statistic CFAR along each beam (cfar.h) */
};

/* Ranges of the config fields: sonar_detector_config_check and sonard's option table both use these. */
#define SONAR_DET_K_MAX 20            /* threshold_k 0..20 */
#define SONAR_DET_MIN_THRESHOLD_MAX 254
#define SONAR_DET_ITERATIONS_MAX 100
#define SONAR_DET_JOIN_BEAMS_MAX 8
#define SONAR_DET_JOIN_M_MAX 10       /* metres */
#define SONAR_DET_ANGLE_OFFSET_MAX 400 /* gradians, either sign */
#define SONAR_DET_DISTANCE_MAX 1000   /* max_extent_m and min_range_m, metres */
#define SONAR_DET_ASPECT_MIN 0.1      /* max_aspect: 0 (off) or 0.1..100 */
#define SONAR_DET_ASPECT_MAX 100
#define SONAR_DET_TRACK_M_MAX 100     /* metres */
#define SONAR_DET_AREA_MAX 100        /* min_area_m2: 0..100 square metres */
#define SONAR_DET_FOOTPRINTS_MAX 100  /* min_footprints: 0..100 */
/*
 * A line (a wall, a lane rope, a dock's edge): a group whose extent along each beam is at most
 * SONAR_DET_LINE_M on all but SONAR_DET_LINE_THICK_16 sixteenths of its beams (a person is 0.5-1 m
 * deep along the beam; a wall's return is the pulse and its roughness). A line wider than
 * max_extent_m is never cut by split_points: it is reported whole, as structure.
 */
#define SONAR_DET_LINE_M 0.3f
#define SONAR_DET_LINE_THICK_16 2
/*
 * A wall in one look: a line over at least SONAR_DET_WALL_BEAMS beams, at least SONAR_DET_WALL_M long,
 * at most SONAR_DET_WALL_THICK_M thick (its hull's least width) and SONAR_DET_WALL_ELONG times longer
 * than thick, is structure at any range in a single look, whatever max_extent_m (when that rule is on:
 * the study's rules have none). A wall returns the pulse smeared by the beam's vertical spread (0.1 to
 * 0.25 m on the RoboSub sweeps at 1-4 m); a person is a blob at least 0.3 m deep along the beam (never
 * this thin on the AquaScan pools), and a buoy is shorter. docs/decisions.md ("Walls, their echoes and
 * streaks in one look").
 */
#define SONAR_DET_WALL_BEAMS 3
#define SONAR_DET_WALL_M 0.6f
#define SONAR_DET_WALL_THICK_M 0.25f
#define SONAR_DET_WALL_ELONG 4.0
/*
 * Longer than any person or prop (SONAR_DET_WALL_LONG_M), two more shapes are walls. A wall seen
 * obliquely returns over a stretch of range in each beam (the beam's footprint along it), so its line is
 * thicker: SONAR_DET_WALL_LONG_ELONG times longer than thick is enough (people on the AquaScan pools are
 * never more than 6 times longer than thick, whatever their length). And a corner, two walls met, is no
 * line but is thin on every beam (SONAR_DET_LINE_M, as each beam meets one wall), as no person is.
 */
#define SONAR_DET_WALL_LONG_M 1.5f
#define SONAR_DET_WALL_LONG_ELONG 6.5
/*
 * A wall broken by its own gaps (a rough or oblique wall returns in patches): thin objects whose hulls
 * come within SONAR_DET_WALL_GAP_M of one another and whose union is still at most SONAR_DET_WALL_THICK_M
 * thick continue one line; a line of such pieces at least SONAR_DET_WALL_M long end to end is a wall,
 * each piece structure. A buoy before a wall is not thin with it (their union is as deep as the gap
 * between them); three buoys in a row within 0.5 m of one another would be (0.5 m: the gaps between a wall's
 * pieces on the RoboSub sweeps and the simulated tank; docs/decisions.md).
 */
#define SONAR_DET_WALL_GAP_M 0.5f

/*
 * The water's boundary in one look. In a tank, a pool or a harbour every beam's leading edge (the
 * first echo of its foreground at least half as strong as its strongest: edge.h) is the wall, until
 * the background has learnt it, where nothing nearer
 * overshadows it, and it runs on smoothly from beam to beam, obliquely or not. A cluster is that
 * wall, structure however thick the beam makes it or short the sector cuts it, when:
 *  - it holds the leading edge (within the pulse, or starting up to SONAR_DET_EDGE_JUMP_M behind it,
 *    where the CFAR cut an oblique wall's slowly rising return) on SONAR_DET_EDGE_16 sixteenths of its
 *    beams that nothing nearer hides;
 *  - it is no deeper on a beam than a line (SONAR_DET_LINE_M) plus what the edge's range changes across
 *    the beam's width there, but on SONAR_DET_LINE_THICK_16 sixteenths of its beams (a person is as deep
 *    as the body, whatever the slope);
 *  - and beside it the edge runs on along its slope (at first the slope over the cluster's last
 *    SONAR_DET_EDGE_BEAMS beams on that side: a straight wall's range bends along the sweep), each beam
 *    within SONAR_DET_EDGE_JUMP_M of where the last two point and at least half as strong as the cluster,
 *    for SONAR_DET_WALL_M over SONAR_DET_EDGE_BEAMS beams or more on one side (behind something nearer,
 *    at most SONAR_DET_EDGE_HIDE_M across at the wall's range, it is looked for where it comes out; a beam
 *    left out, a streak, is bridged, and so are up to SONAR_DET_EDGE_FADED beams in a row where the line
 *    is in place but fainter than half: speckle, the wall's aspect; a point target's side lobes fade on
 *    both its sides and nothing as strong follows); or the sector's end cuts it on one side and on the
 *    other it ends there too or behind something nearer, SONAR_DET_WALL_M longer than a point target's
 *    smear with what runs on.
 * A person or a buoy takes the edge over on its own beams a body's depth or more before the wall (a
 * 0.2 m buoy 0.6 m before it: 0.6 m): the edge jumps back on both its sides, or beside it the water is
 * open. Something touching the wall is one with it in a single look. docs/decisions.md ("The water's
 * boundary").
 */
#define SONAR_DET_EDGE_16 8
#define SONAR_DET_EDGE_BEAMS 3
#define SONAR_DET_EDGE_JUMP_M 0.15f
#define SONAR_DET_EDGE_FADED 2
#define SONAR_DET_EDGE_HIDE_M 1.0f /* a wall runs on behind something nearer at most this wide (a person, a prop) */

/*
 * The tail of a return. Along a beam a strong echo does not end where it is strongest: the pulse, an
 * oblique wall's spread across the beam's width and the CFAR's window across beams (a neighbour's echo
 * lights the block) leave faint cells behind it. A cluster whose every run lies behind its beam's
 * leading edge (more than SONAR_DET_EDGE_JUMP_M) but within a line's depth of it (SONAR_DET_LINE_M
 * more), and whose cells average less than 1/SONAR_DET_TAIL_X of the weakest of those beams' strongest
 * levels, is that return's tail: not an object. A person behind a rope or a buoy is as strong as they
 * are, or stands farther back; a faint swimmer far behind near clutter is beyond a line's depth.
 */
#define SONAR_DET_TAIL_X 8

struct sonar_detector_config {
    uint8_t threshold_mode; /* enum sonar_det_threshold */
    struct sonar_cfar_config cfar; /* SONAR_DET_CFAR's test */
    float threshold_k;     /* k of mean + k std, 0..20 */
    uint8_t min_threshold; /* floor of T, 0..254 */
    uint8_t max_clusters;  /* 1..SONAR_MAX_CLUSTERS */
    uint8_t iterations;    /* Lloyd rounds at most, 1..100 */
    uint8_t join_beams;    /* beams apart that may still join a group, 1..8 */
    uint16_t min_points;   /* cells a detection needs, 1..65535 */
    float join_m;          /* range gap bridged inside a group, metres, 0..10 */
    float angle_offset;    /* gradians added to every angle of the output frame, -400..400 */
    uint8_t min_beams;     /* beams a detection must span, 0..255 (0 or 1: any) */
    float max_extent_m;    /* detections wider than this (hull diameter, metres) are structure; 0 = no limit */
    uint16_t split_points; /* cells a piece cut from a group wider than max_extent_m needs; 0 = never cut */
    float min_range_m;     /* detections nearer than this (centroid, metres, 0..1000) are dropped: the
                              transducer's ring-down and its mount; 0 = none */
    float max_aspect;      /* length along the beam / width across, 0 or 0.1..100; 0 = no limit */
    float track_m;         /* gate to the previous sweep's detections, metres, 0..100; 0 = no tracking */
    uint16_t track_points; /* cells a cluster inside the gate needs (used when < min_points) */
    float min_area_m2;     /* square metres its cells must cover (each r x step x range/n at its range: the
                              same at every range, unlike a cell count), 0..100; 0 = no such rule */
    float min_footprints;  /* point-target footprints its cells must cover at its range (each range/n deep
                              and SONAR_BEAM_WIDTH_DEG wide there: the sonar's resolution), 0..100; 0 = none */
};

/*
 * What a detection is: an object; structure (a wall or rope, wider than any object; a place learnt as
 * structure, structure.h), never an object; or an object that has stood where it is since the first
 * look (structure.h): with no survey of the site it cannot be told from the site's own structure, so
 * it stays an object and says so.
 */
enum sonar_det_kind {
    SONAR_DET_OBJECT = 0,
    SONAR_DET_STRUCTURE = 1,
    SONAR_DET_STATIC_START = 2,
    SONAR_DET_WALL_ECHO = 3 /* a wall's echo: behind a wall on its beams and weaker than it (below) */
};

/*
 * A wall's echo: a cluster with at least SONAR_DET_ECHO_16 sixteenths of its cells beyond the far
 * edge of a wall (a detection of this sweep that is structure) on the same beams, and weaker than that
 * wall (its mean level below the wall's). A wall of a pool, a tank or a quay is opaque to the sonar:
 * nothing in the water lies behind it, and what shows there is the wall's own sound come back late
 * (the beam's vertical spread and the floor's corner just behind it; the round trips between the wall
 * and the vehicle at twice and three times its range), every path longer and with one reflection more
 * than the wall's, so weaker. An echo there stronger than the wall is not the wall's (a rope taken for
 * a wall, a person beyond it): it stays an object. Reported after the objects with structure, never
 * tracked. docs/decisions.md ("Walls, their echoes and streaks in one look").
 */
#define SONAR_DET_ECHO_16 12
#define SONAR_DET_ECHO_BEAMS 2 /* an echo spreads over the beam's width: a wall this many beams aside counts */

/* Is a detection of this kind an object the tracker follows (an object, or one static since start)? */
static inline int sonar_det_kind_tracked(int kind)
{
    return kind == SONAR_DET_OBJECT || kind == SONAR_DET_STATIC_START;
}

/* "object", "structure", "static since start", "wall echo" (enum sonar_det_kind), or "?". */
const char *sonar_det_kind_str(int kind);

/* One object, in the sonar frame (see geometry.h) after the angle offset. */
struct sonar_detection {
    int64_t utime;          /* us since the epoch when it was seen: its cells' beam times, cell-weighted */
    float x_m, y_m;         /* centroid of its cells, metres */
    float range_m;          /* hypot(x, y) */
    float bearing_deg;      /* atan2(y, x), [0, 360) */
    float area_m2;          /* area of the hull */
    float mean_intensity;   /* mean foreground level of its cells, 0..255 */
    uint32_t points;        /* cells */
    uint8_t kind;           /* enum sonar_det_kind */
    uint8_t hull_count;     /* vertices, counter-clockwise; longer hulls are thinned evenly */
    float hull_x[SONAR_MAX_HULL];
    float hull_y[SONAR_MAX_HULL];
};

struct sonar_detections {
    uint32_t sweep;        /* sweep number */
    int64_t utime;         /* us since the epoch of the sweep's last beam */
    uint16_t beams;        /* beams in the sweep */
    uint16_t runs;         /* foreground runs kept */
    uint32_t runs_dropped; /* runs beyond SONAR_MAX_RUNS */
    uint16_t groups;       /* groups big enough to seed a centre, before clustering */
    uint8_t threshold;     /* T used for the sweep's last beam */
    uint8_t count;         /* detections, largest first */
    uint8_t world;         /* 1: every detection had a pose and the sweep was tracked in the world frame */
    struct sonar_detection det[SONAR_MAX_CLUSTERS];
};

struct sonar_detector_run {
    uint16_t beam;   /* index of the beam in the sweep */
    uint16_t start;  /* first sample */
    uint16_t parent; /* union-find link; roots are the lowest index of their group */
    uint16_t size;   /* at a root: cells of the group (saturating) */
    uint32_t sum;    /* sum of foreground levels */
};

struct sonar_detector {
    struct sonar_detector_config cfg;
    struct sonar_point pts[SONAR_MAX_RUNS]; /* run centre in mm; w = run length in cells */
    struct sonar_detector_run runs[SONAR_MAX_RUNS];
    uint8_t labels[SONAR_MAX_RUNS];
    uint16_t angles[SONAR_MAX_SWEEP_BEAMS];
    uint64_t sum, sumsq, cells;
    float prev_mean, prev_std;
    float range_m;
    uint32_t range_mm; /* range_m in mm, rounded: the polar conversions' scale */
    int64_t utime;
    int64_t t0;                                 /* utime of the sweep's first beam */
    uint16_t dt_ms[SONAR_MAX_SWEEP_BEAMS];      /* each beam's time after t0, ms (saturating at 65.5 s) */
    uint16_t edge[SONAR_MAX_SWEEP_BEAMS];       /* each beam's leading edge, sample (sonar_detector_set_edge) ... */
    uint8_t top[SONAR_MAX_SWEEP_BEAMS];         /* ... and its strongest level */
    uint32_t sweep;
    uint32_t runs_dropped;
    uint16_t nruns, beams, n;
    uint8_t have_prev, threshold;
    uint8_t ntracks;                                /* where objects are expected: the previous sweep's */
    struct sonar_xy tracks[SONAR_MAX_CLUSTERS]; /* detections, or sonar_detector_set_tracks'; mm, device frame */
};

/*
 * Checks every field against the ranges above. Returns NULL when cfg is valid, else a static
 * string naming the first bad field and its rule, e.g. "join_beams: 1..8". cfg must not be NULL.
 */
const char *sonar_detector_config_check(const struct sonar_detector_config *cfg);

/* Validates cfg (copied, see sonar_detector_config_check) and starts sweep 0. Returns SONAR_OK or SONAR_ERR_ARG. */
SONAR_CHECK int sonar_detector_init(struct sonar_detector *d, const struct sonar_detector_config *cfg);

/*
 * Adds one foreground beam of n samples (1..SONAR_MAX_SAMPLES) over range_m metres (0 <
 * range_m <= SONAR_DET_DISTANCE_MAX: the run centres are mm within SONAR_KMEANS_MAX_COORD) at angle
 * gradians (0..399). Every beam of a sweep must have the same n and range_m (else
 * SONAR_ERR_STATE: end the sweep first). Returns SONAR_OK, SONAR_ERR_FULL when the sweep already
 * has SONAR_MAX_SWEEP_BEAMS beams, or SONAR_ERR_ARG.
 */
SONAR_CHECK int sonar_detector_add(struct sonar_detector *d, uint16_t angle, const uint8_t *fg, uint16_t n,
                                   float range_m, int64_t utime);

/*
 * sonar_detector_add with the blocks decided by the caller (sonar_cfar_blocks_across over
 * neighbouring beams, say): the runs are the nonzero cells of the blocks with on[b] set (on: (n + 7)
 * / 8 bytes, SONAR_CFAR_BLOCK samples a block); no threshold is computed. Same returns.
 */
SONAR_CHECK int sonar_detector_add_blocks(struct sonar_detector *d, uint16_t angle, const uint8_t *fg, const uint8_t *on,
                                          uint16_t n, float range_m, int64_t utime);

/*
 * The leading edge (edge.h: sonar_edge_leading, of the foreground the detector was given) of
 * the beam last added, as a sample of it (n or more for none, also what a beam added without it
 * holds), and the beam's strongest level beyond the ring-down (top, 0..255). A cluster holding the leading edge of its beams, which runs on smoothly across
 * SONAR_DET_EDGE_BEAMS beams beside it, is the water's boundary: structure (SONAR_DET_EDGE_JUMP_M).
 * Call it right after a sonar_detector_add or _add_blocks that returned SONAR_OK.
 */
void sonar_detector_set_edge(struct sonar_detector *d, uint16_t sample, uint8_t top);

/* Ends the sweep: fills *out and starts the next sweep. Returns the detection count or SONAR_ERR_ARG. */
SONAR_CHECK int sonar_detector_end(struct sonar_detector *d, struct sonar_detections *out);

/* Replaces the rules between sweeps (call it right after sonar_detector_end); the previous sweep's
 * threshold statistics and tracks are kept. Returns SONAR_OK or SONAR_ERR_ARG (nothing changed). */
SONAR_CHECK int sonar_detector_set_config(struct sonar_detector *d, const struct sonar_detector_config *cfg);

/*
 * Replaces where the next sweep's objects are expected (the track_m gate), by default the previous
 * sweep's detections: n <= SONAR_MAX_CLUSTERS positions in metres in the output frame (after
 * angle_offset), e.g. a tracker's predictions; more are ignored. Returns SONAR_OK or SONAR_ERR_ARG.
 */
SONAR_CHECK int sonar_detector_set_tracks(struct sonar_detector *d, const float *x_m, const float *y_m, uint8_t n);

/*
 * The sweep's beams in arrival order, for callers that place them (pipeline_tracks.c): how many the
 * open sweep holds; their angles (gradians, read-only; after sonar_detector_end, the ended sweep's,
 * out->beams of them, until the next sonar_detector_push); beam i's time and the first beam's (us
 * since the epoch; i below the count); the latest beam's time.
 */
uint16_t sonar_detector_beams(const struct sonar_detector *d);
const uint16_t *sonar_detector_angles(const struct sonar_detector *d);
int64_t sonar_detector_beam_utime(const struct sonar_detector *d, uint16_t i);
int64_t sonar_detector_t0(const struct sonar_detector *d);
int64_t sonar_detector_utime(const struct sonar_detector *d);

#endif
