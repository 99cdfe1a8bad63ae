/* tracker_imm.c -- a track's interacting multiple models (near constant velocity, manoeuvre, rest): mixing, prediction, the mixture's likelihood of a detection, the update and the combined estimate; ~150 flops a pair cost, ~400 a hit, no heap, no RAM beyond the track. */
#include <math.h>
#include <string.h>

#include "tracker_internal.h"

/*
 * The probability of going from one model (row) to another (column) between two looks at a
 * track. A look comes every 3-6 s at the Ping360's pace, long enough for a person to turn or
 * stop, so the models change more readily than in a radar's IMM (0.95-0.99 on the diagonal).
 */
static const float TRANSITION[2][SONAR_TRK_MODELS][SONAR_TRK_MODELS] = {
    {{1.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f}}, /* cfg.imm 0: near constant velocity alone */
    {
        {0.85f, 0.10f, 0.05f}, /* near constant velocity */
        {0.30f, 0.60f, 0.10f}, /* manoeuvre */
        {0.05f, 0.10f, 0.85f}, /* rest */
    }};

/* A birth's probabilities: no velocity is known yet, but most of what a sonar tracks swims. */
static const float BIRTH_P[2][SONAR_TRK_MODELS] = {{1.0f, 0.0f, 0.0f}, {0.6f, 0.2f, 0.2f}};

static float model_q(const struct sonar_tracker *tk, int j)
{
    float a = tk->cfg.accel_mps2, m = tk->cfg.manoeuvre_mps2 > a ? tk->cfg.manoeuvre_mps2 : a;
    return j == SONAR_TRK_MANOEUVRE ? m * m : a * a;
}

/* Model j's state moved on by dt seconds. */
static void predict_model(const struct sonar_tracker *tk, int j, struct sonar_track_model *m, float dt)
{
    if (j == SONAR_TRK_REST) {
        m->pa += SONAR_TRK_REST_MPS * SONAR_TRK_REST_MPS * dt;
        return;
    }
    m->px += m->vx * dt;
    m->py += m->vy * dt;
    sonar_trk_predict_cov(model_q(tk, j), dt, &m->pa, &m->pb, &m->pc);
}

/*
 * The models' predictions for a detection at o's time, positions and position variances only:
 * each model's prior p[] (the second chance of near constant velocity alone, cfg.imm 0 and wide,
 * is the manoeuvre model's alone, as a manoeuvre pass), d^2 and S = pa + r2. Returns the combined
 * prediction's d^2 (its mean, and the models' covariances and spread about it), the IMM's gate,
 * and in *least the least of the models' own d^2, the gate of a second chance (the combined
 * covariance of a likely model and an unlikely wide one, a turn, cuts the wide one's tail). No
 * logarithm, exponential or copy: most pairs end at the gate. Where a model's path would cross one
 * of the site's walls, its prediction is the straight one or the one turned at the wall
 * (tracker_walls.c), whichever lies nearer o; turned[j] (NULL: not wanted) says which.
 */
static float predicted(const struct sonar_tracker *tk, const struct sonar_track *t, const struct sonar_tracker_obs *o,
                       float r2, float dt, int wide, float p[SONAR_TRK_MODELS], float d2[SONAR_TRK_MODELS],
                       float sj[SONAR_TRK_MODELS], float *least, uint8_t turned[SONAR_TRK_MODELS])
{
    float x[SONAR_TRK_MODELS], y[SONAR_TRK_MODELS], cx = 0.0f, cy = 0.0f, s = 0.0f, ex, ey, dt2 = dt * dt;
    int j;
    *least = 1e30f;
    for (j = 0; j < SONAR_TRK_MODELS; j++) {
        const struct sonar_track_model *m = &t->m[j];
        p[j] = !tk->cfg.imm && wide ? (j == SONAR_TRK_MANOEUVRE ? 1.0f : 0.0f) : m->p;
        d2[j] = 1e30f;
        if (!(p[j] > 0.0f))
            continue;
        if (j == SONAR_TRK_REST) {
            x[j] = m->px;
            y[j] = m->py;
            sj[j] = m->pa + SONAR_TRK_REST_MPS * SONAR_TRK_REST_MPS * dt + r2;
        } else {
            float wx = m->px, wy = m->py, wvx = m->vx, wvy = m->vy;
            x[j] = m->px + m->vx * dt;
            y[j] = m->py + m->vy * dt;
            sj[j] = m->pa + 2.0f * m->pb * dt + m->pc * dt2 + model_q(tk, j) * dt2 * dt / 3.0f + r2;
            if (t->near_walls != 0 && sonar_trk_wall_turn(tk, t->near_walls, &wx, &wy, &wvx, &wvy, dt)) {
                float tx = wx + wvx * dt, ty = wy + wvy * dt;
                float straight = (o->x_m - x[j]) * (o->x_m - x[j]) + (o->y_m - y[j]) * (o->y_m - y[j]);
                if ((o->x_m - tx) * (o->x_m - tx) + (o->y_m - ty) * (o->y_m - ty) < straight) {
                    x[j] = tx;
                    y[j] = ty;
                    if (turned != NULL)
                        turned[j] = 1;
                }
            }
        }
        ex = o->x_m - x[j];
        ey = o->y_m - y[j];
        d2[j] = (ex * ex + ey * ey) / sj[j];
        *least = d2[j] < *least ? d2[j] : *least;
        cx += p[j] * x[j];
        cy += p[j] * y[j];
    }
    for (j = 0; j < SONAR_TRK_MODELS; j++) {
        if (p[j] > 0.0f) {
            float dx = x[j] - cx, dy = y[j] - cy;
            s += p[j] * (sj[j] + 0.5f * (dx * dx + dy * dy));
        }
    }
    ex = o->x_m - cx;
    ey = o->y_m - cy;
    return (ex * ex + ey * ey) / s;
}

/*
 * Each model's weight p L (L its likelihood scaled by r2: exp(-d2 / 2) r2 / S) into w[]; returns
 * their sum, the mixture's likelihood. 0 when every model is too far for a float (d^2 > ~170).
 */
static float weights(const float p[SONAR_TRK_MODELS], const float d2[SONAR_TRK_MODELS], const float sj[SONAR_TRK_MODELS],
                     float r2, float w[SONAR_TRK_MODELS])
{
    float sum = 0.0f;
    int j;
    for (j = 0; j < SONAR_TRK_MODELS; j++) {
        w[j] = p[j] > 0.0f && d2[j] < 170.0f ? p[j] * (r2 / sj[j]) * expf(-0.5f * d2[j]) : 0.0f;
        sum += w[j];
    }
    return sum;
}

float sonar_trk_imm_cost(const struct sonar_tracker *tk, const struct sonar_track *t, const struct sonar_tracker_obs *o,
                         float r2, float dt, int wide)
{
    float p[SONAR_TRK_MODELS], d2[SONAR_TRK_MODELS], sj[SONAR_TRK_MODELS], w[SONAR_TRK_MODELS], least, comb, sum;
    comb = predicted(tk, t, o, r2, dt, wide, p, d2, sj, &least, NULL);
    if ((wide ? least : comb) > tk->cfg.gate)
        return SONAR_TRK_OUTSIDE;
    sum = weights(p, d2, sj, r2, w);
    return sum > 0.0f ? -2.0f * logf(sum) : SONAR_TRK_OUTSIDE;
}

/*
 * The moment-matched blend of the models post[] with weights w[] (summing to 1) into out's px ..
 * pc: the weighted mean, and the weighted covariances plus the models' spread about it. One
 * covariance serves both axes, so the spread is the two axes' mean. The IMM's combined estimate
 * and its mixing are both this.
 */
static void blend(const struct sonar_track_model post[SONAR_TRK_MODELS], const float w[SONAR_TRK_MODELS],
                  struct sonar_track_model *out)
{
    int j;
    memset(out, 0, sizeof(*out));
    for (j = 0; j < SONAR_TRK_MODELS; j++) {
        out->px += w[j] * post[j].px;
        out->py += w[j] * post[j].py;
        out->vx += w[j] * post[j].vx;
        out->vy += w[j] * post[j].vy;
    }
    for (j = 0; j < SONAR_TRK_MODELS; j++) {
        float dx = post[j].px - out->px, dy = post[j].py - out->py, du = post[j].vx - out->vx, dv = post[j].vy - out->vy;
        out->pa += w[j] * (post[j].pa + 0.5f * (dx * dx + dy * dy));
        out->pb += w[j] * (post[j].pb + 0.5f * (dx * du + dy * dv));
        out->pc += w[j] * (post[j].pc + 0.5f * (du * du + dv * dv));
    }
}

/* The combined estimate of the models post[] with probabilities mu[] into t's px .. pc. */
static void combine(struct sonar_track *t, const struct sonar_track_model post[SONAR_TRK_MODELS], const float mu[SONAR_TRK_MODELS])
{
    struct sonar_track_model c;
    blend(post, mu, &c);
    t->px = c.px;
    t->py = c.py;
    t->vx = c.vx;
    t->vy = c.vy;
    t->pa = c.pa;
    t->pb = c.pb;
    t->pc = c.pc;
}

/* The IMM's mixing: each model's starting state for the next step, and its prior probability, into t->m[]. */
static void mix(const struct sonar_tracker *tk, struct sonar_track *t, const struct sonar_track_model post[SONAR_TRK_MODELS],
                const float mu[SONAR_TRK_MODELS])
{
    const float(*to)[SONAR_TRK_MODELS] = TRANSITION[tk->cfg.imm != 0];
    int i, j;
    for (j = 0; j < SONAR_TRK_MODELS; j++) {
        struct sonar_track_model *m = &t->m[j];
        float c = 0.0f, w[SONAR_TRK_MODELS];
        for (i = 0; i < SONAR_TRK_MODELS; i++)
            c += to[i][j] * mu[i];
        /* A model nothing goes to (near constant velocity alone) still starts from the combined estimate. */
        for (i = 0; i < SONAR_TRK_MODELS; i++)
            w[i] = c > 1e-9f ? to[i][j] * mu[i] / c : mu[i];
        blend(post, w, m);
        m->p = c;
        if (j == SONAR_TRK_REST) {
            m->vx = m->vy = m->pb = m->pc = 0.0f; /* rest has no velocity to carry */
        }
    }
}

/* Posterior probabilities and the published ones (mu 0..255, the mode). */
static void set_mode(struct sonar_track *t, const float mu[SONAR_TRK_MODELS])
{
    int j, best = 0;
    for (j = 0; j < SONAR_TRK_MODELS; j++) {
        t->mu[j] = (uint8_t)(mu[j] * 255.0f + 0.5f);
        if (mu[j] > mu[best])
            best = j;
    }
    t->mode = (uint8_t)(best == SONAR_TRK_REST ? SONAR_TRACK_RESTING : best == SONAR_TRK_MANOEUVRE ? SONAR_TRACK_TURNING
                                                                                                     : SONAR_TRACK_MOVING);
}

int sonar_trk_imm_hit(const struct sonar_tracker *tk, struct sonar_track *t, const struct sonar_tracker_obs *o, float r2, float dt)
{
    struct sonar_track_model post[SONAR_TRK_MODELS];
    float p[SONAR_TRK_MODELS], d2[SONAR_TRK_MODELS], sj[SONAR_TRK_MODELS], mu[SONAR_TRK_MODELS], least, sum;
    uint8_t turned[SONAR_TRK_MODELS] = {0};
    int j;
    (void)predicted(tk, t, o, r2, dt, t->chance, p, d2, sj, &least, turned);
    sum = weights(p, d2, sj, r2, mu);
    for (j = 0; j < SONAR_TRK_MODELS; j++) {
        struct sonar_track_model *m = &post[j];
        *m = t->m[j];
        if (turned[j]) /* the turned prediction explained it: the model turned at the wall */
            (void)sonar_trk_wall_turn(tk, t->near_walls, &m->px, &m->py, &m->vx, &m->vy, dt);
        predict_model(tk, j, m, dt);
        float s = m->pa + r2, ka = m->pa / s, kb = m->pb / s, ex = o->x_m - m->px, ey = o->y_m - m->py;
        float a = m->pa, b = m->pb;
        /* Posterior probabilities; a hit no model explains (a forced one, far off) keeps the priors. */
        mu[j] = sum > 0.0f ? mu[j] / sum : p[j];
        m->px += ka * ex;
        m->py += ka * ey;
        m->pa = a - ka * a;
        if (j != SONAR_TRK_REST) {
            m->vx += kb * ex;
            m->vy += kb * ey;
            m->pb = b - ka * b;
            m->pc = m->pc - kb * b;
        }
    }
    combine(t, post, mu);
    mix(tk, t, post, mu);
    set_mode(t, mu);
    return t->mode;
}

void sonar_trk_imm_birth(const struct sonar_tracker *tk, struct sonar_track *t, const struct sonar_tracker_obs *o, float r2)
{
    struct sonar_track_model post[SONAR_TRK_MODELS];
    int j;
    for (j = 0; j < SONAR_TRK_MODELS; j++) {
        memset(&post[j], 0, sizeof(post[j]));
        post[j].px = o->x_m;
        post[j].py = o->y_m;
        post[j].pa = r2;
        post[j].pc = j == SONAR_TRK_REST ? 0.0f : tk->cfg.speed0_mps * tk->cfg.speed0_mps;
    }
    combine(t, post, BIRTH_P[tk->cfg.imm != 0]);
    mix(tk, t, post, BIRTH_P[tk->cfg.imm != 0]);
    set_mode(t, BIRTH_P[tk->cfg.imm != 0]);
}
