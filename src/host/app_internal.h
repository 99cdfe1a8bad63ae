/* app_internal.h -- struct app, shared by app.c (records, sinks, sweeps), app_device.c (the live link) and app_status.c (health); nothing else includes it. */
#ifndef SONARD_APP_INTERNAL_H
#define SONARD_APP_INTERNAL_H

#include "app.h"
#include "sonar/bgfile.h"

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
    struct sonar_bgfile_meta bg_file; /* a loaded background: what it is a model of (app_bg.c) ... */
    int bg_pending;             /* ... still to be checked against the first beam */
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

/* app_bg.c: a loaded background checked against the first beam (its range, samples and gain); a mismatch restarts it, said. */
void app_background_first_beam(struct app *a, const struct sonar_record *b);

/* app_device.c: --gain auto's decision at the end of sweep number `sweep` (before the sinks see it). */
void app_gain_sweep(struct app *a, uint32_t sweep);

#endif
