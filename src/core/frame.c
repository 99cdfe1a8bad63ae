/* frame.c -- angle arithmetic and polar conversions of the sonar frame; a few flops each, no RAM. */
#include "sonar/frame.h"

#include <math.h>

int sonar_frame_delta(uint16_t a, uint16_t b)
{
    return (((int)(b % SONAR_GRAD_TURN) - (int)(a % SONAR_GRAD_TURN) + (int)(SONAR_GRAD_TURN + SONAR_GRAD_HALF)) % (int)SONAR_GRAD_TURN) - (int)SONAR_GRAD_HALF;
}

int sonar_frame_wrap(int a)
{
    return ((a % (int)SONAR_GRAD_TURN) + (int)SONAR_GRAD_TURN) % (int)SONAR_GRAD_TURN;
}

void sonar_frame_mark_arc(uint8_t *cover, int a, int b)
{
    int d = sonar_frame_delta((uint16_t)sonar_frame_wrap(a), (uint16_t)sonar_frame_wrap(b)), dir = d < 0 ? -1 : 1, k;
    for (k = 0; k <= (d < 0 ? -d : d); k++) {
        int m = sonar_frame_wrap(a + dir * k);
        cover[m / 8] = (uint8_t)(cover[m / 8] | (1u << (m % 8)));
    }
}

uint16_t sonar_frame_gap(uint16_t a, uint16_t b)
{
    uint16_t g = (uint16_t)(a > b ? a - b : b - a);
    return g > SONAR_GRAD_HALF ? (uint16_t)(SONAR_GRAD_TURN - g) : g;
}

double sonar_frame_rad(double g)
{
    return g * SONAR_PI / (double)SONAR_GRAD_HALF;
}

double sonar_frame_deg(double rad)
{
    return rad * 180.0 / SONAR_PI;
}

void sonar_frame_to_xy(double angle_grad, double offset_grad, double r, double *x, double *y)
{
    double th = sonar_frame_rad(angle_grad + offset_grad);
    *x = r * cos(th);
    *y = r * sin(th);
}

double sonar_frame_bearing_deg(double x, double y)
{
    double b;
    if (x == 0.0 && y == 0.0)
        return 0.0;
    b = sonar_frame_deg(atan2(y, x));
    return b < 0.0 ? b + 360.0 : b;
}

uint16_t sonar_frame_sweep_advance(uint16_t pos, int8_t *dir, uint16_t span, uint8_t step, uint8_t full)
{
    if (full)
        return (uint16_t)((pos + step) % SONAR_GRAD_TURN);
    if (*dir > 0) {
        if (pos >= span) {
            *dir = -1;
            return (uint16_t)(span > step ? span - step : 0);
        }
        return (uint16_t)(pos + step > span ? span : pos + step);
    }
    if (pos == 0) {
        *dir = 1;
        return (uint16_t)(step < span ? step : span);
    }
    return (uint16_t)(pos > step ? pos - step : 0);
}
