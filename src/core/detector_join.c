/* detector_join.c -- stage 2: runs that touch become groups (union-find, beam-by-beam sorted merges, wrap-around on full turns); O(runs x join_beams) per sweep. */
#include "detector_internal.h"

uint16_t sonar_det_find(struct sonar_detector_run *r, uint16_t i)
{
    while (r[i].parent != i) {
        r[i].parent = r[r[i].parent].parent; /* path halving keeps later finds short */
        i = r[i].parent;
    }
    return i;
}

static void unite(struct sonar_detector_run *r, uint16_t a, uint16_t b)
{
    uint16_t ra = sonar_det_find(r, a), rb = sonar_det_find(r, b);
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

/*
 * Unites the touching runs of two beams' run lists [a, ae) and [b, be). Each list is sorted by
 * start and, its runs being disjoint, by end too, so a merge that steps past whichever run ends
 * first meets every touching pair or one that joins the same groups through a neighbour in its own
 * beam (linked below): O(length of both lists).
 */
static void join_pair(struct sonar_detector *d, uint16_t a, uint16_t ae, uint16_t b, uint16_t be, uint32_t gap)
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

void sonar_det_join(struct sonar_detector *d)
{
    uint32_t gap = (uint32_t)((double)d->cfg.join_m * (double)d->n / (double)d->range_m);
    uint16_t i, e, lb = d->cfg.join_beams;
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
            join_pair(d, p0, p1, i, e, gap);
            p1 = p0;
        }
    }
    /* A full turn: the last beams adjoin the first ones across the start angle. */
    if (d->beams > 2u * lb + 1u) {
        uint16_t step = sonar_frame_gap(d->angles[0], d->angles[1]);
        uint16_t reach = (uint16_t)(lb * (step ? step : 1u));
        uint16_t a0, a1 = d->nruns;
        if (sonar_frame_gap(d->angles[0], d->angles[d->beams - 1u]) > reach)
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
                if (sonar_frame_gap(d->angles[ab], d->angles[bb]) <= reach)
                    join_pair(d, b0, b1, a0, a1, gap);
                b0 = b1;
            }
            a1 = a0;
        }
    }
}

