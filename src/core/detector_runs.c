/* detector_runs.c -- stage 1: each foreground beam's statistics, the threshold and its above-threshold runs; O(n) per beam, blocks of 64 samples skipped when their maximum is below the threshold. */
#include <math.h>
#include <string.h>

#include "detector_internal.h"
#include "simd_internal.h"
#include "tables_internal.h"

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

struct sonar_xy sonar_det_polar_mm(const struct sonar_detector *d, uint16_t a, uint32_t twice_pos)
{
    struct sonar_xy p;
    uint64_t num = (uint64_t)twice_pos * d->range_mm;
    /* One 32-bit divide when the product fits (up to 1000 m at 1200 samples), not a 64-bit library call. */
    int64_t r = num <= UINT32_MAX ? (int64_t)((uint32_t)num / (2u * (uint32_t)d->n))
                                  : (int64_t)(num / (2u * (uint64_t)d->n));
    int64_t c = sonar_cos_q16[a % SONAR_GRAD_TURN], s = sonar_cos_q16[(a + 300u) % SONAR_GRAD_TURN]; /* sin a = cos(a - 100) */
    p.x = (int32_t)((r * c + 32768) >> 16);
    p.y = (int32_t)((r * s + 32768) >> 16);
    return p;
}

static void add_run(struct sonar_detector *d, uint16_t beam, uint16_t start, uint16_t len, uint32_t sum)
{
    struct sonar_xy c;
    struct sonar_detector_run *r;
    if (d->nruns >= SONAR_MAX_RUNS) {
        d->runs_dropped++;
        return;
    }
    /* Centre of the run: halfway between its first and last sample centres. */
    c = sonar_det_polar_mm(d, d->angles[beam], 2u * start + len);
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
        bq += (uint16_t)(v * v); /* a square fits 16 bits: 16-bit vector multiplies */                        \
        bm = v > bm ? v : bm;                                                                                      \
    }

#if SONAR_SIMD32

/*
 * One 64-sample block four samples a word on ARMv7E-M: usada8 adds four bytes, smlad squares and
 * adds two halfword lanes (a beam's sum of squares, 1200 * 255^2, stays below 2^31), and
 * m + uqsub8(x, m) is the byte-wise maximum.
 */
static uint8_t block4(const uint8_t *p, uint32_t *bs, uint32_t *bq)
{
    uint32_t s = *bs, mx = 0;
    int32_t q = (int32_t)*bq;
    int w;
    for (w = 0; w < BLOCK / 4; w++) {
        uint32_t x, lo, hi;
        memcpy(&x, p + 4 * w, 4);
        s = __usada8(x, 0u, s);
        lo = x & 0x00FF00FFu;
        hi = (x >> 8) & 0x00FF00FFu;
        q = __smlad((int16x2_t)lo, (int16x2_t)lo, q);
        q = __smlad((int16x2_t)hi, (int16x2_t)hi, q);
        mx += __uqsub8(x, mx);
    }
    *bs = s;
    *bq = (uint32_t)q;
    /* The four lanes' maxima to one: bytes 0,1 take max(b0, b2), max(b1, b3); then byte 0 takes both. */
    mx += __uqsub8(mx >> 16, mx);
    mx += __uqsub8(mx >> 8, mx);
    return (uint8_t)(mx & 0xFFu);
}
#endif

static void beam_stats(const uint8_t *fg, uint16_t n, uint32_t *s, uint32_t *q, uint8_t *blockmax)
{
    uint32_t bs = 0, bq = 0;
    uint8_t bm;
    int j, j0, b = 0;
    for (j0 = 0; j0 + BLOCK <= (int)n; j0 += BLOCK) {
#if SONAR_SIMD32
        blockmax[b++] = block4(fg + j0, &bs, &bq);
        continue;
#endif
        bm = 0;
        STATS_SPAN(fg + j0, BLOCK)
        blockmax[b++] = bm;
    }
    bm = 0;
    if (j0 < (int)n) {
        /* The ragged end zero-padded to a full block: zeros add nothing to the sums or the maximum. */
        uint8_t tail[BLOCK];
        memset(tail, 0, sizeof(tail));
        memcpy(tail, fg + j0, (size_t)((int)n - j0));
#if SONAR_SIMD32
        bm = block4(tail, &bs, &bq);
#else
        STATS_SPAN(tail, BLOCK)
#endif
    }
    blockmax[b] = bm;
    *s = bs;
    *q = bq;
}

/* The runs of nonzero cells inside the blocks that pass (a run may span several). */
static void block_runs(struct sonar_detector *d, uint16_t beam, const uint8_t *fg, const uint8_t *on, uint16_t n)
{
    uint16_t i = 0, start, nb = (uint16_t)((n + SONAR_CFAR_BLOCK - 1u) / SONAR_CFAR_BLOCK);
    d->threshold = d->cfg.cfar.floor;
    while (i < n) {
        uint32_t sum = 0;
        unsigned b = i / SONAR_CFAR_BLOCK;
        if (!on[b]) {
            /* Past the failed blocks, eight flags at a time: most of a beam fails. */
            uint64_t eight = 0;
            for (b++; b + 8u <= nb; b += 8u) {
                memcpy(&eight, on + b, 8);
                if (eight != 0)
                    break;
            }
            while (b < nb && !on[b])
                b++;
            i = (uint16_t)(b * SONAR_CFAR_BLOCK);
            continue;
        }
        if (fg[i] == 0) {
            i++;
            continue;
        }
        start = i;
        while (i < n && on[i / SONAR_CFAR_BLOCK] && fg[i] != 0)
            sum += fg[i++];
        add_run(d, beam, start, (uint16_t)(i - start), sum);
    }
}

/* A new beam's slot: its angle and time logged. Returns its index, or SONAR_ERR_ARG, _STATE or _FULL. */
static int open_beam(struct sonar_detector *d, uint16_t angle, const uint8_t *fg, uint16_t n, float range_m,
                     int64_t utime)
{
    int beam;
    if (d == NULL || fg == NULL || n == 0 || n > SONAR_MAX_SAMPLES || angle > SONAR_GRAD_MAX ||
        !(range_m > 0.0f && range_m <= (float)SONAR_DET_DISTANCE_MAX))
        return SONAR_ERR_ARG;
    if (d->beams == 0) {
        d->n = n;
        d->range_m = range_m;
        d->range_mm = (uint32_t)((double)range_m * 1000.0 + 0.5);
    } else if (n != d->n || range_m != d->range_m) {
        return SONAR_ERR_STATE;
    }
    if (d->beams >= SONAR_MAX_SWEEP_BEAMS)
        return SONAR_ERR_FULL;
    beam = d->beams++;
    d->angles[beam] = angle;
    d->utime = utime;
    if (beam == 0)
        d->t0 = utime;
    /* Milliseconds are plenty (a beam takes 28 ms or more) and halve the log. A clock that steps
       back inside a sweep counts as no time; a sweep longer than 65.5 s saturates. */
    d->dt_ms[beam] = (uint16_t)(utime <= d->t0 ? 0 : ((utime - d->t0) / 1000 > 65535 ? 65535 : (utime - d->t0) / 1000));
    d->edge[beam] = n; /* none until sonar_detector_set_edge */
    d->top[beam] = 0;
    return beam;
}

int sonar_detector_add_blocks(struct sonar_detector *d, uint16_t angle, const uint8_t *fg, const uint8_t *on, uint16_t n,
                              float range_m, int64_t utime)
{
    int beam;
    if (on == NULL)
        return SONAR_ERR_ARG;
    if ((beam = open_beam(d, angle, fg, n, range_m, utime)) < 0)
        return beam;
    block_runs(d, (uint16_t)beam, fg, on, n);
    return SONAR_OK;
}

int sonar_detector_add(struct sonar_detector *d, uint16_t angle, const uint8_t *fg, uint16_t n, float range_m,
                       int64_t utime)
{
    uint8_t blockmax[NBLOCKS + 1];
    uint32_t s = 0, q = 0;
    uint16_t i, beam, b, nb;
    uint8_t t;
    int r;
    if ((r = open_beam(d, angle, fg, n, range_m, utime)) < 0)
        return r;
    beam = (uint16_t)r;
    if (d->cfg.threshold_mode == SONAR_DET_CFAR) {
        uint8_t on[SONAR_CFAR_MAX_BLOCKS];
        if (sonar_cfar_blocks(&d->cfg.cfar, fg, n, on, NULL) >= 0)
            block_runs(d, beam, fg, on, n);
        return SONAR_OK;
    }
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

