/* tracker_internal.h -- what tracker.c (the tracks' life) and tracker_assign.c (the association) share; not part of the API; no RAM. */
#ifndef SONAR_TRACKER_INTERNAL_H
#define SONAR_TRACKER_INTERNAL_H

#include "sonar/tracker.h"

#define SONAR_TRK_LOST_M2 100.0f /* position variance beyond which a coasting prediction says nothing: (10 m)^2 */
#define SONAR_TRK_MERGED (-2)    /* det while a track coasts through a merged echo (one update only) */

/* v + 1, saturating at 65535. */
static inline uint16_t sonar_trk_sat_inc(uint16_t v)
{
    return v == UINT16_MAX ? v : (uint16_t)(v + 1u);
}

/* Seconds from t's state to utime: never negative (no prediction backwards), clipped at max_dt_s (*clipped = 1). */
float sonar_trk_step_s(const struct sonar_tracker *tk, const struct sonar_track *t, int64_t utime, int *clipped);

/* The covariance (pa, pb, pc) after dt s of white acceleration noise q = accel^2 (m^2/s^4). */
void sonar_trk_predict_cov(float q, float dt, float *pa, float *pb, float *pc);

/* A hit: t's models predicted to o's time, corrected by it (r2: measurement variance, m^2), mixed; det is o's index. */
void sonar_trk_hit(const struct sonar_tracker *tk, struct sonar_track *t, const struct sonar_tracker_obs *o, uint8_t det,
                   float r2, int *clipped);

/* What a pair outside every gate costs (tracker_assign.c's BIG): finite, so the assignment's arithmetic stays exact. */
#define SONAR_TRK_OUTSIDE 1.0e9f

/*
 * The IMM (tracker_imm.c). _cost: -2 ln of the models' mixture likelihood of o after dt s (scaled
 * so that one model gives d^2 + 2 ln(S / r2)), or SONAR_TRK_OUTSIDE when o is beyond the gate:
 * the combined prediction's squared Mahalanobis distance, or when wide (the second chance) the
 * least of its models' own. _hit: the update at o after dt s; returns the track's mode. _birth: a
 * new track at o.
 */
float sonar_trk_imm_cost(const struct sonar_tracker *tk, const struct sonar_track *t, const struct sonar_tracker_obs *o,
                         float r2, float dt, int wide);
int sonar_trk_imm_hit(const struct sonar_tracker *tk, struct sonar_track *t, const struct sonar_tracker_obs *o, float r2, float dt);
void sonar_trk_imm_birth(const struct sonar_tracker *tk, struct sonar_track *t, const struct sonar_tracker_obs *o, float r2);

/*
 * A model at (*px, *py) moving at (*vx, *vy) m/s whose straight path over dt s would cross one of
 * the walls near (a track's near_walls) from the sonar's side (tk->cur_sw's origin; 0, 0 without
 * one): the path turned at it (and at a second, a corner), given as the start and velocity that
 * predict its end in a straight line. Returns the walls turned at (0: none, nothing changed).
 * tracker_walls.c.
 */
int sonar_trk_wall_turn(const struct sonar_tracker *tk, uint32_t near, float *px, float *py, float *vx, float *vy, float dt);

/*
 * Each live and alternative track's near_walls for an update whose usable detections are obs[rows[0 .. nr)]: the
 * walls whose boxes the box of its models' straight paths to the latest of them reaches (with the turn line's and
 * the wall end's margins). A path to an earlier detection is a part of that one, so a wall out of reach of the
 * latest is out of reach of every pair: sonar_trk_wall_turn looks at no other (its corner's second wall aside).
 */
void sonar_trk_walls_near(struct sonar_tracker *tk, const struct sonar_tracker_obs *obs, const uint8_t *rows, unsigned nr);

/*
 * One gated assignment of detections left[0 .. nl) to tracks cand[0 .. nc) (cost: scratch, nl
 * rows of SONAR_MAX_TRACKS), each model's own gate when wide (a second chance for a turn), else
 * the combined one; the tracks given one have it in det; returns how many detections are left,
 * compacted in left[] (tracker_assign.c says more).
 */
uint8_t sonar_trk_pass(struct sonar_tracker *tk, float (*cost)[SONAR_MAX_TRACKS], const uint8_t *cand, uint8_t nc,
                       const struct sonar_tracker_obs *obs, uint8_t *left, uint8_t nl, float r2, int wide, int merge,
                       int *clipped);

/* The cost of continuing t with o (-2 ln of its mixture likelihood), or 1e9 outside its gate (wide: the second chance's). */
float sonar_trk_pair_cost(const struct sonar_tracker *tk, const struct sonar_track *t, const struct sonar_tracker_obs *o,
                          float r2, int wide, int *clipped);

/*
 * The same for live track slot k and detection d of the update (sonar_trk_cache_reset's obs),
 * computed once an update unless wide: the passes, the alternatives and the next look's decision
 * all read it.
 */
float sonar_trk_cost(struct sonar_tracker *tk, uint8_t k, uint8_t d, float r2, int wide, int *clipped);

/* Empties the pair cost cache for an update over obs (NULL: none); again whenever the live tracks change. */
void sonar_trk_cache_reset(struct sonar_tracker *tk, const struct sonar_tracker_obs *obs);

/*
 * What a track that finds no detection costs: -2 ln(1 - P_D P_real), with P_D = 0.9 the chance a
 * look sees a target in view and P_real = hits / (hits + 1) the chance the track is one (a track
 * of one hit may be clutter): about 1.2 for a one-hit track, 4 for an established one. Deferred
 * association weighs hypotheses with it, so that one which starves an established track costs more
 * than one which starves a new one. (The sweep's own passes leave it out: in them it changed no
 * outcome here, and near constant velocity alone stays the tracker before, output for output.)
 */
float sonar_trk_miss_cost(const struct sonar_track *t);

/* The cost of starting a new track from a detection instead of continuing one. */
float sonar_trk_fresh(const struct sonar_tracker *tk, float r2);

/* The least total cost of assigning rows detections to nc tracks (cost[row][track]) or to new tracks at fresh each. */
float sonar_trk_best_total(const float (*cost)[SONAR_MAX_TRACKS], uint8_t rows, uint8_t nc, float fresh);

/*
 * Its life after a sweep (tracker_exist.c): a hit (hit 1), a miss where it was visible (hit 0,
 * visible 1), or out of view; its existence (read against tk->cur_sw's clutter map, if any),
 * confirmation, coasting; returns 0 when it should end.
 */
int sonar_trk_account(const struct sonar_tracker *tk, struct sonar_track *t, int hit, int visible);

/* A new track's life so far: one hit, tentative (confirmed at once when confirm_m is 1 under hit counts). */
void sonar_trk_exist_birth(const struct sonar_tracker *tk, struct sonar_track *t);

/*
 * After the sweep's tracks are hit and confirmed: each detection that a tentative track took (a
 * newborn's included) teaches sw's clutter map; a confirmed track's never does. A faint swimmer's
 * tentative track teaches its own place too: the cost measured in docs/decisions.md.
 */
void sonar_trk_exist_teach(const struct sonar_tracker *tk, const struct sonar_tracker_obs *obs,
                           const struct sonar_tracker_sweep *sw);

/*
 * Deferred association (tracker_defer.c). _offer: after the passes, before any hit is applied,
 * keeps the SONAR_TRK_HYPOTHESES - 1 likeliest other assignments of this sweep (a swap, a
 * detection taken by a track that found none, a birth that continued a track instead) with their
 * tracks' states. _born: names the tracks the births made. _decide: at the next sweep, before its
 * passes, adopts the alternative that explains that sweep's detections better, if any, and
 * records the revision of IDs.
 */
void sonar_trk_defer_offer(struct sonar_tracker *tk, const struct sonar_tracker_obs *obs, const uint8_t *left, uint8_t nl,
                           float r2, int *clipped);
void sonar_trk_defer_born(struct sonar_tracker *tk, uint8_t det, uint32_t id);
void sonar_trk_defer_decide(struct sonar_tracker *tk, float (*cost)[SONAR_MAX_TRACKS], const struct sonar_tracker_obs *obs,
                            const uint8_t *rows, uint8_t nr, float r2, int *clipped);

#endif
