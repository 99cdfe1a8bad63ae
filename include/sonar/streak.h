/* streak.h -- interference streaks: a beam that stands out along most of its length, unlike the beam before it, is left out of the background and the detector and counted; RAM: sizeof(struct sonar_streak) = 24 B. */
#ifndef SONAR_STREAK_H
#define SONAR_STREAK_H

#include <stdint.h>

#include "sonar/background.h"
#include "sonar/err.h"

/*
 * Another acoustic source (a second sonar, a modem, the vehicle's thrusters) heard by the receiver
 * fills the whole beam it lands in: a bright streak from the transducer outwards, one or a few beams
 * wide. No echo does that: a wall is a line across the beams, a person a blob, the water's clutter
 * speckle. A beam is a streak when at least SONAR_STREAK_16 sixteenths of its length (from its first
 * nonzero sample: some recorders zero the near samples) stand above the background (sonar_streak_standing)
 * and at least SONAR_STREAK_RATIO times the share of the last beam that was not a streak, all beams
 * between being neighbours (SONAR_STREAK_NEAR_GRAD, SONAR_STREAK_NEAR_US): a sector of dense clutter or
 * a wall along the beams raises its neighbours too, and a beam after a jump (a sector's start, a pause
 * while the vehicle moved and the background went stale) has no neighbour to differ from, so it is not
 * judged and becomes the reference. Streaks are narrow (one or two beams on the RoboSub sweeps): after
 * SONAR_STREAK_MAX_RUN lit beams in a row the next lit one is taken as the water changing (a turbid patch,
 * a new place after a turn) and becomes the reference, so that a step in the water's level is learnt
 * rather than cut out for good. Such a beam is neither background nor object: the background does not
 * learn it and the detector sees it empty.
 */
#define SONAR_STREAK_16 12     /* sixteenths of the beam's length standing above the background */
#define SONAR_STREAK_RATIO 2   /* ... and this many times the last ordinary beam's share */
#define SONAR_STREAK_MIN_LEN 16 /* beams with fewer samples after their leading zeros are never judged */
#define SONAR_STREAK_NEAR_GRAD 10   /* the beam before is a neighbour within this many gradians... */
#define SONAR_STREAK_NEAR_US 1000000 /* ... and this many microseconds */
#define SONAR_STREAK_MARGIN 8 /* grey levels above the model a sample stands by, at least (the background's margin if more: with
                                 margin 0, half of any water stands above its median) */
#define SONAR_STREAK_MAX_RUN 4 /* streaks are one to three beams wide: a fifth lit beam in a row is a new scene */

struct sonar_streak {
    uint32_t beams;   /* beams judged streaks since the start (SONAR_STATUS interference_beams) */
    int64_t last_us;  /* the beam before: its time, us since the epoch */
    uint16_t last_angle; /* ... and angle, gradians */
    uint16_t ref256;  /* the last ordinary beam's standing share, 256ths (0..256) */
    uint8_t have_ref; /* 1: ref256 holds a neighbour's share */
    uint8_t run;      /* streaks in a row just before */
};

/*
 * Reads, learns nothing: how many of the samples in[from..n) stand above the background model angle's
 * beam would be compared with (its row once learnt, else the across-beam model once seeded; range mode:
 * its one row) by more than margin grey levels. Where fewer than 3/8 of them stand (SONAR_STREAK_16 /
 * (16 SONAR_STREAK_RATIO) of n - from) the count may stop early and return less, still under 3/8: such a
 * beam is no streak, and as the reference it decides nothing (sonar_streak_judge judges both the same).
 * -1 when there is no such model yet (every row and the across-beam model still seeding), in off mode,
 * for the world grid, or when n is not the model's.
 */
int sonar_streak_standing(const struct sonar_background *bg, uint16_t angle, const uint8_t *in, uint16_t n, uint16_t from,
                          uint8_t margin);

/* Starts with no beam seen. s must not be NULL. */
void sonar_streak_init(struct sonar_streak *s);

/*
 * Judges one beam at angle (gradians 0..399) and utime (us): standing of its length samples stand above
 * the background (sonar_streak_standing; negative: no model yet, never a streak). Returns 1 for a
 * streak (counted), 0 otherwise (the beam then becomes the reference for the next).
 */
int sonar_streak_judge(struct sonar_streak *s, uint16_t angle, int64_t utime, int standing, uint16_t length);

/* The first nonzero sample of s[0..n), or n when all are 0: where a beam's length starts. */
uint16_t sonar_streak_from(const uint8_t *s, uint16_t n);

#endif
