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
            struct sonar_xy p = sonar_det_polar_mm(d, d->angles[r->beam], 2u * cell + 1u);
            x0[j] = p.x < x0[j] ? p.x : x0[j];
            x1[j] = p.x > x1[j] ? p.x : x1[j];
            y0[j] = p.y < y0[j] ? p.y : y0[j];
            y1[j] = p.y > y1[j] ? p.y : y1[j];
        }
    }
    for (j = 0; j < k; j++)
        width[j] = x1[j] - x0[j] > y1[j] - y0[j] ? x1[j] - x0[j] : y1[j] - y0[j];
}

/* The run of group `root` farthest from its labelled centre (maximin), lowest index on ties; -1 if all coincide. */
static int32_t farthest(const struct sonar_detector *d, const struct sonar_xy *c, uint16_t root)
{
    int64_t far_d = 0;
    int32_t far_i = -1;
    uint16_t i;
    for (i = 0; i < d->nruns; i++) {
        const struct sonar_point *p = &d->pts[i];
        int64_t e;
        if (p->w == 0 || d->runs[i].parent != root)
            continue;
        e = sonar_det_dist2_mm(p->x, p->y, c[d->labels[i]].x, c[d->labels[i]].y);
        if (e > far_d) {
            far_d = e;
            far_i = i;
        }
    }
    return far_i;
}

/*
 * One more centre, c[k] = run `at` of group `root`; the group's runs nearer to it move to it.
 * The same pass finds the next farthest run, so each centre costs one pass of two distances.
 */
static int32_t split_at(struct sonar_detector *d, struct sonar_xy *c, uint8_t k, uint16_t root, int32_t at)
{
    int64_t far_d = 0;
    int32_t far_i = -1;
    uint16_t i;
    c[k].x = d->pts[at].x;
    c[k].y = d->pts[at].y;
    for (i = 0; i < d->nruns; i++) {
        const struct sonar_point *p = &d->pts[i];
        int64_t dk, dl;
        if (p->w == 0 || d->runs[i].parent != root)
            continue;
        dk = sonar_det_dist2_mm(p->x, p->y, c[k].x, c[k].y);
        dl = sonar_det_dist2_mm(p->x, p->y, c[d->labels[i]].x, c[d->labels[i]].y);
        if (dk < dl) {
            d->labels[i] = k;
            dl = dk;
        }
        if (dl > far_d) {
            far_d = dl;
            far_i = i;
        }
    }
    return far_i;
}

/*
 * Groups -> k centres, part[j] = the group of centre j, labels = each run's group centre (runs of
 * small groups get weight 0 and stay out). Returns k.
 */
uint8_t sonar_det_seed(struct sonar_detector *d, struct sonar_xy *c, uint8_t *part, uint16_t *groups)
{
    uint16_t root[SONAR_MAX_CLUSTERS];
    int32_t width[SONAR_MAX_CLUSTERS];
    int64_t sx[SONAR_MAX_CLUSTERS], sy[SONAR_MAX_CLUSTERS];
    uint64_t sw[SONAR_MAX_CLUSTERS];
    uint8_t k = 0, ng, j;
    uint16_t i, need = seed_min(d);
    int32_t far;
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
    group_widths(d, k, width);
    ng = k;
    for (j = 0; j < ng; j++) {
        int64_t lim = (int64_t)((double)d->cfg.max_extent_m * 1000.0), piece = lim / 2 > 0 ? lim / 2 : 1;
        int64_t want = (width[j] + piece - 1) / piece, have = 1;
        if (width[j] <= lim)
            continue;
        for (far = farthest(d, c, root[j]); have < want && k < SONAR_MAX_CLUSTERS && far >= 0; have++) {
            far = split_at(d, c, k, root[j], far);
            part[k] = j;
            k++;
        }
    }
    return k;
}

