/* tracker.c -- the tracks' life: initialisation (its configuration in tracker_config.c), frames, one update (the last look's alternatives read, a cascade of gated assignments in tracker_assign.c, the IMM in tracker_imm.c, alternatives kept in tracker_defer.c), confirmation, coasting and ends by existence in tracker_exist.c; O(detections^2 x (tracks + detections)) per sweep, no heap. */
#include "sonar/tracker.h"

#include <math.h>
#include <string.h>

#include "sonar/frame.h"
#include "tracker_internal.h"

SONAR_STATIC_ASSERT(SONAR_TRK_WINDOW_MAX <= 8, history_fits_a_byte);

int sonar_tracker_init(struct sonar_tracker *tk, const struct sonar_tracker_config *cfg)
{
    if (tk == NULL || cfg == NULL || sonar_tracker_config_check(cfg) != NULL)
        return SONAR_ERR_ARG;
    memset(tk, 0, sizeof(*tk));
    tk->next_id = 1;
    return sonar_tracker_tune(tk, cfg);
}

int sonar_tracker_tune(struct sonar_tracker *tk, const struct sonar_tracker_config *cfg)
{
    if (tk == NULL || cfg == NULL || sonar_tracker_config_check(cfg) != NULL)
        return SONAR_ERR_ARG;
    tk->cfg = *cfg;
    return SONAR_OK;
}

enum { MOVE_TURN = 0, MOVE_TO_WORLD = 1, MOVE_TO_BODY = 2 };

/* A point of a track moved: turned by deg about (cx, cy), or into the world or body frame at pose p. */
static void move_point(float *x, float *y, float deg, float cx, float cy, const struct sonar_pose *p, int how)
{
    float x0 = *x, y0 = *y;
    if (how == MOVE_TO_WORLD) {
        sonar_pose_to_world(p, x0, y0, x, y);
    } else if (how == MOVE_TO_BODY) {
        sonar_pose_to_body(p, x0, y0, x, y);
    } else {
        sonar_pose_rotate(deg, x0 - cx, y0 - cy, x, y);
        *x += cx;
        *y += cy;
    }
}

/*
 * Everything of t that has a place or a direction: its position, where it last moved and each
 * model's position as points (move_point), its velocity and each model's turned by deg.
 */
static void move_track(struct sonar_track *t, float deg, float cx, float cy, const struct sonar_pose *p, int how)
{
    float vx = t->vx, vy = t->vy;
    int j;
    move_point(&t->px, &t->py, deg, cx, cy, p, how);
    move_point(&t->ax, &t->ay, deg, cx, cy, p, how);
    sonar_pose_rotate(deg, vx, vy, &t->vx, &t->vy);
    for (j = 0; j < SONAR_TRK_MODELS; j++) {
        struct sonar_track_model *m = &t->m[j];
        vx = m->vx;
        vy = m->vy;
        move_point(&m->px, &m->py, deg, cx, cy, p, how);
        sonar_pose_rotate(deg, vx, vy, &m->vx, &m->vy);
    }
}

void sonar_tracker_reframe(struct sonar_tracker *tk, const struct sonar_pose *p, int to_world)
{
    uint8_t k;
    if ((tk->world != 0) == (to_world != 0))
        return;
    for (k = 0; k < tk->n; k++)
        move_track(&tk->t[k], to_world ? p->yaw_deg : -p->yaw_deg, 0.0f, 0.0f, p, to_world ? MOVE_TO_WORLD : MOVE_TO_BODY);
    tk->world = (uint8_t)(to_world != 0);
    tk->reframes++;
    tk->nalt = 0; /* its alternatives are in the frame left */
}

void sonar_tracker_turn(struct sonar_tracker *tk, float deg, const struct sonar_pose *at)
{
    /* Turning about the sonar in the body frame is turning about where it is in the world: rotations commute. */
    float cx = 0.0f, cy = 0.0f;
    uint8_t k;
    if (tk->world) {
        if (at == NULL)
            return;
        cx = at->north_m;
        cy = at->east_m;
    }
    for (k = 0; k < tk->n; k++)
        move_track(&tk->t[k], deg, cx, cy, NULL, MOVE_TURN);
    tk->nalt = 0; /* its alternatives are in the frame left */
}

/* Seconds from t's state to utime: never negative (no prediction backwards), clipped at max_dt_s. */
float sonar_trk_step_s(const struct sonar_tracker *tk, const struct sonar_track *t, int64_t utime, int *clipped)
{
    int64_t us = utime - t->utime;
    float dt;
    if (us <= 0)
        return 0.0f;
    /* Seconds from microseconds; under 35 min through a 32-bit integer, one instruction on a Cortex-M (not a library call). */
    dt = us < INT32_MAX ? (float)(int32_t)us * 1e-6f : (float)((double)us * 1e-6);
    if (dt > tk->cfg.max_dt_s) {
        *clipped = 1;
        return tk->cfg.max_dt_s;
    }
    return dt;
}

/* The covariance after dt of white acceleration noise q = accel^2 (the standard discretisation). */
void sonar_trk_predict_cov(float q, float dt, float *pa, float *pb, float *pc)
{
    float a = *pa, b = *pb, c = *pc, dt2 = dt * dt;
    *pa = a + 2.0f * b * dt + c * dt2 + q * dt2 * dt / 3.0f;
    *pb = b + c * dt + q * dt2 / 2.0f;
    *pc = c + q * dt;
}

void sonar_tracker_predict(const struct sonar_track *t, int64_t utime, float *x_m, float *y_m)
{
    float dt = utime > t->utime ? (float)((double)(utime - t->utime) * 1e-6) : 0.0f;
    *x_m = t->px + t->vx * dt;
    *y_m = t->py + t->vy * dt;
}

void sonar_tracker_cover(uint8_t *cover, const uint16_t *angles, uint16_t n, uint16_t max_gap, int offset)
{
    uint16_t i;
    memset(cover, 0, SONAR_GRAD_TURN / 8);
    for (i = 0; i < n; i++) {
        int a = (int)angles[i] + offset, d = i + 1u < n ? sonar_frame_delta(angles[i], angles[i + 1]) : 0;
        /* To the next beam the shorter way round, if it is a step and not a jump. */
        sonar_frame_mark_arc(cover, a, (d < 0 ? -d : d) <= (int)max_gap ? a + d : a);
    }
}

static int usable(const struct sonar_tracker_obs *o)
{
    return isfinite(o->x_m) && isfinite(o->y_m) && fabsf(o->x_m) <= (float)SONAR_TRK_COORD_MAX &&
           fabsf(o->y_m) <= (float)SONAR_TRK_COORD_MAX;
}

/*
 * Would the sweep have seen t? Only the gradians decide: a prediction beyond the range scanned
 * is a target leaving, which should coast out like any other miss; one inside min_range (the
 * ring-down, where detections are dropped) cannot be seen.
 */
static int visible(const struct sonar_track *t, const struct sonar_tracker_sweep *sw)
{
    float x, y;
    int a;
    sonar_tracker_predict(t, sw->utime, &x, &y);
    x -= sw->origin_x;
    y -= sw->origin_y;
    if (sqrtf(x * x + y * y) < sw->min_range_m)
        return 0;
    if (sw->cover == NULL)
        return 1;
    /* The nearest whole gradian of its bearing: from north in the world frame. */
    a = sonar_frame_wrap((int)floor(sonar_frame_bearing_deg((double)x, (double)y) / SONAR_DEG_PER_GRAD + 0.5));
    return (int)(((unsigned)sw->cover[a / 8] >> (unsigned)(a % 8)) & 1u);
}

float sonar_track_still_s(const struct sonar_track *t, int64_t utime)
{
    double s = (double)t->still_ms * 1e-3 + (double)(utime - t->utime) * 1e-6;
    return s > 0.0 ? (float)s : 0.0f;
}

/* A radius in decimetres: 0 for nonsense, 255 beyond 25.5 m. */
static uint8_t size_dm(float size_m)
{
    return (uint8_t)(!(size_m >= 0.0f) ? 0.0f : size_m >= 25.5f ? 255.0f : size_m * 10.0f + 0.5f);
}

/*
 * Its size, whether it moved since (state time then: was): the filtered position left the disc
 * about where it last moved; and what it is: still until it has moved, then moving or resting
 * by its models (the rest model likeliest: resting).
 */
static void after_hit(struct sonar_track *t, const struct sonar_tracker_obs *o, int64_t was)
{
    float dx = t->px - t->ax, dy = t->py - t->ay;
    int64_t ms = (t->utime - was) / 1000;
    t->size_dm = size_dm(o->size_m);
    /* The first move takes two hits in a row outside the disc: one stray echo taken beside a place that has
       stood since it was born must not make it a mover for good (an emptied real pool: docs/decisions.md). */
    if (dx * dx + dy * dy > SONAR_TRK_STILL_M * SONAR_TRK_STILL_M && t->moved != 0) {
        t->ax = t->px;
        t->ay = t->py;
        t->still_ms = 0;
        t->moved = 1;
    } else if (dx * dx + dy * dy > SONAR_TRK_STILL_M * SONAR_TRK_STILL_M) {
        t->moved = SONAR_TRK_LEFT_ONCE;
    } else {
        t->moved = t->moved == SONAR_TRK_LEFT_ONCE ? 0 : t->moved;
        t->still_ms = ms >= (int64_t)(UINT32_MAX - t->still_ms) ? UINT32_MAX : t->still_ms + (uint32_t)ms;
    }
    if (t->moved == 1) /* by its models, not by the disc: a drifting float leaves its disc now and then, and stays at rest */
        t->kind = t->mode == SONAR_TRACK_RESTING ? SONAR_TRACK_KIND_RESTING : SONAR_TRACK_KIND_MOVING;
    else
        t->kind = t->hits + 1u >= SONAR_TRK_KIND_HITS ? SONAR_TRACK_KIND_STILL : SONAR_TRACK_KIND_NEW;
}

/*
 * A track of the first pass: confirmed, more than one hit, and not one that lost its object after
 * too few hits to say how it moves. A track of two hits from clutter, missed, then predicted along
 * the velocity those two gave, took a swimmer's detection from the swimmer's own track of 18 hits
 * (AquaScan sonar4, sweep 18). Such tracks have a pass of their own just after, before the second
 * chance's wide gates.
 */
static int established(const struct sonar_track *t)
{
    return t->state != SONAR_TRACK_TENTATIVE && t->hits > 1 &&
           !(t->state == SONAR_TRACK_COASTING && t->hits < SONAR_TRK_KIND_HITS);
}

/* A hit: t's models predicted to o's time, corrected by it; det is o's index. */
void sonar_trk_hit(const struct sonar_tracker *tk, struct sonar_track *t, const struct sonar_tracker_obs *o, uint8_t det,
                   float r2, int *clipped)
{
    float dt = sonar_trk_step_s(tk, t, o->utime, clipped);
    int64_t was = t->utime;
    if (o->utime > t->utime)
        t->utime = o->utime;
    /* Its likelihood per m^2 before the update (the cost is -2 ln of it x 2 pi r2): the evidence that it exists. */
    float c = sonar_trk_imm_cost(tk, t, o, r2, dt, tk->cfg.imm ? 1 : t->chance);
    t->lik = c < SONAR_TRK_OUTSIDE ? expf(-0.5f * c) / (6.2831853f * r2) : 0.0f;
    (void)sonar_trk_imm_hit(tk, t, o, r2, dt);
    after_hit(t, o, was);
    t->det = (int8_t)det;
}

/* Long: the cascade of assignments, then confirmation, coasting and births, in the order the contract above
   gives; issue 36 asks for it split, which needs the passes' shared state in a struct first. */
int sonar_tracker_update(struct sonar_tracker *tk, const struct sonar_tracker_obs *obs, unsigned n,
                         const struct sonar_tracker_sweep *sw)
{
    /* On the stack (2 KB at 16 x 32): it lives for one update, and static RAM is the co-processor's limit. */
    float cost[SONAR_MAX_CLUSTERS][SONAR_MAX_TRACKS];
    uint8_t rows[SONAR_MAX_CLUSTERS], nr = 0, left[SONAR_MAX_CLUSTERS], nl = 0, cand[SONAR_MAX_TRACKS], nc = 0, i, j, k;
    const float r2 = tk != NULL ? tk->cfg.meas_m * tk->cfg.meas_m : 0.0f;
    const float q = tk != NULL ? tk->cfg.accel_mps2 * tk->cfg.accel_mps2 : 0.0f;
    int clipped = 0;
    if (tk == NULL || sw == NULL || (n > 0 && obs == NULL))
        return SONAR_ERR_ARG;
    if (sw->beams == 0) {
        tk->empty_sweeps++;
        return SONAR_OK;
    }
    if (sw->clutter != NULL && sonar_clutter_look(sw->clutter, sw->cover, sw->min_range_m, sw->max_range_m) != SONAR_OK)
        return SONAR_ERR_ARG;
    tk->sweeps++;
    if (n > SONAR_MAX_CLUSTERS) {
        tk->dropped += n - SONAR_MAX_CLUSTERS;
        n = SONAR_MAX_CLUSTERS;
    }
    for (i = 0; i < n; i++) {
        if (!usable(&obs[i])) {
            tk->bad_detections++;
            continue;
        }
        rows[nr++] = i;
        if (tk->sweeps > 1 && obs[i].utime < tk->last_utime && obs[i].utime >= tk->last_utime - 1000000)
            tk->out_of_order++;
    }
    /*
     * A clock that ran backwards (a replay restarted, a host clock stepped): nothing is predicted
     * backwards, so every track is re-timed to the earliest time of this sweep.
     */
    {
        int64_t earliest = sw->utime;
        for (i = 0; i < nr; i++)
            earliest = obs[rows[i]].utime < earliest ? obs[rows[i]].utime : earliest;
        if (tk->n > 0 && earliest < tk->last_utime - 1000000) {
            tk->clock_back++;
            tk->nalt = 0; /* their states are of a time now in the future */
            tk->last_utime = earliest; /* the new clock from here: the next sweep is not "back" again */
            for (k = 0; k < tk->n; k++)
                if (tk->t[k].utime > earliest)
                    tk->t[k].utime = earliest;
        }
    }
    tk->cur_sw = sw;
    for (k = 0; k < tk->n; k++) {
        tk->t[k].det = -1;
        tk->t[k].lik = 0.0f;
        tk->t[k].chance = 0;
        tk->t[k].age = sonar_trk_sat_inc(tk->t[k].age);
    }
    /* The last sweep's other hypotheses, read against this sweep's detections. */
    tk->nrev = 0;
    sonar_trk_cache_reset(tk, obs);
    sonar_trk_walls_near(tk, obs, rows, nr);
    if (tk->cfg.defer)
        sonar_trk_defer_decide(tk, cost, obs, rows, nr, r2, &clipped);
    tk->nalt = 0;
    for (i = 0; i < nr; i++)
        left[nl++] = rows[i];
    /*
     * A cascade of assignments, each over the detections the ones before it left: established
     * tracks first, gated by their IMM's combined covariance (a tentative one, whose velocity is
     * not known, has a wide gate and would take detections that belong to them); then the
     * confirmed ones that lost their object after fewer than 4 hits (established()); then a second
     * chance for manoeuvres, in which a track hit in its last visible sweep that found nothing is
     * gated by each of its models' own covariances, the manoeuvre model's wide one among them (not
     * coasting ones: over two revisits that gate would span half the scene); then the tentative
     * tracks, and those of one hit (confirmed at birth when confirm_m is 1: no velocity either; in
     * one assignment with the established ones they won detections from them, two ID switches on
     * the sector scene). What is left starts new tracks.
     */
    for (k = 0; k < tk->n; k++)
        if (established(&tk->t[k]))
            cand[nc++] = k;
    nl = sonar_trk_pass(tk, cost, cand, nc, obs, left, nl, r2, 0, 1, &clipped);
    for (k = 0, nc = 0; k < tk->n; k++)
        if (!established(&tk->t[k]) && tk->t[k].state != SONAR_TRACK_TENTATIVE && tk->t[k].hits > 1)
            cand[nc++] = k;
    nl = sonar_trk_pass(tk, cost, cand, nc, obs, left, nl, r2, 0, 1, &clipped);
    for (k = 0, nc = 0; k < tk->n; k++)
        if (tk->t[k].det == -1 && tk->t[k].state == SONAR_TRACK_CONFIRMED && tk->t[k].hits > 1)
            cand[nc++] = k;
    nl = sonar_trk_pass(tk, cost, cand, nc, obs, left, nl, r2, 1, 0, &clipped);
    for (k = 0, nc = 0; k < tk->n; k++)
        if (tk->t[k].state == SONAR_TRACK_TENTATIVE || tk->t[k].hits <= 1)
            cand[nc++] = k;
    nl = sonar_trk_pass(tk, cost, cand, nc, obs, left, nl, r2, 0, 0, &clipped);
    for (k = 0; k < tk->n; k++)
        if (tk->t[k].det == SONAR_TRK_MERGED)
            tk->t[k].det = -1;
    /*
     * The other likeliest assignments are kept (their tracks' states computed from the priors)
     * before the hits of the one published are applied.
     */
    if (tk->cfg.defer)
        sonar_trk_defer_offer(tk, obs, left, nl, r2, &clipped);
    for (k = 0; k < tk->n; k++) {
        struct sonar_track *t = &tk->t[k];
        if (t->det >= 0) {
            sonar_trk_hit(tk, t, &obs[t->det], (uint8_t)t->det, r2, &clipped);
            tk->manoeuvres += t->mode == SONAR_TRACK_TURNING;
        }
    }
    /* Confirmation, coasting and deletion; the array stays in birth order. */
    for (k = 0, j = 0; k < tk->n; k++) {
        struct sonar_track *t = &tk->t[k];
        int keep = sonar_trk_account(tk, t, t->det >= 0, t->det >= 0 || visible(t, sw));
        if (keep) {
            float pa = t->pa, pb = t->pb, pc = t->pc;
            sonar_trk_predict_cov(q, sonar_trk_step_s(tk, t, sw->utime, &clipped), &pa, &pb, &pc);
            keep = pa <= SONAR_TRK_LOST_M2;
        }
        if (!keep) {
            tk->deleted++;
            continue;
        }
        if (j != k)
            tk->t[j] = *t;
        j++;
    }
    {
        /* The cost rows refer to the old slots: record which detections were used before compacting changed them. */
        uint8_t used[SONAR_MAX_CLUSTERS];
        memset(used, 0, sizeof(used));
        for (k = 0; k < j; k++)
            if (tk->t[k].det >= 0)
                used[tk->t[k].det] = 1;
        tk->n = j;
        /* Births: every usable detection no track took. */
        for (i = 0; i < nr; i++) {
            const struct sonar_tracker_obs *o = &obs[rows[i]];
            struct sonar_track *t;
            if (used[rows[i]])
                continue;
            if (tk->n >= SONAR_MAX_TRACKS) {
                tk->overflow++;
                continue;
            }
            t = &tk->t[tk->n++];
            memset(t, 0, sizeof(*t));
            t->id = tk->next_id++;
            sonar_trk_exist_birth(tk, t);
            t->det = (int8_t)rows[i];
            t->utime = o->utime;
            t->px = o->x_m;
            t->py = o->y_m;
            t->ax = o->x_m;
            t->ay = o->y_m;
            t->size_dm = size_dm(o->size_m);
            sonar_trk_imm_birth(tk, t, o, r2);
            sonar_trk_defer_born(tk, rows[i], t->id);
        }
    }
    for (i = 0; i < nr; i++)
        tk->last_utime = obs[rows[i]].utime > tk->last_utime ? obs[rows[i]].utime : tk->last_utime;
    tk->last_utime = sw->utime > tk->last_utime ? sw->utime : tk->last_utime;
    tk->clock_gaps += (uint32_t)clipped;
    sonar_trk_exist_teach(tk, obs, sw);
    sonar_trk_cache_reset(tk, NULL); /* the hits moved the tracks: nothing in it holds now */
    tk->cur_sw = NULL;
    return SONAR_OK;
}

void sonar_tracker_static_start(struct sonar_tracker *tk, const uint8_t *is_static, unsigned n)
{
    uint8_t k;
    for (k = 0; k < tk->n; k++) {
        struct sonar_track *t = &tk->t[k];
        if (t->det >= 0 && (unsigned)t->det < n && is_static[t->det] && t->moved != 1)
            t->kind = SONAR_TRACK_KIND_STATIC_START;
    }
}
