/* median.c -- selection-network medians: 1-D as straight-line byte min/max over a padded beam, K x K over 64-byte lanes; stack <= 1.6 KB, no heap. */
#include "sonar/median.h"

#include <string.h>

#include "tables_internal.h"

#define LANES 64

typedef uint8_t lane_t[LANES];

struct net {
    const uint8_t (*ce)[2];
    unsigned count;
};

static struct net net_for(unsigned size)
{
    struct net n = {NULL, 0};
    switch (size) {
    case 3: n.ce = sonar_net3; n.count = sizeof(sonar_net3) / sizeof(sonar_net3[0]); break;
    case 5: n.ce = sonar_net5; n.count = sizeof(sonar_net5) / sizeof(sonar_net5[0]); break;
    case 7: n.ce = sonar_net7; n.count = sizeof(sonar_net7) / sizeof(sonar_net7[0]); break;
    case 9: n.ce = sonar_net9; n.count = sizeof(sonar_net9) / sizeof(sonar_net9[0]); break;
    case 25: n.ce = sonar_net25; n.count = sizeof(sonar_net25) / sizeof(sonar_net25[0]); break;
    default: break;
    }
    return n;
}

/* One compare-exchange across all lanes: min to a, max to b. No branches, so no data-dependent timing. */
static void exchange(uint8_t *restrict a, uint8_t *restrict b)
{
    unsigned j;
    for (j = 0; j < LANES; j++) {
        uint8_t x = a[j], y = b[j];
        a[j] = x < y ? x : y;
        b[j] = x < y ? y : x;
    }
}

static void run_net(lane_t *v, struct net n)
{
    unsigned c;
    for (c = 0; c < n.count; c++)
        exchange(v[n.ce[c][0]], v[n.ce[c][1]]);
}

/* Lane = in[s .. s+LANES) with indices clamped to [0, n): the replicated border. */
static void load_lane(uint8_t *lane, const uint8_t *in, int32_t s, uint16_t n)
{
    int32_t j;
    if (s >= 0 && s + LANES <= (int32_t)n) {
        memcpy(lane, in + s, LANES);
        return;
    }
    for (j = 0; j < LANES; j++) {
        int32_t i = s + j;
        lane[j] = in[i < 0 ? 0 : (i >= (int32_t)n ? (int32_t)n - 1 : i)];
    }
}

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

#if defined(__ARM_FEATURE_SIMD32)
#include <arm_acle.h>

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
/* Full 64-sample blocks have a constant trip count, so -O2 vectorises them; the tail runs scalar. */
#define MEDIAN_BEAM(W)                                                                                             \
    for (j0 = 0; j0 + LANES <= (int)n; j0 += LANES)                                                                \
        MEDIAN_SPAN(W, pad + j0 + PAD - (W) / 2, out + j0, LANES)                                                  \
    MEDIAN_SPAN(W, pad + j0 + PAD - (W) / 2, out + j0, (int)n - j0)
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

/* Filters row e of the sweep, whose rows 0..last are (partly) in the ring. */
static void emit(struct sonar_median2d *m, uint32_t e, uint32_t last, uint8_t *out, struct sonar_median_row *out_meta)
{
    lane_t v[SONAR_MAX_MEDIAN2D * SONAR_MAX_MEDIAN2D];
    const uint8_t *rows[SONAR_MAX_MEDIAN2D];
    unsigned k = m->k, h = k / 2u, r, c;
    struct net net = net_for(k * k);
    uint32_t j0;
    for (r = 0; r < k; r++) {
        int64_t i = (int64_t)e - (int64_t)h + (int64_t)r;
        uint32_t row = i < 0 ? 0u : (i > (int64_t)last ? last : (uint32_t)i);
        rows[r] = m->ring[row % k];
    }
    for (j0 = 0; j0 < m->n; j0 += LANES) {
        uint32_t w = m->n - j0 < LANES ? m->n - j0 : LANES;
        for (r = 0; r < k; r++)
            for (c = 0; c < k; c++)
                load_lane(v[r * k + c], rows[r], (int32_t)j0 - (int32_t)h + (int32_t)c, m->n);
        run_net(v, net);
        memcpy(out + j0, v[(k * k) / 2u], w);
    }
    *out_meta = m->meta[e % k];
    m->emitted = e + 1;
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
    memcpy(m->ring[t % m->k], row, n);
    m->meta[t % m->k] = *meta;
    h = m->k / 2u;
    if (t < h)
        return 0;
    emit(m, t - h, t, out, out_meta);
    return 1;
}

int sonar_median2d_flush(struct sonar_median2d *m, uint8_t *out, struct sonar_median_row *out_meta)
{
    if (m == NULL || out == NULL || out_meta == NULL)
        return SONAR_ERR_ARG;
    if (m->emitted >= m->pushed) {
        m->pushed = 0;
        m->emitted = 0;
        return 0;
    }
    emit(m, m->emitted, m->pushed - 1u, out, out_meta);
    return 1;
}
