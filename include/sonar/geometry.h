/* geometry.h -- Ping360 range, sample-period, transmit-duration and polar-to-metres conversions; pure functions, no RAM. */
#ifndef SONAR_GEOMETRY_H
#define SONAR_GEOMETRY_H

#include <stdint.h>

#include "sonar/err.h"
#include "sonar/frame.h" /* the frame, its angles and its xy */

#define SONAR_TICK_S 25e-9             /* one sample_period tick */
#define SONAR_MIN_SAMPLE_PERIOD 80u    /* firmware minimum, ticks (2 us) */
#define SONAR_MAX_SAMPLE_PERIOD 40000u /* protocol maximum, ticks (1 ms) */
#define SONAR_MIN_TX_US 5u             /* firmware transmit-duration limits, us */
#define SONAR_MAX_TX_US 500u
#define SONAR_DEVICE_MAX_SAMPLES 1200u
#define SONAR_DEVICE_MIN_SAMPLES 200u
#define SONAR_BEAM_WIDTH_DEG 2.0       /* the Ping360's beam between its half-power points, degrees */

/*
 * The sonar frame is in frame.h. Sample i of N over range R covers [i, i+1) * R / N and sits
 * at its centre, r_i = (i + 0.5) * R / N. (Ping Viewer uses i * R / N and ping360_sonar
 * (i + 1) * R / N: we differ from each by half a sample.)
 */

/* Range in metres of n samples at sample_period ticks and speed of sound c (m/s): ticks*25ns*n*c/2. */
double sonar_geometry_range_m(uint16_t sample_period, uint16_t n, double c);

/*
 * sample_period (ticks, truncated as Ping Viewer does) for range_m over n samples at c m/s.
 * Returns SONAR_OK, SONAR_ERR_ARG for non-positive inputs, or SONAR_ERR_RANGE when the period
 * falls outside 80..40000 ticks.
 */
SONAR_CHECK int sonar_geometry_sample_period(double range_m, uint16_t n, double c, uint16_t *ticks);

/* Largest n <= 1200 whose sample period for range_m is >= 80 ticks; 0 if below 200 (range too short). */
uint16_t sonar_geometry_max_samples(double range_m, double c);

/*
 * Automatic transmit duration in us (--transmit-duration auto): round(8000 R / c), at least 2.5
 * sample intervals (2.5 * ticks * 0.025 us, rounded up), clamped to [5, min(500, 64 * ticks *
 * 0.025)]. The rule is Ping Viewer's adjustTransmitDuration (ping-viewer src/sensor/ping360.cpp,
 * "per firmware engineer"), also in the ping360_sonar ROS driver; both compute the 2.5-interval
 * floor with the period in seconds, so it never bites there: here it is in us (ping.md).
 */
uint16_t sonar_geometry_transmit_duration(double range_m, double c, uint16_t sample_period);

/* Range in metres of the centre of sample i of n over range_m; see the frame above. */
double sonar_geometry_sample_range(uint16_t i, uint16_t n, double range_m);

/* Sample index holding range r (floor(r * n / range_m)), or -1 outside [0, range_m). */
int32_t sonar_geometry_sample_index(double r, uint16_t n, double range_m);


#endif
