/* survey_internal.h -- what survey.c (use) and survey_rec.c (recording) share: rows, ranges, the ring-down, a histogram's median; inline, no RAM. */
#ifndef SONAR_SURVEY_INTERNAL_H
#define SONAR_SURVEY_INTERNAL_H

#include <math.h>
#include <stdint.h>

#include "sonar/config.h"
#include "sonar/frame.h"
#include "sonar/survey.h"

static inline unsigned row_of(uint16_t angle)
{
    return (unsigned)angle * SONAR_MAX_ANGLES / SONAR_GRAD_TURN;
}

/* The first gradian of a row (rows are SONAR_GRAD_TURN / SONAR_MAX_ANGLES gradians wide). */
static inline uint16_t angle_of(unsigned row)
{
    return (uint16_t)(row * SONAR_GRAD_TURN / SONAR_MAX_ANGLES);
}

/* Two ranges are one setting: the range is the sample period times the speed of sound, 1 mm is rounding. */
static inline int same_range(float a_m, double b_mm)
{
    return fabs((double)a_m * 1e3 - b_mm) <= 1.0;
}

/* Samples of the ring-down at n samples over range_m (at least one, at most n). */
static inline uint16_t near_samples(uint16_t n, double range_m)
{
    double s = ceil((double)SONAR_SURVEY_NEAR_M * (double)n / range_m);
    return (uint16_t)(s < 1.0 ? 1.0 : s > (double)n ? (double)n : s);
}

/* The median of a byte histogram of count values. */
static inline uint8_t hist_median(const uint16_t *h, unsigned count)
{
    unsigned acc = 0, v;
    for (v = 0; v < 256u; v++)
        if ((acc += h[v]) * 2u >= count)
            return (uint8_t)v;
    return 255;
}

#endif
