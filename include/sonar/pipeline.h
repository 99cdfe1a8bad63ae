/* pipeline.h -- beam-by-beam pipeline: median -> background -> detector, sweeps cut from the angle sequence; RAM: struct sonar_pipeline, the detector's runs and two beams, plus the caller's struct sonar_background (docs/sizes.md). */
#ifndef SONAR_PIPELINE_H
#define SONAR_PIPELINE_H

#include <stdint.h>

#include <stddef.h>

#include "sonar/activity.h"
#include "sonar/background.h"
#include "sonar/clutter.h"
#include "sonar/config.h"
#include "sonar/detector.h"
#include "sonar/err.h"
#include "sonar/median.h"
#include "sonar/scan.h"
#include "sonar/streak.h"
#include "sonar/structure.h"
#include "sonar/survey.h"
#include "sonar/sweep.h"
#include "sonar/tracker.h"

/* One beam as it arrives; samples belong to the caller and are read during the call only. */
struct sonar_beam {
    int64_t utime;  /* us since the epoch */
    uint16_t angle; /* gradians, 0..399 */
    uint16_t n;     /* samples, 1..SONAR_MAX_SAMPLES */
    float range_m;  /* metres covered by the n samples (see geometry.h) */
    const uint8_t *samples;
    int16_t gain;   /* the sonar's gain setting (0 low, 1 normal, 2 high), or -1 unknown: a change restarts the background */
};

enum sonar_stage {
    SONAR_STAGE_RAW = 0,       /* as received */
    SONAR_STAGE_MEDIAN = 1,    /* after the median */
    SONAR_STAGE_FOREGROUND = 2 /* after background subtraction (clamped at 0) */
};

struct sonar_pipeline_config {
    uint8_t median;   /* 1-D window along range: 1 (off) or odd 3..SONAR_MAX_MEDIAN */
    uint8_t median2d; /* 0, or K = 3 / 5 for K x K over adjacent beams (then median is ignored) */
    uint16_t max_step; /* gradians; a larger angle move starts a new sweep (1..200) */
    float sweep_gap_s; /* a beam this long after the one before starts a new sweep, seconds (0.1..3600); 0: never */
    struct sonar_background_config background;
    struct sonar_detector_config detector;
    float structure_s; /* an echo there from the first look that stands this long is structure, learnt into
                          the background and reported as such (structure.h), seconds; 0: never */
    uint8_t track; /* 1: track detections across sweeps (tracker below), 0: off */
    float still_alarm_s; /* a track not moving and still this long raises a still alarm (activity.h), seconds
                            (1..86400); 0: never */
    struct sonar_tracker_config tracker;
    /* Optional callbacks (NULL to skip), called from inside push/finish. on_sweep comes after the
       tracker has taken the sweep, so p->trk holds this sweep's tracks then. */
    void (*on_beam)(void *user, int stage, const struct sonar_beam *beam);
    void (*on_sweep)(void *user, const struct sonar_detections *d);
    void *user;
};

#define SONAR_PIPE_MAX_STEP_MAX 200 /* max_step 1..200 gradians */
#define SONAR_PIPE_DUP_M 1.0f      /* world frame: one object seen twice in a sweep is within this, metres ... */
#define SONAR_PIPE_DUP_US 1000000   /* ... and more than this apart in time, us */
#define SONAR_PIPE_NEAR_M 0.5f /* world grid: the ring-down moves with the sonar, so it is not modelled there */
#define SONAR_PIPE_MAX_RANGE_M 1000 /* a beam's range_m must be in (0, 1000] metres: the detector's mm arithmetic */
/*
 * The CFAR window spreads over a neighbouring beam only this close, gradians: an echo covers about
 * 10 degrees between half-brightness points (AquaScan's people, docs/results.md section 7), so three
 * beams 3 gradians apart lie within it; with wider steps a small object's echo can fill one beam, and
 * spread over three it would be diluted away.
 */
#define SONAR_PIPE_ACROSS_GAP 3
/*
 * ... and this close for a beam judged against a survey (survey.h): its foreground is then only what
 * stands out against each cell's own spread, at its full contrast, so spread over a neighbour 4
 * gradians away an echo is still there, while the far water's one-beam spikes, which one look at 4
 * gradians cannot tell from a small echo, are diluted (a full-circle pool at 4 gradians: precision
 * 0.62 -> 0.92 at the same recall, docs/decisions.md).
 */
#define SONAR_PIPE_ACROSS_GAP_SURVEY 4
#define SONAR_PIPE_KEEP_MIN_M 0.3f /* auto background: the least radius about a track the per-angle model never learns, metres */
#define SONAR_PIPE_LEARN_MAX 16     /* structure places a beam learns at once, at most (spans on the stack: 4 B each) */

struct sonar_pipeline {
    const struct sonar_pipeline_config *cfg;
    const struct sonar_pipeline_config *next; /* pending sonar_pipeline_reconfigure, or NULL */
    struct sonar_sweep sweep;
    struct sonar_median2d m2d;
    struct sonar_background *bg; /* the caller's (sonar_pipeline_init): the one large block, placed where it fits */
    struct sonar_detector det;
    struct sonar_tracker trk; /* used when cfg->track */
    struct sonar_structure st; /* the places structure is learnt from (body frame, per-angle and auto modes) */
    struct sonar_survey *sv;   /* the caller's (sonar_pipeline_set_survey), or NULL: no survey can be used */
    struct sonar_activity *act; /* the caller's (sonar_pipeline_set_activity), or NULL: every track's activity unknown */
    struct sonar_clutter *clutter; /* the caller's (sonar_pipeline_set_clutter), or NULL: no clutter learnt, the floor everywhere */
    struct sonar_survey_rec *rec; /* a survey being recorded (sonar_pipeline_set_recording), or NULL */
    uint32_t survey_unfit_sweep; /* the sweep at whose end the survey was last given up */
    uint32_t bg_sweeps;        /* sweeps since the background (re)started or was loaded */
    struct sonar_detections out;
    /*
     * Beam buffers: the median writes buf[cur] and the background works on it in place. With the
     * CFAR window across beams (detector.cfar.across) the detector takes each beam one beam late,
     * when its next neighbour is known: the waiting beam stays in buf[cur ^ 1].
     */
    uint8_t buf[2][SONAR_MAX_SAMPLES];
    uint8_t cur;
    uint8_t waiting;                           /* a beam waits in buf[cur ^ 1] for its next neighbour */
    uint8_t wait_alone;                        /* its row was seeding: its window stays on it alone */
    uint8_t wait_gap;                          /* the widest gap to a neighbour its window spreads over, gradians */
    uint8_t have_before;                       /* before holds the block sums of the beam before it */
    uint16_t wait_angle;                       /* the waiting beam's angle (gradians) ... */
    int64_t wait_utime;                        /* ... and time */
    uint16_t wait_edge;                        /* ... and leading edge and strongest level (sonar_detector_set_edge) */
    uint8_t wait_top;
    uint16_t before_angle;                     /* the beam before the waiting one: its angle ... */
    uint16_t before[SONAR_CFAR_MAX_BLOCKS];    /* ... and block sums (cfar.h) */
    uint16_t wait_sums[SONAR_CFAR_MAX_BLOCKS]; /* the waiting beam's block sums */
    float range_m;     /* of the open sweep */
    uint16_t n;        /* of the open sweep */
    uint8_t open;      /* a sweep holds beams */
    uint32_t beams;    /* beams pushed in all */
    uint32_t sweeps;   /* sweeps ended */
    const struct sonar_pose_ring *poses; /* the vehicle's, or NULL (sonar_pipeline_set_poses) */
    struct sonar_pose last_pose;         /* of the last sweep in the world frame */
    uint32_t world_sweeps, body_sweeps;  /* sweeps tracked in each frame */
    uint32_t world_beams;                /* beams whose background was the world grid */
    uint32_t repeats;                    /* detections dropped as an object seen twice in a sweep */
    uint32_t geometry_changes;           /* the range or the samples a beam changed: the open sweep
                                            was cut and the background relearns from the next beam */
    uint32_t gap_cuts;                   /* sweeps cut by a gap in time (cfg sweep_gap_s) */
    uint32_t gain_restarts;              /* backgrounds restarted because the beams' gain changed */
    uint32_t blank_beams;                /* beams skipped for every sample 0 or every one 255 (sonar_pipeline_push) */
    struct sonar_streak streak;          /* interference streaks (streak.h) */
    int16_t last_gain;                   /* the gain of the beam before, -1 none known yet */
    int64_t last_utime;                  /* the last beam's time, us */
    float prev_bearing;                  /* world heading of the last such beam, degrees */
    float prev_width;                    /* the footprint it had, degrees */
    uint8_t have_prev_bearing;
};

/*
 * Checks every field, the background's and the detector's included. Returns NULL when cfg is
 * valid, else a static string naming the first bad field and its rule ("detector.join_beams: 1..8").
 */
const char *sonar_pipeline_config_check(const struct sonar_pipeline_config *cfg);

/*
 * Validates cfg (kept by pointer: it must outlive p) and sets p up with bg as its background
 * (caller-allocated, kept by pointer, at least as long-lived as p; struct sonar_background is most
 * of the pipeline's RAM, so a board can place it in its own memory bank). Returns SONAR_OK or
 * SONAR_ERR_ARG (a NULL, or cfg invalid).
 */
SONAR_CHECK int sonar_pipeline_init(struct sonar_pipeline *p, struct sonar_background *bg,
                                    const struct sonar_pipeline_config *cfg);

/* Fills cfg with sonard's defaults (median 5, auto background, CFAR; see docs/architecture.md). */
void sonar_pipeline_defaults(struct sonar_pipeline_config *cfg);

/*
 * The detector's rules that go with the range background (the study's median across scans) when
 * nothing else is asked for: the study's mean + k std threshold, 20 cells, no width or aspect
 * limit, sonard's defaults before the CFAR; so the study's configuration replays as it always has.
 * Sets d's threshold_mode, min_points, max_extent_m, max_aspect, min_area_m2 and min_footprints (0: the study
 * has no such rules).
 */
void sonar_pipeline_study_rules(struct sonar_detector_config *d);

/*
 * Processes one beam. When the beam starts a new sweep (wrap, reversal, jump, or a change of n
 * or range, which also resets the background), the previous sweep is finished first and
 * on_sweep is called with its detections. Returns SONAR_OK or SONAR_ERR_ARG (bad beam: n outside
 * 1..SONAR_MAX_SAMPLES, angle > 399, range_m outside (0, SONAR_PIPE_MAX_RANGE_M] or NaN; nothing
 * changed).
 */
SONAR_CHECK int sonar_pipeline_push(struct sonar_pipeline *p, const struct sonar_beam *b);

/*
 * Where the pipeline keeps its tracks' activity windows (activity.h: the caller's, initialised; NULL:
 * none, every track's activity unknown). Call between sweeps.
 */
void sonar_pipeline_set_activity(struct sonar_pipeline *p, struct sonar_activity *act);

/*
 * Where the pipeline keeps the site's clutter map (clutter.h: the caller's, initialised or loaded;
 * NULL: none, every track judged against the floor density). The tracker reads it and teaches it,
 * and each sweep with its beams' cover takes its look. Kept across sonar_pipeline_init only by
 * setting it again. Call between sweeps.
 */
void sonar_pipeline_set_clutter(struct sonar_pipeline *p, struct sonar_clutter *clutter);

/*
 * Where the pipeline keeps a site's survey (survey.h: the caller's, with its spread block; NULL:
 * none can be used, and a recorded model is learnt on from instead). Call before loading one.
 */
void sonar_pipeline_set_survey(struct sonar_pipeline *p, struct sonar_survey *sv);

/*
 * Records the site's survey into rec (the caller's, sonar_survey_rec_init'd; NULL stops): every beam
 * after the median joins it, judged first against what it holds so far (sonar_survey_rec_apply: rows
 * with too few looks by the background), and every sweep's tracks are checked for something that
 * moves (sonar_survey_rec_sweep). A refusal is rec's (rec->why); the pipeline runs on.
 */
void sonar_pipeline_set_recording(struct sonar_pipeline *p, struct sonar_survey_rec *rec);

/*
 * Starts the background from a recorded one (a bgfile.h image of len bytes, checked whole), forgetting
 * the structure learnt before. With a survey set (sonar_pipeline_set_survey) it is the site's survey:
 * the angles it knows are judged against it and never learnt (survey.h), the rest learn; a survey
 * that no longer fits the beams is given up at a sweep's end and the background learns afresh.
 * Without, its levels are where the background goes on learning from, and what stands out in the
 * first sweeps after it is there from the first look, as after a restart. Returns SONAR_OK, or < 0
 * with *why naming what is wrong (why may be NULL; nothing changed).
 */
SONAR_CHECK int sonar_pipeline_load_background(struct sonar_pipeline *p, const uint8_t *img, size_t len, const char **why);

/*
 * Restarts the background at every angle (the beams' gain changed, or a recorded background did not
 * fit them) and forgets the structure learnt with it. p must be initialised.
 */
void sonar_pipeline_restart_background(struct sonar_pipeline *p);

/*
 * Schedules cfg (kept by pointer: it must outlive p) to take over when the next sweep starts,
 * right after the open sweep's on_sweep. The detector's rules, the background's step and margin
 * change in place; a new median, background mode or warm-up, or max_step, starts a fresh
 * background. With no sweep open it applies at once. Returns SONAR_OK or SONAR_ERR_ARG (invalid:
 * nothing scheduled, the running config stays).
 */
SONAR_CHECK int sonar_pipeline_reconfigure(struct sonar_pipeline *p, const struct sonar_pipeline_config *cfg);

/*
 * The output frame of the configuration running now (a reload's takes over with the next sweep):
 * *angle_offset in gradians added to every head angle, *min_range_m in metres. A sink that places
 * beams as the detections are placed reads them here for each beam, so both turn together.
 */
void sonar_pipeline_frame(const struct sonar_pipeline *p, float *angle_offset, float *min_range_m);

/*
 * Where the vehicle was (kept by pointer, read at each sweep's end; NULL: no pose, everything in
 * the body frame). With poses, each detection whose time has a pose gains its north_m, east_m;
 * a sweep in which every detection and the last beam have one is tracked in the world frame (the
 * tracks move into it, keeping their IDs, and back to the body frame at the last known pose when
 * the pose goes stale); the track_m gate follows the tracks into each beam's body frame. In
 * per-angle mode a beam with a pose is compared with and learnt into the world grid
 * (sonar_background_apply_world; inside max(min_range, SONAR_PIPE_NEAR_M) it has no foreground),
 * one without with the per-angle model; each change between the two starts the model afresh.
 */
void sonar_pipeline_set_poses(struct sonar_pipeline *p, const struct sonar_pose_ring *poses);

/*
 * Detections made elsewhere (a co-processor) through the same last steps: located with the poses
 * and tracked (when cfg->track; every track counts as in view, the beams being unknown). The result
 * is p->out, and p->trk. Returns SONAR_OK or SONAR_ERR_ARG (NULL, count too large).
 */
SONAR_CHECK int sonar_pipeline_track(struct sonar_pipeline *p, const struct sonar_detections *d);

/*
 * The scan planner's targets at utime (us since the epoch): each confirmed or coasting track
 * predicted to then, as a head angle (gradians [0, 400), the angle offset taken off) and a
 * half-width in gradians (three standard deviations of its position, and its radius, across the
 * bearing at its range; at least one). World-frame tracks are placed through the pose at utime,
 * else the one they were last reframed at. Writes at most max; returns how many (0 when not
 * tracking). O(tracks).
 */
unsigned sonar_pipeline_targets(const struct sonar_pipeline *p, int64_t utime, struct sonar_scan_target *out, unsigned max);

/* ---- What a host reads (pipeline_read.c); p must be initialised. ---- */

/* The configuration running now (a pending reload's takes over with the next sweep). */
const struct sonar_pipeline_config *sonar_pipeline_running(const struct sonar_pipeline *p);

/* The last sweep's detections (valid until the next sweep ends). */
const struct sonar_detections *sonar_pipeline_detections(const struct sonar_pipeline *p);

/* The tracker, or NULL when the running configuration does not track. */
const struct sonar_tracker *sonar_pipeline_tracker(const struct sonar_pipeline *p);

/* The vehicle's pose at utime (us) from the poses set (sonar_pipeline_set_poses): 1 with *q, else 0. */
int sonar_pipeline_pose_at(const struct sonar_pipeline *p, int64_t utime, struct sonar_pose *q);

/* The pose to bring a world-frame track last seen at utime into the body frame: the one then, else the last sweep's. */
void sonar_pipeline_track_pose(const struct sonar_pipeline *p, int64_t utime, struct sonar_pose *q);

/* The beams' geometry now: *n samples over *range_m metres (0 and 0 before the first beam). */
void sonar_pipeline_geometry(const struct sonar_pipeline *p, uint16_t *n, float *range_m);

/* The beams' gain now (0 low, 1 normal, 2 high), -1 while unknown. */
int sonar_pipeline_gain(const struct sonar_pipeline *p);

/* Backgrounds restarted because the beams' gain changed; sweeps cut because their range or samples did. */
uint32_t sonar_pipeline_gain_restarts(const struct sonar_pipeline *p);
uint32_t sonar_pipeline_geometry_changes(const struct sonar_pipeline *p);

/*
 * Beams skipped because every sample was 0 (a receiver that heard nothing: unplugged, out of the
 * water, a dead channel) or every one 255 (saturated): they carry no echo to learn or detect, and
 * would teach the background a level no water has. A count that only grows.
 */
uint32_t sonar_pipeline_blank_beams(const struct sonar_pipeline *p);

/* Beams judged interference streaks (streak.h) since the start: left out of the background and the detector. */
uint32_t sonar_pipeline_interference_beams(const struct sonar_pipeline *p);

/* The survey as it is now (state, why, turn, its meta and places), or NULL when none is set. */
const struct sonar_survey *sonar_pipeline_survey(const struct sonar_pipeline *p);

/* Places promoted to structure since the start (a count that only grows), and those that are structure now. */
uint32_t sonar_pipeline_structure_promoted(const struct sonar_pipeline *p);
unsigned sonar_pipeline_structure_count(const struct sonar_pipeline *p);

/* The learnt background as a recorded-background image (sonar_bgfile_write, with the caller's meta): its length or an error. */
struct sonar_bgfile_meta; /* bgfile.h */
SONAR_CHECK int32_t sonar_pipeline_save_background(const struct sonar_pipeline *p, const struct sonar_bgfile_meta *m,
                                                   uint8_t *out, size_t cap);

/* Ends the open sweep (end of a recording, or shutdown): flushes the 2-D median, calls on_sweep. */
SONAR_CHECK int sonar_pipeline_finish(struct sonar_pipeline *p);

#endif
