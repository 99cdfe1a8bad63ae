/* detector_edge.c -- stage 4: a cluster holding the leading edge of its beams, the edge running on smoothly beside it, is the water's boundary (detector.h, SONAR_DET_EDGE_JUMP_M), and a faint one just behind it is its tail (SONAR_DET_TAIL_X); one pass over its runs and the edges beside it, no RAM beyond the detector's 3 B a beam (each one's edge and strongest level). */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "detector_internal.h"

void sonar_detector_set_edge(struct sonar_detector *d, uint16_t sample, uint8_t top)
{
    if (d != NULL && d->beams > 0u) {
        d->edge[d->beams - 1u] = sample;
        d->top[d->beams - 1u] = top;
    }
}

/* SONAR_DET_EDGE_JUMP_M in samples of this sweep, rounded up. */
static int32_t edge_jump(const struct sonar_detector *d)
{
    return (int32_t)((double)SONAR_DET_EDGE_JUMP_M * (double)d->n / (double)d->range_m) + 1;
}

/* Steps of the sweep from beam a to beam a + 1: 1, 2 with one beam left out between, 0 beyond (a gap, a jump). */
static unsigned gap_steps(const struct sonar_detector *d, uint16_t a, uint16_t step)
{
    uint16_t g = sonar_frame_gap(d->angles[a], d->angles[a + 1u]);
    return g <= step ? 1u : g <= 2u * step ? 2u : 0u;
}

/* How the edge beside a cluster ends (runs_on). */
enum side_end {
    SIDE_RUNS,   /* it ran on as far as was needed */
    SIDE_SECTOR, /* the sector ends, or a gap in it */
    SIDE_NEARER, /* something nearer takes the edge over: the wall may run on behind it */
    SIDE_OPEN    /* the edge jumps farther away, is much weaker or the beam holds none: not this line beside it */
};

/*
 * How far (mm, along the edge) the edge runs on from beam `from` towards dir (-1 or +1), each beam's
 * within jump samples of where the last two beams' edges point (at first the cluster's slope at that end,
 * slope16 in 16ths of a sample a beam: a corner bends it) and at least half as strong as top (the cluster's
 * strongest), stopping once it has run need_mm over SONAR_DET_EDGE_BEAMS beams or more (*beams: how
 * many); *how says why it ended. Behind something nearer (a person, a prop: SONAR_DET_EDGE_HIDE_M
 * across at most) the line is looked for where it comes out again, on its slope; up to
 * SONAR_DET_EDGE_FADED beams in a row where it is in place but fainter than half are passed over, not counted.
 */
static double runs_on(const struct sonar_detector *d, uint16_t from, int dir, int32_t slope16, int32_t jump,
                      uint8_t top, uint16_t step, double need_mm, enum side_end *how, unsigned *beams)
{
    const double arc_m = sonar_frame_rad((double)step) * (double)d->range_m / (double)d->n; /* a step's arc a sample of range */
    const double hide_max = (double)SONAR_DET_EDGE_HIDE_M;
    int32_t at = (int32_t)d->edge[from] * 16, b = (int32_t)from;
    struct sonar_xy p = sonar_det_polar_mm(d, d->angles[from], 2u * d->edge[from] + 1u), q;
    double run = 0.0, hidden = 0.0;
    unsigned faded = 0;
    *how = SIDE_RUNS;
    *beams = 0;
    while (run < need_mm || *beams < SONAR_DET_EDGE_BEAMS) {
        int32_t e, want, steps;
        b += dir;
        /* A beam left out between (a streak, or one lost) is bridged: the wall runs on across it. */
        steps = b < 0 || b >= (int32_t)d->beams ? 0 : (int32_t)gap_steps(d, (uint16_t)(dir < 0 ? b : b - 1), step);
        if (steps == 0) {
            *how = hidden > 0.0 ? SIDE_NEARER : SIDE_SECTOR;
            break;
        }
        want = at + dir * slope16 * steps;
        e = (int32_t)d->edge[b] * 16;
        if (d->edge[b] < d->n && want - e > jump * 16) {
            /* Something nearer: the line may run on behind it (its place moves on along the slope). */
            hidden += (double)want / 16.0 * arc_m * (double)steps;
            if (hidden > hide_max) {
                *how = SIDE_NEARER;
                break;
            }
            at = want;
            continue;
        }
        if (d->edge[b] < d->n && e - want <= jump * 16 && 2u * d->top[b] < top && faded < SONAR_DET_EDGE_FADED) {
            /* A fainter beam or two in place is the line's speckle or its aspect, not its end: bridged, as a streak is. */
            faded++;
            at = e;
            continue;
        }
        if (d->edge[b] >= d->n || e - want > jump * 16 || 2u * d->top[b] < top) {
            *how = hidden > 0.0 ? SIDE_NEARER : SIDE_OPEN;
            break;
        }
        faded = 0;
        /* Out from behind something, the line goes on from here: what it hid is not counted as seen. */
        q = sonar_det_polar_mm(d, d->angles[b], 2u * d->edge[b] + 1u);
        if (hidden == 0.0) {
            run += sqrt((double)(q.x - p.x) * (q.x - p.x) + (double)(q.y - p.y) * (q.y - p.y));
            slope16 = dir * (e - at) / steps;
        }
        hidden = 0.0;
        at = e;
        p = q;
        ++*beams;
    }
    return run;
}

/* A cluster's hold on the edge: its beams, those holding the edge (the first and last of them) and their strongest
   level, and the beams on which it is deeper than a wall would be there (wall_depth). */
struct hold {
    uint32_t nb, held, hidden, thick;
    uint16_t first, last;
    uint8_t top;
};

/*
 * How deep (samples) a wall's return on beam b may be: a line's depth (SONAR_DET_LINE_M), and as much as
 * the edge's range changes across the beam's width (its slope over the neighbours between first and last,
 * or the cluster's, slope16, 16ths of a sample a beam, if steeper; per_beam16: the beam width in sweep steps, 16ths). A person is deeper, as deep as the body, whatever the slope.
 */
static int32_t wall_depth(const struct sonar_detector *d, uint16_t b, uint16_t first, uint16_t last, uint16_t step,
                          int32_t per_beam16, int32_t slope16)
{
    int32_t lo = (int32_t)d->edge[b], hi = lo, span = 0;
    if (b > first && gap_steps(d, (uint16_t)(b - 1u), step) == 1u && d->edge[b - 1u] < d->n) {
        lo = (int32_t)d->edge[b - 1u];
        span++;
    }
    if (b < last && gap_steps(d, b, step) == 1u && d->edge[b + 1u] < d->n) {
        hi = (int32_t)d->edge[b + 1u];
        span++;
    }
    /* The slope is the steeper of the neighbours' and the cluster's (the edges are found to a CFAR block). */
    if (span && abs(hi - lo) * 16 / span > abs(slope16))
        slope16 = (hi - lo) * 16 / span;
    return (int32_t)sonar_det_line_samples(d) + abs(slope16) * per_beam16 / 256;
}

/*
 * One pass over cluster j's runs: the beams that hold the edge (a run of the beam holds it, within the
 * pulse's few samples, or begins within jump samples behind it: the CFAR cuts an oblique wall's slowly
 * rising return), and those on which it lies behind something nearer (hidden there: its own edge cannot
 * be seen); with first <= last (the beams holding it, from a pass before), also the beams deeper than a
 * wall's return (wall_depth).
 */
static void hold_of(const struct sonar_detector *d, uint8_t j, const struct sonar_det_cluster *cl, uint16_t step,
                    int32_t jump, uint16_t first, uint16_t last, int32_t slope16, struct hold *h)
{
    const int32_t tol = 2;
    const int32_t per_beam16 = (int32_t)(16.0 * SONAR_BEAM_WIDTH_DEG / ((double)step * SONAR_DEG_PER_GRAD) + 0.5);
    uint16_t i, beam = 0xFFFFu;
    int32_t lo = 0, hi = 0, deep = 0;
    int held_now = 0, hidden_now = 0;
    memset(h, 0, sizeof(*h));
    h->first = 0xFFFFu;
    for (i = cl->first; i <= cl->last + 1u; i++) {
        const struct sonar_detector_run *r = i <= cl->last ? &d->runs[i] : NULL;
        int32_t e, end;
        if (r != NULL && d->labels[i] != j)
            continue;
        if (r == NULL || r->beam != beam) {
            if (beam != 0xFFFFu) {
                h->held += (uint32_t)held_now;
                h->hidden += (uint32_t)(hidden_now && !held_now);
                h->thick += (uint32_t)(hi - lo + 1 > deep);
            }
            if (r == NULL)
                break;
            held_now = 0;
            hidden_now = 0;
            beam = r->beam;
            h->nb++;
            lo = r->start;
            hi = r->start;
            deep = first <= last ? wall_depth(d, beam, first, last, step, per_beam16, slope16) : INT32_MAX;
        }
        e = (int32_t)d->edge[r->beam];
        end = (int32_t)r->start + (int32_t)d->pts[i].w - 1;
        lo = r->start < lo ? r->start : lo;
        hi = end > hi ? end : hi;
        if (e < (int32_t)d->n && e + jump < r->start)
            hidden_now = 1;
        else if (e < (int32_t)d->n && ((r->start <= e + tol && e <= end + tol) || (r->start >= e && r->start <= e + jump))) {
            held_now = 1;
            h->top = d->top[r->beam] > h->top ? d->top[r->beam] : h->top;
            if (h->first == 0xFFFFu)
                h->first = r->beam;
            h->last = r->beam;
        }
    }
}

/*
 * The edge's slope (16ths of a sample a beam, along the sweep) at a cluster's end beam `end`, over up to
 * SONAR_DET_EDGE_BEAMS beams inward towards `other`: a straight wall's range bends along the sweep (r = d / cos),
 * so the slope at its end, not the cluster's mean, says where it runs on. slope16 (the cluster's) when that
 * beam holds no edge.
 */
static int32_t end_slope16(const struct sonar_detector *d, uint16_t end, uint16_t other, int32_t slope16)
{
    int32_t k = (int32_t)other - (int32_t)end, dir = k < 0 ? -1 : 1;
    uint16_t b;
    if (k == 0)
        return slope16;
    if (abs(k) > SONAR_DET_EDGE_BEAMS)
        k = dir * SONAR_DET_EDGE_BEAMS;
    b = (uint16_t)((int32_t)end + k);
    if (d->edge[b] >= d->n)
        return slope16;
    return ((int32_t)d->edge[b] - (int32_t)d->edge[end]) * 16 / k;
}

int sonar_det_on_edge(const struct sonar_detector *d, uint8_t j, const struct sonar_det_cluster *cl)
{
    const int32_t jump = edge_jump(d);
    const double need = (double)SONAR_DET_WALL_M * 1000.0;
    uint16_t step;
    int32_t slope16 = 0;
    unsigned nlo, nhi;
    double lo, hi, own, smear;
    enum side_end end_lo, end_hi;
    struct hold h;
    struct sonar_xy a, z;
    if (cl->beam == 0xFFFFu || d->beams == 0u)
        return 0;
    step = sonar_det_step(d);
    hold_of(d, j, cl, step, jump, 1u, 0u, 0, &h);
    if (h.first == 0xFFFFu || 16u * h.held < (uint32_t)SONAR_DET_EDGE_16 * (h.nb - h.hidden))
        return 0;
    /* The cluster's own slope along the edge, from the first and last beams that hold it (16ths of a sample a beam). */
    if (h.last > h.first)
        slope16 = ((int32_t)d->edge[h.last] - (int32_t)d->edge[h.first]) * 16 / (int32_t)(h.last - h.first);
    hold_of(d, j, cl, step, jump, h.first, h.last, slope16, &h);
    if (!sonar_det_thin(h.thick, h.nb))
        return 0;
    lo = runs_on(d, h.first, -1, end_slope16(d, h.first, h.last, slope16), jump, h.top, step, need, &end_lo, &nlo);
    hi = runs_on(d, h.last, +1, end_slope16(d, h.last, h.first, slope16), jump, h.top, step, need, &end_hi, &nhi);
    if ((lo >= need && nlo >= SONAR_DET_EDGE_BEAMS) || (hi >= need && nhi >= SONAR_DET_EDGE_BEAMS))
        return 1;
    /*
     * Otherwise a line along the edge SONAR_DET_WALL_M longer than a point target's smear, itself and as far
     * as the edge runs on beside it, cut by the sector's end on one side at least, and on the other ending
     * there too or where something nearer stands before it: an object takes the edge over from the open water
     * or the wall behind it.
     */
    a = sonar_det_polar_mm(d, d->angles[h.first], 2u * d->edge[h.first] + 1u);
    z = sonar_det_polar_mm(d, d->angles[h.last], 2u * d->edge[h.last] + 1u);
    own = sqrt((double)(z.x - a.x) * (z.x - a.x) + (double)(z.y - a.y) * (z.y - a.y));
    smear = sonar_det_smear_mm(d, sqrt((double)a.x * a.x + (double)a.y * a.y));
    return (end_lo == SIDE_SECTOR || end_hi == SIDE_SECTOR) && end_lo != SIDE_OPEN && end_hi != SIDE_OPEN &&
           own + lo + hi >= need + smear;
}

int sonar_det_in_tail(const struct sonar_detector *d, uint8_t j, const struct sonar_det_cluster *cl)
{
    const int32_t jump = edge_jump(d);
    const int32_t deep = jump + (int32_t)sonar_det_line_samples(d);
    uint64_t s = 0;
    uint32_t top = 255u;
    uint16_t i;
    if (cl->w == 0)
        return 0;
    for (i = cl->first; i <= cl->last; i++) {
        const struct sonar_detector_run *r = &d->runs[i];
        int32_t e = (int32_t)d->edge[r->beam];
        if (d->labels[i] != j)
            continue;
        if (e >= (int32_t)d->n || (int32_t)r->start <= e + jump || (int32_t)r->start > e + deep)
            return 0;
        s += r->sum;
        top = d->top[r->beam] < top ? d->top[r->beam] : top;
    }
    return (uint64_t)SONAR_DET_TAIL_X * s < (uint64_t)top * cl->w;
}
