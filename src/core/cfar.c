/* cfar.c -- order-statistic CFAR over 8-sample block means along a beam; O(n) block sums, then a sorting network run eight blocks at a time (lanes vectorise) where a window could pass; no heap, no state. */
#include "sonar/cfar.h"

#include <string.h>

#include "simd_internal.h"

#define LANES 8 /* blocks ranked side by side: int16 lanes of one 128-bit vector */
#define MAX_TRAIN (2 * SONAR_CFAR_TRAIN_MAX)

const char *sonar_cfar_config_check(const struct sonar_cfar_config *c)
{
    if (c->across > 1)
        return "cfar.across: 0 or 1 beam each side";
    if (c->cut > SONAR_CFAR_CUT_MAX)
        return "cfar.cut: 0.." SONAR_STR(SONAR_CFAR_CUT_MAX) " blocks";
    if (c->guard > SONAR_CFAR_GUARD_MAX)
        return "cfar.guard: 0.." SONAR_STR(SONAR_CFAR_GUARD_MAX) " blocks";
    if (c->train < 1 || c->train > SONAR_CFAR_TRAIN_MAX)
        return "cfar.train: 1.." SONAR_STR(SONAR_CFAR_TRAIN_MAX) " blocks";
    if (c->rank16 < 1 || c->rank16 > 16)
        return "cfar.rank16: 1..16 sixteenths";
    if (!(c->scale >= (float)SONAR_CFAR_SCALE_MIN && c->scale <= (float)SONAR_CFAR_SCALE_MAX))
        return "cfar.scale: " SONAR_STR(SONAR_CFAR_SCALE_MIN) ".." SONAR_STR(SONAR_CFAR_SCALE_MAX);
    if (c->floor > 254)
        return "cfar.floor: 0..254 grey levels";
    return NULL;
}

/*
 * Sums of each block of 8 samples (at most 2040); a short last block scaled to a full one. Returns
 * the block count. Sixteen blocks at a time through a constant-length loop, which -O2 vectorises
 * (on ARMv7E-M, usad8 against zero sums four bytes; on x86-64, psadbw eight).
 */
#define SUM_RUN 16
static int block_sums(const uint8_t *restrict fg, uint16_t n, uint16_t *restrict s)
{
    int nb = n / SONAR_CFAR_BLOCK, b = 0, rest = n - nb * SONAR_CFAR_BLOCK, i;
#if SONAR_SSE2
    /*
     * psadbw against zero sums each 8 bytes into a 64-bit lane; two packs bring eight such sums (at most 2040,
     * within int16) down to the eight 16-bit lanes stored: a quarter of the plain loop's time.
     */
    const __m128i zero = _mm_setzero_si128();
    for (; b + 8 <= nb; b += 8) {
        const uint8_t *p = fg + b * SONAR_CFAR_BLOCK;
        __m128i s01 = _mm_sad_epu8(_mm_loadu_si128((const __m128i *)p), zero);
        __m128i s23 = _mm_sad_epu8(_mm_loadu_si128((const __m128i *)(p + 16)), zero);
        __m128i s45 = _mm_sad_epu8(_mm_loadu_si128((const __m128i *)(p + 32)), zero);
        __m128i s67 = _mm_sad_epu8(_mm_loadu_si128((const __m128i *)(p + 48)), zero);
        _mm_storeu_si128((__m128i *)(s + b),
                         _mm_packs_epi32(_mm_packs_epi32(s01, s23), _mm_packs_epi32(s45, s67)));
    }
#endif
#if SONAR_SIMD32
    for (; b < nb; b++) {
        uint32_t lo, hi;
        memcpy(&lo, fg + b * SONAR_CFAR_BLOCK, 4);
        memcpy(&hi, fg + b * SONAR_CFAR_BLOCK + 4, 4);
        s[b] = (uint16_t)(__usad8(lo, 0u) + __usad8(hi, 0u));
    }
#else
    for (; b + SUM_RUN <= nb; b += SUM_RUN) {
        const uint8_t *p = fg + b * SONAR_CFAR_BLOCK;
        for (i = 0; i < SUM_RUN; i++) {
            const uint8_t *q = p + SONAR_CFAR_BLOCK * i;
            s[b + i] = (uint16_t)(q[0] + q[1] + q[2] + q[3] + q[4] + q[5] + q[6] + q[7]);
        }
    }
    for (; b < nb; b++) {
        const uint8_t *q = fg + b * SONAR_CFAR_BLOCK;
        s[b] = (uint16_t)(q[0] + q[1] + q[2] + q[3] + q[4] + q[5] + q[6] + q[7]);
    }
#endif
    if (rest > 0) {
        int t = 0;
        for (i = 0; i < rest; i++)
            t += fg[nb * SONAR_CFAR_BLOCK + i];
        s[nb++] = (uint16_t)(t * SONAR_CFAR_BLOCK / rest);
    }
    return nb;
}

/* The k-th smallest (1-based, 1 <= k <= m) of v[0 .. m), m <= 16, by insertion: for the blocks near the beam's ends. */
static int16_t kth(int16_t *v, int m, int k)
{
    int i, j;
    for (i = 1; i < m; i++) {
        int16_t x = v[i];
        for (j = i; j > 0 && v[j - 1] > x; j--)
            v[j] = v[j - 1];
        v[j] = x;
    }
    return v[k - 1];
}

/* The rank over m training blocks: rank16 sixteenths of them, at least the first. */
static int rank_of(const struct sonar_cfar_config *c, int m)
{
    int k = (c->rank16 * m + 15) / 16;
    return k < 1 ? 1 : k;
}

/* Noise of block b from whichever of its training blocks exist (the generic path). */
static int16_t noise_edge(const struct sonar_cfar_config *c, const int16_t *s, int nb, int b)
{
    int16_t t[MAX_TRAIN];
    int m = 0, j, lead = b - c->cut - c->guard, lag = b + c->cut + c->guard + 1;
    for (j = lead - c->train; j < lead; j++)
        if (j >= 0)
            t[m++] = s[j];
    for (j = lag; j < lag + c->train; j++)
        if (j < nb)
            t[m++] = s[j];
    return m > 0 ? kth(t, m, rank_of(c, m)) : 0;
}

/*
 * Noise of LANES consecutive blocks b0 .. b0 + 7 whose training blocks all exist: the same
 * insertion network on every lane, data-independent, so the compiler runs the lanes as vectors.
 */
static void noise_lanes(const struct sonar_cfar_config *c, const int16_t *s, int b0, int16_t *out)
{
    int16_t v[MAX_TRAIN][LANES];
    int m = 2 * c->train, i, j, l, lead = b0 - c->cut - c->guard - c->train, lag = b0 + c->cut + c->guard + 1;
    for (i = 0; i < c->train; i++)
        for (l = 0; l < LANES; l++) {
            v[i][l] = s[lead + i + l];
            v[c->train + i][l] = s[lag + i + l];
        }
    for (i = 1; i < m; i++)
        for (j = i; j > 0; j--)
            for (l = 0; l < LANES; l++) {
                int16_t a = v[j - 1][l], d = v[j][l];
                v[j - 1][l] = a < d ? a : d;
                v[j][l] = a < d ? d : a;
            }
    memcpy(out, v[rank_of(c, m) - 1], sizeof(v[0]));
}

/*
 * cut[b] = the sum of blocks b - h .. b + h (s padded with zeros), cand[b] = cut[b] > inner; over
 * whole chunks of CHUNK blocks (the arrays have room past nb), so -O2 vectorises them.
 */
#define CHUNK 16
static void window_sums(const int16_t *s, int nb, int h, uint16_t inner, uint16_t *restrict cut, uint8_t *restrict cand)
{
    int b, b0, j;
    for (b0 = 0; b0 < nb; b0 += CHUNK) {
        for (b = b0; b < b0 + CHUNK; b++)
            cut[b] = (uint16_t)s[b];
        for (j = 1; j <= h; j++)
            for (b = b0; b < b0 + CHUNK; b++)
                cut[b] = (uint16_t)(cut[b] + (uint16_t)s[b - j] + (uint16_t)s[b + j]);
        for (b = b0; b < b0 + CHUNK; b++)
            cand[b] = (uint8_t)(cut[b] > inner);
    }
}

/*
 * s = own + prev + next (either may be NULL). Whole runs of SUM_RUN blocks through constant-length
 * loops, which -O2 vectorises, then the ragged end.
 */
static void add_run(int16_t *restrict s, const uint16_t *restrict a, int len)
{
    int b;
    for (b = 0; b < len; b++)
        s[b] = (int16_t)(s[b] + (int16_t)a[b]);
}

static void add_sums(int16_t *restrict s, const uint16_t *restrict own, const uint16_t *prev, const uint16_t *next, int nb)
{
    const uint16_t *more[2];
    int b0, k;
    more[0] = prev;
    more[1] = next;
    memcpy(s, own, (size_t)nb * sizeof(*s)); /* at most 2040: the same bits as int16 */
    for (k = 0; k < 2; k++) {
        if (more[k] == NULL)
            continue;
        for (b0 = 0; b0 + SUM_RUN <= nb; b0 += SUM_RUN)
            add_run(s + b0, more[k] + b0, SUM_RUN);
        add_run(s + b0, more[k] + b0, nb - b0);
    }
}

int sonar_cfar_sums(const uint8_t *fg, uint16_t n, uint16_t *sums)
{
    if (fg == NULL || sums == NULL || n == 0 || n > SONAR_MAX_SAMPLES)
        return SONAR_ERR_ARG;
    return block_sums(fg, n, sums);
}

int sonar_cfar_blocks(const struct sonar_cfar_config *c, const uint8_t *fg, uint16_t n, uint8_t *on, uint8_t *thr)
{
    return sonar_cfar_blocks_across(c, NULL, fg, NULL, n, on, thr);
}

int sonar_cfar_blocks_across(const struct sonar_cfar_config *c, const uint16_t *prev, const uint8_t *fg,
                             const uint16_t *next, uint16_t n, uint8_t *on, uint8_t *thr)
{
    uint16_t own[SONAR_CFAR_MAX_BLOCKS];
    if (fg == NULL || n == 0 || n > SONAR_MAX_SAMPLES)
        return SONAR_ERR_ARG;
    (void)block_sums(fg, n, own);
    return sonar_cfar_blocks_sums(c, prev, own, next, n, on, thr);
}

int sonar_cfar_blocks_sums(const struct sonar_cfar_config *c, const uint16_t *prev, const uint16_t *own,
                           const uint16_t *next, uint16_t n, uint8_t *on, uint8_t *thr)
{
    /* s is padded with SONAR_CFAR_CUT_MAX zeros before and after, so every window sums without bounds checks. */
    int16_t pad[SONAR_CFAR_CUT_MAX + SONAR_CFAR_MAX_BLOCKS + CHUNK + SONAR_CFAR_CUT_MAX], noise[LANES];
    int16_t *s = pad + SONAR_CFAR_CUT_MAX;
    uint16_t cut[SONAR_CFAR_MAX_BLOCKS + CHUNK];
    uint8_t cand[SONAR_CFAR_MAX_BLOCKS + CHUNK];
    uint32_t scale16, kb;
    int nb, b, b0, l, passed = 0, reach, w;
    uint16_t inner;
    if (c == NULL || own == NULL || on == NULL || n == 0 || n > SONAR_MAX_SAMPLES || sonar_cfar_config_check(c) != NULL)
        return SONAR_ERR_ARG;
    scale16 = (uint32_t)(c->scale * 16.0f + 0.5f);
    w = 2 * c->cut + 1;
    nb = (n + SONAR_CFAR_BLOCK - 1) / SONAR_CFAR_BLOCK;
    /* The beams' block sums added: at most 3 * 2040, within int16. */
    kb = 1u + (prev != NULL) + (next != NULL);
    add_sums(s, own, prev, next, nb);
    reach = c->cut + c->guard + c->train;
    memset(pad, 0, SONAR_CFAR_CUT_MAX * sizeof(pad[0]));
    memset(s + nb, 0, (CHUNK + SONAR_CFAR_CUT_MAX) * sizeof(pad[0]));
    /* Window sums (at most 9 * 3 * 2040, within 16 bits); the zeros past the ends add nothing. */
    /* A window can pass only when its mean exceeds the floor: sum > 8 floor blocks beams (fewer blocks at the ends). */
    inner = (uint16_t)(SONAR_CFAR_BLOCK * c->floor * (unsigned)w * kb);
    window_sums(s, nb, c->cut, inner, cut, cand);
    for (b = 0; b < nb; b = b + 1 < c->cut || b + 1 >= nb - c->cut ? b + 1 : nb - c->cut) {
        /* The ends' windows hold fewer blocks. */
        int w0 = b - c->cut < 0 ? 0 : b - c->cut, w1 = b + c->cut + 1 > nb ? nb : b + c->cut + 1;
        cand[b] = (uint8_t)(cut[b] > SONAR_CFAR_BLOCK * c->floor * (uint32_t)(w1 - w0) * kb);
    }
    memset(cand + nb, 0, CHUNK);
    for (b0 = 0; b0 < nb; b0 += LANES) {
        int nl = nb - b0 < LANES ? nb - b0 : LANES, any = thr != NULL;
        for (l = 0; l < LANES; l++)
            any |= cand[b0 + l];
        if (!any) {
            /* Nothing here exceeds the floor: no need to rank the training blocks. */
            memset(on + b0, 0, (size_t)nl);
            continue;
        }
        if (nl == LANES && b0 - reach >= 0 && b0 + LANES - 1 + reach < nb)
            noise_lanes(c, s, b0, noise);
        else
            for (l = 0; l < nl; l++)
                noise[l] = noise_edge(c, s, nb, b0 + l);
        for (l = 0; l < nl; l++) {
            int b1 = b0 + l, w0 = b1 - c->cut < 0 ? 0 : b1 - c->cut, w1 = b1 + c->cut + 1 > nb ? nb : b1 + c->cut + 1;
            uint32_t kc = (uint32_t)(w1 - w0), sc = cut[b1], base = 128u * c->floor * kc * kb;
            /*
             * The window's mean per sample exceeds scale * noise + floor, sums of 8 samples over kb
             * beams: 16 sc > scale16 noise kc + 128 floor kc kb.
             */
            uint32_t lim = scale16 * (uint32_t)(uint16_t)noise[l] * kc + base;
            on[b1] = (uint8_t)(16u * sc > lim);
            passed += on[b1];
            if (thr != NULL) {
                uint32_t level = lim / (128u * kc * kb); /* per sample */
                thr[b1] = (uint8_t)(level > 255u ? 255u : level);
            }
        }
    }
    return passed;
}
