/* background.c -- uint8 running-median background, subtract and clamp; one pass of saturating byte ops per beam, no heap. */
#include "sonar/background.h"

#include <string.h>

int sonar_background_init(struct sonar_background *bg, const struct sonar_background_config *cfg)
{
    if (bg == NULL || cfg == NULL || cfg->mode > SONAR_BACKGROUND_RANGE || cfg->warmup < 1 || cfg->warmup > 64 ||
        cfg->step < 1 || cfg->step > 64 || cfg->margin > 64)
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

/* Warm-up: running mean of the first observations, which the ±step tracker then refines. A cell
 * still being seeded has no model to compare with, so it reports no foreground. */
static void seed(uint8_t *b, const uint8_t *in, uint8_t *fg, uint16_t n, unsigned v)
{
    uint16_t i;
    memset(fg, 0, n);
    for (i = 0; i < n; i++) {
        int d = (int)in[i] - (int)b[i];
        if (v == 1)
            b[i] = in[i];
        else
            b[i] = (uint8_t)((int)b[i] + (d >= 0 ? (d + (int)v / 2) / (int)v : -((-d + (int)v / 2) / (int)v)));
    }
}

/* Steady state: byte-wise saturating arithmetic only, so the loop vectorises. */
static void track(uint8_t *restrict b, const uint8_t *restrict in, uint8_t *restrict fg, uint16_t n, uint8_t step,
                  uint8_t margin)
{
    uint16_t i;
    for (i = 0; i < n; i++) {
        uint8_t x = in[i], m = b[i];
        uint8_t up = (uint8_t)(x > m ? x - m : 0);
        uint8_t dn = (uint8_t)(m > x ? m - x : 0);
        uint8_t gate = (uint8_t)(((unsigned)m * margin) >> 4 > 255u ? 255u : ((unsigned)m * margin) >> 4);
        fg[i] = (uint8_t)(up > gate ? up - gate : 0);
        b[i] = (uint8_t)(m + (up < step ? up : step) - (dn < step ? dn : step));
    }
}

int sonar_background_apply(struct sonar_background *bg, uint16_t angle, const uint8_t *in, uint8_t *fg, uint16_t n)
{
    unsigned row, v;
    if (bg == NULL || in == NULL || fg == NULL || angle > 399u || n == 0 || n > SONAR_MAX_SAMPLES)
        return SONAR_ERR_ARG;
    if (bg->mode == SONAR_BACKGROUND_OFF) {
        memcpy(fg, in, n);
        return SONAR_OK;
    }
    if (n != bg->n) {
        sonar_background_reset(bg);
        bg->n = n;
    }
    row = bg->mode == SONAR_BACKGROUND_RANGE ? 0u : (unsigned)angle * SONAR_MAX_ANGLES / 400u;
    v = bg->visits[row] < 255u ? (unsigned)bg->visits[row] + 1u : 255u;
    bg->visits[row] = (uint8_t)v;
    if (v <= bg->warmup)
        seed(bg->cell[row], in, fg, n, v);
    else
        track(bg->cell[row], in, fg, n, bg->step, bg->margin);
    return SONAR_OK;
}
