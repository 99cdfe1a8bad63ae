/* frame.h -- the sonar frame's one vocabulary: gradians per turn, wrap-aware angle differences, gradians to radians, polar to xy, bearing, and the point type (mm); pure functions, no RAM. */
#ifndef SONAR_FRAME_H
#define SONAR_FRAME_H

#include <stdint.h>

/*
 * A beam at device angle a gradians (0..399) plus an offset o gradians points at
 * theta = (a + o) * 0.9 degrees; a point at range r metres on it is x = r cos(theta),
 * y = r sin(theta). The head has SONAR_GRAD_TURN positions a turn.
 */
#define SONAR_GRAD_TURN 400u /* gradians per turn */
#define SONAR_GRAD_MAX 399u  /* largest device angle */
#define SONAR_GRAD_HALF 200u /* half a turn */
#define SONAR_PI 3.14159265358979323846
#define SONAR_DEG_PER_GRAD 0.9                /* degrees per gradian: 360 / SONAR_GRAD_TURN */
#define SONAR_RAD_PER_DEG (SONAR_PI / 180.0) /* radians per degree */

/* A point in the sonar frame, millimetres (|x|, |y| < 2^30). */
struct sonar_xy {
    int32_t x;
    int32_t y;
};

/* Signed shortest move from a to b in gradians, -200..199 (inputs taken mod 400). */
int sonar_frame_delta(uint16_t a, uint16_t b);

/* a gradians taken into one turn, 0..399, for any sign. */
int sonar_frame_wrap(int a);

/*
 * Marks, in a 400-bit map of the gradians scanned (SONAR_GRAD_TURN / 8 bytes, bit g % 8 of byte
 * g / 8), every gradian on the shorter way from a to b, both included (any sign; taken mod 400).
 */
void sonar_frame_mark_arc(uint8_t *cover, int a, int b);

/* Unsigned angular distance between a and b (each 0..399), 0..200 gradians. */
uint16_t sonar_frame_gap(uint16_t a, uint16_t b);

/* g gradians in radians: g * pi / 200. */
double sonar_frame_rad(double g);

/* rad radians in degrees: rad * 180 / pi. */
double sonar_frame_deg(double rad);

/* Polar (angle gradians + offset gradians, range m) to sonar-frame x, y in metres. */
void sonar_frame_to_xy(double angle_grad, double offset_grad, double r, double *x, double *y);

/* Bearing in degrees [0, 360) of sonar-frame x, y (atan2(y, x)); 0 when both are 0. */
double sonar_frame_bearing_deg(double x, double y);

/*
 * One step of a stepping sweep, pos gradians from its start: full turns (full != 0; pos mod 400),
 * or back and forth between 0 and span, *dir (+1 / -1) turning at either end. step: 1..50. Returns
 * the new position. The Ping360 driver and the scan planner step a sector with it.
 */
uint16_t sonar_frame_sweep_advance(uint16_t pos, int8_t *dir, uint16_t span, uint8_t step, uint8_t full);

#endif
