/* sweep.c -- sweep segmentation from head angles; O(1) per beam, no heap. */
#include "sonar/sweep.h"

#include <string.h>

#include "sonar/frame.h"

int sonar_sweep_init(struct sonar_sweep *s, uint16_t max_step, uint16_t max_beams)
{
    if (s == NULL || max_step < 1 || max_step > SONAR_GRAD_HALF || max_beams < 2)
        return SONAR_ERR_ARG;
    memset(s, 0, sizeof(*s));
    s->max_step = max_step;
    s->max_beams = max_beams;
    return SONAR_OK;
}


static int open_sweep(struct sonar_sweep *s, uint16_t angle, int cut)
{
    if (s->started)
        s->index++;
    s->started = 1;
    s->last = angle;
    s->traversed = 0;
    s->beams = 1;
    s->dir = 0;
    return cut;
}

int sonar_sweep_step(struct sonar_sweep *s, uint16_t angle)
{
    int d, mag;
    int8_t dir;
    angle = (uint16_t)(angle % SONAR_GRAD_TURN);
    if (!s->started)
        return open_sweep(s, angle, SONAR_SWEEP_SAME);
    if (s->beams >= s->max_beams)
        return open_sweep(s, angle, SONAR_SWEEP_FULL);
    d = sonar_frame_delta(s->last, angle);
    if (d == 0) {
        s->beams++;
        return SONAR_SWEEP_SAME;
    }
    mag = d < 0 ? -d : d;
    if (mag > (int)s->max_step)
        return open_sweep(s, angle, SONAR_SWEEP_JUMP);
    dir = (int8_t)(d < 0 ? -1 : 1);
    if (s->dir != 0 && dir != s->dir)
        return open_sweep(s, angle, SONAR_SWEEP_REVERSE);
    if ((int)s->traversed + mag >= (int)SONAR_GRAD_TURN)
        return open_sweep(s, angle, SONAR_SWEEP_WRAP);
    s->dir = dir;
    s->traversed = (uint16_t)(s->traversed + mag);
    s->last = angle;
    s->beams++;
    return SONAR_SWEEP_SAME;
}
