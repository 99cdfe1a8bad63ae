/* geometry.c -- Ping360 physics conversions (speed of sound, 25 ns ticks, gradians); a few flops each. */
#include "sonar/geometry.h"

#include <math.h>
#include <stddef.h>

double sonar_geometry_range_m(uint16_t sample_period, uint16_t n, double c)
{
    return (double)sample_period * SONAR_TICK_S * (double)n * c / 2.0;
}

int sonar_geometry_sample_period(double range_m, uint16_t n, double c, uint16_t *ticks)
{
    double t;
    if (ticks == NULL || !(range_m > 0.0) || n == 0 || !(c > 0.0))
        return SONAR_ERR_ARG;
    t = 2.0 * range_m / ((double)n * c * SONAR_TICK_S);
    /* A hair of slack so that exact products (2 m, 1200, 1500 -> 88.88) truncate as the device does. */
    t = floor(t + 1e-9);
    if (t < (double)SONAR_MIN_SAMPLE_PERIOD || t > (double)SONAR_MAX_SAMPLE_PERIOD)
        return SONAR_ERR_RANGE;
    *ticks = (uint16_t)t;
    return SONAR_OK;
}

uint16_t sonar_geometry_max_samples(double range_m, double c)
{
    double n;
    uint16_t ticks;
    if (!(range_m > 0.0) || !(c > 0.0))
        return 0;
    n = floor(2.0 * range_m / (c * SONAR_TICK_S * (double)SONAR_MIN_SAMPLE_PERIOD));
    if (n > (double)SONAR_DEVICE_MAX_SAMPLES)
        n = SONAR_DEVICE_MAX_SAMPLES;
    /* Rounding near a boundary: step down until the truncated period is legal. */
    while (n >= (double)SONAR_DEVICE_MIN_SAMPLES && sonar_geometry_sample_period(range_m, (uint16_t)n, c, &ticks) != SONAR_OK)
        n -= 1.0;
    return n >= (double)SONAR_DEVICE_MIN_SAMPLES ? (uint16_t)n : 0;
}

uint16_t sonar_geometry_transmit_duration(double range_m, double c, uint16_t sample_period)
{
    double sp_us = (double)sample_period * 0.025;
    double tx = floor(8000.0 * range_m / c + 0.5);
    double lo = ceil(2.5 * sp_us - 1e-9);
    double hi = 64.0 * sp_us;
    if (hi > (double)SONAR_MAX_TX_US)
        hi = SONAR_MAX_TX_US;
    hi = floor(hi);
    if (tx < lo)
        tx = lo;
    if (tx > hi)
        tx = hi;
    if (tx < (double)SONAR_MIN_TX_US)
        tx = SONAR_MIN_TX_US;
    return (uint16_t)tx;
}

double sonar_geometry_sample_range(uint16_t i, uint16_t n, double range_m)
{
    return n == 0 ? 0.0 : ((double)i + 0.5) * range_m / (double)n;
}

int32_t sonar_geometry_sample_index(double r, uint16_t n, double range_m)
{
    double i;
    if (n == 0 || !(range_m > 0.0) || !(r >= 0.0) || r >= range_m)
        return -1;
    i = floor(r * (double)n / range_m);
    return i >= (double)n ? (int32_t)n - 1 : (int32_t)i;
}
