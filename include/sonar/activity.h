/* activity.h -- what each track is doing (moving, standing, struggling) and its alarms, from its motion over two looks and the look-to-look correlation of its raw echo in a small window; RAM: sizeof(struct sonar_activity) = 20 800 B at 32 slots (sizeof(struct sonar_act_slot) = 616 B a slot, two 258 B windows in it, and the alarm events); per beam O(slots), per look O(slots x 256 + tracks x slots). */
#ifndef SONAR_ACTIVITY_H
#define SONAR_ACTIVITY_H

#include <stdint.h>

#include "sonar/config.h"
#include "sonar/err.h"
#include "sonar/frame.h"
#include "sonar/tracker.h"

/*
 * A standing body is a steady reflector: the raw echo in a small window at it is much the same
 * look after look. Limbs and splash decorrelate it. So each track keeps the raw samples of a
 * window at where it stood when the look began (+-0.5 m by -7..+8 gradians about its bearing, 16
 * range samples a beam, every beam the sweep had there), from this look and the one before, and
 * correlates them (Pearson, each beam paired with the last look's nearest, SONAR_ACT_PAIR_GRAD at
 * most: a back-and-forth sector visits other gradians each way). Below SONAR_ACT_CORR_MIN averaged over the last three looks it struggles,
 * above it stands; a track that moved more than SONAR_ACT_MOVE_M in two looks moves, whatever its
 * echo. Only looks where the track had a detection, this one and the one before, are correlated:
 * a missed track's window may hold only water, whose speckle decorrelates like splash. The
 * thresholds were fixed on AquaScan sonar4 and the simulator (docs/activity.md); the
 * window stays put while the track stays within SONAR_ACT_REANCHOR_M of it, and the look after it
 * moves has no correlation (the two windows would hold different water).
 *
 * Only a fixed sonar keeps windows (tracks in the body frame): from a moving vehicle the same
 * window holds other water each look, and tracks are moving or unknown.
 */

#define SONAR_ACT_ROWS 16          /* gradians of the window: -7 .. +8 about the track's bearing */
#define SONAR_ACT_COLS 16          /* range samples of each beam's part of the window */
#define SONAR_ACT_HALF_M 0.5f      /* the window's half-depth in range, metres */
#define SONAR_ACT_CORR_MIN 0.40f   /* below it a still track struggles: the middle of sonar4's gap (its standers 0.48 and up, its struggler 0.31 and down) */
#define SONAR_ACT_MOVE_M 1.0f      /* path over its last two looks beyond which a track moves, metres */
#define SONAR_ACT_REANCHOR_M 0.25f /* a track this far from its window's centre gets a new window */
SONAR_STATIC_ASSERT(SONAR_ACT_ROWS <= 16 && SONAR_ACT_ROWS * SONAR_ACT_COLS * 255u * 255u <= 0xffffffffu, act_sums_fit_u32);
#define SONAR_ACT_PAIR_GRAD 2       /* a beam pairs with the last look's nearest one this many gradians away at most */
#define SONAR_ACT_MIN_ROWS 3       /* beams each window needs for a correlation */
#define SONAR_ACT_MIN_LOOKS 1      /* correlations a still track needs before standing or struggling is said */
#define SONAR_ACT_STILL_ALARM_MAX 86400.0f /* still_alarm_s: 0 (off) or 1 .. one day */

enum sonar_activity_kind {
    SONAR_ACT_UNKNOWN = 0,   /* too few looks yet, no window (a moving sonar, slots full, out of the sweep) */
    SONAR_ACT_MOVING = 1,    /* it travelled more than SONAR_ACT_MOVE_M over its last two looks */
    SONAR_ACT_STANDING = 2,  /* still, and its echo steady */
    SONAR_ACT_STRUGGLING = 3 /* still, and its echo changing look to look */
};

/* Alarm bits on a track (struct sonar_track.alarms). */
#define SONAR_ALARM_STRUGGLE 1u /* struggling in 2 of its last 3 looks */
#define SONAR_ALARM_STILL 2u    /* not moving, and still (tracker.h's still_ms) for still_alarm_s or longer */

/* Marks echo_corr on a track: no correlation yet. */
#define SONAR_ACT_NO_CORR (-128)

/* One window's samples: row r is gradian r - 7 about the centre; bit r of rows: row r was filled. */
struct sonar_act_patch {
    uint8_t v[SONAR_ACT_ROWS][SONAR_ACT_COLS];
    uint16_t rows;
};

/* One track's windows and history. */
struct sonar_act_slot {
    uint32_t id;          /* the track's ID; 0: unused */
    uint16_t centre_a;    /* the window's centre, beam gradians (0 .. 399) */
    uint8_t have_prev;    /* w[cur ^ 1] holds the last look's window at this centre */
    uint8_t looks;        /* looks the slot has had (saturating) */
    float centre_r;       /* the window's centre range, metres ... */
    float centre_x, centre_y; /* ... and where that is in the body frame, metres */
    uint16_t idx[SONAR_ACT_COLS]; /* the window's samples in a beam of the bank's n and range ... */
    uint8_t idx_state;    /* ... 0: not yet worked out, 1: idx holds them, 2: the window passes the range's end or start */
    float x[3], y[3];     /* the track's position at its last three looks (x[0] the latest), body frame, m */
    float corr[3];        /* the last three correlations (corr[0] the latest) ... */
    uint8_t ncorr;        /* ... of which this many are known */
    uint8_t struggled;    /* bit k: struggling k looks ago */
    uint8_t said;         /* the alarms last reported in an event */
    uint8_t hit;          /* the track had a detection at the last look */
    uint8_t cur;          /* w[cur] fills this look, w[cur ^ 1] holds the last (a swap, not a copy) */
    struct sonar_act_patch w[2];
};

/* An alarm raised or cleared at the last look (a track gone clears its alarms). */
struct sonar_alarm_event {
    uint32_t id;       /* the track */
    uint8_t alarms;    /* SONAR_ALARM_* now (0: all cleared) ... */
    uint8_t was;       /* ... and before */
    uint8_t gone;      /* 1: the track ended */
    float x_m, y_m;    /* where it is (was), in the tracks' frame, metres */
};

struct sonar_activity {
    struct sonar_act_slot s[SONAR_ACT_SLOTS];
    struct sonar_alarm_event ev[2 * SONAR_ACT_SLOTS]; /* the last look's alarm changes (a slot can end and start) ... */
    uint8_t nev;                                      /* ... this many */
    uint8_t cover[SONAR_GRAD_TURN / 8]; /* the gradians some window spans (frame.h's map): other beams cost a bit test */
    uint16_t n;        /* samples a beam of the windows being filled (0: none yet) ... */
    int16_t gain;      /* ... their gain (-1: unknown) ... */
    float range_m;     /* ... and range, metres: a change restarts every window */
    uint32_t unplaced; /* track-looks that found every slot taken (their activity unknown), since init */
};

/* Empties every slot. a: caller's. Returns SONAR_OK or SONAR_ERR_ARG (NULL). */
SONAR_CHECK int sonar_activity_init(struct sonar_activity *a);

/*
 * Fills the open windows from one raw beam (before any filter): samples[0 .. n) over range_m
 * metres at beam gradian angle (0 .. 399), at gain (-1: unknown). A change of n, range or gain
 * from the windows' first beam restarts them all (the looks before no longer compare). O(slots).
 */
void sonar_activity_beam(struct sonar_activity *a, uint16_t angle, const uint8_t *samples, uint16_t n,
                         float range_m, int gain);

/*
 * Ends a look after tk's update: for each track in tk (body frame; angle_offset_grad the beams'
 * offset, as the detector's), correlates its windows, sets its activity, echo_corr (x100, or
 * SONAR_ACT_NO_CORR) and alarms (still_alarm_s 0: no still alarm; utime the sweep's end, us), and
 * places the next look's windows. Slots of tracks gone are freed. world: the tracks are in the
 * world frame (a moving sonar): no windows, moving or unknown only.
 */
void sonar_activity_look(struct sonar_activity *a, struct sonar_tracker *tk, int64_t utime, float angle_offset_grad,
                         float still_alarm_s, int world);

/* The alarm changes of the last sonar_activity_look: *n of them (a: NULL gives none). */
const struct sonar_alarm_event *sonar_activity_events(const struct sonar_activity *a, unsigned *n);

/* The activity's name ("unknown", "moving", "standing", "struggling"); "?" out of range. */
const char *sonar_activity_str(uint8_t activity);

#endif
