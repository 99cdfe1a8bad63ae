/* tracker_assign.c -- the tracker's association: gated pair costs, a least-total assignment (shortest augmenting paths), merged echoes; O(rows^2 x columns) an assignment, stack ~1.3 KB, no heap. */
#include "sonar/tracker.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "tracker_internal.h"

SONAR_STATIC_ASSERT(SONAR_ASSIGN_MAX <= 127, assignment_columns_fit_int8);

/* A pair outside the gate: finite, so the assignment's arithmetic stays exact and branch-free. */
#define BIG ((double)SONAR_TRK_OUTSIDE)

#ifndef SONAR_TRK_MERGE_M
#define SONAR_TRK_MERGE_M 1.0f /* metres: a prediction this near another track's detection is on a merged echo */
#endif

/* The columns of an assignment: either a plain matrix, or the tracker's cost plus one "new track" column a row. */
struct costs {
    const float *m; /* rows x stride */
    unsigned stride, real; /* columns 0 .. real) come from m */
    float fresh;           /* cost of row i's own extra column real + i; other extra columns are BIG */
};

static double cost_at(const struct costs *c, unsigned i, unsigned j)
{
    if (j < c->real)
        return (double)c->m[i * c->stride + j];
    return j - c->real == i ? (double)c->fresh : BIG;
}

/*
 * Shortest augmenting paths with row and column potentials (Kuhn-Munkres as in Jonker and
 * Volgenant), 1-based inside: p[j] = the row on column j, way[] the path back. Strict < on
 * every minimum, so ties go to the lowest column on any platform.
 */
static void hungarian(const struct costs *c, unsigned rows, unsigned cols, int8_t *row_col)
{
    double u[SONAR_ASSIGN_MAX + 1], v[SONAR_ASSIGN_MAX + 1], minv[SONAR_ASSIGN_MAX + 1];
    uint8_t p[SONAR_ASSIGN_MAX + 1], way[SONAR_ASSIGN_MAX + 1], used[SONAR_ASSIGN_MAX + 1];
    unsigned i, j;
    for (j = 0; j <= cols; j++) {
        v[j] = 0.0;
        p[j] = 0;
        way[j] = 0;
    }
    for (i = 0; i <= rows; i++)
        u[i] = 0.0;
    for (i = 1; i <= rows; i++) {
        unsigned j0 = 0;
        p[0] = (uint8_t)i;
        for (j = 0; j <= cols; j++) {
            minv[j] = 1e300;
            used[j] = 0;
        }
        do {
            unsigned i0 = p[j0], j1 = 0;
            double delta = 1e300;
            used[j0] = 1;
            for (j = 1; j <= cols; j++) {
                double cur;
                if (used[j])
                    continue;
                cur = cost_at(c, i0 - 1u, j - 1u) - u[i0] - v[j];
                if (cur < minv[j]) {
                    minv[j] = cur;
                    way[j] = (uint8_t)j0;
                }
                if (minv[j] < delta) {
                    delta = minv[j];
                    j1 = j;
                }
            }
            for (j = 0; j <= cols; j++) {
                if (used[j]) {
                    u[p[j]] += delta;
                    v[j] -= delta;
                } else {
                    minv[j] -= delta;
                }
            }
            j0 = j1;
        } while (p[j0] != 0);
        do {
            unsigned j1 = way[j0];
            p[j0] = p[j1];
            j0 = j1;
        } while (j0 != 0);
    }
    for (j = 1; j <= cols; j++)
        if (p[j] != 0)
            row_col[p[j] - 1u] = (int8_t)(j - 1u);
}

int sonar_tracker_assign(const float *cost, uint8_t rows, uint8_t cols, int8_t *row_col)
{
    struct costs c;
    unsigned i;
    if (cost == NULL || row_col == NULL || rows < 1 || rows > cols || cols > SONAR_ASSIGN_MAX)
        return SONAR_ERR_ARG;
    for (i = 0; i < (unsigned)rows * cols; i++)
        if (!(cost[i] == cost[i]) || cost[i] > (float)BIG || cost[i] < -(float)BIG)
            return SONAR_ERR_ARG; /* NaN or beyond the range the potentials stay exact in */
    c.m = cost;
    c.stride = cols;
    c.real = cols;
    c.fresh = 0.0f;
    hungarian(&c, rows, cols, row_col);
    return SONAR_OK;
}

/* The cost of continuing t with o: -2 ln of its models' mixture likelihood, or BIG outside the gate. */
static float pair_cost(const struct sonar_tracker *tk, const struct sonar_track *t, const struct sonar_tracker_obs *o,
                       float r2, int wide, int *clipped)
{
    float dt = sonar_trk_step_s(tk, t, o->utime, clipped), c;
    if (tk->cfg.max_speed_mps > 0.0f) {
        /* Kinematics: from where the track last was, nothing this fast (people, divers, swimmers). */
        float mx = o->x_m - t->px, my = o->y_m - t->py, reach = tk->cfg.max_speed_mps * dt + 3.0f * tk->cfg.meas_m;
        if (mx * mx + my * my > reach * reach)
            return (float)BIG;
    }
    if (t->hits > 1) {
        /*
         * An established track's models allow a manoeuvre, whose noise gates metres around a track
         * that stood still: on the vehicle scene a buoy's track, its buoy missed, took a post 3.4 m
         * away and carried 0.7 m/s for sweeps. A turn changes where a track goes more than how
         * fast it goes.
         */
        float mx = o->x_m - t->px, my = o->y_m - t->py, v = sqrtf(t->vx * t->vx + t->vy * t->vy);
        float reach = (SONAR_TRK_TURN_SPEEDUP * v + SONAR_TRK_TURN_FROM_REST) * dt + 3.0f * tk->cfg.meas_m;
        if (mx * mx + my * my > reach * reach)
            return (float)BIG;
    }
    c = sonar_trk_imm_cost(tk, t, o, r2, dt, wide);
    return c < SONAR_TRK_OUTSIDE ? c : (float)BIG;
}

/* Squared distance, m^2, from t's prediction to the time of o to where o is. */
static float pred_d2(const struct sonar_tracker *tk, const struct sonar_track *t, const struct sonar_tracker_obs *o,
                     int *clipped)
{
    float dt = sonar_trk_step_s(tk, t, o->utime, clipped), ex, ey;
    ex = o->x_m - (t->px + t->vx * dt);
    ey = o->y_m - (t->py + t->vy * dt);
    return ex * ex + ey * ey;
}

/* Whether detection row jj was given a track (a gated pair, not a fresh start). */
static int assigned(const float (*cost)[SONAR_MAX_TRACKS], const int8_t *row_col, unsigned jj, uint8_t nc)
{
    return row_col[jj] >= 0 && (unsigned)row_col[jj] < nc && cost[jj][row_col[jj]] < (float)BIG;
}

/*
 * Two objects seen as one: a track whose prediction falls on a detection another track took, much
 * nearer than the one it was given, is on a merged echo (swimmers crossing); it coasts through it
 * rather than jumping to a farther detection that is someone else's. A track left without a
 * detection whose prediction lies on one another track took is merged too, kept from the
 * second chance. Marks them SONAR_TRK_MERGED (no later pass may move them) and unassigns them.
 */
static void find_merged(struct sonar_tracker *tk, const float (*cost)[SONAR_MAX_TRACKS], const uint8_t *cand, uint8_t nc,
                        const struct sonar_tracker_obs *obs, const uint8_t *left, uint8_t nl, int8_t *row_col, int *clipped)
{
    uint8_t i, k;
    unsigned jj;
    for (i = 0; i < nl; i++) {
        float own;
        if (!assigned(cost, row_col, i, nc))
            continue;
        k = (uint8_t)row_col[i];
        own = pred_d2(tk, &tk->t[cand[k]], &obs[left[i]], clipped);
        for (jj = 0; jj < nl; jj++) {
            float d2;
            if (jj == i || !assigned(cost, row_col, jj, nc))
                continue;
            d2 = pred_d2(tk, &tk->t[cand[k]], &obs[left[jj]], clipped);
            if (d2 < SONAR_TRK_MERGE_M * SONAR_TRK_MERGE_M && 4.0f * d2 < own) {
                row_col[i] = -1;
                tk->t[cand[k]].det = SONAR_TRK_MERGED;
                break;
            }
        }
    }
    for (k = 0; k < nc; k++) {
        struct sonar_track *t = &tk->t[cand[k]];
        for (jj = 0; jj < nl && row_col[jj] != (int8_t)k; jj++)
            ;
        if (jj < nl || t->det == SONAR_TRK_MERGED)
            continue;
        for (jj = 0; jj < nl; jj++)
            if (assigned(cost, row_col, jj, nc) &&
                pred_d2(tk, t, &obs[left[jj]], clipped) < SONAR_TRK_MERGE_M * SONAR_TRK_MERGE_M) {
                t->det = SONAR_TRK_MERGED;
                break;
            }
    }
}

/*
 * One assignment of detections left[0 .. nl) to tracks cand[0 .. nc); each pair gated, each
 * detection free to start a track instead at more than a gated pair of one model costs (S <=
 * SONAR_TRK_LOST_M2 + r2 for a track still alive: a detection inside a live track's gate continues it, and
 * the 2 ln S term only settles which). Each track given one has it in det (the hit is applied
 * later, once the other hypotheses are read); returns how many detections are left, compacted
 * in left[] in their order.
 */
uint8_t sonar_trk_pass(struct sonar_tracker *tk, float (*cost)[SONAR_MAX_TRACKS], const uint8_t *cand, uint8_t nc,
                       const struct sonar_tracker_obs *obs, uint8_t *left, uint8_t nl, float r2, int wide, int merge,
                       int *clipped)
{
    int8_t row_col[SONAR_MAX_CLUSTERS];
    struct costs c;
    uint8_t i, k, m = 0;
    if (nl == 0 || nc == 0)
        return nl;
    for (i = 0; i < nl; i++)
        for (k = 0; k < nc; k++)
            cost[i][k] = sonar_trk_cost(tk, cand[k], left[i], r2, wide, clipped);
    c.m = &cost[0][0];
    c.stride = SONAR_MAX_TRACKS;
    c.real = nc;
    c.fresh = sonar_trk_fresh(tk, r2);
    hungarian(&c, nl, (unsigned)nc + nl, row_col);
    if (merge)
        find_merged(tk, (const float (*)[SONAR_MAX_TRACKS])cost, cand, nc, obs, left, nl, row_col, clipped);
    for (i = 0; i < nl; i++) {
        k = (uint8_t)row_col[i];
        if (assigned((const float (*)[SONAR_MAX_TRACKS])cost, row_col, i, nc)) {
            tk->t[cand[k]].det = (int8_t)left[i];
            tk->t[cand[k]].chance = (uint8_t)wide;
        }
        else
            left[m++] = left[i];
    }
    return m;
}

float sonar_trk_pair_cost(const struct sonar_tracker *tk, const struct sonar_track *t, const struct sonar_tracker_obs *o,
                          float r2, int wide, int *clipped)
{
    return pair_cost(tk, t, o, r2, wide, clipped);
}

float sonar_trk_cost(struct sonar_tracker *tk, uint8_t k, uint8_t d, float r2, int wide, int *clipped)
{
    uint64_t bit = (uint64_t)1 << k;
    if (wide)
        return pair_cost(tk, &tk->t[k], &tk->cache_obs[d], r2, 1, clipped);
    if (!(tk->cache_known[d] & bit)) {
        tk->cache_cost[d][k] = pair_cost(tk, &tk->t[k], &tk->cache_obs[d], r2, 0, clipped);
        tk->cache_known[d] |= bit;
    }
    return tk->cache_cost[d][k];
}

void sonar_trk_cache_reset(struct sonar_tracker *tk, const struct sonar_tracker_obs *obs)
{
    memset(tk->cache_known, 0, sizeof(tk->cache_known));
    tk->cache_obs = obs;
}

float sonar_trk_miss_cost(const struct sonar_track *t)
{
    float real = (float)t->hits / ((float)t->hits + 1.0f);
    return -2.0f * logf(1.0f - 0.9f * real);
}

float sonar_trk_fresh(const struct sonar_tracker *tk, float r2)
{
    return tk->cfg.gate + 2.0f * logf(1.0f + SONAR_TRK_LOST_M2 / r2);
}

float sonar_trk_best_total(const float (*cost)[SONAR_MAX_TRACKS], uint8_t rows, uint8_t nc, float fresh)
{
    int8_t row_col[SONAR_MAX_CLUSTERS];
    struct costs c;
    float total = 0.0f;
    uint8_t i;
    if (rows == 0)
        return 0.0f;
    c.m = &cost[0][0];
    c.stride = SONAR_MAX_TRACKS;
    c.real = nc;
    c.fresh = fresh;
    hungarian(&c, rows, (unsigned)nc + rows, row_col);
    for (i = 0; i < rows; i++)
        total += assigned(cost, row_col, i, nc) ? cost[i][row_col[i]] : fresh;
    return total;
}
