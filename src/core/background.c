/* background.c -- uint8 running-median background, subtract and clamp; one pass of saturating byte ops per beam, no heap. */
#include "sonar/background.h"

#include <string.h>

#include "sonar/frame.h"

#define STR2(x) #x
#define STR(x) STR2(x)

const char *sonar_background_config_check(const struct sonar_background_config *cfg)
{
    if (cfg->mode > SONAR_BACKGROUND_RANGE)
        return "mode: off, per-angle or range";
    if (cfg->warmup < 1 || cfg->warmup > SONAR_BG_WARMUP_MAX)
        return "warmup: 1.." STR(SONAR_BG_WARMUP_MAX) " observations";
    if (cfg->step < 1 || cfg->step > SONAR_BG_STEP_MAX)
        return "step: 1.." STR(SONAR_BG_STEP_MAX) " grey levels";
    if (cfg->margin > SONAR_BG_MARGIN_MAX)
        return "margin: 0.." STR(SONAR_BG_MARGIN_MAX) " sixteenths";
    return NULL;
}

int sonar_background_tune(struct sonar_background *bg, const struct sonar_background_config *cfg)
{
    if (bg == NULL || cfg == NULL || sonar_background_config_check(cfg) != NULL)
        return SONAR_ERR_ARG;
    bg->step = cfg->step;
    bg->margin = cfg->margin;
    return SONAR_OK;
}

int sonar_background_init(struct sonar_background *bg, const struct sonar_background_config *cfg)
{
    if (bg == NULL || cfg == NULL || sonar_background_config_check(cfg) != NULL)
        return SONAR_ERR_ARG;
    bg->mode = cfg->mode;
    bg->warmup = cfg->warmup;
    bg->step = cfg->step;
    bg->margin = cfg->margin;
    sonar_background_reset(bg);
    return SONAR_OK;
}

void sonar_background_reset(struct sonar_background *bg)
{
    /* Only the visit counters matter: a row with 0 visits is reseeded before it is read. */
    memset(bg->visits, 0, sizeof(bg->visits));
    bg->n = 0;
}

#define BLOCK 64

/*
 * Warm-up: running mean of the first observations, b += (x - b) / v rounded half away from zero,
 * which the ±step tracker then refines. A cell still being seeded has no model to compare with,
 * so it reports no foreground. The division is a multiply by m = ceil(2^16 / v) and a shift:
 * exact here, since the numerator is at most 255 + 32 and v at most 64 (the rounding error
 * stays below 1/v). Byte min/max and no branches, so full blocks vectorise.
 */
#define SEED_SPAN(b, in, len)                                                                                      \
    for (i = 0; i < (len); i++) {                                                                                  \
        uint8_t x = (in)[i], c = (b)[i];                                                                           \
        uint8_t hi = x > c ? x : c, lo = x < c ? x : c;                                                            \
        uint8_t q = (uint8_t)((((uint32_t)(hi - lo) + h) * m) >> 16);                                             \
        (b)[i] = (uint8_t)(x >= c ? c + q : c - q);                                                                \
    }

static void seed(uint8_t *restrict b, const uint8_t *restrict in, uint8_t *restrict fg, uint16_t n, unsigned v)
{
    uint32_t m = (65536u + v - 1u) / v, h = v / 2u;
    int i, i0;
    memset(fg, 0, n);
    if (v == 1) {
        memcpy(b, in, n);
        return;
    }
    for (i0 = 0; i0 + BLOCK <= (int)n; i0 += BLOCK)
        SEED_SPAN(b + i0, in + i0, BLOCK)
    SEED_SPAN(b + i0, in + i0, (int)n - i0)
}

/*
 * Steady state over len samples, as byte min/max only (no branches), so that with the constant
 * len of a full block -O2 vectorises it: up = max(x, m) - m, dn = m - min(x, m).
 */
#define TRACK_SPAN(b, in, fg, len, step, margin) TRACK_SPAN_G(b, in, fg, len, step, GATE_SAT(m, margin))
/* margin <= 16 keeps m * margin / 16 within a byte: no saturation, a quarter fewer vector ops. */
#define TRACK_SPAN_SMALL(b, in, fg, len, step, margin) TRACK_SPAN_G(b, in, fg, len, step, GATE_BYTE(m, margin))
#define GATE16(m, margin) ((uint16_t)(((uint16_t)(m) * (margin)) >> 4))
#define GATE_SAT(m, margin) (uint8_t)(GATE16(m, margin) < 255u ? GATE16(m, margin) : 255u)
#define GATE_BYTE(m, margin) (uint8_t)GATE16(m, margin)
#define TRACK_SPAN_G(b, in, fg, len, step, GATE)                                                                   \
    for (i = 0; i < (len); i++) {                                                                                  \
        uint8_t x = (in)[i], m = (b)[i];                                                                           \
        uint8_t hi = x > m ? x : m, lo = x < m ? x : m;                                                            \
        uint8_t up = (uint8_t)(hi - m), dn = (uint8_t)(m - lo);                                                    \
        uint8_t gate = GATE;                                                                                       \
        uint8_t over = up > gate ? up : gate;                                                                      \
        (fg)[i] = (uint8_t)(over - gate);                                                                          \
        (b)[i] = (uint8_t)(m + (up < (step) ? up : (step)) - (dn < (step) ? dn : (step)));                         \
    }

#if defined(__ARM_FEATURE_SIMD32)
#include <arm_acle.h>

/*
 * The same rule four cells a word on ARMv7E-M. uqsub8(x, m) is max(x, m) - m per byte; min(u, s) is
 * u - uqsub8(u, s); and since a cell moves up or down but not both, m + min(up, step) - min(dn, step)
 * never carries or borrows across bytes. The gate m * margin / 16 (saturated at 255) is two
 * halfword lanes, each product at most 255 * 64, saturated with uqsub16.
 */
static uint32_t gate4(uint32_t m, uint32_t margin)
{
    uint32_t even = ((m & 0x00FF00FFu) * margin >> 4) & 0x0FFF0FFFu;
    uint32_t odd = (((m >> 8) & 0x00FF00FFu) * margin >> 4) & 0x0FFF0FFFu;
    /* min(lane, 255) = lane - uqsub16(lane, 255), per halfword */
    even -= __uqsub16(even, 0x00FF00FFu);
    odd -= __uqsub16(odd, 0x00FF00FFu);
    return even | odd << 8;
}

static void track4(uint8_t *b, const uint8_t *in, uint8_t *fg, int words, uint8_t step, uint8_t margin)
{
    uint32_t s4 = 0x01010101u * step;
    int w;
    for (w = 0; w < words; w++) {
        uint32_t x, m, up, dn, gate;
        memcpy(&x, in + 4 * w, 4);
        memcpy(&m, b + 4 * w, 4);
        up = __uqsub8(x, m);
        dn = __uqsub8(m, x);
        gate = margin ? gate4(m, margin) : 0u;
        x = __uqsub8(up, gate); /* the foreground */
        memcpy(fg + 4 * w, &x, 4);
        m = m + (up - __uqsub8(up, s4)) - (dn - __uqsub8(dn, s4));
        memcpy(b + 4 * w, &m, 4);
    }
}
#endif

static void track(uint8_t *restrict b, const uint8_t *restrict in, uint8_t *restrict fg, uint16_t n, uint8_t step,
                  uint8_t margin)
{
    int i, i0;
#if defined(__ARM_FEATURE_SIMD32)
    i0 = (int)n & ~3;
    track4(b, in, fg, i0 / 4, step, margin);
    TRACK_SPAN(b + i0, in + i0, fg + i0, (int)n - i0, step, margin)
    return;
#endif
    if (margin <= 16)
        for (i0 = 0; i0 + BLOCK <= (int)n; i0 += BLOCK)
            TRACK_SPAN_SMALL(b + i0, in + i0, fg + i0, BLOCK, step, margin)
    else
        for (i0 = 0; i0 + BLOCK <= (int)n; i0 += BLOCK)
            TRACK_SPAN(b + i0, in + i0, fg + i0, BLOCK, step, margin)
    if (i0 < (int)n) {
        /* The ragged end as one more full block through copies: the scalar loop cost a third of the beam. */
        uint8_t tb[BLOCK], tin[BLOCK], tfg[BLOCK];
        size_t len = (size_t)((int)n - i0);
        memset(tb + len, 0, BLOCK - len);
        memset(tin + len, 0, BLOCK - len);
        memcpy(tb, b + i0, len);
        memcpy(tin, in + i0, len);
        TRACK_SPAN(tb, tin, tfg, BLOCK, step, margin)
        memcpy(b + i0, tb, len);
        memcpy(fg + i0, tfg, len);
    }
}

int sonar_background_apply(struct sonar_background *bg, uint16_t angle, const uint8_t *in, uint8_t *fg, uint16_t n)
{
    unsigned row, v;
    if (bg == NULL || in == NULL || fg == NULL || angle > SONAR_GRAD_MAX || n == 0 || n > SONAR_MAX_SAMPLES)
        return SONAR_ERR_ARG;
    if (bg->mode == SONAR_BACKGROUND_OFF) {
        memcpy(fg, in, n);
        return SONAR_OK;
    }
    if (n != bg->n) {
        sonar_background_reset(bg);
        bg->n = n;
    }
    row = bg->mode == SONAR_BACKGROUND_RANGE ? 0u : (unsigned)angle * SONAR_MAX_ANGLES / SONAR_GRAD_TURN;
    v = bg->visits[row] < 255u ? (unsigned)bg->visits[row] + 1u : 255u;
    bg->visits[row] = (uint8_t)v;
    if (v <= bg->warmup)
        seed(bg->cell[row], in, fg, n, v);
    else
        track(bg->cell[row], in, fg, n, bg->step, bg->margin);
    return SONAR_OK;
}
