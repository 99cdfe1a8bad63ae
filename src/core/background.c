/* background.c -- uint8 running-median background, subtract and clamp; one pass of saturating byte ops per beam, no heap. */
#include "sonar/background.h"

#include <math.h>
#include <string.h>

#include "simd_internal.h"
#include "sonar/frame.h"

#define STR2(x) #x
#define STR(x) STR2(x)

const char *sonar_background_config_check(const struct sonar_background_config *cfg)
{
    if (cfg->mode > SONAR_BACKGROUND_AUTO)
        return "mode: off, per-angle, range or auto";
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

static void follow_row4(uint8_t *b, const uint8_t *in, uint8_t *fg, int words, uint8_t step, uint8_t margin)
{
    uint32_t s4 = 0x01010101u * step, mask;
    unsigned shift;
    int w, shifted = gate_shift(margin, &shift, &mask);
    for (w = 0; w < words; w++) {
        uint32_t x, m, up, dn, gate;
        memcpy(&x, in + 4 * w, 4);
        memcpy(&m, b + 4 * w, 4);
        up = __uqsub8(x, m);
        dn = __uqsub8(m, x);
        gate = shifted ? (m >> shift) & mask : gate4(m, margin);
        x = __uqsub8(up, gate); /* the foreground */
        memcpy(fg + 4 * w, &x, 4);
        m = m + (up - __uqsub8(up, s4)) - (dn - __uqsub8(dn, s4));
        memcpy(b + 4 * w, &m, 4);
    }
}

/* m stepped towards x by at most s4 per byte: never carries or borrows across bytes (see above). */
static uint32_t towards4(uint32_t m, uint32_t x, uint32_t s4)
{
    uint32_t up = __uqsub8(x, m), dn = __uqsub8(m, x);
    return m + (up - __uqsub8(up, s4)) - (dn - __uqsub8(dn, s4));
}

static void pair4(uint8_t *b, uint8_t *a, const uint8_t *in, uint8_t *fg, int words, uint8_t step, uint8_t margin)
{
    uint32_t s4 = 0x01010101u * step, mask;
    unsigned shift;
    int w, shifted = gate_shift(margin, &shift, &mask);
    for (w = 0; w < words; w++) {
        uint32_t x, m, c, top, out;
        memcpy(&x, in + 4 * w, 4);
        memcpy(&m, b + 4 * w, 4);
        memcpy(&c, a + 4 * w, 4);
        top = c + __uqsub8(m, c); /* max(m, c) per byte */
        out = __uqsub8(__uqsub8(x, top), shifted ? (top >> shift) & mask : gate4(top, margin));
        memcpy(fg + 4 * w, &out, 4);
        m = towards4(m, x, s4);
        c = towards4(c, x, s4);
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

int sonar_background_apply_keep(struct sonar_background *bg, uint16_t angle, const uint8_t *in, uint8_t *fg,
                                uint16_t n, const struct sonar_bg_span *keep, uint8_t nkeep)
{
    unsigned row;
    uint8_t k;
    if (bg == NULL || in == NULL || fg == NULL || angle > SONAR_GRAD_MAX || n == 0 || n > SONAR_MAX_SAMPLES ||
        (nkeep > 0 && keep == NULL))
        return SONAR_ERR_ARG;
    for (k = 0; k < nkeep; k++)
        if (keep[k].lo > keep[k].hi)
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
    if (bg->mode == SONAR_BACKGROUND_AUTO)
        apply_auto(bg, row, in, fg, n, keep, nkeep);
    else
        observe(bg->cell[row], &bg->visits[row], bg->warmup, in, fg, n, bg->step, bg->margin);
    return SONAR_OK;
}

int sonar_background_seeding(const struct sonar_background *bg, uint16_t angle)
{
    if (bg == NULL || bg->world || angle > SONAR_GRAD_MAX ||
        (bg->mode != SONAR_BACKGROUND_PER_ANGLE && bg->mode != SONAR_BACKGROUND_AUTO))
        return 0;
    return bg->visits[(unsigned)angle * SONAR_MAX_ANGLES / SONAR_GRAD_TURN] < bg->warmup;
}

int sonar_background_apply(struct sonar_background *bg, uint16_t angle, const uint8_t *in, uint8_t *fg, uint16_t n)
{
    return sonar_background_apply_keep(bg, angle, in, fg, n, NULL, 0);
}

/* ---- the world grid ---- */

/* Cells a side: the largest square of two-byte cells that the per-angle bytes hold beside the range profile. */
static uint16_t grid_side(void)
{
    uint32_t g = 1;
    while (2u * (g + 1u) * (g + 1u) <= SONAR_BG_GRID_CELLS - SONAR_MAX_SAMPLES)
        g++;
    return (uint16_t)g;
}

/* a modulo m, 0..m-1, for any sign. */
static uint32_t mod(int32_t a, uint16_t m)
{
    int32_t r = a % (int32_t)m;
    return (uint32_t)(r < 0 ? r + (int32_t)m : r);
}

/* A cell: its model (0 = never seen) and, next to it, its observations so far (saturating). */
static uint8_t *grid_at(struct sonar_background *bg, int32_t i, int32_t j)
{
    return &bg->cell[0][0] + 2u * (mod(i, bg->grid) * bg->grid + mod(j, bg->grid));
}

/* The world cell index holding coordinate v (metres). */
static int32_t cell_index(const struct sonar_background *bg, double v)
{
    return (int32_t)floor(v / (double)bg->cell_m);
}

/* The range profile: the last SONAR_MAX_SAMPLES bytes, after the grid. */
static uint8_t *profile(struct sonar_background *bg)
{
    return &bg->cell[0][0] + SONAR_BG_GRID_CELLS - SONAR_MAX_SAMPLES;
}

/*
 * Keeps the window [wi0, wi0 + grid) x [wj0, wj0 + grid) centred on cell (ci, cj): rows and
 * columns that scroll in were last used for cells that scrolled out, so they are cleared.
 */
static void scroll(struct sonar_background *bg, int32_t ci, int32_t cj)
{
    const int32_t g = (int32_t)bg->grid;
    int32_t ni = ci - g / 2, nj = cj - g / 2, k, r;
    if (ni - bg->wi0 >= g || bg->wi0 - ni >= g || nj - bg->wj0 >= g || bg->wj0 - nj >= g) {
        memset(&bg->cell[0][0], 0, 2u * (size_t)g * (size_t)g);
    } else {
        /* Entering rows: [wi0 + g, ni + g) moving north, [ni, wi0) moving south; columns alike. */
        for (k = ni > bg->wi0 ? bg->wi0 + g : ni; k < (ni > bg->wi0 ? ni + g : bg->wi0); k++)
            memset(grid_at(bg, k, 0), 0, 2u * (size_t)g);
        for (k = nj > bg->wj0 ? bg->wj0 + g : nj; k < (nj > bg->wj0 ? nj + g : bg->wj0); k++)
            for (r = 0; r < g; r++) {
                uint8_t *c = grid_at(bg, r, k);
                c[0] = c[1] = 0;
            }
    }
    bg->wi0 = ni;
    bg->wj0 = nj;
}

/* One step of the running median toward x, 0 being "never seen" (seeded by x). */
static uint8_t follow(uint8_t b, uint8_t x, unsigned st)
{
    unsigned m = b, up, dn;
    if (b == 0)
        return x > 0 ? x : 1u;
    up = x > m ? x - m : 0u;
    dn = x < m ? m - x : 0u;
    m = m + (up < st ? up : st) - (dn < st ? dn : st);
    return (uint8_t)(m > 0u ? m : 1u);
}

/* One observation of a grid cell: averaged in over the first warmup ones, then the step rule. */
static void learn(uint8_t *c, uint8_t x, unsigned warmup, unsigned st)
{
    unsigned v = c[1] < 255u ? c[1] + 1u : 255u;
    c[1] = (uint8_t)v;
    if (v <= warmup) {
        /* b += (x - b) / v, rounded; kept >= 1 since 0 means never seen */
        int b = v == 1u ? (int)x : (int)c[0] + ((int)x - (int)c[0] + (x >= c[0] ? (int)v / 2 : -(int)v / 2)) / (int)v;
        c[0] = (uint8_t)(b < 1 ? 1 : b > 255 ? 255 : b);
    } else {
        c[0] = follow(c[0], x, st);
    }
}

static int ray_ok(const struct sonar_bg_ray *r)
{
    return isfinite(r->north_m) && isfinite(r->east_m) && fabs(r->north_m) <= 1e6 && fabs(r->east_m) <= 1e6 &&
           isfinite(r->bearing_deg) && fabs(r->bearing_deg) <= 1e6 && isfinite(r->width_deg) &&
           r->range_m > 0.0f && r->range_m <= 1000.0f && r->near_m >= 0.0f && isfinite(r->near_m);
}

/*
 * Rings of cells a beam crosses at most: it reaches a third of the grid's side, which is at most
 * 905 cells (400 x 4096 bytes of two-byte cells). Stack: 2 bytes a ring.
 */
#define RINGS_MAX 310
SONAR_STATIC_ASSERT(SONAR_MAX_ANGLES * SONAR_MAX_SAMPLES <= 400 * 4096, rings_max_holds_the_grid);

/*
 * A rotation by a fixed angle, the points of an arc stepped by it: the beams' arcs have a few dozen
 * distinct point counts, so each count's step is computed once a beam, not once a ring.
 */
#define ARC_CACHE 64
struct arc_steps {
    double c[ARC_CACHE], s[ARC_CACHE]; /* cos, sin of span / pts for pts < ARC_CACHE */
    uint8_t have[ARC_CACHE];
    double span;
};

static void arc_step(struct arc_steps *a, int32_t pts, double *c, double *s)
{
    if (pts >= ARC_CACHE) {
        *c = cos(a->span / (double)pts);
        *s = sin(a->span / (double)pts);
        return;
    }
    if (!a->have[pts]) {
        a->c[pts] = cos(a->span / (double)pts);
        a->s[pts] = sin(a->span / (double)pts);
        a->have[pts] = 1;
    }
    *c = a->c[pts];
    *s = a->s[pts];
}

/*
 * What static structure can return at each range along the beam: for every ring of cells the beam
 * reaches, the largest model on the arc of SONAR_BG_LOOK_DEG about the beam (ringmax), then the
 * largest over +- slack rings (out). A wall's echo depends on where it is seen from (strong head-on,
 * weak and spread out in range at a glance), and the pose and the beam's width place it only so
 * well; comparing with the cell under the sample alone made walls the detections on the simulated
 * vehicle scene. 0 where none was ever seen. One pass over the arc's cells, about 1 000 reads at
 * 15 m, instead of the arc again for every sample (the first form of this cost 500 us a beam).
 */
static void look_rings(struct sonar_background *bg, const struct sonar_bg_ray *ray, double th, int32_t rings,
                       int32_t slack, uint8_t *out)
{
    static const double deg = SONAR_RAD_PER_DEG;
    struct arc_steps a;
    uint8_t ringmax[RINGS_MAX];
    double cs = (double)bg->cell_m, c0 = cos(th - SONAR_BG_LOOK_DEG * deg / 2.0), s0 = sin(th - SONAR_BG_LOOK_DEG * deg / 2.0);
    int32_t k, j;
    memset(a.have, 0, sizeof(a.have));
    a.span = SONAR_BG_LOOK_DEG * deg;
    for (k = 0; k < rings; k++) {
        double r = ((double)k + 0.5) * cs, cu = c0, su = s0, cd, sd;
        int32_t pts = (int32_t)ceil(r * a.span / cs);
        uint8_t m = 0;
        pts = pts < 1 ? 1 : pts;
        arc_step(&a, pts, &cd, &sd);
        for (j = 0; j <= pts; j++) {
            double t = cu * cd - su * sd;
            uint8_t v = *grid_at(bg, cell_index(bg, ray->north_m + r * cu), cell_index(bg, ray->east_m + r * su));
            m = v > m ? v : m;
            su = su * cd + cu * sd;
            cu = t;
        }
        ringmax[k] = m;
    }
    for (k = 0; k < rings; k++) {
        uint8_t m = 0;
        for (j = k - slack; j <= k + slack; j++)
            if (j >= 0 && j < rings && ringmax[j] > m)
                m = ringmax[j];
        out[k] = m;
    }
}

/* Is (north, east) inside one of the discs? */
static int kept(const struct sonar_bg_disc *keep, uint8_t nkeep, double north, double east)
{
    uint8_t k;
    for (k = 0; k < nkeep; k++) {
        double dn = north - (double)keep[k].north_m, de = east - (double)keep[k].east_m;
        if (dn * dn + de * de <= (double)keep[k].radius_m * (double)keep[k].radius_m)
            return 1;
    }
    return 0;
}

int sonar_background_apply_world(struct sonar_background *bg, const struct sonar_bg_ray *ray, const uint8_t *in,
                                 uint8_t *fg, uint16_t n)
{
    return sonar_background_apply_world_keep(bg, ray, in, fg, n, NULL, 0);
}

int sonar_background_apply_world_keep(struct sonar_background *bg, const struct sonar_bg_ray *ray, const uint8_t *in,
                                      uint8_t *fg, uint16_t n, const struct sonar_bg_disc *keep, uint8_t nkeep)
{
    static const double deg = SONAR_RAD_PER_DEG;
    uint8_t src[SONAR_MAX_SAMPLES], near[RINGS_MAX];
    struct sonar_bg_disc here[SONAR_BG_DISCS_MAX];
    struct arc_steps arc;
    double th, w, c0, s0, cs, rmax, cw, sw;
    int32_t k, k0, kmax, slack, rings;
    uint16_t i;
    uint8_t nhere = 0, d;
    if (bg == NULL || ray == NULL || in == NULL || fg == NULL || n == 0 || n > SONAR_MAX_SAMPLES || !ray_ok(ray) ||
        (nkeep > 0 && keep == NULL))
        return SONAR_ERR_ARG;
    if (bg->mode != SONAR_BACKGROUND_PER_ANGLE && bg->mode != SONAR_BACKGROUND_AUTO)
        return sonar_background_apply(bg, 0, in, fg, n);
    /* The beam is learnt from after fg is written, and they may be the same buffer. */
    memcpy(src, in, n);
    in = src;
    if (!bg->world || n != bg->n || ray->range_m != bg->grid_range_m) {
        if (!bg->world && bg->n != 0)
            bg->reframes++;
        sonar_background_reset(bg);
        bg->world = 1;
        bg->n = n;
        bg->grid = grid_side();
        bg->grid_range_m = ray->range_m;
        bg->cell_m = (float)SONAR_BG_WINDOW * ray->range_m / (float)(bg->grid - 4u);
        bg->wi0 = cell_index(bg, ray->north_m) - (int32_t)bg->grid / 2;
        bg->wj0 = cell_index(bg, ray->east_m) - (int32_t)bg->grid / 2;
        memset(&bg->cell[0][0], 0, 2u * (size_t)bg->grid * bg->grid);
        memset(profile(bg), 0, SONAR_MAX_SAMPLES);
    }
    cs = (double)bg->cell_m;
    slack = (int32_t)ceil((double)SONAR_BG_SLACK_M / cs);
    scroll(bg, cell_index(bg, ray->north_m), cell_index(bg, ray->east_m));
    th = ray->bearing_deg * deg;
    c0 = cos(th);
    s0 = sin(th);
    rmax = (double)ray->range_m;
    rings = (int32_t)ceil(rmax / cs) + 1;
    rings = rings > RINGS_MAX ? RINGS_MAX : rings;
    look_rings(bg, ray, th, rings, slack, near);
    /* The foreground against the model before this beam. */
    for (i = 0; i < n; i++) {
        double r = ((double)i + 0.5) * rmax / (double)n;
        const uint8_t *under;
        int32_t ring = (int32_t)(r / cs);
        uint8_t x = in[i], m, pr = profile(bg)[i];
        fg[i] = 0;
        if (r < (double)ray->near_m)
            continue;
        /* A cell seen fewer than SONAR_BG_MIN_SEEN times (the edge of what the vehicle has explored) says nothing yet. */
        under = grid_at(bg, cell_index(bg, ray->north_m + r * c0), cell_index(bg, ray->east_m + r * s0));
        if (under[1] < SONAR_BG_MIN_SEEN)
            continue;
        m = near[ring < rings ? ring : rings - 1];
        /* The level every beam sees at this range (the ring-down's tail, the gain's curve) moves with the sonar. */
        m = pr > m ? pr : m;
        if (m != 0) {
            unsigned gate = ((unsigned)m * bg->margin) >> 4, up = x > m ? (unsigned)(x - m) : 0u;
            fg[i] = (uint8_t)(up > gate ? up - gate : 0u);
        }
    }
    for (i = 0; i < n; i++)
        profile(bg)[i] = follow(profile(bg)[i], in[i], bg->step);
    /*
     * The footprint: rings one cell apart, each crossed by points at most a cell apart along its
     * arc (so every cell of the wedge is visited about once), turned by a rotation each step
     * rather than a sine per point. Each point takes the sample at its ring's range. Cells within
     * a kept disc (a tracked object) are not learnt: of those discs, only the ones this wedge can
     * reach are looked at.
     */
    w = ray->width_deg < 0.5 ? 0.5 : ray->width_deg > 90.0 ? 90.0 : ray->width_deg;
    w *= deg;
    for (d = 0; d < nkeep && nhere < SONAR_BG_DISCS_MAX; d++) {
        double dn = (double)keep[d].north_m - ray->north_m, de = (double)keep[d].east_m - ray->east_m;
        double dist = sqrt(dn * dn + de * de), rad = (double)keep[d].radius_m;
        double off = fabs(remainder(atan2(de, dn) - th, 2.0 * SONAR_PI));
        if (dist - rad < rmax && (dist <= rad || off <= w / 2.0 + asin(rad / dist)))
            here[nhere++] = keep[d];
    }
    k0 = (int32_t)floor((double)ray->near_m / cs);
    kmax = (int32_t)floor(rmax / cs);
    cw = cos(th - w / 2.0);
    sw = sin(th - w / 2.0);
    memset(arc.have, 0, sizeof(arc.have));
    arc.span = w / 2.0; /* the half step from the wedge's edge to its first point, by points */
    for (k = k0; k < kmax; k++) {
        double r = ((double)k + 0.5) * cs, ca, sa, ch, sh, cd, sd;
        int32_t pts = (int32_t)ceil(r * w / cs), j;
        uint8_t x;
        if (r < (double)ray->near_m)
            continue;
        i = (uint16_t)(r / rmax * (double)n);
        if (i >= n)
            break;
        x = in[i];
        pts = pts < 1 ? 1 : pts;
        /* Points at the middles of pts equal parts of the wedge: half a part in, then whole parts. */
        arc_step(&arc, pts, &ch, &sh);
        cd = ch * ch - sh * sh;
        sd = 2.0 * sh * ch;
        ca = cw * ch - sw * sh;
        sa = sw * ch + cw * sh;
        for (j = 0; j < pts; j++) {
            double t = ca * cd - sa * sd, pn = ray->north_m + r * ca, pe = ray->east_m + r * sa;
            if (nhere == 0 || !kept(here, nhere, pn, pe))
                learn(grid_at(bg, cell_index(bg, pn), cell_index(bg, pe)), x, bg->warmup, bg->step);
            sa = sa * cd + ca * sd;
            ca = t;
        }
    }
    return SONAR_OK;
}

int sonar_background_world_at(const struct sonar_background *bg, double north_m, double east_m, uint8_t *model,
                              uint8_t *seen)
{
    int32_t i, j;
    const uint8_t *c;
    *model = *seen = 0;
    if (bg == NULL || !bg->world || !isfinite(north_m) || !isfinite(east_m) || fabs(north_m) > 1e6 || fabs(east_m) > 1e6)
        return 0;
    i = cell_index(bg, north_m);
    j = cell_index(bg, east_m);
    if (i < bg->wi0 || i >= bg->wi0 + (int32_t)bg->grid || j < bg->wj0 || j >= bg->wj0 + (int32_t)bg->grid)
        return 0;
    c = &bg->cell[0][0] + 2u * (mod(i, bg->grid) * bg->grid + mod(j, bg->grid));
    *model = c[0];
    *seen = c[1];
    return 1;
}
