/* tracker_internal.h -- what tracker.c (the tracks' life) and tracker_assign.c (the association) share; not part of the API; no RAM. */
#ifndef SONAR_TRACKER_INTERNAL_H
#define SONAR_TRACKER_INTERNAL_H

#include "sonar/tracker.h"

#define SONAR_TRK_LOST_M2 100.0f /* position variance beyond which a coasting prediction says nothing: (10 m)^2 */
#define SONAR_TRK_MERGED (-2)    /* det while a track coasts through a merged echo (one update only) */

/* Seconds from t's state to utime: never negative (no prediction backwards), clipped at max_dt_s (*clipped = 1). */
float sonar_trk_step_s(const struct sonar_tracker *tk, const struct sonar_track *t, int64_t utime, int *clipped);

/* The covariance (pa, pb, pc) after dt s of white acceleration noise q = accel^2 (m^2/s^4). */
void sonar_trk_predict_cov(float q, float dt, float *pa, float *pb, float *pc);

/* A hit: t predicted to o's time under noise q, then corrected by it (r2: measurement variance, m^2); det is o's index. */
void sonar_trk_hit(const struct sonar_tracker *tk, struct sonar_track *t, const struct sonar_tracker_obs *o, uint8_t det,
                   float q, float r2, int *clipped);

/*
 * One gated assignment of detections left[0 .. nl) to tracks cand[0 .. nc) under noise q
 * (cost: scratch, nl rows of SONAR_MAX_TRACKS); hits applied; returns how many detections are
 * left, compacted in left[] (tracker_assign.c says more).
 */
uint8_t sonar_trk_pass(struct sonar_tracker *tk, float (*cost)[SONAR_MAX_TRACKS], const uint8_t *cand, uint8_t nc,
                       const struct sonar_tracker_obs *obs, uint8_t *left, uint8_t nl, float q, float r2, int turn,
                       int merge, int *clipped);

#endif
