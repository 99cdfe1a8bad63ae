/* sweep.h -- finds sweep boundaries in the sequence of beam angles (wrap, jump, direction reversal); RAM: sizeof(struct sonar_sweep) = 16 B. */
#ifndef SONAR_SWEEP_H
#define SONAR_SWEEP_H

#include <stdint.h>

#include "sonar/err.h"

enum sonar_sweep_cut {
    SONAR_SWEEP_SAME = 0,     /* the beam continues the current sweep */
    SONAR_SWEEP_WRAP = 1,     /* a full turn (400 gradians) was completed */
    SONAR_SWEEP_REVERSE = 2,  /* the head changed direction (back-and-forth sector scan) */
    SONAR_SWEEP_JUMP = 3,     /* the angle jumped by more than max_step (sector restarted) */
    SONAR_SWEEP_FULL = 4      /* the sweep already holds max_beams beams */
};

struct sonar_sweep {
    uint32_t index;     /* sweep number, 0 for the first */
    uint16_t last;      /* last angle, gradians */
    uint16_t traversed; /* gradians moved since the sweep's first beam */
    uint16_t beams;     /* beams in the current sweep */
    uint16_t max_step;  /* larger moves are jumps, gradians 1..200 */
    uint16_t max_beams; /* cut after this many beams */
    int8_t dir;         /* +1, -1, or 0 until the sweep's second distinct angle */
    uint8_t started;
};

/* max_step: 1..200 gradians; max_beams: >= 2. Returns SONAR_OK or SONAR_ERR_ARG. */
SONAR_CHECK int sonar_sweep_init(struct sonar_sweep *s, uint16_t max_step, uint16_t max_beams);

/*
 * Feeds the next beam's angle (0..399 gradians; larger values are taken mod 400). Returns
 * SONAR_SWEEP_SAME when it continues the current sweep, or the reason it opens a new one (then
 * s->index has been incremented and the beam is the new sweep's first). The first beam ever
 * opens sweep 0 and returns SONAR_SWEEP_SAME. A repeated angle continues the sweep.
 */
int sonar_sweep_step(struct sonar_sweep *s, uint16_t angle);

#endif
