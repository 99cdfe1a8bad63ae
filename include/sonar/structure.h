/* structure.h -- static echoes learnt as structure: places where detections stand still since the first look, promoted after structure_s; RAM: sizeof(struct sonar_place) = 40 B a place (SONAR_MAX_PLACES), sizeof(struct sonar_structure) = 672 B. */
#ifndef SONAR_STRUCTURE_H
#define SONAR_STRUCTURE_H

#include <stdint.h>

#include "sonar/config.h"
#include "sonar/detector.h"
#include "sonar/err.h"

/*
 * A place is where detections stand: each detection of a sweep (body frame) joins the nearest place
 * within SONAR_PLACE_M of where that place was first seen; a detection at a first look (where the
 * background had not yet learnt the water: the echo was there before the model was) that joins none
 * starts one. Only such places are kept: nothing that came in later can become structure. A place
 * that has stood there since (seen in at least 3 of every 4 sweeps since it was first seen, and
 * SONAR_PLACE_MIN_SEEN times) for structure_s becomes structure: its detections are reported as
 * structure rather than objects and kept from the tracker, and the background learns its echo at
 * once (sonar_background_apply_spans). What was first seen after the background had learnt the
 * water came in: it is never structure, however still it stands.
 *
 * The rule cannot tell structure from a person motionless from the first ping: both were there
 * before the background, and stand. structure_s is how long such an echo is an object before it is
 * structure (0: never); until then its detections are objects of kind "static since start". A fixed
 * installation records a survey of its empty site instead (survey.h), and then nothing is a first look.
 *
 * Places not seen for SONAR_PLACE_FORGET_S are forgotten, except structure, which is kept until the
 * background restarts (its echo learnt, it is seldom seen, and if it comes back it is still
 * structure). A full table evicts the place seen longest ago that is not structure; when all are
 * structure the new one is not kept (counted in evicted).
 */
#define SONAR_PLACE_M 1.0f        /* metres within which a detection is at a place */
#define SONAR_PLACE_MIN_SEEN 3    /* sweeps a place is seen before it can be structure */
#define SONAR_PLACE_FORGET_S 30   /* seconds unseen after which a place that is not structure is forgotten */
#define SONAR_STRUCTURE_S_MAX 3600 /* structure_s: 0 (never) or 1..3600 s */
#define SONAR_PLACE_MAX_RADIUS_M 3.0f /* a place's radius (its detections' largest) is clipped to this */

struct sonar_place {
    float x, y;           /* where it was first seen, metres, body frame */
    float radius;         /* its detections' largest radius, metres */
    int64_t first_us;     /* when it was first seen, us since the epoch */
    uint32_t last_ms;     /* when it was last seen, ms after first_us (saturating) */
    uint32_t first_sweep; /* the sweep (sonar_structure.sweeps + 1) it was first seen in */
    uint16_t seen;        /* sweeps it was seen in (saturating) */
    uint8_t structure;    /* promoted */
};

/* One detection as the rule sees it. */
struct sonar_structure_obs {
    float x_m, y_m;     /* body frame, metres */
    float radius_m;     /* centroid to farthest hull vertex, metres */
    int64_t utime;      /* when it was seen, us since the epoch */
    uint8_t first_look; /* its place was not yet learnt by the background (it may start a place) */
};

struct sonar_structure {
    float structure_s;  /* seconds a first-look place stands before it is structure; 0: never */
    struct sonar_place p[SONAR_MAX_PLACES];
    uint8_t n;          /* places in p */
    uint32_t sweeps;    /* sonar_structure_sweep calls */
    uint32_t promoted;  /* places made structure */
    uint32_t evicted;   /* places dropped for room (the table was full) */
    uint32_t detections; /* detections reported as structure */
    uint32_t restarts;  /* sonar_structure_restart calls (the background restarted) */
};

/* Sets s up with structure_s seconds (0: never, else 1..SONAR_STRUCTURE_S_MAX). Returns SONAR_OK or SONAR_ERR_ARG. */
SONAR_CHECK int sonar_structure_init(struct sonar_structure *s, float structure_s);

/* Changes structure_s in place, keeping the places. Returns SONAR_OK or SONAR_ERR_ARG (nothing changed). */
SONAR_CHECK int sonar_structure_tune(struct sonar_structure *s, float structure_s);

/* Forgets every place: the background restarted (a new range, gain or frame), so nothing is learnt. */
void sonar_structure_restart(struct sonar_structure *s);

/*
 * The output frame turned by deg degrees clockwise (a reload's new angle offset): every place turns
 * about the sonar with it, so the structure learnt stays where its echoes will now be reported.
 */
void sonar_structure_turn(struct sonar_structure *s, float deg);

/*
 * One sweep's detections (n <= SONAR_MAX_CLUSTERS; obs may be NULL when n is 0) at the sweep's end
 * utime: each joins or starts a place, places are promoted and forgotten, and kind[i] says what the
 * detection is by its place (enum sonar_det_kind): SONAR_DET_STRUCTURE at a structure place;
 * SONAR_DET_STATIC_START at a place that has stood there since the first look (seen
 * SONAR_PLACE_MIN_SEEN times and in 3 of every 4 sweeps), not yet structure; else SONAR_DET_OBJECT.
 * Returns how many are structure, or SONAR_ERR_ARG (NULL, n too large, a non-finite coordinate;
 * nothing changed).
 */
SONAR_CHECK int sonar_structure_sweep(struct sonar_structure *s, const struct sonar_structure_obs *obs, uint8_t n,
                                      int64_t utime, uint8_t *kind);

/* How many places are structure now. */
unsigned sonar_structure_count(const struct sonar_structure *s);

#endif
