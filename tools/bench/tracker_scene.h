/* tracker_scene.h -- the tracker's benchmark sweep, one place for the host bench (tools/bench/bench.c) and the firmware's (src/mcu/bench_main.c); no RAM of its own. */
#ifndef BENCH_TRACKER_SCENE_H
#define BENCH_TRACKER_SCENE_H

#include <string.h>

#include "sonar/activity.h"
#include "sonar/tracker.h"

/*
 * Starts tk with c and gives it 32 tracks, each seen twice 5 s apart (moving at 0.12 m/s, so each
 * has a velocity and its IMM its models); leaves in ob[16] and *sw the sweep to time: 16
 * detections near half of them (the other half coast), two of them a pair crossing 0.5 m apart
 * (alternatives kept for the next look), read after the last sweep's alternatives. Returns 0, or
 * -1 when the tracker refused something.
 */
static int bench_tracker_scene(struct sonar_tracker *tk, const struct sonar_tracker_config *c,
                               struct sonar_tracker_obs ob[16], struct sonar_tracker_sweep *sw)
{
    int s, k;
    memset(sw, 0, sizeof(*sw));
    sw->beams = 400;
    sw->max_range_m = 50.0f;
    if (sonar_tracker_init(tk, c) != SONAR_OK)
        return -1;
    for (s = 0; s < 5; s++) {
        /* looks 0, 1: group A (x near 0) then group B (x near 20) at 1 s; looks 2, 3 the same at 6 s; look 4: A at 11 s */
        int group = s % 2, look = s / 2;
        for (k = 0; k < 16; k++) {
            float cross = k < 2 ? (k == 0 ? 0.25f : -0.25f) * (float)(look - 1) : 0.0f;
            ob[k].x_m = (k < 2 ? 0.3f * (float)k : (float)(k % 4) * 4.0f) - 6.0f + (float)group * 20.0f + 0.6f * (float)look;
            ob[k].y_m = (k < 2 ? 0.5f * (float)k + 12.0f : (float)(k / 4) * 4.0f) - 6.0f + cross;
            ob[k].utime = 1000000 + (int64_t)look * 5000000 + (int64_t)k * 10000;
            ob[k].size_m = 0.3f;
        }
        sw->utime = ob[15].utime + 500000;
        if (s < 4 && sonar_tracker_update(tk, ob, 16, sw) != SONAR_OK)
            return -1;
    }
    return 0;
}

/*
 * The same scene in a walled site: SONAR_TRK_MAX_WALLS walls, nested boxes about the scene's tracks (x -6 .. 26,
 * y -6 .. 6; the innermost 2 m beyond its outermost tracks, which reach it), set on tk. Returns 0, or -1 when refused.
 */
static int bench_tracker_walls(struct sonar_tracker *tk)
{
    float walls[SONAR_TRK_MAX_WALLS][4];
    int k;
    for (k = 0; k < SONAR_TRK_MAX_WALLS; k++) {
        /* Box k / 4, wall k % 4: left, right, bottom, top. */
        float hx = 18.0f + 2.0f * (float)(k / 4), hy = 9.0f + 2.0f * (float)(k / 4);
        float x = (k % 4) == 1 ? 10.0f + hx : 10.0f - hx, y = (k % 4) == 3 ? hy : -hy;
        walls[k][0] = (k % 4) < 2 ? x : 10.0f - hx;
        walls[k][1] = (k % 4) < 2 ? -hy : y;
        walls[k][2] = (k % 4) < 2 ? x : 10.0f + hx;
        walls[k][3] = (k % 4) < 2 ? hy : y;
    }
    return sonar_tracker_set_walls(tk, (const float(*)[4])walls, SONAR_TRK_MAX_WALLS) == SONAR_OK ? 0 : -1;
}

/*
 * The activity's worst look over that scene's tracks (activity.h): each has a slot and both windows
 * full (a turn of 400 beams of 1200 samples over 50 m filled them), so a look correlates all of them.
 * row: 1200 bytes of scratch.
 */
static int bench_activity_scene(struct sonar_activity *a, struct sonar_tracker *tk, uint8_t *row)
{
    int look, g, i;
    if (sonar_activity_init(a) != SONAR_OK)
        return -1;
    for (look = 0; look < 3; look++) {
        for (g = 0; g < 400 && look > 0; g++) {
            for (i = 0; i < 1200; i++)
                row[i] = (uint8_t)((unsigned)(g * 7 + i * 13 + look * 29) * 2654435761u >> 24);
            sonar_activity_beam(a, (uint16_t)g, row, 1200, 50.0f, 0);
        }
        sonar_activity_look(a, tk, tk->last_utime, 0.0f, 60.0f, 0);
    }
    for (g = 0; g < 400; g++) {
        for (i = 0; i < 1200; i++)
            row[i] = (uint8_t)((unsigned)(g * 7 + i * 13) * 2654435761u >> 24);
        sonar_activity_beam(a, (uint16_t)g, row, 1200, 50.0f, 0);
    }
    return 0;
}

#endif
