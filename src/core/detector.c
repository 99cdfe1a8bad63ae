/* detector.c -- the detector's config and sweep orchestration: runs (detector_runs.c) -> joined runs (detector_join.c) -> groups and k-means (detector_group.c) -> rules and hulls (detector_accept.c); no heap. */
#include "sonar/detector.h"

#include <math.h>
#include <string.h>

#include "detector_internal.h"


const char *sonar_detector_config_check(const struct sonar_detector_config *cfg)
{
    const struct sonar_detector_config *c = cfg;
    if (c->threshold_mode > SONAR_DET_CFAR)
        return "threshold_mode: global or cfar";
    if (c->threshold_mode == SONAR_DET_CFAR && sonar_cfar_config_check(&c->cfar) != NULL)
        return sonar_cfar_config_check(&c->cfar);
    if (!(c->threshold_k >= 0.0f && c->threshold_k <= (float)SONAR_DET_K_MAX))
        return "threshold_k: 0.." SONAR_STR(SONAR_DET_K_MAX);
    if (c->min_threshold > SONAR_DET_MIN_THRESHOLD_MAX)
        return "min_threshold: 0.." SONAR_STR(SONAR_DET_MIN_THRESHOLD_MAX);
    if (c->max_clusters < 1 || c->max_clusters > SONAR_MAX_CLUSTERS)
        return "max_clusters: 1..SONAR_MAX_CLUSTERS (" SONAR_STR(SONAR_MAX_CLUSTERS) ")";
    if (c->iterations < 1 || c->iterations > SONAR_DET_ITERATIONS_MAX)
        return "iterations: 1.." SONAR_STR(SONAR_DET_ITERATIONS_MAX);
    if (c->join_beams < 1 || c->join_beams > SONAR_DET_JOIN_BEAMS_MAX)
        return "join_beams: 1.." SONAR_STR(SONAR_DET_JOIN_BEAMS_MAX);
    if (c->min_points < 1)
        return "min_points: 1..65535";
    if (!(c->join_m >= 0.0f && c->join_m <= (float)SONAR_DET_JOIN_M_MAX))
        return "join_m: 0.." SONAR_STR(SONAR_DET_JOIN_M_MAX) " metres";
    if (!(c->angle_offset >= -(float)SONAR_DET_ANGLE_OFFSET_MAX && c->angle_offset <= (float)SONAR_DET_ANGLE_OFFSET_MAX))
        return "angle_offset: -" SONAR_STR(SONAR_DET_ANGLE_OFFSET_MAX) ".." SONAR_STR(SONAR_DET_ANGLE_OFFSET_MAX) " gradians";
    if (!(c->min_area_m2 >= 0.0f && c->min_area_m2 <= (float)SONAR_DET_AREA_MAX))
        return "min_area_m2: 0.." SONAR_STR(SONAR_DET_AREA_MAX) " square metres";
    if (!(c->min_footprints >= 0.0f && c->min_footprints <= (float)SONAR_DET_FOOTPRINTS_MAX))
        return "min_footprints: 0.." SONAR_STR(SONAR_DET_FOOTPRINTS_MAX) " footprints";
    if (!(c->max_extent_m >= 0.0f && c->max_extent_m <= (float)SONAR_DET_DISTANCE_MAX))
        return "max_extent_m: 0.." SONAR_STR(SONAR_DET_DISTANCE_MAX) " metres";
    if (!(c->min_range_m >= 0.0f && c->min_range_m <= (float)SONAR_DET_DISTANCE_MAX))
        return "min_range_m: 0.." SONAR_STR(SONAR_DET_DISTANCE_MAX) " metres";
    if (!(c->max_aspect == 0.0f ||
          (c->max_aspect >= (float)SONAR_DET_ASPECT_MIN && c->max_aspect <= (float)SONAR_DET_ASPECT_MAX)))
        return "max_aspect: 0 (no limit) or " SONAR_STR(SONAR_DET_ASPECT_MIN) ".." SONAR_STR(SONAR_DET_ASPECT_MAX);
    if (!(c->track_m >= 0.0f && c->track_m <= (float)SONAR_DET_TRACK_M_MAX))
        return "track_m: 0.." SONAR_STR(SONAR_DET_TRACK_M_MAX) " metres";
    if (c->track_m > 0.0f && c->track_points < 1)
        return "track_points: 1..65535 when track_m is set";
    return NULL;
}

int sonar_detector_init(struct sonar_detector *d, const struct sonar_detector_config *cfg)
{
    if (d == NULL || cfg == NULL || sonar_detector_config_check(cfg) != NULL)
        return SONAR_ERR_ARG;
    memset(d, 0, sizeof(*d));
    d->cfg = *cfg;
    return SONAR_OK;
}

int sonar_detector_set_config(struct sonar_detector *d, const struct sonar_detector_config *cfg)
{
    if (d == NULL || cfg == NULL || sonar_detector_config_check(cfg) != NULL)
        return SONAR_ERR_ARG;
    d->cfg = *cfg;
    return SONAR_OK;
}

int sonar_detector_set_tracks(struct sonar_detector *d, const float *x_m, const float *y_m, uint8_t n)
{
    double th, c, s;
    uint8_t i;
    if (d == NULL || (n > 0 && (x_m == NULL || y_m == NULL)))
        return SONAR_ERR_ARG;
    /* Output frame -> device frame: undo the angle offset the detections were rotated by. */
    th = -sonar_frame_rad((double)d->cfg.angle_offset);
    c = cos(th);
    s = sin(th);
    d->ntracks = 0;
    for (i = 0; i < n && d->ntracks < SONAR_MAX_CLUSTERS; i++) {
        double x = (double)x_m[i], y = (double)y_m[i];
        double dx = (x * c - y * s) * 1000.0, dy = (x * s + y * c) * 1000.0;
        /* Off the detector's mm grid (or NaN): such a prediction cannot gate a cluster anyway. */
        if (!(fabs(dx) < (double)SONAR_KMEANS_MAX_COORD && fabs(dy) < (double)SONAR_KMEANS_MAX_COORD))
            continue;
        d->tracks[d->ntracks].x = (int32_t)floor(dx + 0.5);
        d->tracks[d->ntracks].y = (int32_t)floor(dy + 0.5);
        d->ntracks++;
    }
    return SONAR_OK;
}

/*
 * Moves the objects flagged in move (out->det[0..count), at their centroids, oj their labels) to the
 * tail where the ns structure detections sit at the array's end (sj their labels), as kind; walls'
 * labels join sj. The tail grows downwards in the objects' order. Returns the detections moved.
 */
static uint8_t to_tail(struct sonar_detections *out, struct sonar_xy *at, uint8_t *oj, const uint8_t *move,
                       uint8_t kind, uint8_t ns, uint8_t *sj)
{
    struct sonar_detection e[SONAR_MAX_CLUSTERS];
    uint8_t ej[SONAR_MAX_CLUSTERS];
    uint8_t i, keep = 0, ne = 0;
    for (i = 0; i < out->count; i++)
        if (move[i]) {
            e[ne] = out->det[i];
            e[ne].kind = kind;
            ej[ne++] = oj[i];
        }
    if (ne == 0)
        return 0;
    for (i = 0; i < out->count; i++)
        if (!move[i]) {
            out->det[keep] = out->det[i];
            oj[keep] = oj[i];
            at[keep++] = at[i];
        }
    out->count = keep;
    for (i = 0; i < ne; i++) {
        out->det[SONAR_MAX_CLUSTERS - 1 - ns - i] = e[i];
        sj[ns + i] = ej[i];
    }
    return ne;
}

/*
 * Stage 5 on a sweep's objects and structure: the pieces of a wall join the structure, then what lies
 * behind a wall, weaker and as thin along the beam as a wall (the wall's return again: a person is
 * deeper) is that wall's echo (detector_wall.c, detector_echo.c). cl: the clusters, by label. Returns the
 * new count of the tail (structure and echoes).
 */
static uint8_t walls_and_echoes(struct sonar_detector *d, const struct sonar_det_cluster *cl, struct sonar_detections *out,
                                struct sonar_xy *at, uint8_t *oj, uint8_t ns, uint8_t *sj)
{
    const struct sonar_detection *w[SONAR_MAX_CLUSTERS];
    uint8_t flag[SONAR_MAX_CLUSTERS], wecho[SONAR_MAX_CLUSTERS];
    float wl[SONAR_MAX_CLUSTERS], ol[SONAR_MAX_CLUSTERS];
    uint8_t i;
    /* Without the extent rule (the study's rules) nothing is a wall, in pieces or whole. */
    if (d->cfg.max_extent_m > 0.0f) {
        for (i = 0; i < ns; i++)
            w[i] = &out->det[SONAR_MAX_CLUSTERS - 1 - i];
        sonar_det_wall_pieces(out->det, out->count, w, ns, sonar_det_smear_mm(d, 1000.0) / 1000.0, flag);
        ns = (uint8_t)(ns + to_tail(out, at, oj, flag, SONAR_DET_STRUCTURE, ns, sj));
    }
    if (ns == 0)
        return 0;
    for (i = 0; i < ns; i++)
        wl[i] = out->det[SONAR_MAX_CLUSTERS - 1 - i].mean_intensity;
    for (i = 0; i < out->count; i++)
        ol[i] = out->det[i].mean_intensity;
    sonar_det_echoes(d, sj, wl, ns, oj, ol, out->count, flag, wecho);
    for (i = 0; i < out->count; i++)
        flag[i] = (uint8_t)(flag[i] && sonar_det_thin(cl[oj[i]].thick, cl[oj[i]].nbeams));
    for (i = 0; i < ns; i++)
        if (wecho[i])
            out->det[SONAR_MAX_CLUSTERS - 1 - i].kind = SONAR_DET_WALL_ECHO;
    return (uint8_t)(ns + to_tail(out, at, oj, flag, SONAR_DET_WALL_ECHO, ns, sj));
}

/*
 * Object o (centroid a, cluster j) into out's objects, largest first, at most max_clusters (equal sizes
 * keep cluster order), taking the room of the last structure found when the array is full. Returns the
 * structure's count, ns or one less.
 */
static uint8_t insert_object(const struct sonar_detector *d, struct sonar_detections *out, struct sonar_xy *at, uint8_t *oj,
                             const struct sonar_detection *o, struct sonar_xy a, uint8_t j, uint8_t ns)
{
    uint8_t pos;
    for (pos = out->count; pos > 0 && out->det[pos - 1].points < o->points; pos--)
        ;
    if (pos >= d->cfg.max_clusters)
        return ns;
    if (out->count == d->cfg.max_clusters)
        out->count--;
    else if (out->count + ns == SONAR_MAX_CLUSTERS)
        ns--; /* an object before structure */
    memmove(&out->det[pos + 1], &out->det[pos], (size_t)(out->count - pos) * sizeof(*o));
    memmove(&at[pos + 1], &at[pos], (size_t)(out->count - pos) * sizeof(a));
    memmove(&oj[pos + 1], &oj[pos], (size_t)(out->count - pos));
    out->det[pos] = *o;
    at[pos] = a;
    oj[pos] = j;
    out->count++;
    return ns;
}

int sonar_detector_end(struct sonar_detector *d, struct sonar_detections *out)
{
    struct sonar_xy c[SONAR_MAX_CLUSTERS], at[SONAR_MAX_CLUSTERS];
    uint8_t part[SONAR_MAX_CLUSTERS], oj[SONAR_MAX_CLUSTERS], sj[SONAR_MAX_CLUSTERS];
    uint8_t k = 0, j, q, ns = 0;
    int r;
    if (d == NULL || out == NULL)
        return SONAR_ERR_ARG;
    out->sweep = d->sweep;
    out->utime = d->utime;
    out->beams = d->beams;
    out->runs = d->nruns;
    out->runs_dropped = d->runs_dropped;
    out->threshold = d->threshold;
    out->groups = 0;
    out->count = 0;
    out->world = 0;
    if (d->nruns > 0) {
        sonar_det_join(d);
        k = sonar_det_seed(d, c, part, &out->groups);
    }
    if (k > 0 && sonar_kmeans_lloyd_within(d->pts, d->nruns, d->labels, c, part, k, d->cfg.iterations) > 0) {
        struct sonar_det_cluster cl[SONAR_MAX_CLUSTERS];
        sonar_det_clusters(d, k, cl);
        for (j = 0; j < k; j++) {
            struct sonar_detection o;
            struct sonar_xy a;
            int cut = 0;
            for (q = 0; q < k; q++)
                cut |= q != j && part[q] == part[j];
            if ((r = sonar_det_accept(d, j, &cl[j], cut, &o, &a)) == 0)
                continue;
            if (r == 2) {
                /* Structure fills the array from its end, in the room objects leave. */
                if (out->count + ns < SONAR_MAX_CLUSTERS) {
                    sj[ns] = j;
                    out->det[SONAR_MAX_CLUSTERS - 1 - ns++] = o;
                }
                continue;
            }
            ns = insert_object(d, out, at, oj, &o, a, j, ns);
        }
        ns = walls_and_echoes(d, cl, out, at, oj, ns, sj);
    }
    /* This sweep's objects are the next sweep's tracks. */
    d->ntracks = out->count;
    memcpy(d->tracks, at, (size_t)out->count * sizeof(at[0]));
    /* Structure after the objects (last found first). */
    memmove(&out->det[out->count], &out->det[SONAR_MAX_CLUSTERS - ns], (size_t)ns * sizeof(out->det[0]));
    out->count = (uint8_t)(out->count + ns);
    /* A sweep with no foreground at all (background still seeding, or empty) has no statistics to lend. */
    d->have_prev = 0;
    if (d->cells > 0 && d->sum > 0) {
        double mean = (double)d->sum / (double)d->cells;
        double var = (double)d->sumsq / (double)d->cells - mean * mean;
        d->prev_mean = (float)mean;
        d->prev_std = (float)(var > 0.0 ? sqrt(var) : 0.0);
        d->have_prev = 1;
    }
    d->sweep++;
    d->nruns = 0;
    d->beams = 0;
    d->runs_dropped = 0;
    d->sum = d->sumsq = d->cells = 0;
    return out->count;
}

uint16_t sonar_detector_beams(const struct sonar_detector *d) { return d->beams; }
const uint16_t *sonar_detector_angles(const struct sonar_detector *d) { return d->angles; }
int64_t sonar_detector_t0(const struct sonar_detector *d) { return d->t0; }
int64_t sonar_detector_utime(const struct sonar_detector *d) { return d->utime; }

int64_t sonar_detector_beam_utime(const struct sonar_detector *d, uint16_t i)
{
    return d->t0 + (int64_t)d->dt_ms[i] * 1000;
}

const char *sonar_det_kind_str(int kind)
{
    switch (kind) {
    case SONAR_DET_OBJECT: return "object";
    case SONAR_DET_STRUCTURE: return "structure";
    case SONAR_DET_STATIC_START: return "static since start";
    case SONAR_DET_WALL_ECHO: return "wall echo";
    default: return "?";
    }
}
