/* tracker_walls.c -- the site's walls in the tracker: a model's straight prediction that would cross one, seen from the sonar's side, turned at it (reflected, its speed kept; two walls at most a step: a corner); O(walls) a prediction, 16 B a wall, no heap. */
#include <math.h>
#include <string.h>

#include "tracker_internal.h"

int sonar_tracker_set_walls(struct sonar_tracker *tk, const float (*seg)[4], unsigned n)
{
    unsigned k, j, keep;
    if (tk == NULL || (seg == NULL && n > 0))
        return SONAR_ERR_ARG;
    keep = n < SONAR_TRK_MAX_WALLS ? n : SONAR_TRK_MAX_WALLS;
    for (k = 0; k < keep; k++)
        for (j = 0; j < 4; j++)
            if (!(fabsf(seg[k][j]) <= (float)SONAR_TRK_COORD_MAX))
                return SONAR_ERR_ARG;
    for (k = 0; k < keep; k++)
        memcpy(tk->wall[k], seg[k], sizeof(tk->wall[k]));
    tk->nwalls = (uint8_t)keep;
    return n > SONAR_TRK_MAX_WALLS ? SONAR_ERR_SPACE : SONAR_OK;
}

/* Which side of wall w's line (x, y) lies: the sign of (b - a) x (p - a); 0 on it. */
static float side(const float *w, float x, float y)
{
    return (w[2] - w[0]) * (y - w[1]) - (w[3] - w[1]) * (x - w[0]);
}

/*
 * Wall k where a swimmer's centre turns: its line moved SONAR_TRK_WALL_TURN_M toward the sonar (ox,
 * oy), into w; 0 when the sonar is on the line or the wall has no length.
 */
static int turn_line(const struct sonar_tracker *tk, int k, float ox, float oy, float w[4])
{
    const float *a = tk->wall[k];
    float ux = a[2] - a[0], uy = a[3] - a[1], len = sqrtf(ux * ux + uy * uy), so = side(a, ox, oy), nx, ny;
    if (!(len > 1e-3f) || so == 0.0f)
        return 0;
    /* The unit normal on the sonar's side: side() > 0 is to the left of a -> b. */
    nx = (so > 0.0f ? -uy : uy) / len * SONAR_TRK_WALL_TURN_M;
    ny = (so > 0.0f ? ux : -ux) / len * SONAR_TRK_WALL_TURN_M;
    w[0] = a[0] + nx;
    w[1] = a[1] + ny;
    w[2] = a[2] + nx;
    w[3] = a[3] + ny;
    return 1;
}

/*
 * The first wall (not skip) the path from (x, y) by (dx, dy) crosses where a swimmer turns at it
 * (turn_line, into w), starting on the side the sonar (ox, oy) is on, and in *s the fraction (0, 1]
 * of the path there; -1 when it crosses none.
 */
static int first_crossing(const struct sonar_tracker *tk, float x, float y, float dx, float dy, float ox, float oy,
                          int skip, float *s, float w_out[4])
{
    int k, best = -1;
    const float m = SONAR_TRK_WALL_TURN_M + SONAR_TRK_WALL_END_M, lx = (dx < 0.0f ? x + dx : x) - m, hx = (dx < 0.0f ? x : x + dx) + m;
    const float ly = (dy < 0.0f ? y + dy : y) - m, hy = (dy < 0.0f ? y : y + dy) + m;
    *s = 2.0f;
    for (k = 0; k < tk->nwalls; k++) {
        const float *a = tk->wall[k];
        float w[4], ux, uy, den, so, sp, se, ax, ay, f, r, e;
        /* Most walls are nowhere near the path: their boxes apart, no square root spent. */
        if (k == skip || (a[0] < lx && a[2] < lx) || (a[0] > hx && a[2] > hx) || (a[1] < ly && a[3] < ly) ||
            (a[1] > hy && a[3] > hy) || !turn_line(tk, k, ox, oy, w))
            continue;
        ux = w[2] - w[0];
        uy = w[3] - w[1];
        den = dx * uy - dy * ux;
        so = side(tk->wall[k], ox, oy); /* the wall's own line: a sonar on the wall sees the pool from its side */
        sp = side(w, x, y);
        se = side(w, x + dx, y + dy);
        /* From the sonar's side (or on the line: a corner's second wall) to strictly beyond; never back in. */
        if (fabsf(den) < 1e-9f || (sp != 0.0f && (sp > 0.0f) != (so > 0.0f)) || se == 0.0f || (se > 0.0f) == (so > 0.0f))
            continue;
        ax = w[0] - x;
        ay = w[1] - y;
        f = (ax * uy - ay * ux) / den;
        r = (ax * dy - ay * dx) / den;
        e = SONAR_TRK_WALL_END_M / sqrtf(ux * ux + uy * uy); /* the line past its ends, as a fraction of it */
        if (f >= 0.0f && f <= 1.0f && r >= -e && r <= 1.0f + e && f < *s) {
            *s = f;
            best = k;
            memcpy(w_out, w, sizeof(w));
        }
    }
    return best;
}

/* (x, y) reflected about wall w's line; as a direction (a velocity) when dir. */
static void reflect(const float *w, float *x, float *y, int dir)
{
    float ux = w[2] - w[0], uy = w[3] - w[1], len2 = ux * ux + uy * uy;
    float px = dir ? *x : *x - w[0], py = dir ? *y : *y - w[1], along = (px * ux + py * uy) / len2;
    /* The point's mirror image: twice its projection on the line, less itself. */
    float rx = 2.0f * along * ux - px, ry = 2.0f * along * uy - py;
    *x = dir ? rx : rx + w[0];
    *y = dir ? ry : ry + w[1];
}

int sonar_trk_wall_turn(const struct sonar_tracker *tk, float *px, float *py, float *vx, float *vy, float dt)
{
    float ox = 0.0f, oy = 0.0f, x = *px, y = *py, ex, ey, wx = *vx, wy = *vy, s, w[4];
    int k, skip = -1, turns = 0;
    if (tk->nwalls == 0 || !tk->cfg.walls || !(dt > 0.0f))
        return 0;
    if (tk->cur_sw != NULL) {
        ox = tk->cur_sw->origin_x;
        oy = tk->cur_sw->origin_y;
    }
    ex = x + wx * dt;
    ey = y + wy * dt;
    /* Leg by leg: to the wall, then on from where it met it along the mirrored path (a corner's second wall). */
    while (turns < 2 && (k = first_crossing(tk, x, y, ex - x, ey - y, ox, oy, skip, &s, w)) >= 0) {
        x += s * (ex - x);
        y += s * (ey - y);
        reflect(w, &ex, &ey, 0);
        reflect(w, &wx, &wy, 1);
        skip = k;
        turns++;
    }
    if (turns == 0)
        return 0;
    /* A start the straight model moves on to the turned end: predict() needs no other change. */
    *vx = wx;
    *vy = wy;
    *px = ex - wx * dt;
    *py = ey - wy * dt;
    return turns;
}
