/* streak.c -- interference streaks judged beam by beam against the last ordinary beam (streak.h); one read-only pass over a beam against the background model (32 samples side by side, 16 with SSE2, 4 with ARMv7E-M's SIMD), stopping once the beam cannot matter, 24 B of state. */
#include "sonar/streak.h"

#include <string.h>

#include "sonar/frame.h"
#include "simd_internal.h"

#define LANES 32 /* samples compared side by side, each lane counting in a byte: the loop vectorises at -O2 */
#define RUN 256  /* samples counted before looking whether the beam can still matter */
SONAR_STATIC_ASSERT(RUN / 16 < 256 && RUN % LANES == 0, streak_lane_counts_fit_a_byte);

/*
 * Samples of in[i .. end) above model + margin (saturating at 255), end - i <= RUN. On ARMv7E-M eight at a
 * time, a word each (in less the margin, saturating at 0, against the model: usub8 sets a lane's GE where the model is
 * at least as high, sel picks 0 there and 1 elsewhere, usada8 adds them up); on x86-64 sixteen at a time
 * with SSE2 (in less the margin is at most the model where their minimum is itself: those lanes count down
 * from 0, psadbw adds them up); elsewhere LANES byte counters (the loop vectorises), then their sum. The
 * same count every way.
 */
static unsigned run_count(const uint8_t *in, const uint8_t *model, unsigned i, unsigned end, uint8_t margin)
{
    unsigned total = 0;
#if SONAR_SIMD32
    /* Two words a turn through pointers: -O2 otherwise recomputes both addresses for every word. */
    const uint32_t m4 = (uint32_t)margin * 0x01010101u;
    const uint8_t *px = in + i, *pm = model + i, *stop = in + i + ((end - i) & ~7u);
    for (; px < stop; px += 8, pm += 8) {
        uint32_t x0, m0, x1, m1;
        memcpy(&x0, px, 4);
        memcpy(&m0, pm, 4);
        memcpy(&x1, px + 4, 4);
        memcpy(&m1, pm + 4, 4);
        (void)__usub8(m0, __uqsub8(x0, m4));
        total = __usada8(__sel(0u, 0x01010101u), 0u, total);
        (void)__usub8(m1, __uqsub8(x1, m4));
        total = __usada8(__sel(0u, 0x01010101u), 0u, total);
    }
    i = (unsigned)(px - in);
#elif SONAR_SSE2
    const __m128i m16 = _mm_set1_epi8((char)margin), zero = _mm_setzero_si128();
    __m128i quiet = zero;
    unsigned start = i;
    for (; i + 16u <= end; i += 16u) {
        __m128i t = _mm_subs_epu8(_mm_loadu_si128((const __m128i *)(in + i)), m16);
        __m128i m = _mm_loadu_si128((const __m128i *)(model + i));
        quiet = _mm_sub_epi8(quiet, _mm_cmpeq_epi8(_mm_min_epu8(t, m), t));
    }
    quiet = _mm_sad_epu8(quiet, zero);
    total = (i - start) - (unsigned)(_mm_cvtsi128_si32(quiet) + _mm_cvtsi128_si32(_mm_srli_si128(quiet, 8)));
#else
    const uint8_t lim = (uint8_t)(255u - margin);
    uint8_t count[LANES] = {0};
    unsigned k;
    for (; i + LANES <= end; i += LANES)
        for (k = 0; k < LANES; k++) {
            uint8_t above = model[i + k] > lim ? 255u : (uint8_t)(model[i + k] + margin);
            count[k] = (uint8_t)(count[k] + (in[i + k] > above));
        }
    for (k = 0; k < LANES; k++)
        total += count[k];
#endif
    for (; i < end; i++)
        total += (unsigned)in[i] > (unsigned)model[i] + margin;
    return total;
}

/*
 * The standing samples of in[from .. n), RUN at a time. A beam is judged on its share only where that share
 * reaches SONAR_STREAK_16 / (16 SONAR_STREAK_RATIO) of its length (3/8): below it, it is no streak, and as
 * the reference its share is under half of what a streak needs, so it decides nothing. Once the samples
 * left could not bring it there, the count stops: on a quiet beam after some 5/8 of it.
 */
static int standing_count(const uint8_t *in, const uint8_t *model, uint16_t from, uint16_t n, uint8_t margin)
{
    const unsigned length = (unsigned)n - from;
    unsigned i = from, standing = 0;
    while (i < n) {
        unsigned end = (unsigned)n - i > RUN ? i + RUN : n;
        standing += run_count(in, model, i, end, margin);
        i = end;
        if (16u * SONAR_STREAK_RATIO * (standing + (unsigned)n - i) < SONAR_STREAK_16 * length)
            break;
    }
    return (int)standing;
}

int sonar_streak_standing(const struct sonar_background *bg, uint16_t angle, const uint8_t *in, uint16_t n, uint16_t from,
                          uint8_t margin)
{
    const uint8_t *model = NULL;
    unsigned row;
    if (bg == NULL || in == NULL || bg->world || bg->mode == SONAR_BACKGROUND_OFF || angle > SONAR_GRAD_MAX ||
        n != bg->n || n > SONAR_MAX_SAMPLES)
        return -1;
    row = bg->mode == SONAR_BACKGROUND_RANGE ? 0u : (unsigned)angle * SONAR_MAX_ANGLES / SONAR_GRAD_TURN;
    if (bg->visits[row] > bg->warmup)
        model = bg->cell[row];
    else if (bg->mode == SONAR_BACKGROUND_AUTO && bg->across_visits >= SONAR_BG_ACROSS_WARMUP)
        model = bg->across;
    if (model == NULL)
        return -1;
    return standing_count(in, model, from, n, margin);
}

void sonar_streak_init(struct sonar_streak *s)
{
    memset(s, 0, sizeof(*s));
}

int sonar_streak_judge(struct sonar_streak *s, uint16_t angle, int64_t utime, int standing, uint16_t length)
{
    uint32_t share;
    int near = s->have_ref && sonar_frame_gap(s->last_angle, angle) <= SONAR_STREAK_NEAR_GRAD &&
               utime - s->last_us >= 0 && utime - s->last_us <= SONAR_STREAK_NEAR_US;
    s->last_angle = angle;
    s->last_us = utime;
    if (standing < 0 || length < SONAR_STREAK_MIN_LEN) {
        s->have_ref = 0;
        s->run = 0;
        return 0;
    }
    /* The share in 256ths, so that the ratio to a quiet reference stays an integer test. */
    share = (uint32_t)standing * 256u / length;
    if (near && s->run < SONAR_STREAK_MAX_RUN && share >= (uint32_t)SONAR_STREAK_16 * 16u &&
        share >= (uint32_t)SONAR_STREAK_RATIO * s->ref256) {
        s->beams++;
        s->run++;
        return 1;
    }
    s->ref256 = (uint16_t)(share > 256u ? 256u : share);
    s->have_ref = 1;
    s->run = 0;
    return 0;
}

uint16_t sonar_streak_from(const uint8_t *s, uint16_t n)
{
    uint16_t i;
    for (i = 0; i < n && s[i] == 0u; i++)
        ;
    return i;
}
