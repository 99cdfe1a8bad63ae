/* detector_echo.c -- stage 5: objects behind a wall on its beams and weaker than it are the wall's echo (detector.h); for each run, a look at the runs of the beams beside it (they come beam by beam), no RAM beyond the stack's 0.3 KB. */
#include <string.h>

#include "detector_internal.h"

static int index_of(const uint8_t *labels, uint8_t n, uint8_t l)
{
    uint8_t i;
    for (i = 0; i < n; i++)
        if (labels[i] == l)
            return i;
    return -1;
}

/*
 * The runs on beam want, found from run i (the runs come beam by beam, so they lie next to each other,
 * on i's side): [*lo, *hi]. Returns 0 when the sweep has none there.
 */
static int beam_runs(const struct sonar_detector *d, uint16_t i, int32_t want, uint16_t *lo, uint16_t *hi)
{
    int32_t j = i;
    while (j > 0 && (int32_t)d->runs[j].beam > want)
        j--;
    while (j + 1 < (int32_t)d->nruns && (int32_t)d->runs[j].beam < want)
        j++;
    if ((int32_t)d->runs[j].beam != want)
        return 0;
    *lo = *hi = (uint16_t)j;
    while (*lo > 0 && (int32_t)d->runs[*lo - 1u].beam == want)
        (*lo)--;
    while (*hi + 1u < d->nruns && (int32_t)d->runs[*hi + 1u].beam == want)
        (*hi)++;
    return 1;
}

/*
 * The wall run i lies behind: on its own beam, or else on the nearest beam within SONAR_DET_ECHO_BEAMS
 * that has one (the echo comes back over the beam's width), the wall whose cells start nearest there
 * (no sound goes through it to a farther one), never wall self. Returns its index in walls and its
 * farthest cell on that beam in *far, or -1 when no wall is near.
 */
static int wall_before(const struct sonar_detector *d, uint16_t i, const uint8_t *walls, uint8_t nw, int self,
                       uint32_t *far)
{
    int32_t gap, side;
    for (gap = 0; gap <= SONAR_DET_ECHO_BEAMS; gap++) {
        int best = -1;
        uint32_t start = UINT32_MAX, end = 0;
        for (side = -1; side <= 1; side += 2) {
            uint16_t lo, hi, j;
            if (!beam_runs(d, i, (int32_t)d->runs[i].beam + side * gap, &lo, &hi))
                continue;
            for (j = lo; j <= hi; j++) {
                int w = index_of(walls, nw, d->labels[j]);
                if (w >= 0 && w != self && d->runs[j].start < start) {
                    best = w;
                    start = d->runs[j].start;
                }
            }
            for (j = lo; j <= hi && best >= 0; j++) {
                uint32_t e = (uint32_t)d->runs[j].start + d->pts[j].w - 1u;
                if (index_of(walls, nw, d->labels[j]) == best && e > end)
                    end = e;
            }
            if (gap == 0)
                break; /* the run's own beam, once */
        }
        if (best >= 0) {
            *far = end;
            return best;
        }
    }
    return -1;
}

void sonar_det_echoes(struct sonar_detector *d, const uint8_t *walls, const float *wall_level, uint8_t nw,
                      const uint8_t *objs, const float *obj_level, uint8_t no, uint8_t *echo, uint8_t *wall_echo)
{
    uint32_t behind[2 * SONAR_MAX_CLUSTERS], cells[2 * SONAR_MAX_CLUSTERS];
    uint16_t i;
    uint8_t k;
    memset(echo, 0, no);
    memset(wall_echo, 0, nw);
    if (nw == 0)
        return;
    /* Objects and walls alike: a wall behind a nearer, stronger one is that one's echo (twice its range). */
    memset(behind, 0, sizeof(behind));
    memset(cells, 0, sizeof(cells));
    for (i = 0; i < d->nruns; i++) {
        const struct sonar_detector_run *r = &d->runs[i];
        int o = index_of(objs, no, d->labels[i]), w = o < 0 ? index_of(walls, nw, d->labels[i]) : -1;
        int c = o >= 0 ? o : w >= 0 ? no + w : -1, at;
        uint32_t far = 0;
        if (c < 0)
            continue;
        cells[c] += d->pts[i].w;
        at = wall_before(d, i, walls, nw, w, &far);
        if (at >= 0 && r->start > far && (o >= 0 ? obj_level[o] : wall_level[w]) < wall_level[at])
            behind[c] += d->pts[i].w;
    }
    for (k = 0; k < no + nw; k++) {
        uint8_t e = (uint8_t)(cells[k] > 0 && 16u * (uint64_t)behind[k] >= (uint64_t)SONAR_DET_ECHO_16 * cells[k]);
        if (k < no)
            echo[k] = e;
        else
            wall_echo[k - no] = e;
    }
}
