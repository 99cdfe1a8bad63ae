/* background.h -- per-angle (or per-range) approximate running median of the echo, subtracted and clamped at 0; RAM: SONAR_MAX_ANGLES * (SONAR_MAX_SAMPLES + 1) + 16 B. */
#ifndef SONAR_BACKGROUND_H
#define SONAR_BACKGROUND_H

#include <stdint.h>

#include "sonar/config.h"
#include "sonar/err.h"

enum sonar_background_mode {
    SONAR_BACKGROUND_OFF = 0,       /* foreground = input */
    SONAR_BACKGROUND_PER_ANGLE = 1, /* one model per (angle, range) cell, updated once per visit */
    SONAR_BACKGROUND_RANGE = 2      /* the study's: one model per range bin, across the beams */
};

/*
 * Model of each cell b (uint8): the first `warmup` observations are averaged (b += (x - b) / v,
 * rounded, so the first observation seeds it), then b moves `step` levels toward every new
 * observation (McFarlane-Schofield / Frugal-1U), which converges on the median. While a cell is
 * being seeded it reports no foreground. In per-angle mode
 * a cell is observed once per sweep; in range mode once per beam.
 *
 * Sonar speckle is multiplicative (a Rayleigh echo's spread grows with its mean), so a bright
 * static echo such as a wall fluctuates by tens of levels around its median. margin > 0 makes the
 * subtraction a contrast test, x must exceed b by b * margin / 16 before anything is left (a
 * constant-false-alarm-rate rule); margin = 0 is the study's plain subtraction.
 */
#define SONAR_BG_WARMUP_MAX 64 /* warmup 1..64 */
#define SONAR_BG_STEP_MAX 64   /* step 1..64 */
#define SONAR_BG_MARGIN_MAX 64 /* margin 0..64 */

struct sonar_background_config {
    uint8_t mode;   /* enum sonar_background_mode */
    uint8_t warmup; /* observations averaged to seed a cell, 1..64 */
    uint8_t step;   /* levels per observation after warm-up, 1..64 */
    uint8_t margin; /* contrast margin in 16ths of b, 0..64: fg = max(0, x - b - b * margin / 16) */
};

struct sonar_background {
    uint8_t cell[SONAR_MAX_ANGLES][SONAR_MAX_SAMPLES];
    uint8_t visits[SONAR_MAX_ANGLES]; /* observations so far per row, saturating at 255 */
    uint16_t n;                       /* samples per beam the model holds; 0 = empty */
    uint8_t mode;
    uint8_t warmup;
    uint8_t step;
    uint8_t margin;
};

/* NULL when cfg is valid, else a static "field: rule" string naming the first bad field. cfg must not be NULL. */
const char *sonar_background_config_check(const struct sonar_background_config *cfg);

/* Validates cfg (copied) and empties the model. Returns SONAR_OK or SONAR_ERR_ARG. */
SONAR_CHECK int sonar_background_init(struct sonar_background *bg, const struct sonar_background_config *cfg);

/* Changes step and margin in place, keeping the model; a new mode or warmup needs init (a fresh
 * model). Returns SONAR_OK or SONAR_ERR_ARG (nothing changed). */
SONAR_CHECK int sonar_background_tune(struct sonar_background *bg, const struct sonar_background_config *cfg);

/* Forgets every cell (e.g. after the range or sample count changed). */
void sonar_background_reset(struct sonar_background *bg);

/*
 * fg[i] = max(0, in[i] - b[i] - b[i] * margin / 16) using the model before this observation, then updates the model.
 * angle: gradians 0..399; n: 1..SONAR_MAX_SAMPLES. A different n than the model holds resets the
 * model first. in and fg may not overlap. Returns SONAR_OK or SONAR_ERR_ARG.
 */
SONAR_CHECK int sonar_background_apply(struct sonar_background *bg, uint16_t angle, const uint8_t *in, uint8_t *fg,
                                       uint16_t n);

#endif
