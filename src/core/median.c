/* median.c -- selection-network medians as straight-line byte min/max: 1-D over a padded beam, K x K over the padded delay line, 64 outputs a block; stack <= 1.3 KB, no heap. */
#include "sonar/median.h"

#include <string.h>

#include "simd_internal.h"
#include "tables_internal.h"

#define LANES 64

/* Min to a, max to b; the compiler turns these into byte min/max instructions. */
#define CE(a, b)                                                                                                   \
    {                                                                                                              \
        uint8_t lo_ = (a) < (b) ? (a) : (b), hi_ = (a) < (b) ? (b) : (a);                                        \
        (a) = lo_;                                                                                                 \
        (b) = hi_;                                                                                                 \
    }

/* out[j] for j in [j0, j0 + len): the window of out[j] starts at q[j], q = pad + j0 + PAD - W/2. */
#define MEDIAN_SPAN(W, q, o, len)                                                                                  \
    for (j = 0; j < (len); j++) {                                                                                  \
        uint8_t v[W];                                                                                              \
        SONAR_NET##W##_LOAD(v, q, j)                                                                               \
        SONAR_NET##W##_APPLY(v, CE)                                                                                \
        (o)[j] = v[(W) / 2];                                                                                       \
    }

#define PAD (SONAR_MAX_MEDIAN / 2)

#if SONAR_SIMD32

/*
 * Four samples per word on ARMv7E-M (Cortex-M4/M7 have no vector unit, but byte-wise saturating
 * arithmetic): d = uqsub8(a, b) is max(a - b, 0) per byte, so a - d is the minimum and b + d the
 * maximum, and neither can borrow or carry across bytes. Three instructions exchange four pairs.
 */
#define CE4(a, b)                                                                                                  \
    {                                                                                                              \
        uint32_t d_ = __uqsub8((a), (b));                                                                          \
        (a) -= d_;                                                                                                 \
        (b) += d_;                                                                                                 \
    }
/* Unrolled word loads of the window (unaligned loads are single instructions on ARMv7E-M). */
#define L4(v, p, k) memcpy(&(v)[k], (p) + (k), 4);
#define LOADS_3(v, p) L4(v, p, 0) L4(v, p, 1) L4(v, p, 2)
#define LOADS_5(v, p) LOADS_3(v, p) L4(v, p, 3) L4(v, p, 4)
#define LOADS_7(v, p) LOADS_5(v, p) L4(v, p, 5) L4(v, p, 6)
#define LOADS_9(v, p) LOADS_7(v, p) L4(v, p, 7) L4(v, p, 8)
#define MEDIAN_BEAM(W)                                                                                             \
    {                                                                                                              \
        const uint8_t *q = pad + PAD - (W) / 2;                                                                    \
        for (j = 0; j + 4 <= (int)n; j += 4) {                                                                     \
            uint32_t v[W];                                                                                         \
            LOADS_##W(v, q + j)                                                                                    \
            SONAR_NET##W##_APPLY(v, CE4)                                                                           \
            memcpy(out + j, &v[(W) / 2], 4);                                                                       \
        }                                                                                                          \
        j0 = j;                                                                                                    \
        MEDIAN_SPAN(W, q + j0, out + j0, (int)n - j0)                                                              \
    }
#else
/*
 * Full 64-sample blocks have a constant trip count, so -O2 vectorises them. A ragged end is one
 * more block ending at n, overlapping the one before (recomputed to the same values); only beams
 * shorter than a block run scalar.
 */
#define MEDIAN_BEAM(W)                                                                                             \
    for (j0 = 0; j0 + LANES <= (int)n; j0 += LANES)                                                                \
        MEDIAN_SPAN(W, pad + j0 + PAD - (W) / 2, out + j0, LANES)                                                  \
    if (j0 < (int)n && n >= LANES) {                                                                               \
        j0 = (int)n - LANES;                                                                                       \
        MEDIAN_SPAN(W, pad + j0 + PAD - (W) / 2, out + j0, LANES)                                                  \
    } else {                                                                                                       \
        MEDIAN_SPAN(W, pad + j0 + PAD - (W) / 2, out + j0, (int)n - j0)                                            \
    }
#endif

int sonar_median_1d(const uint8_t *in, uint8_t *out, uint16_t n, uint8_t window)
{
    uint8_t pad[SONAR_MAX_SAMPLES + 2 * PAD];
    int j0, j;
    unsigned k;
    if (in == NULL || out == NULL || n == 0 || n > SONAR_MAX_SAMPLES || window > SONAR_MAX_MEDIAN)
        return SONAR_ERR_ARG;
    memcpy(pad + PAD, in, n);
    for (k = 0; k < PAD; k++) {
        pad[k] = in[0];
        pad[PAD + n + k] = in[n - 1];
    }
    switch (window) {
    case 3: MEDIAN_BEAM(3) break;
    case 5: MEDIAN_BEAM(5) break;
#if SONAR_MAX_MEDIAN >= 7
    case 7: MEDIAN_BEAM(7) break;
#endif
#if SONAR_MAX_MEDIAN >= 9
    case 9: MEDIAN_BEAM(9) break;
#endif
    default: return SONAR_ERR_ARG;
    }
    return SONAR_OK;
}

int sonar_median2d_init(struct sonar_median2d *m, uint8_t k)
{
    if (m == NULL || (k != 3 && k != 5) || k > SONAR_MAX_MEDIAN2D)
        return SONAR_ERR_ARG;
    memset(m, 0, sizeof(*m));
    m->k = k;
    return SONAR_OK;
}

/* Window loads of the K x K median: v[K r + c] = p_r[j + c], rows p0..p(K-1) offset to the window's first column. */
#define M2_ROW3(v, b, p, j) v[b] = (p)[(j)]; v[(b) + 1] = (p)[(j) + 1]; v[(b) + 2] = (p)[(j) + 2];
#define M2_ROW5(v, b, p, j) M2_ROW3(v, b, p, j) v[(b) + 3] = (p)[(j) + 3]; v[(b) + 4] = (p)[(j) + 4];
#define M2_LOAD3(v, j) M2_ROW3(v, 0, p0, j) M2_ROW3(v, 3, p1, j) M2_ROW3(v, 6, p2, j)
#define M2_LOAD5(v, j) M2_ROW5(v, 0, p0, j) M2_ROW5(v, 5, p1, j) M2_ROW5(v, 10, p2, j) M2_ROW5(v, 15, p3, j) M2_ROW5(v, 20, p4, j)

/*
 * out[0 .. len) of a K x K median, K x K = NET inputs (K = 3 runs the 9-input network). restrict
 * lets -O2 vectorise without runtime alias checks (the ring never overlaps out); the _block
 * forms have a constant trip count, which -O2's cheap vectoriser needs.
 */
#define M2_SPAN_FN(name, K, NET, LEN, ...)                                                                         \
    static void name(const uint8_t *restrict p0, const uint8_t *restrict p1, const uint8_t *restrict p2,          \
                     __VA_ARGS__ uint8_t *restrict out, int len)                                                 \
    {                                                                                                              \
        int j;                                                                                                     \
        (void)len;                                                                                                 \
        for (j = 0; j < (LEN); j++) {                                                                              \
            uint8_t v[(K) * (K)];                                                                                  \
            M2_LOAD##K(v, j)                                                                                       \
            SONAR_NET##NET##_APPLY(v, CE)                                                                          \
            out[j] = v[((K) * (K)) / 2];                                                                           \
        }                                                                                                          \
    }
#define M2_ROWS45 const uint8_t *restrict p3, const uint8_t *restrict p4,

M2_SPAN_FN(span3, 3, 9, len, )
#if SONAR_MAX_MEDIAN2D >= 5
M2_SPAN_FN(span5, 5, 25, len, M2_ROWS45)
#endif
#if !SONAR_SIMD32
M2_SPAN_FN(span3_block, 3, 9, LANES, )
#if SONAR_MAX_MEDIAN2D >= 5
M2_SPAN_FN(span5_block, 5, 25, LANES, M2_ROWS45)
#endif
#endif

#if SONAR_SIMD32
#define M2_W(v, b, p, j) memcpy(&(v)[b], (p) + (j), 4);
#define M2_ROW3W(v, b, p, j) M2_W(v, b, p, j) M2_W(v, (b) + 1, p, (j) + 1) M2_W(v, (b) + 2, p, (j) + 2)
#define M2_ROW5W(v, b, p, j) M2_ROW3W(v, b, p, j) M2_W(v, (b) + 3, p, (j) + 3) M2_W(v, (b) + 4, p, (j) + 4)
/* Four outputs per word as in the 1-D median; the last n % 4 run scalar. */
static void row3(const uint8_t *p0, const uint8_t *p1, const uint8_t *p2, uint8_t *out, int n)
{
    int j;
    for (j = 0; j + 4 <= n; j += 4) {
        uint32_t v[9];
        M2_ROW3W(v, 0, p0, j) M2_ROW3W(v, 3, p1, j) M2_ROW3W(v, 6, p2, j)
        SONAR_NET9_APPLY(v, CE4)
        memcpy(out + j, &v[4], 4);
    }
    span3(p0 + j, p1 + j, p2 + j, out + j, n - j);
}

#if SONAR_MAX_MEDIAN2D >= 5
static void row5(const uint8_t *const *p, uint8_t *out, int n)
{
    int j;
    for (j = 0; j + 4 <= n; j += 4) {
        uint32_t v[25];
        M2_ROW5W(v, 0, p[0], j) M2_ROW5W(v, 5, p[1], j) M2_ROW5W(v, 10, p[2], j) M2_ROW5W(v, 15, p[3], j)
        M2_ROW5W(v, 20, p[4], j)
        SONAR_NET25_APPLY(v, CE4)
        memcpy(out + j, &v[12], 4);
    }
    span5(p[0] + j, p[1] + j, p[2] + j, p[3] + j, p[4] + j, out + j, n - j);
}
#endif
#else
/*
 * Blocks of LANES outputs have a constant trip count, so -O2 vectorises them with the window in
 * registers. A ragged end is one more block ending at n that overlaps the one before: the overlap
 * is recomputed to the same values. Only rows shorter than LANES run scalar.
 */
static int next_block(int b, int n)
{
    return b + LANES >= n ? -1 : (b + 2 * LANES > n ? n - LANES : b + LANES);
}

static void row3(const uint8_t *p0, const uint8_t *p1, const uint8_t *p2, uint8_t *out, int n)
{
    int b;
    if (n < LANES)
        span3(p0, p1, p2, out, n);
    else
        for (b = 0; b >= 0; b = next_block(b, n))
            span3_block(p0 + b, p1 + b, p2 + b, out + b, LANES);
}

#if SONAR_MAX_MEDIAN2D >= 5
static void row5(const uint8_t *const *p, uint8_t *out, int n)
{
    int b;
    if (n < LANES)
        span5(p[0], p[1], p[2], p[3], p[4], out, n);
    else
        for (b = 0; b >= 0; b = next_block(b, n))
            span5_block(p[0] + b, p[1] + b, p[2] + b, p[3] + b, p[4] + b, out + b, LANES);
}
#endif
#endif

/* Filters row e of the sweep, whose rows 0..last are (partly) in the ring. */
static void release_row(struct sonar_median2d *m, uint32_t e, uint32_t last, uint8_t *out,
                        struct sonar_median_row *out_meta)
{
    const uint8_t *rows[SONAR_MAX_MEDIAN2D];
    unsigned k = m->k, h = k / 2u, r;
    for (r = 0; r < k; r++) {
        int64_t i = (int64_t)e - (int64_t)h + (int64_t)r;
        uint32_t row = i < 0 ? 0u : (i > (int64_t)last ? last : (uint32_t)i);
        /* Column j's window starts at sample j - h, stored at j - h + SONAR_MEDIAN2D_PAD. */
        rows[r] = m->ring[row % k] + SONAR_MEDIAN2D_PAD - h;
    }
    if (k == 3)
        row3(rows[0], rows[1], rows[2], out, (int)m->n);
#if SONAR_MAX_MEDIAN2D >= 5
    else
        row5(rows, out, (int)m->n);
#endif
    *out_meta = m->meta[e % k];
    m->released = e + 1;
}

int sonar_median2d_push(struct sonar_median2d *m, const uint8_t *row, uint16_t n, const struct sonar_median_row *meta,
                        uint8_t *out, struct sonar_median_row *out_meta)
{
    uint32_t t, h;
    if (m == NULL || row == NULL || meta == NULL || out == NULL || out_meta == NULL || n == 0 ||
        n > SONAR_MAX_SAMPLES || m->k == 0)
        return SONAR_ERR_ARG;
    if (m->pushed == 0)
        m->n = n;
    else if (n != m->n)
        return SONAR_ERR_ARG;
    t = m->pushed++;
    {
        uint8_t *dst = m->ring[t % m->k];
        unsigned b;
        memcpy(dst + SONAR_MEDIAN2D_PAD, row, n);
        for (b = 0; b < SONAR_MEDIAN2D_PAD; b++) {
            dst[b] = row[0];
            dst[SONAR_MEDIAN2D_PAD + n + b] = row[n - 1];
        }
    }
    m->meta[t % m->k] = *meta;
    h = m->k / 2u;
    if (t < h)
        return 0;
    release_row(m, t - h, t, out, out_meta);
    return 1;
}

int sonar_median2d_flush(struct sonar_median2d *m, uint8_t *out, struct sonar_median_row *out_meta)
{
    if (m == NULL || out == NULL || out_meta == NULL)
        return SONAR_ERR_ARG;
    if (m->released >= m->pushed) {
        m->pushed = 0;
        m->released = 0;
        return 0;
    }
    release_row(m, m->released, m->pushed - 1u, out, out_meta);
    return 1;
}
