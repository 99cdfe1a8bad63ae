/* pipeline.h -- beam-by-beam pipeline: median -> background -> detector, sweeps cut from the angle sequence; RAM: sizeof(struct sonar_pipeline) ~ 515 KB at 400 x 1200. */
#ifndef SONAR_PIPELINE_H
#define SONAR_PIPELINE_H

#include <stdint.h>

#include "sonar/background.h"
#include "sonar/config.h"
#include "sonar/detector.h"
#include "sonar/err.h"
#include "sonar/median.h"
#include "sonar/sweep.h"
#include "sonar/tracker.h"

/* One beam as it arrives; samples belong to the caller and are read during the call only. */
struct sonar_beam {
    int64_t utime;  /* us since the epoch */
    uint16_t angle; /* gradians, 0..399 */
    uint16_t n;     /* samples, 1..SONAR_MAX_SAMPLES */
    float range_m;  /* metres covered by the n samples (see geometry.h) */
    const uint8_t *samples;
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
    struct sonar_background_config background;
    struct sonar_detector_config detector;
    uint8_t track; /* 1: track detections across sweeps (tracker below), 0: off */
    struct sonar_tracker_config tracker;
    /* Optional callbacks (NULL to skip), called from inside push/finish. on_sweep comes after the
       tracker has taken the sweep, so p->trk holds this sweep's tracks then. */
    void (*on_beam)(void *user, int stage, const struct sonar_beam *beam);
    void (*on_sweep)(void *user, const struct sonar_detections *d);
    void *user;
};

#define SONAR_PIPE_MAX_STEP_MAX 200 /* max_step 1..200 gradians */
#define SONAR_PIPE_MAX_RANGE_M 1000 /* a beam's range_m must be in (0, 1000] metres: the detector's mm arithmetic */

struct sonar_pipeline {
    const struct sonar_pipeline_config *cfg;
    const struct sonar_pipeline_config *next; /* pending sonar_pipeline_reconfigure, or NULL */
    struct sonar_sweep sweep;
    struct sonar_median2d m2d;
    struct sonar_background bg;
    struct sonar_detector det;
    struct sonar_tracker trk; /* used when cfg->track */
    struct sonar_detections out;
    uint8_t filt[SONAR_MAX_SAMPLES];
    uint8_t fg[SONAR_MAX_SAMPLES];
    float range_m;     /* of the open sweep */
    uint16_t n;        /* of the open sweep */
    uint8_t open;      /* a sweep holds beams */
    uint32_t beams;    /* beams pushed in all */
    uint32_t sweeps;   /* sweeps ended */
};

/*
 * Checks every field, the background's and the detector's included. Returns NULL when cfg is
 * valid, else a static string naming the first bad field and its rule ("detector.link_beams: 1..8").
 */
const char *sonar_pipeline_config_check(const struct sonar_pipeline_config *cfg);

/* Validates cfg (kept by pointer: it must outlive p). Returns SONAR_OK or SONAR_ERR_ARG. */
SONAR_CHECK int sonar_pipeline_init(struct sonar_pipeline *p, const struct sonar_pipeline_config *cfg);

/* Fills cfg with sonard's defaults (median 5, per-angle background, k = 3, see docs/architecture.md). */
void sonar_pipeline_defaults(struct sonar_pipeline_config *cfg);

/*
 * Processes one beam. When the beam starts a new sweep (wrap, reversal, jump, or a change of n
 * or range, which also resets the background), the previous sweep is finished first and
 * on_sweep is called with its detections. Returns SONAR_OK or SONAR_ERR_ARG (bad beam: n outside
 * 1..SONAR_MAX_SAMPLES, angle > 399, range_m outside (0, SONAR_PIPE_MAX_RANGE_M] or NaN; nothing
 * changed).
 */
SONAR_CHECK int sonar_pipeline_push(struct sonar_pipeline *p, const struct sonar_beam *b);

/*
 * Schedules cfg (kept by pointer: it must outlive p) to take over when the next sweep starts,
 * right after the open sweep's on_sweep. The detector's rules, the background's step and margin
 * change in place; a new median, background mode or warm-up, or max_step, starts a fresh
 * background. With no sweep open it applies at once. Returns SONAR_OK or SONAR_ERR_ARG (invalid:
 * nothing scheduled, the running config stays).
 */
SONAR_CHECK int sonar_pipeline_reconfigure(struct sonar_pipeline *p, const struct sonar_pipeline_config *cfg);

/* Ends the open sweep (end of a recording, or shutdown): flushes the 2-D median, calls on_sweep. */
SONAR_CHECK int sonar_pipeline_finish(struct sonar_pipeline *p);

#endif
