/* detector_group.c -- stage 3: groups -> k-means centres, the max_clusters largest, wide groups cut with farthest-point seeds; O(runs x centres) per sweep. */
#include <string.h>

#include "detector_internal.h"

/* Cells a group needs to seed a centre: the smaller of min_points and, when tracking, track_points. */
static uint16_t seed_min(const struct sonar_detector *d)
{
    if (d->cfg.track_m > 0.0f && d->cfg.track_points < d->cfg.min_points)
        return d->cfg.track_points;
    return d->cfg.min_points;
}

/* Widens box b (x0, x1, y0, y1) to hold cells lo and hi of beam `beam`. */
static void box_add(const struct sonar_detector *d, int32_t *b, uint16_t beam, uint16_t lo, uint16_t hi)
{
    uint8_t e;
    for (e = 0; e < 2; e++) {
        struct sonar_xy p = sonar_det_polar_mm(d, d->angles[beam], 2u * (e ? hi : lo) + 1u);
        b[0] = p.x < b[0] ? p.x : b[0];
        b[1] = p.x > b[1] ? p.x : b[1];
        b[2] = p.y < b[2] ? p.y : b[2];
        b[3] = p.y > b[3] ? p.y : b[3];
    }
}

/*
 * Width of each kept group (labels[i] = its index): the larger side of the box around its runs'
 * end cells, mm. Along one beam x and y are monotone in range (sonar_det_polar_mm rounds r cos a
 * and r sin a of a monotone r), so only a group's nearest and farthest end cells on a beam can be
 * on the box: the runs come beam by beam, and a group converts two cells a beam, not two a run.
 */
static void group_widths(const struct sonar_detector *d, uint8_t k, int32_t *width, uint8_t *thin)
{
    int32_t box[SONAR_MAX_CLUSTERS][4];
    uint16_t beam[SONAR_MAX_CLUSTERS], lo[SONAR_MAX_CLUSTERS], hi[SONAR_MAX_CLUSTERS];
    uint16_t nb[SONAR_MAX_CLUSTERS], thick[SONAR_MAX_CLUSTERS];
    uint8_t open[SONAR_MAX_CLUSTERS];
    const uint32_t line = sonar_det_line_samples(d);
    uint16_t i;
    uint8_t j;
    for (j = 0; j < k; j++) {
        box[j][0] = box[j][2] = INT32_MAX;
        box[j][1] = box[j][3] = INT32_MIN;
        open[j] = 0;
        nb[j] = thick[j] = 0;
    }
    for (i = 0; i < d->nruns; i++) {
        const struct sonar_detector_run *r = &d->runs[i];
        uint16_t end;
        j = d->labels[i];
        if (d->pts[i].w == 0 || j >= k)
            continue;
        end = (uint16_t)(r->start + d->pts[i].w - 1u);
        if (open[j] && beam[j] == r->beam) {
            lo[j] = r->start < lo[j] ? r->start : lo[j];
            hi[j] = end > hi[j] ? end : hi[j];
            continue;
        }
        if (open[j]) {
            box_add(d, box[j], beam[j], lo[j], hi[j]);
            nb[j]++;
            thick[j] = (uint16_t)(thick[j] + ((uint32_t)(hi[j] - lo[j]) + 1u > line));
        }
        open[j] = 1;
        beam[j] = r->beam;
        lo[j] = r->start;
        hi[j] = end;
    }
    for (j = 0; j < k; j++) {
        if (open[j]) {
            box_add(d, box[j], beam[j], lo[j], hi[j]);
            nb[j]++;
            thick[j] = (uint16_t)(thick[j] + ((uint32_t)(hi[j] - lo[j]) + 1u > line));
        }
        width[j] = box[j][1] - box[j][0] > box[j][3] - box[j][2] ? box[j][1] - box[j][0] : box[j][3] - box[j][2];
        thin[j] = (uint8_t)sonar_det_thin(thick[j], nb[j]);
    }
}

/*
 * Each centre's farthest run (maximin): far_d[l] its squared distance, far_i[l] its index (the
 * lowest on ties), -1 and 0 when every run of centre l sits on it.
 */
struct farthest {
    int64_t far_d[SONAR_MAX_CLUSTERS];
    int32_t far_i[SONAR_MAX_CLUSTERS];
};

/*
 * Rescans the runs of the centres with redo[l] set (all below k): when k < SONAR_MAX_CLUSTERS and
 * c[k] is a new centre, each such run nearer to c[k] moves to it, and centre k's farthest is
 * found too. Runs of other centres keep their labels and their centres' farthest runs.
 */
static void rescan(struct sonar_detector *d, const struct sonar_xy *c, uint8_t k, int add, const uint8_t *redo,
                   struct farthest *f)
{
    uint16_t i;
    uint8_t l;
    for (l = 0; l <= k && l < SONAR_MAX_CLUSTERS; l++)
        if (l == k ? add : redo[l]) {
            f->far_d[l] = 0;
            f->far_i[l] = -1;
        }
    for (i = 0; i < d->nruns; i++) {
        const struct sonar_point *p = &d->pts[i];
        int64_t dl;
        l = d->labels[i];
        if (l >= k || !redo[l] || p->w == 0)
            continue;
        dl = sonar_det_dist2_mm(p->x, p->y, c[l].x, c[l].y);
        if (add) {
            int64_t dk = sonar_det_dist2_mm(p->x, p->y, c[k].x, c[k].y);
            if (dk < dl) {
                d->labels[i] = l = k;
                dl = dk;
            }
        }
        /* Ascending i with a strict test keeps the lowest index on ties. */
        if (dl > f->far_d[l]) {
            f->far_d[l] = dl;
            f->far_i[l] = i;
        }
    }
}

/* The farthest run of all of group j's centres (part[l] == j, l < k), lowest index on ties; -1 if none. */
static int32_t farthest_of(const struct farthest *f, const uint8_t *part, uint8_t k, uint8_t j)
{
    int64_t best_d = 0;
    int32_t best_i = -1;
    uint8_t l;
    for (l = 0; l < k; l++)
        if (part[l] == j && f->far_i[l] >= 0 &&
            (f->far_d[l] > best_d || (f->far_d[l] == best_d && f->far_i[l] < best_i))) {
            best_d = f->far_d[l];
            best_i = f->far_i[l];
        }
    return best_i;
}

/*
 * Cuts group j (centre j, the k centres so far) with farthest-point centres up to `want` pieces,
 * while centres remain: each new centre is the run farthest from its centre, and the group's runs
 * nearer to it move to it. A centre l can lose runs to the new centre c only if
 * |c - c_l| < 2 max|p - c_l| (else every run of l is at least as near c_l: triangle inequality),
 * so only those centres are rescanned; the labels and the centres are those of rescanning every
 * run each time. Returns the new k.
 */
static uint8_t cut_group(struct sonar_detector *d, struct sonar_xy *c, uint8_t *part, uint8_t k, uint8_t j,
                         int64_t want)
{
    struct farthest f;
    uint8_t redo[SONAR_MAX_CLUSTERS], l;
    int64_t have = 1;
    int32_t far;
    memset(redo, 0, sizeof(redo));
    redo[j] = 1;
    rescan(d, c, k, 0, redo, &f);
    for (far = f.far_i[j]; have < want && k < SONAR_MAX_CLUSTERS && far >= 0; have++) {
        c[k].x = d->pts[far].x;
        c[k].y = d->pts[far].y;
        for (l = 0; l < k; l++)
            redo[l] = part[l] == j && 4 * f.far_d[l] > sonar_det_dist2_mm(c[l].x, c[l].y, c[k].x, c[k].y);
        rescan(d, c, k, 1, redo, &f);
        part[k] = j;
        k++;
        far = farthest_of(&f, part, k, j);
    }
    return k;
}

/*
 * Groups -> k centres, part[j] = the group of centre j, labels = each run's group centre (runs of
 * small groups get weight 0 and stay out). Returns k.
 */
uint8_t sonar_det_seed(struct sonar_detector *d, struct sonar_xy *c, uint8_t *part, uint16_t *groups)
{
    uint16_t root[SONAR_MAX_CLUSTERS];
    int32_t width[SONAR_MAX_CLUSTERS];
    uint8_t thin[SONAR_MAX_CLUSTERS];
    int64_t sx[SONAR_MAX_CLUSTERS], sy[SONAR_MAX_CLUSTERS];
    uint64_t sw[SONAR_MAX_CLUSTERS];
    uint8_t k = 0, ng, j;
    uint16_t i, need = seed_min(d);
    struct sonar_detector_run *r = d->runs;
    for (i = 0; i < d->nruns; i++) {
        r[i].parent = sonar_det_find(r, i);
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
    group_widths(d, k, width, thin);
    ng = k;
    for (j = 0; j < ng; j++) {
        int64_t lim = (int64_t)((double)d->cfg.max_extent_m * 1000.0), piece = lim / 2 > 0 ? lim / 2 : 1;
        /* A wall or a rope is never cut into object-sized pieces: it stays whole, and is structure. */
        if (width[j] > lim && !thin[j])
            k = cut_group(d, c, part, k, j, (width[j] + piece - 1) / piece);
    }
    return k;
}
