/* detector_internal.h -- the detector's stages, shared by its files (runs, linking, grouping and cutting, rules and emission); not a public header. */
#ifndef SONAR_DETECTOR_INTERNAL_H
#define SONAR_DETECTOR_INTERNAL_H

#include "sonar/detector.h"
#include "sonar/frame.h"
#include "sonar/geometry.h"

/* Sample position twice_pos halves (2i+1: the centre of sample i) at angle a (gradians) in mm, device frame. */
struct sonar_xy sonar_det_polar_mm(const struct sonar_detector *d, uint16_t a, uint32_t twice_pos);

/* Union-find root of run i (path halving). */
uint16_t sonar_det_find(struct sonar_detector_run *r, uint16_t i);

/* Stage 2, detector_join.c: unites touching runs (join_beams, join_m), across the start angle on a full turn. */
void sonar_det_join(struct sonar_detector *d);

/*
 * Stage 3, detector_group.c: groups -> k centres c, part[j] = the group of centre j, labels = each
 * run's centre; groups wider than max_extent_m get extra farthest-point centres. Returns k.
 */
uint8_t sonar_det_seed(struct sonar_detector *d, struct sonar_xy *c, uint8_t *part, uint16_t *groups);

/* What the rules need of a cluster: its cells, centroid sums (mm x cells), beams and sample span. */
struct sonar_det_cluster {
    uint64_t w;
    int64_t sx, sy;
    uint64_t rw;      /* sum over its runs of cells x (2 start + cells): twice its cells' range sum, samples */
    uint32_t rlo, rhi;
    uint16_t nbeams, beam; /* beam: its last run's, 0xFFFF for none */
    uint16_t blo, bhi;     /* its cells' first and last sample on that beam */
    uint16_t thick;        /* beams on which it is deeper than SONAR_DET_LINE_M (detector.h) */
    uint16_t first, last;  /* its runs' lowest and highest index */
};

/* A line's depth along a beam at most (SONAR_DET_LINE_M), in samples of this sweep. */
static inline uint32_t sonar_det_line_samples(const struct sonar_detector *d)
{
    return (uint32_t)((double)SONAR_DET_LINE_M * (double)d->n / (double)d->range_m) + 1u;
}

/* A line: thin on all but SONAR_DET_LINE_THICK_16 sixteenths of its beams (an object on it is a bulge). */
static inline int sonar_det_thin(uint32_t thick, uint32_t beams)
{
    return 16u * thick <= (uint32_t)SONAR_DET_LINE_THICK_16 * beams;
}

/* The sweep's step between beams, gradians (1 for a sweep of one beam, or a first gap of none). */
static inline uint16_t sonar_det_step(const struct sonar_detector *d)
{
    uint16_t step = d->beams > 1u ? sonar_frame_gap(d->angles[0], d->angles[1]) : 1u;
    return step ? step : 1u;
}

/*
 * How wide a point target at range_mm looks across the beams, mm: the beam's width and the sweep's step
 * (a target is seen on every beam whose half-power width reaches it). A wall must be longer than this
 * by its own length: a post far away, smeared over three beams, is not a line.
 */
static inline double sonar_det_smear_mm(const struct sonar_detector *d, double range_mm)
{
    return range_mm * (SONAR_BEAM_WIDTH_DEG * SONAR_RAD_PER_DEG + sonar_frame_rad((double)sonar_det_step(d)));
}

/* Stage 4, detector_accept.c: cl[j] for the k clusters (labels 0..k-1), in one pass over the runs. */
void sonar_det_clusters(const struct sonar_detector *d, uint8_t k, struct sonar_det_cluster *cl);

/*
 * Stage 4: cluster j (cl from sonar_det_clusters) -> detection *o and its device-frame centroid
 * *at (mm), when it passes every rule (cut: it is a piece of a wider group); only then are its runs
 * read again, for the hull and the detection. Returns 1 (an object), 2 (it passes every rule but is
 * wider than max_extent_m: structure, o->kind says so), or 0.
 */
int sonar_det_accept(const struct sonar_detector *d, uint8_t j, const struct sonar_det_cluster *cl, int cut,
                     struct sonar_detection *o, struct sonar_xy *at);

/*
 * Stage 4, detector_edge.c: does cluster j (cl from sonar_det_clusters) hold the leading edge of its
 * beams, the edge running on smoothly beside it (detector.h, SONAR_DET_EDGE_JUMP_M)? One pass over its runs.
 */
int sonar_det_on_edge(const struct sonar_detector *d, uint8_t j, const struct sonar_det_cluster *cl);

/*
 * Stage 4, detector_edge.c: is cluster j only the tail of the return in front of it (detector.h,
 * SONAR_DET_TAIL_X)? Every run of it behind its beam's leading edge, within a line's depth of it, and its
 * cells' mean below 1/SONAR_DET_TAIL_X of the weakest of those beams' strongest levels. One pass over its runs.
 */
int sonar_det_in_tail(const struct sonar_detector *d, uint8_t j, const struct sonar_det_cluster *cl);

/*
 * Stage 5, detector_wall.c: of the n objects det (hulls in metres), sets wall[i] for each that is a
 * piece of a wall (detector.h, SONAR_DET_WALL_GAP_M): thin, continued by other thin pieces into one
 * line at least SONAR_DET_WALL_M longer than a point target's smear at its range (smear_per_m: the
 * smear a metre of range, sonar_det_smear_mm(d, 1000) / 1000), or continuing one of the nw walls found.
 */
void sonar_det_wall_pieces(const struct sonar_detection *det, uint8_t n, const struct sonar_detection *const *walls,
                           uint8_t nw, double smear_per_m, uint8_t *wall);

/*
 * Stage 5, detector_echo.c: which objects are a wall's echo (detector.h, SONAR_DET_ECHO_16). walls:
 * the labels of the nw clusters accepted as structure, wall_level their mean levels; objs: the labels of
 * the no objects, obj_level theirs. Sets echo[i] (0 or 1) for each object i and
 * wall_echo[w] for each wall w (one behind a nearer, stronger wall). One pass over the runs, each
 * looking at the runs of the beams beside it.
 */
void sonar_det_echoes(struct sonar_detector *d, const uint8_t *walls, const float *wall_level, uint8_t nw,
                      const uint8_t *objs, const float *obj_level, uint8_t no, uint8_t *echo, uint8_t *wall_echo);

/*
 * Squared distance in mm^2 between points within SONAR_KMEANS_MAX_COORD (run centres at ranges up
 * to SONAR_DET_DISTANCE_MAX, their means, and the tracks set_tracks keeps): a difference fits an
 * int32, so each square is one 32 x 32 -> 64 multiply on a Cortex-M.
 */
static inline int64_t sonar_det_dist2_mm(int32_t ax, int32_t ay, int32_t bx, int32_t by)
{
    int32_t dx = ax - bx, dy = ay - by;
    return (int64_t)dx * dx + (int64_t)dy * dy;
}

#endif
