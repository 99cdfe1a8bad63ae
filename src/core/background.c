/* background.c -- uint8 running-median background per angle (or per range bin, or auto: with the across-beam model), subtract and clamp; one pass of saturating byte ops per beam, no heap. The world grid is background_world.c. */
#include "sonar/background.h"

#include <string.h>

#include "simd_internal.h"
#include "sonar/frame.h"

const char *sonar_background_config_check(const struct sonar_background_config *cfg)
{
    if (cfg->mode > SONAR_BACKGROUND_AUTO)
        return "mode: off, per-angle, range or auto";
    if (cfg->warmup < 1 || cfg->warmup > SONAR_BG_WARMUP_MAX)
        return "warmup: 1.." SONAR_STR(SONAR_BG_WARMUP_MAX) " observations";
    if (cfg->step < 1 || cfg->step > SONAR_BG_STEP_MAX)
        return "step: 1.." SONAR_STR(SONAR_BG_STEP_MAX) " grey levels";
    if (cfg->margin > SONAR_BG_MARGIN_MAX)
        return "margin: 0.." SONAR_STR(SONAR_BG_MARGIN_MAX) " sixteenths";
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
    bg->across_visits = 0;
    bg->n = 0;
    bg->world = 0;
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

static void seed(uint8_t *restrict b, const uint8_t *in, uint8_t *fg, uint16_t n, unsigned v)
{
    uint32_t m = (65536u + v - 1u) / v, h = v / 2u;
    int i, i0;
    /* in is read before fg is written: they may be the same buffer. */
    if (v == 1) {
        memcpy(b, in, n);
    } else {
        for (i0 = 0; i0 + BLOCK <= (int)n; i0 += BLOCK)
            SEED_SPAN(b + i0, in + i0, BLOCK)
        SEED_SPAN(b + i0, in + i0, (int)n - i0)
    }
    memset(fg, 0, n);
}

/*
 * Steady state over len samples, as byte min/max only (no branches), so that with the constant
 * len of a full block -O2 vectorises it: up = max(x, m) - m, dn = m - min(x, m).
 */
#define FOLLOW_SPAN(b, in, fg, len, step, margin) FOLLOW_SPAN_G(b, in, fg, len, step, GATE_SAT(m, margin))
/* margin <= 16 keeps m * margin / 16 within a byte: no saturation, a quarter fewer vector ops. */
#define FOLLOW_SPAN_SMALL(b, in, fg, len, step, margin) FOLLOW_SPAN_G(b, in, fg, len, step, GATE_BYTE(m, margin))
#define GATE16(m, margin) ((uint16_t)(((uint16_t)(m) * (margin)) >> 4))
#define GATE_SAT(m, margin) (uint8_t)(GATE16(m, margin) < 255u ? GATE16(m, margin) : 255u)
#define GATE_BYTE(m, margin) (uint8_t)GATE16(m, margin)
#define FOLLOW_SPAN_G(b, in, fg, len, step, GATE)                                                                   \
    for (i = 0; i < (len); i++) {                                                                                  \
        uint8_t x = (in)[i], m = (b)[i];                                                                           \
        uint8_t hi = x > m ? x : m, lo = x < m ? x : m;                                                            \
        uint8_t up = (uint8_t)(hi - m), dn = (uint8_t)(m - lo);                                                    \
        uint8_t gate = GATE;                                                                                       \
        uint8_t over = up > gate ? up : gate;                                                                      \
        (fg)[i] = (uint8_t)(over - gate);                                                                          \
        (b)[i] = (uint8_t)(m + (up < (step) ? up : (step)) - (dn < (step) ? dn : (step)));                         \
    }

/*
 * Auto mode's steady state in one pass: the foreground against the larger of the row's cell m and
 * the across-beam model's c (the foreground falls as the model rises, so this is the smaller of
 * the two foregrounds), and both models step towards x.
 */
#define PAIR_SPAN(b, a, in, fg, len, step, margin) PAIR_SPAN_G(b, a, in, fg, len, step, GATE_SAT(top, margin))
#define PAIR_SPAN_SMALL(b, a, in, fg, len, step, margin) PAIR_SPAN_G(b, a, in, fg, len, step, GATE_BYTE(top, margin))
#define PAIR_SPAN_G(b, a, in, fg, len, step, GATE)                                                                 \
    for (i = 0; i < (len); i++) {                                                                                  \
        uint8_t x = (in)[i], m = (b)[i], c = (a)[i];                                                               \
        uint8_t top = m > c ? m : c, hit = x > top ? x : top;                                                      \
        uint8_t hm = x > m ? x : m, lm = x < m ? x : m, hc = x > c ? x : c, lc = x < c ? x : c;                    \
        uint8_t up = (uint8_t)(hit - top), gate = GATE, over = up > gate ? up : gate;                              \
        uint8_t upm = (uint8_t)(hm - m), dnm = (uint8_t)(m - lm), upc = (uint8_t)(hc - c), dnc = (uint8_t)(c - lc);  \
        (fg)[i] = (uint8_t)(over - gate);                                                                          \
        (b)[i] = (uint8_t)(m + (upm < (step) ? upm : (step)) - (dnm < (step) ? dnm : (step)));                     \
        (a)[i] = (uint8_t)(c + (upc < (step) ? upc : (step)) - (dnc < (step) ? dnc : (step)));                     \
    }

#if SONAR_SIMD32

/*
 * The same rule four cells a word on ARMv7E-M. uqsub8(x, m) is max(x, m) - m per byte; min(u, s) is
 * u - uqsub8(u, s); and since a cell moves up or down but not both, m + min(up, step) - min(dn, step)
 * never carries or borrows across bytes. The gate m * margin / 16 (saturated at 255) is two
 * halfword lanes, each product at most 255 * 64, saturated with uqsub16.
 */
static uint32_t gate4(uint32_t m, uint32_t margin)
{
    uint32_t even = (m & 0x00FF00FFu) * margin >> 4, odd = ((m >> 8) & 0x00FF00FFu) * margin >> 4;
    if (margin <= 16u) /* each lane's gate fits its byte */
        return (even & 0x00FF00FFu) | (odd & 0x00FF00FFu) << 8;
    even &= 0x0FFF0FFFu;
    odd &= 0x0FFF0FFFu;
    /* min(lane, 255) = lane - uqsub16(lane, 255), per halfword */
    even -= __uqsub16(even, 0x00FF00FFu);
    odd -= __uqsub16(odd, 0x00FF00FFu);
    return even | odd << 8;
}

/*
 * A margin of 0 or a power of two up to 16 makes the gate a shift, (m >> shift) & mask (the bits
 * shifted in from the next byte masked off): returns 1 and sets both, else 0.
 */
static int gate_shift(uint8_t margin, unsigned *shift, uint32_t *mask)
{
    unsigned k;
    if (margin == 0u) {
        *shift = 0u;
        *mask = 0u;
        return 1;
    }
    for (k = 0; k <= 4u; k++)
        if (margin == 16u >> k) {
            *shift = k;
            *mask = 0x01010101u * (0xFFu >> k);
            return 1;
        }
    return 0;
}

/* The gate of each byte of m: a shift for a margin that allows one (gate_shift), else gate4. */
struct gate_rule {
    uint32_t margin, mask;
    unsigned shift;
    int shifted;
};

static struct gate_rule gate_rule(uint8_t margin)
{
    struct gate_rule g;
    g.margin = margin;
    g.shifted = gate_shift(margin, &g.shift, &g.mask);
    return g;
}

static uint32_t gate_of(struct gate_rule g, uint32_t m)
{
    return g.shifted ? (m >> g.shift) & g.mask : gate4(m, g.margin);
}

/* m stepped by at most s4 per byte, up (up = uqsub8(x, m)) or down (dn = uqsub8(m, x)): never carries or borrows across bytes (see above). */
static uint32_t step4(uint32_t m, uint32_t up, uint32_t dn, uint32_t s4)
{
    return m + (up - __uqsub8(up, s4)) - (dn - __uqsub8(dn, s4));
}

static void follow_row4(uint8_t *b, const uint8_t *in, uint8_t *fg, int words, uint8_t step, uint8_t margin)
{
    uint32_t s4 = 0x01010101u * step;
    struct gate_rule g = gate_rule(margin);
    int w;
    for (w = 0; w < words; w++) {
        uint32_t x, m, up, dn;
        memcpy(&x, in + 4 * w, 4);
        memcpy(&m, b + 4 * w, 4);
        up = __uqsub8(x, m);
        dn = __uqsub8(m, x);
        x = __uqsub8(up, gate_of(g, m)); /* the foreground */
        memcpy(fg + 4 * w, &x, 4);
        m = step4(m, up, dn, s4);
        memcpy(b + 4 * w, &m, 4);
    }
}

static void pair4(uint8_t *b, uint8_t *a, const uint8_t *in, uint8_t *fg, int words, uint8_t step, uint8_t margin)
{
    uint32_t s4 = 0x01010101u * step;
    struct gate_rule g = gate_rule(margin);
    int w;
    for (w = 0; w < words; w++) {
        uint32_t x, m, c, top, out;
        memcpy(&x, in + 4 * w, 4);
        memcpy(&m, b + 4 * w, 4);
        memcpy(&c, a + 4 * w, 4);
        top = c + __uqsub8(m, c); /* max(m, c) per byte */
        out = __uqsub8(__uqsub8(x, top), gate_of(g, top));
        memcpy(fg + 4 * w, &out, 4);
        m = step4(m, __uqsub8(x, m), __uqsub8(m, x), s4);
        c = step4(c, __uqsub8(x, c), __uqsub8(c, x), s4);
        memcpy(b + 4 * w, &m, 4);
        memcpy(a + 4 * w, &c, 4);
    }
}
#endif

/* in and fg may be the same buffer: each block of in is copied before fg is written (follow_row4 reads each word first). */
static void follow_row(uint8_t *restrict b, const uint8_t *in, uint8_t *fg, uint16_t n, uint8_t step, uint8_t margin)
{
    uint8_t blk[BLOCK];
    int i, i0;
#if SONAR_SIMD32
    i0 = (int)n & ~3;
    follow_row4(b, in, fg, i0 / 4, step, margin);
    memcpy(blk, in + i0, (size_t)((int)n - i0));
    FOLLOW_SPAN(b + i0, blk, fg + i0, (int)n - i0, step, margin)
    return;
#endif
    if (margin <= 16)
        for (i0 = 0; i0 + BLOCK <= (int)n; i0 += BLOCK) {
            memcpy(blk, in + i0, BLOCK);
            FOLLOW_SPAN_SMALL(b + i0, blk, fg + i0, BLOCK, step, margin)
        }
    else
        for (i0 = 0; i0 + BLOCK <= (int)n; i0 += BLOCK) {
            memcpy(blk, in + i0, BLOCK);
            FOLLOW_SPAN(b + i0, blk, fg + i0, BLOCK, step, margin)
        }
    if (i0 < (int)n) {
        /* The ragged end as one more full block through copies: the scalar loop cost a third of the beam. */
        uint8_t tb[BLOCK], tin[BLOCK], tfg[BLOCK];
        size_t len = (size_t)((int)n - i0);
        memset(tb + len, 0, BLOCK - len);
        memset(tin + len, 0, BLOCK - len);
        memcpy(tb, b + i0, len);
        memcpy(tin, in + i0, len);
        FOLLOW_SPAN(tb, tin, tfg, BLOCK, step, margin)
        memcpy(b + i0, tb, len);
        memcpy(fg + i0, tfg, len);
    }
}

/* Auto mode's steady state (PAIR_SPAN): in and fg may be the same buffer, as in follow_row. */
static void pair(uint8_t *restrict b, uint8_t *restrict a, const uint8_t *in, uint8_t *fg, uint16_t n, uint8_t step,
                 uint8_t margin)
{
    uint8_t blk[BLOCK];
    int i, i0;
#if SONAR_SIMD32
    i0 = (int)n & ~3;
    pair4(b, a, in, fg, i0 / 4, step, margin);
    memcpy(blk, in + i0, (size_t)((int)n - i0));
    PAIR_SPAN(b + i0, a + i0, blk, fg + i0, (int)n - i0, step, margin)
    return;
#endif
    if (margin <= 16)
        for (i0 = 0; i0 + BLOCK <= (int)n; i0 += BLOCK) {
            memcpy(blk, in + i0, BLOCK);
            PAIR_SPAN_SMALL(b + i0, a + i0, blk, fg + i0, BLOCK, step, margin)
        }
    else
        for (i0 = 0; i0 + BLOCK <= (int)n; i0 += BLOCK) {
            memcpy(blk, in + i0, BLOCK);
            PAIR_SPAN(b + i0, a + i0, blk, fg + i0, BLOCK, step, margin)
        }
    if (i0 < (int)n) {
        /* The ragged end as one more full block through copies, as in follow_row. */
        uint8_t tb[BLOCK], ta[BLOCK], tfg[BLOCK];
        size_t len = (size_t)((int)n - i0);
        memset(tb + len, 0, BLOCK - len);
        memset(ta + len, 0, BLOCK - len);
        memset(blk + len, 0, BLOCK - len);
        memcpy(tb, b + i0, len);
        memcpy(ta, a + i0, len);
        memcpy(blk, in + i0, len);
        PAIR_SPAN(tb, ta, blk, tfg, BLOCK, step, margin)
        memcpy(b + i0, tb, len);
        memcpy(a + i0, ta, len);
        memcpy(fg + i0, tfg, len);
    }
}

/* One observation of a model row: seeded over its first warmup visits (no foreground then), then followed. */
static void observe(uint8_t *row, uint8_t *visits, unsigned warmup, const uint8_t *in, uint8_t *fg, uint16_t n,
                    uint8_t step, uint8_t margin)
{
    unsigned v = *visits < 255u ? (unsigned)*visits + 1u : 255u;
    *visits = (uint8_t)v;
    if (v <= warmup)
        seed(row, in, fg, n, v);
    else
        follow_row(row, in, fg, n, step, margin);
}

/*
 * fg[i] = min(fg[i], other[i]) in constant-length blocks from offset 0 so that -O2 vectorises it;
 * the ragged end is one more block ending at n, as taking a minimum twice changes nothing.
 */
static void min_block(uint8_t *restrict f, const uint8_t *restrict o)
{
    int i;
    for (i = 0; i < BLOCK; i++)
        f[i] = f[i] < o[i] ? f[i] : o[i];
}

static void lesser(uint8_t *restrict fg, const uint8_t *restrict other, uint16_t n)
{
    int i, i0;
    for (i0 = 0; i0 + BLOCK <= (int)n; i0 += BLOCK)
        min_block(fg + i0, other + i0);
    if (i0 == (int)n)
        return;
    if (n >= BLOCK) {
        min_block(fg + n - BLOCK, other + n - BLOCK);
        return;
    }
    for (i = 0; i < (int)n; i++)
        fg[i] = fg[i] < other[i] ? fg[i] : other[i];
}

/* The keep spans clipped to the beam, applied as dst[span] = src[span]. */
static void copy_spans(uint8_t *dst, const uint8_t *src, uint16_t n, const struct sonar_bg_span *keep, uint8_t nkeep)
{
    uint8_t k;
    for (k = 0; k < nkeep; k++) {
        uint16_t lo = keep[k].lo, hi = keep[k].hi < n ? keep[k].hi : n;
        if (lo < hi)
            memcpy(dst + lo, src + lo, (size_t)(hi - lo));
    }
}

/*
 * Auto mode. A row still seeding reports the across-beam model's foreground. The visit that first
 * compares with the row sets the cells under the keep spans to the across-beam model: what the
 * warm-up learnt there was the tracked object. From then on those cells keep their value (the
 * object is never learnt); the rest of the row learns as in per-angle mode.
 */
static void apply_auto(struct sonar_background *bg, unsigned row, const uint8_t *in, uint8_t *fg, uint16_t n,
                       const struct sonar_bg_span *keep, uint8_t nkeep)
{
    uint8_t held[SONAR_MAX_SAMPLES], fga[SONAR_MAX_SAMPLES];
    uint8_t *b = bg->cell[row];
    unsigned seen = bg->visits[row];
    if (seen < bg->warmup) {
        observe(b, &bg->visits[row], bg->warmup, in, held, n, bg->step, bg->margin);
        observe(bg->across, &bg->across_visits, SONAR_BG_ACROSS_WARMUP, in, fg, n, bg->step, bg->margin);
        return;
    }
    if (seen == bg->warmup)
        copy_spans(b, bg->across, n, keep, nkeep);
    if (bg->across_visits >= SONAR_BG_ACROSS_WARMUP) {
        /* Both models past their warm-up: the steps below in one pass. */
        copy_spans(held, b, n, keep, nkeep);
        bg->visits[row] = (uint8_t)(seen < 255u ? seen + 1u : 255u);
        bg->across_visits = (uint8_t)(bg->across_visits < 255u ? bg->across_visits + 1u : 255u);
        pair(b, bg->across, in, fg, n, bg->step, bg->margin);
        copy_spans(b, held, n, keep, nkeep);
        return;
    }
    observe(bg->across, &bg->across_visits, SONAR_BG_ACROSS_WARMUP, in, fga, n, bg->step, bg->margin);
    copy_spans(held, b, n, keep, nkeep);
    observe(b, &bg->visits[row], bg->warmup, in, fg, n, bg->step, bg->margin);
    copy_spans(b, held, n, keep, nkeep);
    /*
     * Against the larger of the two models: a row seeded from two or three looks knows its water
     * worse than the across-beam model, which has seen every beam (the foreground is smaller against
     * the larger model, as it falls with the model).
     */
    lesser(fg, fga, n);
}

/* Spans well formed: lo <= hi (those beyond n are clipped where used). */
static int spans_ok(const struct sonar_bg_span *sp, uint8_t nsp)
{
    uint8_t k;
    if (nsp > 0 && sp == NULL)
        return 0;
    for (k = 0; k < nsp; k++)
        if (sp[k].lo > sp[k].hi)
            return 0;
    return 1;
}

/* The learn spans' cells of the row raised to the observation x where it is brighter: structure's echo learnt at once. */
static void raise_spans(uint8_t *row, const uint8_t *x, uint16_t n, const struct sonar_bg_span *sp, uint8_t nsp)
{
    uint8_t k;
    for (k = 0; k < nsp; k++) {
        uint16_t i, hi = sp[k].hi < n ? sp[k].hi : n;
        for (i = sp[k].lo; i < hi; i++)
            row[i] = x[i] > row[i] ? x[i] : row[i];
    }
}

int sonar_background_apply_keep(struct sonar_background *bg, uint16_t angle, const uint8_t *in, uint8_t *fg,
                                uint16_t n, const struct sonar_bg_span *keep, uint8_t nkeep)
{
    return sonar_background_apply_spans(bg, angle, in, fg, n, keep, nkeep, NULL, 0);
}

int sonar_background_apply_spans(struct sonar_background *bg, uint16_t angle, const uint8_t *in, uint8_t *fg,
                                 uint16_t n, const struct sonar_bg_span *keep, uint8_t nkeep,
                                 const struct sonar_bg_span *learn, uint8_t nlearn)
{
    unsigned row;
    if (bg == NULL || in == NULL || fg == NULL || angle > SONAR_GRAD_MAX || n == 0 || n > SONAR_MAX_SAMPLES ||
        !spans_ok(keep, nkeep) || !spans_ok(learn, nlearn))
        return SONAR_ERR_ARG;
    if (bg->mode == SONAR_BACKGROUND_OFF) {
        if (fg != in)
            memcpy(fg, in, n);
        return SONAR_OK;
    }
    if (bg->world) {
        /* The grid's bytes mean nothing per angle: start afresh. */
        sonar_background_reset(bg);
        bg->reframes++;
    }
    if (n != bg->n) {
        sonar_background_reset(bg);
        bg->n = n;
    }
    row = bg->mode == SONAR_BACKGROUND_RANGE ? 0u : (unsigned)angle * SONAR_MAX_ANGLES / SONAR_GRAD_TURN;
    /* Before the observation, so this look already compares with what it raised (no copy of in needed). */
    if ((bg->mode == SONAR_BACKGROUND_AUTO || bg->mode == SONAR_BACKGROUND_PER_ANGLE) && bg->visits[row] >= bg->warmup)
        raise_spans(bg->cell[row], in, n, learn, nlearn);
    if (bg->mode == SONAR_BACKGROUND_AUTO)
        apply_auto(bg, row, in, fg, n, keep, nkeep);
    else
        observe(bg->cell[row], &bg->visits[row], bg->warmup, in, fg, n, bg->step, bg->margin);
    return SONAR_OK;
}

/* Observations of angle's row, or -1 where there are no per-angle rows (other modes, the world grid). */
static int row_visits(const struct sonar_background *bg, uint16_t angle)
{
    if (bg == NULL || bg->world || angle > SONAR_GRAD_MAX ||
        (bg->mode != SONAR_BACKGROUND_PER_ANGLE && bg->mode != SONAR_BACKGROUND_AUTO))
        return -1;
    return bg->visits[(unsigned)angle * SONAR_MAX_ANGLES / SONAR_GRAD_TURN];
}

int sonar_background_seeding(const struct sonar_background *bg, uint16_t angle)
{
    int v = row_visits(bg, angle);
    return v >= 0 && v < (int)bg->warmup;
}

int sonar_background_learnt(const struct sonar_background *bg, uint16_t angle)
{
    return row_visits(bg, angle) > (int)bg->warmup;
}

int sonar_background_apply(struct sonar_background *bg, uint16_t angle, const uint8_t *in, uint8_t *fg, uint16_t n)
{
    return sonar_background_apply_keep(bg, angle, in, fg, n, NULL, 0);
}
