/* gain.h -- automatic receiver gain for the Ping360's three settings, from each sweep's raw echo statistics, with hysteresis; RAM: sizeof(struct sonar_gain) = 1 064 B, a 256-bin histogram and a few counters. */
#ifndef SONAR_GAIN_H
#define SONAR_GAIN_H

#include <stdint.h>

#include "sonar/err.h"

#define SONAR_GAIN_MAX 2 /* 0 low, 1 normal, 2 high */

/*
 * A sweep's raw samples (before any filter) decide, at its end only (never mid-sector): more than
 * sat_max of them at or above sat_level -> one setting lower; else, with fewer than sat_max / 10
 * saturated, a median at or below floor_level (the noise floor at the bottom of the scale) -> one
 * higher. Hysteresis: after a change, hold_sweeps sweeps pass before the next; a setting that
 * saturated is not gone back up to for memory_sweeps sweeps, twice as long each time it saturates
 * again right after going back up (no oscillating between two).
 */
struct sonar_gain_config {
    uint8_t start;          /* the setting at first, 0..2 */
    uint8_t sat_level;      /* a saturated sample: >= this, 128..255 */
    float sat_max;          /* fraction of a sweep's samples saturated that is too many, (0, 0.5] */
    uint8_t floor_level;    /* a median at or below this is the floor, 0..64 */
    uint8_t hold_sweeps;    /* sweeps after a change before another, 1..100 */
    uint8_t memory_sweeps;  /* sweeps a saturating setting stays barred, 0..255 */
};

struct sonar_gain {
    struct sonar_gain_config cfg;
    uint32_t hist[256];     /* this sweep's raw samples by value */
    uint32_t samples;       /* in hist */
    uint32_t other;         /* beams this sweep at another setting (not counted): replies from before a change, or a
                               sonar that did not take it */
    uint32_t changes;       /* settings changed */
    uint8_t gain;           /* the setting now, 0..2 */
    uint8_t held;           /* sweeps since the last change (saturating) */
    uint8_t barred;         /* the lowest setting that saturated lately, SONAR_GAIN_MAX + 1: none */
    uint16_t barred_for;    /* sweeps it stays barred */
    uint16_t bar_len;       /* the last bar's length: doubled when a setting saturates again just after a raise to it */
    uint8_t raised;         /* the last change went up */
    uint8_t last_median;    /* the last ended sweep's median sample */
    float last_sat;         /* ... and its saturated fraction */
};

/* sonard's defaults: start 0, saturated at 250, too many at 1 %, floor at 2, hold 2 sweeps, memory 30. */
void sonar_gain_defaults(struct sonar_gain_config *cfg);

/* NULL when cfg is valid, else a static "field: rule" string naming the first bad field. cfg must not be NULL. */
const char *sonar_gain_config_check(const struct sonar_gain_config *cfg);

/* Copies cfg; the setting is cfg->start. Returns SONAR_OK or SONAR_ERR_ARG. */
SONAR_CHECK int sonar_gain_init(struct sonar_gain *g, const struct sonar_gain_config *cfg);

/* Counts one raw beam of n samples (read during the call only) taken at setting `at`; one at another setting is only counted in other. */
void sonar_gain_beam(struct sonar_gain *g, const uint8_t *samples, uint16_t n, uint8_t at);

/*
 * Ends a sweep: decides from its beams and starts the next count (samples and other back to 0).
 * Returns the new setting (0..2) when it changes, else -1. O(256).
 */
int sonar_gain_sweep_end(struct sonar_gain *g);

#endif
