/* survey.h -- the empty site recorded once (each cell's level and spread over N sweeps, its structure) and judged against while it fits; RAM: sizeof(struct sonar_survey_rec) = 3 362 648 B to record (host), sizeof(struct sonar_survey) = 2 992 B and a spread block, sizeof(struct sonar_survey_spread) = 480 000 B, to use. */
#ifndef SONAR_SURVEY_H
#define SONAR_SURVEY_H

#include <stddef.h>
#include <stdint.h>

#include "sonar/background.h"
#include "sonar/bgfile.h"
#include "sonar/config.h"
#include "sonar/detector.h"
#include "sonar/err.h"
#include "sonar/tracker.h"

/*
 * Things present and motionless from the first ping cannot be told from the site's own structure by
 * their echoes, so a fixed installation records its empty site once: the survey. Each cell's level
 * (the mean of its looks) and spread (their standard deviation: a bobbing float or a ladder's
 * changing echo varies, still water and walls by their speckle) are learnt over the survey's
 * sweeps, after the same median as the running beams. In use, a surveyed cell is foreground only
 * where the echo stands out against its own spread:
 *
 *     x > T = L + max(L * margin / 16, SONAR_SURVEY_SPREADS16 * S / 16)   ->   fg = x - L,  else 0
 *
 * (L level, S spread; without a spread block, the margin alone). S is the cells' standard deviation, or
 * more where a look stood out further (a heavy-tailed echo: spiky far water, a float): never less than
 * what puts every look the survey saw under the gate, so the survey replayed against itself has no
 * foreground at all. The survey is never learnt into,
 * so nothing present at the start and nothing that stands still later is taken for the site: what
 * the survey holds is never an object, and what it does not hold always is. The foreground is the
 * echo above the level, not above the gate, so a faint body far out keeps its contrast for the
 * CFAR after it.
 *
 * Recording refuses, naming why: a track that moved more than SONAR_SURVEY_MOVED_M (someone was in
 * the water: over a track's last SONAR_SURVEY_PATH hits it went more than that, and in a line), a change of samples, range or gain, and (sonar_survey_rec_check) angles of the sector
 * not looked at SONAR_SURVEY_MIN_LOOKS times.
 *
 * In use, every beam is checked against the survey's geometry and gain, and every sweep against
 * its structure (the strongest echo of each surveyed angle that holds some, beyond the ring-down):
 * a survey that no longer fits (another range, samples or gain; the mount turned, with the turn
 * estimated; the sonar moved, or the site changed) is said within a few sweeps and given up, and
 * the background learns afresh: sonard never blinds itself with a survey of somewhere else.
 */
#define SONAR_SURVEY_MIN_LOOKS 8      /* looks at each cell before its level and spread are known */
#define SONAR_SURVEY_REC_LOOKS 4      /* looks after which a recording judges a row against what it holds so far */
#define SONAR_SURVEY_MAX_LOOKS 255    /* looks a cell's sums hold (uint16 of 255 levels) */
#define SONAR_SURVEY_SPREADS16 48     /* the gate: 3 spreads above the level (16ths of a spread) */
#ifndef SONAR_SURVEY_MOVED_M
#define SONAR_SURVEY_MOVED_M 0.5f     /* a track that moved this far over its last hits, on a straight path: someone in the water */
#endif
#define SONAR_SURVEY_PATH 4           /* ... its last hits (within SONAR_SURVEY_PATH + 2 sweeps) ... */
#define SONAR_SURVEY_STRAIGHT 0.7f    /* ... the distance at least this part of the path's length (clutter a track
                                         joins zigzags; a swimmer, a drifting float or a walker goes somewhere); or
                                         the mean of its last hits this far from the mean of its first (a slow drift) */
#define SONAR_SURVEY_FILL 2           /* gradians: an angle the survey did not look at takes one it did this close */
#define SONAR_SURVEY_NEAR_M 0.5f      /* the ring-down: no structure is looked for nearer */
#define SONAR_SURVEY_SIG_LEVEL 48     /* an angle holds structure when its strongest level is at least this ... */
#define SONAR_SURVEY_SIG_TIMES 4      /* ... and this many times its median level beyond the ring-down */
#define SONAR_SURVEY_SIG_M 0.06f      /* a look agrees when its strongest echo is this close to the survey's, metres (at least 2 samples) */
#define SONAR_SURVEY_MIN_SIG 16       /* angles with structure a sweep needs before it can say the survey fits or not ... */
#define SONAR_SURVEY_MIN_VIEW 4       /* ... of them in view, when the rest are hidden behind people */
#define SONAR_SURVEY_OCCLUDE_M 0.5f   /* an echo standing out this much nearer than the structure hides it (not counted) */
#define SONAR_SURVEY_PERSON_M 2.0f    /* ... unless what hides it is wider than this end to end (no person, nor two side by
                                         side, with the beam's spread): then the site in front of the structure changed */
#define SONAR_SURVEY_AGREE16 8        /* a sweep fits when this many 16ths of those angles agree ... */
#define SONAR_SURVEY_STANDOUT1000 250 /* ... and no more than this many thousandths of its cells stand out (a crowd is a tenth) */
#define SONAR_SURVEY_UNFIT_SWEEPS 2   /* sweeps in a row that do not fit before the survey is given up */
#define SONAR_SURVEY_NEW_SWEEPS 2     /* ... or of the last 3 with structure it does not hold (no person makes a line) */
#define SONAR_SURVEY_REFIT_SWEEPS 3   /* sweeps in a row that fit again before it may be taken back */
#define SONAR_SURVEY_MAX_TURN 100     /* gradians either way a turned mount is looked for */

/* Why a recording was refused, or why a survey in use no longer fits. */
enum sonar_survey_why {
    SONAR_SURVEY_OK = 0,
    SONAR_SURVEY_MOVED = 1,    /* recording: a track moved more than SONAR_SURVEY_MOVED_M */
    SONAR_SURVEY_GEOMETRY = 2, /* the samples or the range are not the survey's */
    SONAR_SURVEY_GAIN = 3,     /* the gain is not the survey's */
    SONAR_SURVEY_ANGLES = 4,   /* recording: angles of the sector not looked at, or too few times */
    SONAR_SURVEY_TURNED = 5,   /* in use: the structure is where the survey has it, turned (turn_grad) */
    SONAR_SURVEY_CHANGED = 6,  /* in use: the structure is not where the survey has it (moved, the site changed) */
    SONAR_SURVEY_STANDOUT = 7, /* in use: too much of the sweep stands out against it */
    SONAR_SURVEY_WORLD = 8,    /* a moving sonar (poses): a survey is of a fixed site */
    SONAR_SURVEY_RESTART = 9,  /* in use: the background restarted (a reload's new filter or mode) */
    SONAR_SURVEY_NEW = 10      /* in use: structure it does not hold stands out (lines wider than any object) */
};

/* "moved", "geometry", ... (enum sonar_survey_why), or "?". */
const char *sonar_survey_why_str(int why);

/* ---- Recording: the host's (it holds every look's sums). ---- */

struct sonar_survey_rec {
    uint16_t sum[SONAR_MAX_ANGLES][SONAR_MAX_SAMPLES]; /* each cell's looks summed */
    uint32_t sq[SONAR_MAX_ANGLES][SONAR_MAX_SAMPLES];  /* ... and their squares */
    uint8_t top[SONAR_MAX_ANGLES][SONAR_MAX_SAMPLES];  /* ... and the largest */
    uint8_t looks[SONAR_MAX_ANGLES];                   /* looks at each angle's row (saturating) */
    uint16_t n;                                        /* samples a beam, 0 before the first */
    float range_m;
    int16_t gain;                                      /* of the first beam, -1 unknown */
    int64_t first_utime, last_utime;                   /* us since the epoch */
    uint32_t beams, sweeps;
    uint32_t judged, sweep_beams;                      /* this sweep's beams judged against the sums, and all its beams */
    uint8_t why;                                       /* enum sonar_survey_why: SONAR_SURVEY_OK while it may be kept */
    uint32_t moved_id;                                 /* SONAR_SURVEY_MOVED: the track, how far, and where it was then */
    float moved_m, moved_x, moved_y;
    struct sonar_survey_path {
        uint32_t id;                                   /* a live track's, 0: free */
        uint8_t n;                                     /* hits kept in x, y (the last SONAR_SURVEY_PATH) */
        uint32_t sweep[SONAR_SURVEY_PATH];             /* the sweep of each hit, oldest first */
        float x[SONAR_SURVEY_PATH], y[SONAR_SURVEY_PATH]; /* where it was, the tracker's frame */
        uint16_t hits;                                 /* hits since its first kept one ... */
        float x0, y0;                                  /* ... and their first SONAR_SURVEY_PATH's mean (a drift from it) */
    } path[SONAR_MAX_TRACKS];
};

/* Empties rec for a new recording. */
void sonar_survey_rec_init(struct sonar_survey_rec *rec);

/*
 * One beam after the pipeline's median (angle gradians 0..399, n 1..SONAR_MAX_SAMPLES samples over
 * range_m metres, gain 0..2 or -1): its samples join each cell's sums. A beam of other samples,
 * range or gain than the first refuses the recording (SONAR_SURVEY_GEOMETRY, SONAR_SURVEY_GAIN).
 * Returns SONAR_OK, SONAR_ERR_STATE (refused, now or before: rec->why says why) or SONAR_ERR_ARG.
 */
SONAR_CHECK int sonar_survey_rec_beam(struct sonar_survey_rec *rec, uint16_t angle, const uint8_t *samples, uint16_t n,
                                      float range_m, int16_t gain, int64_t utime);

/*
 * The beam judged against what the recording holds so far, before it joins it (sonar_survey_rec_beam
 * after): once its row has SONAR_SURVEY_REC_LOOKS looks, fg[i] = in[i] - mean where in[i] stands out
 * over the mean by 3 standard deviations and margin / 16 of the mean, else 0 (in and fg may be the same
 * buffer), so that what moves through the site stands out while it is recorded and is tracked.
 * Returns 1 when done, 0 when the row has too few looks yet (the caller's background judges it).
 */
int sonar_survey_rec_apply(struct sonar_survey_rec *rec, uint16_t angle, const uint8_t *in, uint8_t *fg, uint16_t n,
                           uint8_t margin);

/*
 * A sweep's end with its tracks (tk, or NULL when not tracking): a confirmed track whose last
 * SONAR_SURVEY_PATH hits, within SONAR_SURVEY_PATH + 2 sweeps of which at least half the beams were
 * judged against the sums (sonar_survey_rec_apply), went more than SONAR_SURVEY_MOVED_M and at least
 * SONAR_SURVEY_STRAIGHT of their path's length refuses the recording
 * (SONAR_SURVEY_MOVED, the track, distance and place in rec). world: the sweep was in the world
 * frame (a moving sonar): refused (SONAR_SURVEY_WORLD). Returns as sonar_survey_rec_beam.
 */
SONAR_CHECK int sonar_survey_rec_sweep(struct sonar_survey_rec *rec, const struct sonar_tracker *tk, int world);

/*
 * Whether every angle of the sector was looked at often enough: the angles from `from` to `to`
 * (gradians, inclusive, going up and wrapping; from == to + 1 mod 400 or from == to: the full turn)
 * every `step` gradians (1..200), each row at least SONAR_SURVEY_MIN_LOOKS times. step 0: the
 * angles the recording looked at at all. Returns SONAR_OK, or SONAR_ERR_STATE with rec->why
 * SONAR_SURVEY_ANGLES and *row_out the first angle short of looks (*looks_out its looks).
 */
SONAR_CHECK int sonar_survey_rec_check(struct sonar_survey_rec *rec, uint16_t from, uint16_t to, uint16_t step,
                                       uint16_t *angle_out, uint8_t *looks_out);

/*
 * The survey as a bgfile.h image into out (cap bytes): the levels, the spread, the looks, the level
 * across the angles, and its structure: the places where the levels stand out from that level
 * (walls, ladders), found by a detector of config dc in det (caller's scratch, 26 KB) over the
 * levels and reported in places (up to SONAR_MAX_CLUSTERS, *nplaces; may be NULL). m: the header's
 * filters, mode, sound speed and angle offset of the frame (dc->angle_offset); n, range, gain,
 * sweeps and time come from rec. The level and spread are written in place of the sums' first
 * rows (rec cannot be added to afterwards). Returns the image's length, or SONAR_ERR_STATE (refused
 * or nothing looked at), SONAR_ERR_SPACE, SONAR_ERR_ARG.
 */
SONAR_CHECK int32_t sonar_survey_rec_image(struct sonar_survey_rec *rec, const struct sonar_bgfile_meta *m,
                                           const struct sonar_detector_config *dc, struct sonar_detector *det,
                                           struct sonar_detection *places, uint8_t *nplaces, uint8_t *out, size_t cap);

/* ---- Use: the pipeline's (sonar_pipeline_set_survey). ---- */

enum sonar_survey_state {
    SONAR_SURVEY_NONE = 0,  /* no survey */
    SONAR_SURVEY_IN_USE = 1, /* the beams are judged against it */
    SONAR_SURVEY_UNFIT = 2   /* it no longer fits (why): the background learns; it is checked on */
};

/* Where a spread is held: one byte a cell, the caller's (a co-processor may hold none). In use it holds each
   cell's gate over its level instead (the larger of SONAR_SURVEY_SPREADS16 spreads and the margin's share, at most
   255), made once at load, so that a beam's pass is a subtraction and a compare a cell. */
struct sonar_survey_spread {
    uint8_t s[SONAR_MAX_ANGLES][SONAR_MAX_SAMPLES];
};

struct sonar_survey {
    struct sonar_bgfile_meta meta;           /* the survey's: what it is of, when, and over how many sweeps */
    struct sonar_survey_spread *spread;      /* the caller's, or NULL: the level and the margin alone */
    uint8_t state;                           /* enum sonar_survey_state */
    uint8_t why;                             /* enum sonar_survey_why, while unfit */
    uint8_t has_spread;                      /* the spread block holds the survey's */
    uint8_t fixed;                           /* 1: a survey (SONAR_BGFILE_SURVEY): judged against, never learnt into;
                                                0: a learnt model the background learns on from (only its fit is checked) */
    int16_t turn_grad;                       /* SONAR_SURVEY_TURNED: the estimated turn, gradians (+: the head's 0 turned clockwise) */
    uint16_t src[SONAR_MAX_ANGLES];          /* per row: the surveyed row it is judged with (SONAR_SURVEY_FILL), 0xFFFF none */
    uint16_t sig[SONAR_MAX_ANGLES];          /* per row: the sample of its strongest structure, 0xFFFF none ... */
    uint8_t sig_level[SONAR_MAX_ANGLES];     /* ... and its level */
    uint16_t obs[SONAR_MAX_ANGLES];          /* this sweep's strongest echo per row looked at, 0xFFFF none */
    uint8_t looked[SONAR_MAX_ANGLES / 8 + 1]; /* rows looked at this sweep */
    uint16_t checked, agreed;                /* this sweep: rows with structure looked at, and those that agree ... */
    uint16_t occluded;                       /* ... and those hidden behind something nearer (not counted: unless it is
                                                wider than a person: then the site in front of the structure changed) */
    uint8_t hid[SONAR_MAX_ANGLES / 8 + 1];   /* rows hidden this sweep */
    uint32_t cells, standout;                /* this sweep: surveyed cells compared, and those that stood out */
    uint8_t bad_run, good_run;               /* sweeps in a row that did not fit / fit (while unfit) */
    uint8_t lines;                           /* bit k: the sweep k sweeps ago had structure the survey does not hold */
    uint8_t refit;                           /* 1: it fits again: the caller may take it back (sonar_pipeline_load_background) */
    uint32_t unfits;                         /* times it was given up */
    uint32_t sweeps_in_use;                  /* sweeps judged against it */
    uint8_t agree16, standout1000;           /* the last sweep's agreement (16ths) and stand-out (thousandths) */
    uint16_t near;                           /* samples of the ring-down (SONAR_SURVEY_NEAR_M) at the survey's range */
    uint8_t nplaces;                         /* its structure ... */
    struct sonar_detection *places;          /* ... the caller's (up to SONAR_MAX_CLUSTERS), or NULL */
};

/*
 * Sets sv up with no survey, spread the caller's block (NULL: none: the level and the margin alone)
 * and places the caller's array of SONAR_MAX_CLUSTERS detections for its structure (NULL: not kept).
 */
void sonar_survey_init(struct sonar_survey *sv, struct sonar_survey_spread *spread, struct sonar_detection *places);

/*
 * Takes a checked bgfile.h image (sonar_bgfile_check): its levels into bg (whose mode must be
 * per-angle or auto), its spread into sv's block (when both have one), its structure; sv is then in
 * use. A survey (SONAR_BGFILE_SURVEY) is fixed: the angles it knows are judged against it; a learnt
 * model (--background-save's) is where the background learns on from, its setting and structure
 * checked as a survey's. Returns SONAR_OK, or < 0 with *why naming what is wrong (bg and sv
 * unchanged).
 */
SONAR_CHECK int sonar_survey_use(struct sonar_survey *sv, struct sonar_background *bg, const uint8_t *img, size_t len,
                                 const char **why);

/*
 * The background restarted, or the sonar moved into the world frame: the levels in the background
 * are gone; the survey is unfit for `why` and is checked on (SONAR_SURVEY_MIN_SIG rows agreeing for
 * SONAR_SURVEY_REFIT_SWEEPS sweeps, or the geometry and gain its own again, set refit).
 */
void sonar_survey_lost(struct sonar_survey *sv, int why);

/*
 * Whether a beam of n samples over range_m at gain (-1 unknown) is of the survey's geometry and
 * gain: SONAR_SURVEY_OK, or SONAR_SURVEY_GEOMETRY / SONAR_SURVEY_GAIN while in use (the caller gives
 * it up: sonar_survey_lost, and restarts the background, whose levels are of another setting).
 * While unfit for either, a beam of the survey's own setting sets refit.
 */
int sonar_survey_fits_beam(struct sonar_survey *sv, uint16_t n, float range_m, int16_t gain);

/*
 * One beam after the median, before its comparison (in use or unfit; bg holds the survey's levels
 * while it is in use): its strongest echo beyond the ring-down is kept for the sweep's check, and
 * where the survey has structure at its angle, whether it agrees (its strongest echo there, or the
 * survey's still echoing behind something brighter). A beam whose strongest echo is nearer and
 * stands out against the survey there is occluded (a person in front of the wall) and not counted.
 */
void sonar_survey_look(struct sonar_survey *sv, const struct sonar_background *bg, uint16_t angle, const uint8_t *in,
                       uint16_t n);

/*
 * The beam compared with the survey: fg as above from bg's surveyed row (in and fg may be the same
 * buffer), with the background's margin. Returns 1 when done, 0 when the survey is not in use or
 * does not cover the angle (the caller runs the background instead).
 */
int sonar_survey_apply(struct sonar_survey *sv, const struct sonar_background *bg, uint16_t angle, const uint8_t *in,
                       uint8_t *fg, uint16_t n);

/*
 * The sweep's end, with the detections of kind structure it made (lines wider than any object, which
 * a survey in use should hold): whether the survey fits (in use) or fits again (unfit). Returns 1
 * when it has just stopped fitting (sv->why, and turn_grad for a turn; sv is then unfit: the caller
 * restarts the background and learns), else 0. Sets refit when an unfit survey fits again.
 */
int sonar_survey_sweep(struct sonar_survey *sv, unsigned structures);

/* Whether angle's row is judged against the survey now (a fixed survey, in use and covering it). */
int sonar_survey_covers(const struct sonar_survey *sv, uint16_t angle);

#endif
