/* edge.c -- a beam's strongest echo (one pass, 32 bytes side by side: it vectorises, then memchr) and its leading edge (over the CFAR's 8-sample block sums, eight at a time with SSE2, two with SIMD32, then one block); no state. */
#include "sonar/edge.h"

#include <string.h>

#include "sonar/cfar.h"
#include "simd_internal.h"

#define LANES 32 /* bytes compared side by side: the loops over them vectorise at -O2 (two SSE registers, 8 words on a Cortex-M) */

/* The largest level of s[from .. n): LANES running maxima, then theirs. */
static uint8_t top_of(const uint8_t *s, uint16_t from, uint16_t n)
{
    uint8_t lane[LANES] = {0}, top = 0;
    unsigned i = from, k;
    for (; i + LANES <= n; i += LANES)
        for (k = 0; k < LANES; k++)
            lane[k] = s[i + k] > lane[k] ? s[i + k] : lane[k];
    for (; i < n; i++)
        top = s[i] > top ? s[i] : top;
    for (k = 0; k < LANES; k++)
        top = lane[k] > top ? lane[k] : top;
    return top;
}

uint16_t sonar_edge_strongest(const uint8_t *s, uint16_t from, uint16_t n)
{
    /* The top first, then where it first is: a quarter of the branchy search's time. */
    const uint8_t *at;
    if (from >= n)
        return from;
    at = memchr(s + from, top_of(s, from, n), (size_t)(n - from));
    return at != NULL ? (uint16_t)(at - s) : from;
}

#define SUM_LANES 16 /* block sums compared side by side (two SSE registers of 16-bit lanes): the loops vectorise */

/*
 * With SSE2, eight block sums at a time as int16 (each at most 2040): -O2 makes the plain loops' unsigned
 * 16-bit tests from several instructions each; with ARMv7E-M's SIMD32 two at a time (usub16, sel). The
 * plain loops are arm64's; every way the same answer, then the ragged end one by one.
 */

/* The first of sums[b .. nb) at least lim (above = 0) or at most lim (above = 1), or nb; a run at a time, then within. */
static unsigned first_sum(const uint16_t *sums, unsigned b, unsigned nb, unsigned lim, int above)
{
#if SONAR_SSE2
    const __m128i l = _mm_set1_epi16((short)lim);
    for (; b + 8u <= nb; b += 8u) {
        __m128i v = _mm_loadu_si128((const __m128i *)(sums + b));
        if (_mm_movemask_epi8(above ? _mm_cmpgt_epi16(v, l) : _mm_cmpgt_epi16(l, v)) != 0xFFFF)
            break;
    }
#elif SONAR_SIMD32
    /* Two at a time: usub16 sets a half's GE where it is at least the bound, sel turns that into a mask. */
    const uint32_t l2 = (above ? lim + 1u : lim) * 0x00010001u, pass = above ? 0xFFFFFFFFu : 0u;
    for (; b + 2u <= nb; b += 2u) {
        uint32_t v;
        memcpy(&v, sums + b, 4);
        (void)__usub16(v, l2);
        if (__sel(0xFFFFFFFFu, 0u) != pass)
            break;
    }
#else
    unsigned k;
    for (; b + SUM_LANES <= nb; b += SUM_LANES) {
        uint16_t hit = 0;
        if (above)
            for (k = 0; k < SUM_LANES; k++)
                hit |= (uint16_t)(sums[b + k] <= lim);
        else
            for (k = 0; k < SUM_LANES; k++)
                hit |= (uint16_t)(sums[b + k] >= lim);
        if (hit)
            break;
    }
#endif
    for (; b < nb && (above ? sums[b] > lim : sums[b] < lim); b++)
        ;
    return b;
}

/* The largest of sums[b .. nb): running maxima side by side, then theirs. */
static unsigned top_sum(const uint16_t *sums, unsigned b, unsigned nb)
{
    unsigned top;
#if SONAR_SSE2
    __m128i t = _mm_setzero_si128();
    for (; b + 8u <= nb; b += 8u)
        t = _mm_max_epi16(t, _mm_loadu_si128((const __m128i *)(sums + b)));
    t = _mm_max_epi16(t, _mm_srli_si128(t, 8));
    t = _mm_max_epi16(t, _mm_srli_si128(t, 4));
    t = _mm_max_epi16(t, _mm_srli_si128(t, 2));
    top = (uint16_t)_mm_cvtsi128_si32(t);
#elif SONAR_SIMD32
    uint32_t t2 = 0;
    for (; b + 2u <= nb; b += 2u) {
        uint32_t v;
        memcpy(&v, sums + b, 4);
        (void)__usub16(v, t2);
        t2 = __sel(v, t2);
    }
    top = (t2 & 0xFFFFu) > (t2 >> 16) ? (t2 & 0xFFFFu) : (t2 >> 16);
#else
    uint16_t lane[SUM_LANES] = {0};
    unsigned k;
    for (; b + SUM_LANES <= nb; b += SUM_LANES)
        for (k = 0; k < SUM_LANES; k++)
            lane[k] = sums[b + k] > lane[k] ? sums[b + k] : lane[k];
    for (top = 0, k = 0; k < SUM_LANES; k++)
        top = lane[k] > top ? lane[k] : top;
#endif
    for (; b < nb; b++)
        top = sums[b] > top ? sums[b] : top;
    return top;
}

uint16_t sonar_edge_leading(const uint8_t *s, const uint16_t *sums, uint16_t from, uint16_t n, uint8_t *strongest)
{
    const unsigned nb = ((unsigned)n + SONAR_CFAR_BLOCK - 1u) / SONAR_CFAR_BLOCK;
    unsigned b, first = ((unsigned)from + SONAR_CFAR_BLOCK - 1u) / SONAR_CFAR_BLOCK, i;
    unsigned top = top_sum(sums, first, nb);
    *strongest = (uint8_t)(top / SONAR_CFAR_BLOCK);
    if (top < 2u * SONAR_CFAR_BLOCK)
        return n;
    /* An edge rises out of quieter water (a quarter of the strongest): past the ring-down's tail, or anything
       across from, first; then to half the strongest; then the first sample of that block to reach half. */
    b = first_sum(sums, first_sum(sums, first, nb, top / 4u, 1), nb, top / 2u, 0);
    for (i = b * SONAR_CFAR_BLOCK; i < n && (unsigned)s[i] * 2u * SONAR_CFAR_BLOCK < top; i++)
        ;
    return b < nb && i < n ? (uint16_t)i : n;
}
