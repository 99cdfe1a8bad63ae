/* detector_accept.c -- stage 4: each cluster against the rules (cells, beams, range, aspect, extent, tracking gate), its incremental hull and the detection in metres; one pass over the runs for the rules, one more per cluster that passes them. */
#include <math.h>
#include <string.h>

#include "detector_internal.h"
#include "sonar/geometry.h"

/* A cluster's hull being built: the points so far and the hull's vertices (1.5 KB, on the stack of one emission). */
struct hull_scratch {
    struct sonar_xy work[SONAR_HULL_WORK];
    struct sonar_xy hull[2 * SONAR_HULL_WORK];
};

/* Folds the work points into their hull when full; thins a hull that alone nearly fills it. */
static void hull_push(struct hull_scratch *d, uint16_t *nw, struct sonar_xy p)
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
        if (sonar_det_dist2_mm(x, y, d->tracks[t].x, d->tracks[t].y) <= gate * gate)
            return 1;
    return 0;
}

/*
 * Is cluster cl, centroid (x, y) mm, an object? Every rule but the hull's diameter; `cut` = the
 * cluster is a piece of a wider group.
 */
static int passes(const struct sonar_detector *d, const struct sonar_det_cluster *cl, int32_t x, int32_t y, int cut)
{
    uint64_t need = d->cfg.min_points, w = cl->w;
    double rc = sqrt((double)x * x + (double)y * y) / 1000.0;
    if (d->cfg.track_m > 0.0f && d->cfg.track_points < need && tracked(d, x, y))
        need = d->cfg.track_points;
    if (w < need || cl->nbeams < d->cfg.min_beams || (cut && w < d->cfg.split_points) || rc < (double)d->cfg.min_range_m)
        return 0;
    /*
     * Where the beams overlap (the step at most half the beam's width), a reflector inside the sector lights two
     * beams or more: a cluster on one beam is a fragment (the CFAR's cut end of a longer return, a speck).
     */
    if (cl->nbeams < 2u && (double)sonar_det_step(d) * SONAR_DEG_PER_GRAD <= SONAR_BEAM_WIDTH_DEG / 2.0)
        return 0;
    if (d->cfg.min_area_m2 > 0.0f || d->cfg.min_footprints > 0.0f) {
        /* Each cell is range/n deep and r x step wide at its range r = (sample + 1/2) range/n; a point target's
           footprint at the cluster's range, range/n deep and the beam's width across. */
        double dr = (double)d->range_m / (double)d->n;
        double area = (double)cl->rw * 0.5 * dr * dr * sonar_frame_rad((double)sonar_det_step(d));
        double foot = dr * rc * SONAR_BEAM_WIDTH_DEG * SONAR_RAD_PER_DEG;
        if (area < (double)d->cfg.min_area_m2 || area < (double)d->cfg.min_footprints * foot)
            return 0;
    }
    if (d->cfg.max_aspect > 0.0f) {
        /* Along: the cells' range span. Across: its beams times the sweep's step, at the centroid's range. */
        uint16_t step = sonar_det_step(d);
        uint32_t rlo = cl->rlo, rhi = cl->rhi;
        uint16_t nbeams = cl->nbeams;
        double along = (double)(rhi - rlo + 1u) * (double)d->range_m / (double)d->n;
        double across = sonar_frame_rad((double)nbeams * (double)step) * rc;
        if (along > (double)d->cfg.max_aspect * across)
            return 0;
    }
    return 1;
}

/* Is the hull's diameter (its widest pair of vertices, h <= 2 * SONAR_HULL_WORK) more than lim_m metres? */
static int wider_than(const struct sonar_xy *hull, int h, float lim_m)
{
    int64_t lim = (int64_t)((double)lim_m * 1000.0), lim2 = lim * lim;
    int a, b;
    for (a = 0; a < h; a++)
        for (b = a + 1; b < h; b++) {
            int64_t dx = (int64_t)hull[a].x - hull[b].x, dy = (int64_t)hull[a].y - hull[b].y;
            if (dx * dx + dy * dy > lim2)
                return 1;
        }
    return 0;
}

/*
 * A wall in one look (detector.h): a line of at least SONAR_DET_WALL_BEAMS beams, at least
 * SONAR_DET_WALL_M longer than a point target at its range smears (smear_mm: sonar_det_smear_mm) and at
 * most SONAR_DET_WALL_THICK_M thick (its hull's width), and at least SONAR_DET_WALL_ELONG times longer
 * than thick; or, SONAR_DET_WALL_LONG_M longer than the smear, seen obliquely or bent at a corner.
 */
static int wall_line(const struct sonar_det_cluster *cl, const struct sonar_xy *hull, int h, double smear_mm)
{
    int64_t diam, width;
    if (cl->nbeams < SONAR_DET_WALL_BEAMS)
        return 0;
    diam = sonar_hull_diameter(hull, (uint16_t)h);
    if ((double)diam < (double)SONAR_DET_WALL_M * 1000.0 + smear_mm)
        return 0;
    width = sonar_hull_width(hull, (uint16_t)h);
    if ((double)diam >= (double)SONAR_DET_WALL_LONG_M * 1000.0 + smear_mm &&
        ((double)diam >= SONAR_DET_WALL_LONG_ELONG * (double)width || sonar_det_thin(cl->thick, cl->nbeams)))
        return 1;
    return width <= (int64_t)(SONAR_DET_WALL_THICK_M * 1000.0f) && (double)diam >= SONAR_DET_WALL_ELONG * (double)width;
}

void sonar_det_clusters(const struct sonar_detector *d, uint8_t k, struct sonar_det_cluster *cl)
{
    const uint32_t line = sonar_det_line_samples(d);
    uint16_t i;
    uint8_t j;
    for (j = 0; j < k; j++) {
        memset(&cl[j], 0, sizeof(cl[j]));
        cl[j].rlo = UINT32_MAX;
        cl[j].beam = 0xFFFFu;
    }
    for (i = 0; i < d->nruns; i++) {
        const struct sonar_detector_run *r = &d->runs[i];
        struct sonar_det_cluster *q;
        uint32_t end;
        if (d->labels[i] >= k)
            continue;
        q = &cl[d->labels[i]];
        q->w += d->pts[i].w;
        q->rw += (uint64_t)d->pts[i].w * (2u * (uint32_t)r->start + d->pts[i].w);
        q->sx += (int64_t)d->pts[i].x * d->pts[i].w;
        q->sy += (int64_t)d->pts[i].y * d->pts[i].w;
        end = (uint32_t)r->start + d->pts[i].w - 1u;
        q->rlo = r->start < q->rlo ? r->start : q->rlo;
        q->rhi = end > q->rhi ? end : q->rhi;
        if (q->beam == 0xFFFFu)
            q->first = i;
        q->last = i;
        if (r->beam != q->beam) {
            if (q->beam != 0xFFFFu)
                q->thick = (uint16_t)(q->thick + ((uint32_t)(q->bhi - q->blo) + 1u > line));
            q->beam = r->beam;
            q->nbeams++;
            q->blo = r->start;
            q->bhi = (uint16_t)end;
        } else {
            q->blo = r->start < q->blo ? r->start : q->blo;
            q->bhi = end > q->bhi ? (uint16_t)end : q->bhi;
        }
    }
    for (j = 0; j < k; j++)
        if (cl[j].beam != 0xFFFFu)
            cl[j].thick = (uint16_t)(cl[j].thick + ((uint32_t)(cl[j].bhi - cl[j].blo) + 1u > line));
}

int sonar_det_accept(const struct sonar_detector *d, uint8_t j, const struct sonar_det_cluster *cl, int cut,
                     struct sonar_detection *o, struct sonar_xy *at)
{
    struct hull_scratch hs;
    uint64_t w = cl->w, s = 0, st = 0;
    int64_t sx = cl->sx, sy = cl->sy;
    uint16_t i, nw = 0, beam = 0xFFFFu;
    uint32_t lo = 0, hi = 0;
    int h, v, wide = 0;
    double c = 1.0, sn = 0.0;
    if (w == 0 || cl->beam == 0xFFFFu)
        return 0;
    at->x = (int32_t)(sx / (int64_t)w);
    at->y = (int32_t)(sy / (int64_t)w);
    if (!passes(d, cl, at->x, at->y, cut))
        return 0;
    for (i = cl->first; i <= cl->last; i++) {
        const struct sonar_detector_run *r = &d->runs[i];
        uint32_t end;
        if (d->labels[i] != j)
            continue;
        s += r->sum;
        st += (uint64_t)d->dt_ms[r->beam] * d->pts[i].w;
        end = (uint32_t)r->start + d->pts[i].w - 1u;
        /* Runs of one beam lie on one ray: only its nearest and farthest cells can be hull vertices. */
        if (r->beam != beam) {
            if (beam != 0xFFFFu) {
                hull_push(&hs, &nw, sonar_det_polar_mm(d, d->angles[beam], 2u * lo + 1u));
                hull_push(&hs, &nw, sonar_det_polar_mm(d, d->angles[beam], 2u * hi + 1u));
            }
            beam = r->beam;
            lo = r->start;
            hi = end;
        } else {
            lo = r->start < lo ? r->start : lo;
            hi = end > hi ? end : hi;
        }
    }
    hull_push(&hs, &nw, sonar_det_polar_mm(d, d->angles[beam], 2u * lo + 1u));
    hull_push(&hs, &nw, sonar_det_polar_mm(d, d->angles[beam], 2u * hi + 1u));
    h = sonar_hull_build(hs.work, nw, hs.hull, 2 * SONAR_HULL_WORK);
    if (h < 1)
        return 0;
    /* Wider than any object (a wall, a rope, a dock's edge), or a piece of wall cut from a wider group: structure. */
    wide = (d->cfg.max_extent_m > 0.0f && wider_than(hs.hull, h, d->cfg.max_extent_m)) ||
           (cut && sonar_det_thin(cl->thick, cl->nbeams)) ||
           (d->cfg.max_extent_m > 0.0f &&
            (wall_line(cl, hs.hull, h, sonar_det_smear_mm(d, sqrt((double)at->x * at->x + (double)at->y * at->y))) ||
             sonar_det_on_edge(d, j, cl)));
    if (!wide && sonar_det_in_tail(d, j, cl))
        return 0;
    if (d->cfg.angle_offset != 0.0f) {
        double th = sonar_frame_rad((double)d->cfg.angle_offset);
        c = cos(th);
        sn = sin(th);
    }
    memset(o, 0, sizeof(*o));
    o->utime = d->t0 + (int64_t)(st * 1000u / w);
    o->points = (uint32_t)w;
    o->mean_intensity = (float)((double)s / (double)w);
    o->x_m = (float)((double)sx / (double)w / 1000.0);
    o->y_m = (float)((double)sy / (double)w / 1000.0);
    o->area_m2 = (float)((double)sonar_hull_area2(hs.hull, (uint16_t)h) / 2.0e6);
    o->hull_count = (uint8_t)(h > SONAR_MAX_HULL ? SONAR_MAX_HULL : h);
    for (v = 0; v < o->hull_count; v++) {
        const struct sonar_xy *p = &hs.hull[(long)v * h / o->hull_count];
        o->hull_x[v] = (float)p->x / 1000.0f;
        o->hull_y[v] = (float)p->y / 1000.0f;
        if (d->cfg.angle_offset != 0.0f)
            rotate(&o->hull_x[v], &o->hull_y[v], c, sn);
    }
    if (d->cfg.angle_offset != 0.0f)
        rotate(&o->x_m, &o->y_m, c, sn);
    o->range_m = (float)sqrt((double)o->x_m * o->x_m + (double)o->y_m * o->y_m);
    o->bearing_deg = (float)(o->x_m == 0.0f && o->y_m == 0.0f ? 0.0 : sonar_frame_deg(atan2((double)o->y_m, (double)o->x_m)));
    if (o->bearing_deg < 0.0f)
        o->bearing_deg += 360.0f;
    o->kind = wide ? SONAR_DET_STRUCTURE : SONAR_DET_OBJECT;
    return wide ? 2 : 1;
}

