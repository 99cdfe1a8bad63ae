/* detector.c -- runs -> groups (union-find, beam-by-beam merge) -> k-means inside groups -> rules -> incremental hulls; O(runs * (link_beams + k * iterations)) per sweep, no heap. */
#include "sonar/detector.h"

#include <math.h>
#include <string.h>

#include "tables_internal.h"


#define STR2(x) #x
#define STR(x) STR2(x)

const char *sonar_detector_config_check(const struct sonar_detector_config *cfg)
{
    const struct sonar_detector_config *c = cfg;
    if (!(c->threshold_k >= 0.0f && c->threshold_k <= (float)SONAR_DET_K_MAX))
        return "threshold_k: 0.." STR(SONAR_DET_K_MAX);
    if (c->min_threshold > SONAR_DET_MIN_THRESHOLD_MAX)
        return "min_threshold: 0.." STR(SONAR_DET_MIN_THRESHOLD_MAX);
    if (c->max_clusters < 1 || c->max_clusters > SONAR_MAX_CLUSTERS)
        return "max_clusters: 1..SONAR_MAX_CLUSTERS (" STR(SONAR_MAX_CLUSTERS) ")";
    if (c->iterations < 1 || c->iterations > SONAR_DET_ITERATIONS_MAX)
        return "iterations: 1.." STR(SONAR_DET_ITERATIONS_MAX);
    if (c->link_beams < 1 || c->link_beams > SONAR_DET_LINK_BEAMS_MAX)
        return "link_beams: 1.." STR(SONAR_DET_LINK_BEAMS_MAX);
    if (c->min_points < 1)
        return "min_points: 1..65535";
    if (!(c->link_m >= 0.0f && c->link_m <= (float)SONAR_DET_LINK_M_MAX))
        return "link_m: 0.." STR(SONAR_DET_LINK_M_MAX) " metres";
    if (!(c->angle_offset >= -(float)SONAR_DET_ANGLE_OFFSET_MAX && c->angle_offset <= (float)SONAR_DET_ANGLE_OFFSET_MAX))
        return "angle_offset: -" STR(SONAR_DET_ANGLE_OFFSET_MAX) ".." STR(SONAR_DET_ANGLE_OFFSET_MAX) " gradians";
    if (!(c->max_extent_m >= 0.0f && c->max_extent_m <= (float)SONAR_DET_DISTANCE_MAX))
        return "max_extent_m: 0.." STR(SONAR_DET_DISTANCE_MAX) " metres";
    if (!(c->min_range_m >= 0.0f && c->min_range_m <= (float)SONAR_DET_DISTANCE_MAX))
        return "min_range_m: 0.." STR(SONAR_DET_DISTANCE_MAX) " metres";
    if (!(c->max_aspect == 0.0f ||
          (c->max_aspect >= (float)SONAR_DET_ASPECT_MIN && c->max_aspect <= (float)SONAR_DET_ASPECT_MAX)))
        return "max_aspect: 0 (no limit) or " STR(SONAR_DET_ASPECT_MIN) ".." STR(SONAR_DET_ASPECT_MAX);
    if (!(c->track_m >= 0.0f && c->track_m <= (float)SONAR_DET_TRACK_M_MAX))
        return "track_m: 0.." STR(SONAR_DET_TRACK_M_MAX) " metres";
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

static uint8_t threshold_now(const struct sonar_detector *d)
{
    double mean, sd, t;
    if (d->have_prev) {
        mean = d->prev_mean;
        sd = d->prev_std;
    } else {
        double var;
        mean = d->cells ? (double)d->sum / (double)d->cells : 0.0;
        var = d->cells ? (double)d->sumsq / (double)d->cells - mean * mean : 0.0;
        sd = var > 0.0 ? sqrt(var) : 0.0;
    }
    t = floor(mean + (double)d->cfg.threshold_k * sd);
    if (t < (double)d->cfg.min_threshold)
        t = d->cfg.min_threshold;
    return (uint8_t)(t > 254.0 ? 254.0 : t);
}

/* Sample position 2i+1 halves (the centre of sample i) at angle a, in mm, device frame. */
static struct sonar_hull_point polar_mm(const struct sonar_detector *d, uint16_t a, uint32_t twice_pos)
{
    struct sonar_hull_point p;
    int64_t range_mm = (int64_t)((double)d->range_m * 1000.0 + 0.5);
    int64_t r = ((int64_t)twice_pos * range_mm) / (2 * (int64_t)d->n);
    int64_t c = sonar_cos_q16[a % 400u], s = sonar_cos_q16[(a + 300u) % 400u];
    p.x = (int32_t)((r * c + 32768) >> 16);
    p.y = (int32_t)((r * s + 32768) >> 16);
    return p;
}

static void add_run(struct sonar_detector *d, uint16_t beam, uint16_t start, uint16_t len, uint32_t sum)
{
    struct sonar_hull_point c;
    struct sonar_detector_run *r;
    if (d->nruns >= SONAR_MAX_RUNS) {
        d->runs_dropped++;
        return;
    }
    /* Centre of the run: halfway between its first and last sample centres. */
    c = polar_mm(d, d->angles[beam], 2u * start + len);
    d->pts[d->nruns].x = c.x;
    d->pts[d->nruns].y = c.y;
    d->pts[d->nruns].w = len;
    r = &d->runs[d->nruns];
    r->beam = beam;
    r->start = start;
    r->parent = d->nruns;
    r->size = 0;
    r->sum = sum;
    d->nruns++;
}

#define BLOCK 64
#define NBLOCKS ((SONAR_MAX_SAMPLES + BLOCK - 1) / BLOCK)

/* Sum, sum of squares and the maximum of each 64-sample block; constant-length blocks, so -O2 vectorises them. */
#define STATS_SPAN(p, len)                                                                                         \
    for (j = 0; j < (len); j++) {                                                                                  \
        uint8_t v = (p)[j];                                                                                        \
        bs += v;                                                                                                   \
        bq += (uint32_t)v * v;                                                                                     \
        bm = v > bm ? v : bm;                                                                                      \
    }

static void beam_stats(const uint8_t *fg, uint16_t n, uint32_t *s, uint32_t *q, uint8_t *blockmax)
{
    uint32_t bs = 0, bq = 0;
    uint8_t bm;
    int j, j0, b = 0;
    for (j0 = 0; j0 + BLOCK <= (int)n; j0 += BLOCK) {
        bm = 0;
        STATS_SPAN(fg + j0, BLOCK)
        blockmax[b++] = bm;
    }
    bm = 0;
    STATS_SPAN(fg + j0, (int)n - j0)
    blockmax[b] = bm;
    *s = bs;
    *q = bq;
}

int sonar_detector_add(struct sonar_detector *d, uint16_t angle, const uint8_t *fg, uint16_t n, float range_m,
                       int64_t utime)
{
    uint8_t blockmax[NBLOCKS + 1];
    uint32_t s = 0, q = 0;
    uint16_t i, beam, b, nb;
    uint8_t t;
    if (d == NULL || fg == NULL || n == 0 || n > SONAR_MAX_SAMPLES || angle > 399u || !(range_m > 0.0f))
        return SONAR_ERR_ARG;
    if (d->beams == 0) {
        d->n = n;
        d->range_m = range_m;
    } else if (n != d->n || range_m != d->range_m) {
        return SONAR_ERR_STATE;
    }
    if (d->beams >= SONAR_MAX_SWEEP_BEAMS)
        return SONAR_ERR_FULL;
    beam = d->beams++;
    d->angles[beam] = angle;
    d->utime = utime;
    beam_stats(fg, n, &s, &q, blockmax);
    d->sum += s;
    d->sumsq += q;
    d->cells += n;
    t = threshold_now(d);
    d->threshold = t;
    /* Runs: scan only the blocks whose maximum passes; a run may continue into the next block. */
    nb = (uint16_t)((n + BLOCK - 1) / BLOCK);
    for (b = 0, i = 0; b < nb; b++) {
        uint16_t end = (uint16_t)((b + 1u) * BLOCK < n ? (b + 1u) * BLOCK : n);
        if (blockmax[b] <= t) {
            i = i > end ? i : end;
            continue;
        }
        if (i < b * BLOCK)
            i = (uint16_t)(b * BLOCK);
        while (i < end) {
            uint16_t start;
            uint32_t sum = 0;
            if (fg[i] <= t) {
                i++;
                continue;
            }
            start = i;
            while (i < n && fg[i] > t)
                sum += fg[i++];
            add_run(d, beam, start, (uint16_t)(i - start), sum);
        }
    }
    return SONAR_OK;
}

static uint16_t find(struct sonar_detector_run *r, uint16_t i)
{
    while (r[i].parent != i) {
        r[i].parent = r[r[i].parent].parent; /* path halving keeps later finds short */
        i = r[i].parent;
    }
    return i;
}

static void unite(struct sonar_detector_run *r, uint16_t a, uint16_t b)
{
    uint16_t ra = find(r, a), rb = find(r, b);
    /* The lower index stays root, so a root precedes every member in run order. */
    if (ra < rb)
        r[rb].parent = ra;
    else if (rb < ra)
        r[ra].parent = rb;
}

static int touch(const struct sonar_detector *d, uint16_t a, uint16_t b, uint32_t gap)
{
    uint32_t sa = d->runs[a].start, ea = sa + d->pts[a].w - 1u;
    uint32_t sb = d->runs[b].start, eb = sb + d->pts[b].w - 1u;
    uint32_t lo = sa > sb ? sa : sb, hi = ea < eb ? ea : eb;
    return lo <= hi + 1u + gap;
}

static uint16_t angle_gap(uint16_t a, uint16_t b)
{
    uint16_t g = (uint16_t)(a > b ? a - b : b - a);
    return g > 200u ? (uint16_t)(400u - g) : g;
}

/*
 * Unites the touching runs of two beams' run lists [a, ae) and [b, be). Each list is sorted by
 * start and, its runs being disjoint, by end too, so a merge that steps past whichever run ends
 * first meets every touching pair or one that joins the same groups through a neighbour in its own
 * beam (linked below): O(length of both lists).
 */
static void link_beams(struct sonar_detector *d, uint16_t a, uint16_t ae, uint16_t b, uint16_t be, uint32_t gap)
{
    while (a < ae && b < be) {
        uint32_t ea = (uint32_t)d->runs[a].start + d->pts[a].w, eb = (uint32_t)d->runs[b].start + d->pts[b].w;
        if (touch(d, a, b, gap))
            unite(d->runs, a, b);
        if (ea <= eb)
            a++;
        if (eb <= ea)
            b++;
    }
}

static void link_runs(struct sonar_detector *d)
{
    uint32_t gap = (uint32_t)((double)d->cfg.link_m * (double)d->n / (double)d->range_m);
    uint16_t i, e, lb = d->cfg.link_beams;
    /* Runs are stored beam by beam, each beam's in range order: link each beam to itself and to the lb before it. */
    for (i = 0; i < d->nruns; i = e) {
        uint16_t beam = d->runs[i].beam, p1 = i;
        for (e = (uint16_t)(i + 1u); e < d->nruns && d->runs[e].beam == beam; e++)
            if (touch(d, (uint16_t)(e - 1u), e, gap)) /* in one beam, neighbours suffice: gaps only grow */
                unite(d->runs, (uint16_t)(e - 1u), e);
        while (p1 > 0 && beam - d->runs[p1 - 1u].beam <= lb) {
            uint16_t p0 = (uint16_t)(p1 - 1u), pb = d->runs[p0].beam;
            while (p0 > 0 && d->runs[p0 - 1u].beam == pb)
                p0--;
            link_beams(d, p0, p1, i, e, gap);
            p1 = p0;
        }
    }
    /* A full turn: the last beams adjoin the first ones across the start angle. */
    if (d->beams > 2u * lb + 1u) {
        uint16_t step = angle_gap(d->angles[0], d->angles[1]);
        uint16_t reach = (uint16_t)(lb * (step ? step : 1u));
        uint16_t a0, a1 = d->nruns;
        if (angle_gap(d->angles[0], d->angles[d->beams - 1u]) > reach)
            return;
        /* Each of the last lb beams against each of the first lb, merged as above. */
        while (a1 > 0 && d->runs[a1 - 1u].beam + lb >= d->beams) {
            uint16_t ab = d->runs[a1 - 1u].beam, b0 = 0;
            for (a0 = (uint16_t)(a1 - 1u); a0 > 0 && d->runs[a0 - 1u].beam == ab; a0--)
                ;
            while (b0 < a0 && d->runs[b0].beam < lb) {
                uint16_t bb = d->runs[b0].beam, b1;
                for (b1 = (uint16_t)(b0 + 1u); b1 < a0 && d->runs[b1].beam == bb; b1++)
                    ;
                if (angle_gap(d->angles[ab], d->angles[bb]) <= reach)
                    link_beams(d, b0, b1, a0, a1, gap);
                b0 = b1;
            }
            a1 = a0;
        }
    }
}

static int64_t dist2_mm(int32_t ax, int32_t ay, int32_t bx, int32_t by)
{
    int64_t dx = (int64_t)ax - bx, dy = (int64_t)ay - by;
    return dx * dx + dy * dy;
}

/* Cells a group needs to seed a centre: the smaller of min_points and, when tracking, track_points. */
static uint16_t seed_min(const struct sonar_detector *d)
{
    if (d->cfg.track_m > 0.0f && d->cfg.track_points < d->cfg.min_points)
        return d->cfg.track_points;
    return d->cfg.min_points;
}

/* Width of each kept group (labels[i] = its index): the larger side of the box around its runs' end cells, mm. */
static void group_widths(const struct sonar_detector *d, uint8_t k, int32_t *width)
{
    int32_t x0[SONAR_MAX_CLUSTERS], x1[SONAR_MAX_CLUSTERS], y0[SONAR_MAX_CLUSTERS], y1[SONAR_MAX_CLUSTERS];
    uint16_t i;
    uint8_t j, e;
    for (j = 0; j < k; j++) {
        x0[j] = y0[j] = INT32_MAX;
        x1[j] = y1[j] = INT32_MIN;
    }
    for (i = 0; i < d->nruns; i++) {
        const struct sonar_detector_run *r = &d->runs[i];
        if (d->pts[i].w == 0)
            continue;
        j = d->labels[i];
        for (e = 0; e < 2; e++) {
            uint32_t cell = e ? (uint32_t)r->start + d->pts[i].w - 1u : r->start;
            struct sonar_hull_point p = polar_mm(d, d->angles[r->beam], 2u * cell + 1u);
            x0[j] = p.x < x0[j] ? p.x : x0[j];
            x1[j] = p.x > x1[j] ? p.x : x1[j];
            y0[j] = p.y < y0[j] ? p.y : y0[j];
            y1[j] = p.y > y1[j] ? p.y : y1[j];
        }
    }
    for (j = 0; j < k; j++)
        width[j] = x1[j] - x0[j] > y1[j] - y0[j] ? x1[j] - x0[j] : y1[j] - y0[j];
}

/*
 * One more centre, c[k], for group `root`: its run farthest from the nearest of the group's
 * centres (maximin). labels[i] holds that nearest centre, so each new centre costs two passes.
 */
static int add_split_seed(struct sonar_detector *d, struct sonar_centroid *c, uint8_t k, uint16_t root)
{
    int64_t far_d = 0;
    int32_t far_i = -1;
    uint16_t i;
    for (i = 0; i < d->nruns; i++) {
        const struct sonar_point *p = &d->pts[i];
        int64_t e;
        if (p->w == 0 || d->runs[i].parent != root)
            continue;
        e = dist2_mm(p->x, p->y, c[d->labels[i]].x, c[d->labels[i]].y);
        if (e > far_d) {
            far_d = e;
            far_i = i;
        }
    }
    if (far_i < 0)
        return 0;
    c[k].x = d->pts[far_i].x;
    c[k].y = d->pts[far_i].y;
    for (i = 0; i < d->nruns; i++) {
        const struct sonar_point *p = &d->pts[i];
        if (p->w == 0 || d->runs[i].parent != root)
            continue;
        if (dist2_mm(p->x, p->y, c[k].x, c[k].y) < dist2_mm(p->x, p->y, c[d->labels[i]].x, c[d->labels[i]].y))
            d->labels[i] = k;
    }
    return 1;
}

/*
 * Groups -> k centres, part[j] = the group of centre j, labels = each run's group centre (runs of
 * small groups get weight 0 and stay out). Returns k.
 */
static uint8_t seed_groups(struct sonar_detector *d, struct sonar_centroid *c, uint8_t *part, uint16_t *groups)
{
    uint16_t root[SONAR_MAX_CLUSTERS];
    int32_t width[SONAR_MAX_CLUSTERS];
    int64_t sx[SONAR_MAX_CLUSTERS], sy[SONAR_MAX_CLUSTERS];
    uint64_t sw[SONAR_MAX_CLUSTERS];
    uint8_t k = 0, ng, j;
    uint16_t i, need = seed_min(d);
    struct sonar_detector_run *r = d->runs;
    for (i = 0; i < d->nruns; i++) {
        r[i].parent = find(r, i);
        r[i].size = 0;
    }
    for (i = 0; i < d->nruns; i++) {
        uint32_t s = (uint32_t)r[r[i].parent].size + d->pts[i].w;
        r[r[i].parent].size = (uint16_t)(s > 65535u ? 65535u : s);
    }
    *groups = 0;
    for (i = 0; i < d->nruns; i++) {
        uint8_t at;
        if (r[i].parent != i || r[i].size < need)
            continue;
        (*groups)++;
        /* Keep the max_clusters largest, in descending size (earlier wins ties). */
        if (k < d->cfg.max_clusters)
            at = k++;
        else if (r[root[k - 1]].size < r[i].size)
            at = (uint8_t)(k - 1);
        else
            continue;
        for (; at > 0 && r[root[at - 1]].size < r[i].size; at--)
            root[at] = root[at - 1];
        root[at] = i;
    }
    memset(sx, 0, sizeof(sx));
    memset(sy, 0, sizeof(sy));
    memset(sw, 0, sizeof(sw));
    for (i = 0; i < d->nruns; i++) {
        uint16_t p = r[i].parent;
        for (j = 0; j < k && root[j] != p; j++)
            ;
        /* Noise, or a group beyond max_clusters: weight 0 keeps it out of every cluster. */
        if (j == k) {
            d->pts[i].w = 0;
            d->labels[i] = SONAR_KMEANS_SKIP;
            continue;
        }
        d->labels[i] = j;
        sx[j] += (int64_t)d->pts[i].x * d->pts[i].w;
        sy[j] += (int64_t)d->pts[i].y * d->pts[i].w;
        sw[j] += d->pts[i].w;
    }
    for (j = 0; j < k; j++) {
        c[j].x = (int32_t)(sx[j] / (int64_t)sw[j]);
        c[j].y = (int32_t)(sy[j] / (int64_t)sw[j]);
        part[j] = j;
    }
    if (d->cfg.split_points == 0 || !(d->cfg.max_extent_m > 0.0f))
        return k;
    /* Wide groups, largest first, get a centre per half max_extent_m while centres remain. */
    group_widths(d, k, width);
    ng = k;
    for (j = 0; j < ng; j++) {
        int64_t lim = (int64_t)((double)d->cfg.max_extent_m * 1000.0), piece = lim / 2 > 0 ? lim / 2 : 1;
        int64_t want = (width[j] + piece - 1) / piece, have = 1;
        if (width[j] <= lim)
            continue;
        for (; have < want && k < SONAR_MAX_CLUSTERS && add_split_seed(d, c, k, root[j]); have++) {
            part[k] = j;
            k++;
        }
    }
    return k;
}

/* Folds the work points into their hull when full; thins a hull that alone nearly fills it. */
static void hull_push(struct sonar_detector *d, uint16_t *nw, struct sonar_hull_point p)
{
    if (*nw == SONAR_HULL_WORK) {
        int h = sonar_hull_build(d->work, *nw, d->hull, 2 * SONAR_HULL_WORK);
        uint16_t i, keep = (uint16_t)(h > 0 ? h : 0);
        if (keep > SONAR_HULL_WORK - 8u) {
            for (i = 0; i < SONAR_HULL_WORK / 2u; i++)
                d->work[i] = d->hull[(uint32_t)i * keep / (SONAR_HULL_WORK / 2u)];
            keep = SONAR_HULL_WORK / 2u;
        } else {
            memcpy(d->work, d->hull, (size_t)keep * sizeof(d->hull[0]));
        }
        *nw = keep;
    }
    d->work[(*nw)++] = p;
}

static void rotate(float *x, float *y, double c, double s)
{
    double nx = (double)*x * c - (double)*y * s, ny = (double)*x * s + (double)*y * c;
    *x = (float)nx;
    *y = (float)ny;
}

/* Within track_m of a detection of the previous sweep? (device frame, mm) */
static int tracked(const struct sonar_detector *d, int32_t x, int32_t y)
{
    int64_t gate = (int64_t)((double)d->cfg.track_m * 1000.0);
    uint8_t t;
    for (t = 0; t < d->ntracks; t++)
        if (dist2_mm(x, y, d->tracks[t].x, d->tracks[t].y) <= gate * gate)
            return 1;
    return 0;
}

/*
 * Is a cluster of w cells over nbeams beams and samples [rlo, rhi], centroid (x, y) mm, an object?
 * Every rule but the hull's diameter; `cut` = the cluster is a piece of a wider group.
 */
static int passes(const struct sonar_detector *d, uint64_t w, uint16_t nbeams, uint32_t rlo, uint32_t rhi, int32_t x,
                  int32_t y, int cut)
{
    uint64_t need = d->cfg.min_points;
    double rc = sqrt((double)x * x + (double)y * y) / 1000.0;
    if (d->cfg.track_m > 0.0f && d->cfg.track_points < need && tracked(d, x, y))
        need = d->cfg.track_points;
    if (w < need || nbeams < d->cfg.min_beams || (cut && w < d->cfg.split_points) || rc < (double)d->cfg.min_range_m)
        return 0;
    if (d->cfg.max_aspect > 0.0f) {
        /* Along: the cells' range span. Across: its beams times the sweep's step, at the centroid's range. */
        uint16_t step = d->beams > 1u ? angle_gap(d->angles[0], d->angles[1]) : 1u;
        double along = (double)(rhi - rlo + 1u) * (double)d->range_m / (double)d->n;
        double across = (double)nbeams * (double)(step ? step : 1u) * 3.14159265358979323846 / 200.0 * rc;
        if (along > (double)d->cfg.max_aspect * across)
            return 0;
    }
    return 1;
}

/* Cluster j -> detection and its device-frame centroid *at (mm); returns 0 when it is not an object. */
static int make_detection(struct sonar_detector *d, uint8_t j, int cut, struct sonar_detection *o,
                          struct sonar_centroid *at)
{
    uint64_t w = 0, s = 0;
    int64_t sx = 0, sy = 0;
    uint16_t i, nw = 0, beam = 0xFFFFu, nbeams = 0;
    uint32_t lo = 0, hi = 0, rlo = UINT32_MAX, rhi = 0;
    int h, v;
    double th = (double)d->cfg.angle_offset * 3.14159265358979323846 / 200.0, c = cos(th), sn = sin(th);
    for (i = 0; i < d->nruns; i++) {
        const struct sonar_detector_run *r = &d->runs[i];
        uint32_t end;
        if (d->labels[i] != j)
            continue;
        w += d->pts[i].w;
        s += r->sum;
        sx += (int64_t)d->pts[i].x * d->pts[i].w;
        sy += (int64_t)d->pts[i].y * d->pts[i].w;
        end = (uint32_t)r->start + d->pts[i].w - 1u;
        rlo = r->start < rlo ? r->start : rlo;
        rhi = end > rhi ? end : rhi;
        /* Runs of one beam lie on one ray: only its nearest and farthest cells can be hull vertices. */
        if (r->beam != beam) {
            if (beam != 0xFFFFu) {
                hull_push(d, &nw, polar_mm(d, d->angles[beam], 2u * lo + 1u));
                hull_push(d, &nw, polar_mm(d, d->angles[beam], 2u * hi + 1u));
            }
            beam = r->beam;
            nbeams++;
            lo = r->start;
            hi = end;
        } else {
            lo = r->start < lo ? r->start : lo;
            hi = end > hi ? end : hi;
        }
    }
    if (w == 0 || beam == 0xFFFFu)
        return 0;
    at->x = (int32_t)(sx / (int64_t)w);
    at->y = (int32_t)(sy / (int64_t)w);
    if (!passes(d, w, nbeams, rlo, rhi, at->x, at->y, cut))
        return 0;
    hull_push(d, &nw, polar_mm(d, d->angles[beam], 2u * lo + 1u));
    hull_push(d, &nw, polar_mm(d, d->angles[beam], 2u * hi + 1u));
    h = sonar_hull_build(d->work, nw, d->hull, 2 * SONAR_HULL_WORK);
    if (h < 1)
        return 0;
    if (d->cfg.max_extent_m > 0.0f) {
        /* hull diameter: the widest pair of vertices (h <= 2 * SONAR_HULL_WORK, once per cluster) */
        int64_t lim = (int64_t)((double)d->cfg.max_extent_m * 1000.0), lim2 = lim * lim;
        int a, b;
        for (a = 0; a < h; a++)
            for (b = a + 1; b < h; b++) {
                int64_t dx = (int64_t)d->hull[a].x - d->hull[b].x, dy = (int64_t)d->hull[a].y - d->hull[b].y;
                if (dx * dx + dy * dy > lim2)
                    return 0;
            }
    }
    memset(o, 0, sizeof(*o));
    o->points = (uint32_t)w;
    o->mean_intensity = (float)((double)s / (double)w);
    o->x_m = (float)((double)sx / (double)w / 1000.0);
    o->y_m = (float)((double)sy / (double)w / 1000.0);
    o->area_m2 = (float)((double)sonar_hull_area2(d->hull, (uint16_t)h) / 2.0e6);
    o->hull_count = (uint8_t)(h > SONAR_MAX_HULL ? SONAR_MAX_HULL : h);
    for (v = 0; v < o->hull_count; v++) {
        const struct sonar_hull_point *p = &d->hull[(long)v * h / o->hull_count];
        o->hull_x[v] = (float)p->x / 1000.0f;
        o->hull_y[v] = (float)p->y / 1000.0f;
        if (d->cfg.angle_offset != 0.0f)
            rotate(&o->hull_x[v], &o->hull_y[v], c, sn);
    }
    if (d->cfg.angle_offset != 0.0f)
        rotate(&o->x_m, &o->y_m, c, sn);
    o->range_m = (float)sqrt((double)o->x_m * o->x_m + (double)o->y_m * o->y_m);
    o->bearing_deg = (float)(o->x_m == 0.0f && o->y_m == 0.0f ? 0.0 : atan2((double)o->y_m, (double)o->x_m) * 180.0 / 3.14159265358979323846);
    if (o->bearing_deg < 0.0f)
        o->bearing_deg += 360.0f;
    return 1;
}

int sonar_detector_end(struct sonar_detector *d, struct sonar_detections *out)
{
    struct sonar_centroid c[SONAR_MAX_CLUSTERS], at[SONAR_MAX_CLUSTERS];
    uint8_t part[SONAR_MAX_CLUSTERS];
    uint8_t k = 0, j, q;
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
    if (d->nruns > 0) {
        link_runs(d);
        k = seed_groups(d, c, part, &out->groups);
    }
    if (k > 0 && sonar_kmeans_lloyd_within(d->pts, d->nruns, d->labels, c, part, k, d->cfg.iterations) > 0) {
        for (j = 0; j < k; j++) {
            struct sonar_detection o;
            struct sonar_centroid a;
            uint8_t pos;
            int cut = 0;
            for (q = 0; q < k; q++)
                cut |= q != j && part[q] == part[j];
            if (!make_detection(d, j, cut, &o, &a))
                continue;
            /* Largest first, at most max_clusters; equal sizes keep cluster order. */
            for (pos = out->count; pos > 0 && out->det[pos - 1].points < o.points; pos--)
                ;
            if (pos >= d->cfg.max_clusters)
                continue;
            if (out->count == d->cfg.max_clusters)
                out->count--;
            memmove(&out->det[pos + 1], &out->det[pos], (size_t)(out->count - pos) * sizeof(o));
            memmove(&at[pos + 1], &at[pos], (size_t)(out->count - pos) * sizeof(a));
            out->det[pos] = o;
            at[pos] = a;
            out->count++;
        }
    }
    /* This sweep's objects are the next sweep's tracks. */
    d->ntracks = out->count;
    memcpy(d->tracks, at, (size_t)out->count * sizeof(at[0]));
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
