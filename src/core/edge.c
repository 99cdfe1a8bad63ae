/* edge.c -- a beam's strongest echo and its leading edge (edge.h); one pass for the top, 32 bytes side by side (it vectorises), then memchr or two scans that stop at the edge; no state. */
#include "sonar/edge.h"

#include <string.h>

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

/* The first sample of s[i .. n) at least lim, or n: LANES at a time (a compare and an or: it vectorises), then within. */
static uint16_t first_at_least(const uint8_t *s, unsigned i, uint16_t n, uint8_t lim)
{
    unsigned k;
    for (; i + LANES <= n; i += LANES) {
        uint8_t hit = 0;
        for (k = 0; k < LANES; k++)
            hit |= (uint8_t)(s[i + k] >= lim);
        if (hit)
            break;
    }
    for (; i < n && s[i] < lim; i++)
        ;
    return (uint16_t)i;
}

/* The first sample of s[i .. n) at most lim, or n: as first_at_least. */
static uint16_t first_at_most(const uint8_t *s, unsigned i, uint16_t n, uint8_t lim)
{
    unsigned k;
    for (; i + LANES <= n; i += LANES) {
        uint8_t hit = 0;
        for (k = 0; k < LANES; k++)
            hit |= (uint8_t)(s[i + k] <= lim);
        if (hit)
            break;
    }
    for (; i < n && s[i] > lim; i++)
        ;
    return (uint16_t)i;
}

uint16_t sonar_edge_leading(const uint8_t *s, uint16_t from, uint16_t n, uint8_t *strongest)
{
    uint8_t top, half;
    *strongest = 0;
    if (from >= n)
        return n;
    top = top_of(s, from, n);
    *strongest = top;
    half = (uint8_t)((top + 1u) / 2u);
    if (half <= 1u)
        return n;
    /* An edge rises out of quieter water (a quarter of the strongest): past the ring-down's tail, or anything
       across from, first; then to half the strongest. */
    return first_at_least(s, first_at_most(s, from, n, (uint8_t)(top / 4u)), n, half);
}
