/* pose.h -- the vehicle's pose (local NED position, heading) over time: a ring of samples, checks against jumps and disorder, interpolation to a beam's time, body to world; RAM: SONAR_MAX_POSES * sizeof(struct sonar_pose) + 40 = 24 616 B. */
#ifndef SONAR_POSE_H
#define SONAR_POSE_H

#include <stdint.h>

#include "sonar/config.h"
#include "sonar/err.h"

/*
 * Frames (issue 11). Body: the sonar frame, x = r cos(theta), y = r sin(theta), taken as FRD (x
 * forward, y right). World: local NED in metres (north, east). Heading (yaw) is in degrees
 * clockwise from north. world = R(yaw) body + (north, east):
 *   north = n0 + x cos(yaw) - y sin(yaw),  east = e0 + x sin(yaw) + y cos(yaw).
 */
struct sonar_pose {
    int64_t utime;  /* us since the epoch */
    float north_m;  /* local NED, metres */
    float east_m;
    float yaw_deg;  /* heading, degrees clockwise from north, [0, 360) */
};

#define SONAR_POSE_STALE_US 1000000 /* no sample within 1 s of a time: the pose there is unknown */
#define SONAR_POSE_COORD_MAX 1.0e6f /* |north|, |east| beyond this (metres) are refused */

struct sonar_pose_limits {
    float max_speed_mps;    /* a sample implying a faster move than this from the newest is a jump, 0.1..1000 */
    float max_yaw_rate_dps; /* ... or a faster turn, 1..100000 degrees/s */
    int64_t min_gap_us;     /* stored samples are this far apart, 0..10^7 us; a new sample replaces a newest one
                               closer than this to the one before it (thinned) */
};

struct sonar_pose_ring {
    struct sonar_pose_limits lim;
    struct sonar_pose s[SONAR_MAX_POSES]; /* oldest first from head */
    uint16_t head, n;
    uint32_t accepted;
    uint32_t out_of_order; /* not later than the newest sample: refused */
    uint32_t jumps;        /* too fast a move or turn from the newest sample: refused */
    uint32_t bad;          /* NaN, infinite or beyond SONAR_POSE_COORD_MAX: refused */
    uint32_t thinned;      /* good, and took the place of a newest one within min_gap_us of the one before */
};

/* sonard's limits: 50 m/s, 720 degrees/s, 50 ms between stored samples (the ring then spans 51 s, longer than a 40 s turn). */
void sonar_pose_limits_default(struct sonar_pose_limits *lim);

/* Empties the ring. Returns SONAR_OK, or SONAR_ERR_ARG (NULL, or a limit out of range). */
SONAR_CHECK int sonar_pose_init(struct sonar_pose_ring *r, const struct sonar_pose_limits *lim);

/*
 * Adds one sample (yaw taken modulo 360). Samples must come in time order: one not later than
 * the newest, one that jumps, or one with a non-finite or absurd field is refused and counted.
 * A sample more than SONAR_POSE_STALE_US after the newest is never a jump (the vehicle may have
 * moved while nothing was heard). A good sample replaces the newest when that one is less than
 * min_gap_us after the one before it (thinned): the ring keeps its spacing and always ends at the
 * latest sample.
 * The oldest sample goes when the ring is full. Returns SONAR_OK (stored or thinned), SONAR_ERR_ARG
 * (NULL), or SONAR_ERR_RANGE (refused, counted).
 */
SONAR_CHECK int sonar_pose_push(struct sonar_pose_ring *r, const struct sonar_pose *p);

/*
 * sonar_pose_push, saying why a sample was refused: NULL when it was stored or thinned, else a
 * static sentence ("not later than the pose before it", ...). r and p must not be NULL.
 */
const char *sonar_pose_push_why(struct sonar_pose_ring *r, const struct sonar_pose *p);

/* Samples accepted since sonar_pose_init (0: no pose has come yet). */
uint32_t sonar_pose_accepted(const struct sonar_pose_ring *r);

/*
 * The pose at utime: linear between the two samples around it (yaw the short way round),
 * or the nearest end sample when utime lies outside them by at most SONAR_POSE_STALE_US.
 * Returns 1 with *out filled, 0 when the ring has no sample within SONAR_POSE_STALE_US of utime
 * on the side needed (stale: *out untouched).
 */
int sonar_pose_at(const struct sonar_pose_ring *r, int64_t utime, struct sonar_pose *out);

/* Body-frame x, y (metres) to world north, east at pose p. */
void sonar_pose_to_world(const struct sonar_pose *p, float x_m, float y_m, float *north_m, float *east_m);

/* World north, east to body-frame x, y at pose p (the inverse of sonar_pose_to_world). */
void sonar_pose_to_body(const struct sonar_pose *p, float north_m, float east_m, float *x_m, float *y_m);

/* A body-frame velocity (or any vector) turned into the world frame at heading yaw_deg. */
void sonar_pose_rotate(float yaw_deg, float x, float y, float *north, float *east);

#endif
