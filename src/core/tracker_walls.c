/* tracker_walls.c -- the site's walls in the tracker: a model's straight prediction that would cross one, seen from the sonar's side, turned at it (reflected, its speed kept; two walls at most a step: a corner); the walls within each track's reach found once an update (O(walls) a track), a prediction looking at those alone; 48 B a wall, 2 B a track (in its padding), no heap. */
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
    for (k = 0; k < keep; k++) {
        memcpy(tk->wall[k], seg[k], sizeof(tk->wall[k]));
        tk->wall_box[0][k] = seg[k][0] < seg[k][2] ? seg[k][0] : seg[k][2];
        tk->wall_box[1][k] = seg[k][0] < seg[k][2] ? seg[k][2] : seg[k][0];
        tk->wall_box[2][k] = seg[k][1] < seg[k][3] ? seg[k][1] : seg[k][3];
        tk->wall_box[3][k] = seg[k][1] < seg[k][3] ? seg[k][3] : seg[k][1];
    }
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
static int first_crossing(const struct sonar_tracker *tk, uint32_t near, float x, float y, float dx, float dy, float ox,
                          float oy, int skip, float *s, float w_out[4])
{
    int k, best = -1;
    *s = 2.0f;
    /* Only the walls near holds: up to its highest bit. */
    for (k = 0; k < tk->nwalls && (near >> k) != 0u; k++) {
        const float *w = tk->turn[k];
        float ux, uy, den, so, sp, se, ax, ay, f, r, e;
        if (k == skip || !((near >> k) & 1u))
            continue;
        /* Most paths end short of the line: two products and a comparison, nothing divided. */
        so = side(tk->wall[k], ox, oy); /* the wall's own line: a sonar on the wall sees the pool from its side */
        se = side(w, x + dx, y + dy);
        if (se == 0.0f || (se > 0.0f) == (so > 0.0f))
            continue;
        ux = w[2] - w[0];
        uy = w[3] - w[1];
        den = dx * uy - dy * ux;
        sp = side(w, x, y);
        /* From the sonar's side (or on the line: a corner's second wall) to strictly beyond; never back in. */
        if (fabsf(den) < 1e-9f || (sp != 0.0f && (sp > 0.0f) != (so > 0.0f)))
            continue;
        ax = w[0] - x;
        ay = w[1] - y;
        f = (ax * uy - ay * ux) / den;
        r = (ax * dy - ay * dx) / den;
        e = SONAR_TRK_WALL_END_M / sqrtf(ux * ux + uy * uy); /* the line past its ends, as a fraction of it */
        if (f >= 0.0f && f <= 1.0f && r >= -e && r <= 1.0f + e && f < *s) {
            *s = f;
            best = k;
            memcpy(w_out, w, 4 * sizeof(float));
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

/*
 * The walls (with a turn line) whose boxes reach the box lx .. hx, ly .. hy widened by the turn line's and the wall
 * end's margins: a path in that box can cross no other.
 */
static uint32_t walls_in_box(const struct sonar_tracker *tk, float lx, float hx, float ly, float hy)
{
    const float m = SONAR_TRK_WALL_TURN_M + SONAR_TRK_WALL_END_M;
    const float(*b)[SONAR_TRK_MAX_WALLS] = tk->wall_box;
    uint32_t near = 0;
    int k;
    lx -= m;
    hx += m;
    ly -= m;
    hy += m;
    for (k = 0; k < tk->nwalls; k++)
        if (b[0][k] <= hx && b[1][k] >= lx && b[2][k] <= hy && b[3][k] >= ly)
            near |= 1u << k;
    return near & tk->turnable;
}

static void near_of(const struct sonar_tracker *tk, struct sonar_track *t, int64_t latest)
{
    const float dt = (float)(latest - t->utime) * 1e-6f;
    float lx = 1e30f, hx = -1e30f, ly = 1e30f, hy = -1e30f;
    int j;
    t->near_walls = 0;
    if (!(dt > 0.0f))
        return;
    for (j = 0; j < SONAR_TRK_MODELS; j++) {
        const struct sonar_track_model *md = &t->m[j];
        float ex = md->px + md->vx * dt, ey = md->py + md->vy * dt;
        if (j == SONAR_TRK_REST || !(md->p > 0.0f))
            continue; /* rest goes nowhere: it never turns */
        /* Comparisons, not fminf: a libm call each where NaN rules keep the compiler from inlining it. */
        lx = md->px < lx ? md->px : lx;
        lx = ex < lx ? ex : lx;
        hx = md->px > hx ? md->px : hx;
        hx = ex > hx ? ex : hx;
        ly = md->py < ly ? md->py : ly;
        ly = ey < ly ? ey : ly;
        hy = md->py > hy ? md->py : hy;
        hy = ey > hy ? ey : hy;
    }
    if (lx <= hx)
        t->near_walls = (uint16_t)walls_in_box(tk, lx, hx, ly, hy);
}

void sonar_trk_walls_near(struct sonar_tracker *tk, const struct sonar_tracker_obs *obs, const uint8_t *rows, unsigned nr)
{
    int64_t latest = INT64_MIN;
    unsigned i, a;
    int k;
    if (tk->nwalls == 0 || !tk->cfg.walls)
        return;
    /* The turn lines, once an update: they move with the sonar's origin (tk->cur_sw's; 0, 0 without one). */
    tk->turnable = 0;
    for (k = 0; k < tk->nwalls; k++)
        if (turn_line(tk, k, tk->cur_sw != NULL ? tk->cur_sw->origin_x : 0.0f, tk->cur_sw != NULL ? tk->cur_sw->origin_y : 0.0f,
                      tk->turn[k]))
            tk->turnable |= 1u << k;
    for (i = 0; i < nr; i++)
        latest = obs[rows[i]].utime > latest ? obs[rows[i]].utime : latest;
    for (i = 0; i < tk->n; i++)
        near_of(tk, &tk->t[i], latest);
    for (a = 0; a < tk->nalt; a++) {
        near_of(tk, &tk->alt[a].t[0], latest);
        near_of(tk, &tk->alt[a].t[1], latest);
    }
}

int sonar_trk_wall_turn(const struct sonar_tracker *tk, uint32_t near, float *px, float *py, float *vx, float *vy, float dt)
{
    float ox = 0.0f, oy = 0.0f, x = *px, y = *py, ex, ey, wx = *vx, wy = *vy, s, w[4];
    int k, skip = -1, turns = 0;
    if (near == 0 || tk->nwalls == 0 || !tk->cfg.walls || !(dt > 0.0f))
        return 0;
    if (tk->cur_sw != NULL) {
        ox = tk->cur_sw->origin_x;
        oy = tk->cur_sw->origin_y;
    }
    ex = x + wx * dt;
    ey = y + wy * dt;
    /* Leg by leg: to the wall, then on from where it met it along the mirrored path (a corner's second wall). */
    while (turns < 2 && (k = first_crossing(tk, near, x, y, ex - x, ey - y, ox, oy, skip, &s, w)) >= 0) {
        x += s * (ex - x);
        y += s * (ey - y);
        reflect(w, &ex, &ey, 0);
        reflect(w, &wx, &wy, 1);
        skip = k;
        turns++;
        /* The mirrored leg may reach a wall the straight path did not: those its own box reaches. */
        near = walls_in_box(tk, x < ex ? x : ex, x < ex ? ex : x, y < ey ? y : ey, y < ey ? ey : y);
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
