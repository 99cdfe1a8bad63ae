/* app_internal.h -- struct app, shared by app.c (records, sinks, sweeps), app_device.c (the live link) and app_status.c (health); nothing else includes it. */
#ifndef SONARD_APP_INTERNAL_H
#define SONARD_APP_INTERNAL_H

#include "app.h"
#include "sonar/bgfile.h"
#include "sonar/survey.h"

struct app {
    struct sonar_pipeline_config pcfg[2]; /* running and reloaded; the pipeline points at one */
    struct {                            /* --track-late: the last sweep, held until the next one's revisions */
        int on, have;
        struct sonar_detections det;
        struct sonar_tracker trk;
        struct msg_view view;
    } late;
    struct sonar_pipeline pipe;
    struct sonar_background bg; /* the pipeline's */
    struct sonar_activity act;  /* the pipeline's: its tracks' echo windows */
    struct sonar_clutter clutter; /* the pipeline's: the site's clutter map */
    struct sonar_device dev;
    int have_dev;
    struct sonar_scan scan;     /* follow mode: chooses each request's angle (app_set_scan) */
    int have_scan;
    int scan_said;              /* the planner's idleness under auto_transmit was said */
    struct sonar_gain gain;     /* --gain auto (app_set_gain_auto) */
    int have_gain_auto;
    int gain_off;               /* the sonar did not take a change: auto gain stopped */
    uint32_t gain_refused;
    int32_t last_gain;          /* the gain of the beam before, -1: none yet */
    uint32_t bg_restarts;       /* backgrounds restarted for a change of the beams' gain */
    struct sonar_survey survey; /* the site's survey, in use or not (app_bg.c) */
    struct sonar_survey_spread spread; /* its cells' spread */
    struct sonar_detection survey_places[SONAR_MAX_CLUSTERS]; /* its structure */
    const uint8_t *survey_img;  /* the loaded image (the caller's, outliving the app): taken back when it fits again */
    size_t survey_len;
    int survey_state;           /* the survey's state and why, and its misfits, when last said */
    int survey_why;
    uint32_t survey_unfits;
    struct sonar_survey_rec *rec; /* a survey being recorded: each beam after the median goes into it, or NULL */
    int rec_ends_run;             /* --survey N: its refusal ends the run (--control's: it does not) */
    uint32_t structure_said;    /* places promoted to structure when it was last said */
    uint32_t hyp_overflow_said; /* the tracker's alternatives that did not fit, when it was last said */
    int passive_idle;           /* --passive: the beams stopped (said); the next one is said too */
    uint32_t passive_changes;   /* --passive: the driving program changed range, samples or gain */
    struct sonar_record passive_last; /* --passive: the settings of its latest beam (no samples kept) */
    struct app_clock clock;
    app_log_fn log;
    void *log_user;
    struct app_sink *sinks[APP_MAX_SINKS];
    unsigned nsinks;
    struct sonar_record cur;    /* the beam in the pipeline: stage callbacks get only its samples */
    long max_sweeps;            /* stop after this many; 0 = never */
    int sweeps_done;            /* max_sweeps reached: later beams are ignored */
    uint32_t sweeps, beams_rejected, rows_bad;
    int64_t sweep_t0;
    float last_sweep_s;
    const char *link;
    struct sonar_pose_ring poses;  /* every pose source's samples (app_pose) */
    struct msg_view view;        /* the sweep going to the sinks, in both frames */
    int pose_state;                /* enum sonar_pose_state at the latest beam */
    uint32_t pose_stale;
    float proc_us[APP_PROC_RING];
    float sorted[APP_PROC_RING];
    unsigned long nproc;
};

/* app_bg.c: after each beam, what became of the survey (given up, fitting again: taken back), said once. */
void app_survey_watch(struct app *a);

/* app_device.c: --gain auto's decision at the end of sweep number `sweep` (before the sinks see it). */
void app_gain_sweep(struct app *a, uint32_t sweep);

#endif
