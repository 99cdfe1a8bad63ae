/* app.h -- sonard's app core: owns the Ping parser, the Ping360 driver and the pipeline; sources push beam records in, each sink maps a record once; ~0.6 MB per struct app (the pipeline). */
#ifndef SONARD_APP_H
#define SONARD_APP_H

#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include "herr.h"
#include "sonar/detector.h"
#include "sonar/ping.h"
#include "sonar/ping360.h"
#include "sonar/pipeline.h"
#include "sonar/pose.h"

#define APP_MAX_SINKS 8
#define APP_PROC_RING 1024 /* per-beam processing times kept for the percentiles */

/* One beam and its acquisition, from any source to every sink. Unknown integer metadata is -1. */
struct app_beam {
    int64_t utime;              /* us since the epoch: receipt (live) or the recording's */
    uint16_t angle;             /* gradians 0..399 */
    uint16_t n;                 /* samples */
    int32_t gain;               /* 0 low, 1 normal, 2 high */
    int32_t sample_period;      /* 25 ns ticks */
    int32_t transmit_duration;  /* us */
    int32_t transmit_frequency; /* kHz */
    float speed_of_sound;       /* m/s */
    float range_m;              /* metres covered by the n samples */
    uint8_t stage;              /* enum sonar_stage */
    uint8_t has_pose;           /* 1: the vehicle's pose at utime below (from the source, or the app's poses) */
    float north_m, east_m;      /* local NED, metres */
    float yaw_deg;              /* heading, degrees clockwise from north */
    const uint8_t *samples;     /* n samples, valid during the call only */
};

enum app_pose_state { APP_POSE_NONE = 0, APP_POSE_OK = 1, APP_POSE_STALE = 2 };

/* Health, once a second and at exit. */
struct app_status {
    int64_t utime;
    int link_state;                        /* enum sonar_ping360_state (SONAR_P360_CONNECTING included) */
    const char *link;                      /* "tcp:127.0.0.1:5000", "replay:FILE" */
    uint8_t fw[3];
    struct sonar_ping_counters parser;     /* every parser counter */
    struct sonar_ping360_counters driver;  /* every driver counter */
    uint32_t sweeps;
    uint32_t beams_rejected;               /* beams the pipeline refused (bad geometry) */
    uint32_t rows_bad;                     /* replay: malformed rows skipped */
    uint32_t sink_errors;                  /* sink calls that failed, all sinks */
    float last_sweep_s;                    /* seconds the last sweep took */
    float beam_us_p50, beam_us_p99;        /* per-beam processing time */
    uint32_t stack_used;                   /* co-processor: stack high-water mark, bytes; 0 on the host */
    struct {
        uint32_t live, ended, bad_detections, clock_back, overflow;
    } tracker;                             /* all 0 with tracking off */
    struct {
        int state;                         /* enum app_pose_state, at the latest beam */
        uint32_t accepted, out_of_order, jumps, bad, thinned; /* the ring's counters */
        uint32_t stale;                    /* times the pose went stale (none within 1 s of a beam) */
        uint32_t world_sweeps, body_sweeps; /* sweeps tracked in each frame */
    } pose;
};

/* An output. Any callback may be NULL. Each returns HOST_OK or < 0 (counted in errors). */
struct app_sink {
    const char *name;
    void *self;
    uint8_t stages; /* bit (1 << stage) for each stage of beams it takes */
    int (*beam)(void *self, const struct app_beam *b);
    /* d: one sweep; tk: the tracks after it, or NULL when tracking is off; v: both in both frames */
    int (*detections)(void *self, const struct sonar_detections *d, const struct sonar_tracker *tk,
                      const struct sonar_view *v);
    int (*status)(void *self, const struct app_status *s);
    unsigned long errors; /* failed calls, kept by the app */
    unsigned long n_beams, n_detections, n_statuses; /* calls that succeeded, kept by the app */
};

/* Clocks, injected so tests can drive time. mono_ns: monotonic; wall_us: us since the epoch. */
struct app_clock {
    int64_t (*mono_ns)(void *user);
    int64_t (*wall_us)(void *user);
    void *user;
};

/* Messages for people (stderr in sonard); NULL to drop them. */
typedef void (*app_log_fn)(void *user, const char *fmt, va_list ap);

enum app_link_event { APP_LINK_NONE = 0, APP_LINK_LOST = 1, APP_LINK_STOPPED = 2 };

struct app {
    struct sonar_pipeline_config pcfg[2]; /* running and reloaded; the pipeline points at one */
    struct sonar_pipeline pipe;
    struct sonar_ping_parser parser;
    struct sonar_ping360 drv;
    int have_drv;
    struct app_clock clock;
    app_log_fn log;
    void *log_user;
    struct app_sink *sinks[APP_MAX_SINKS];
    unsigned nsinks;
    struct app_beam cur;        /* the beam in the pipeline: stage callbacks get only its samples */
    float speed_of_sound;
    long max_sweeps;            /* stop after this many; 0 = never */
    int sweeps_done;            /* max_sweeps reached: later beams are ignored */
    uint32_t sweeps, beams_rejected, rows_bad;
    uint32_t backoff_us;        /* with APP_LINK_LOST: reconnect after this */
    int64_t sweep_t0;
    float last_sweep_s;
    const char *link;
    struct sonar_pose_ring poses;  /* every pose source's samples (app_pose) */
    struct sonar_view view;        /* the sweep going to the sinks, in both frames */
    int pose_state;                /* enum app_pose_state at the latest beam */
    uint32_t pose_stale;
    float proc_us[APP_PROC_RING];
    float sorted[APP_PROC_RING];
    unsigned long nproc;
};

/*
 * Sets up the core. pcfg: pipeline config (copied; its callbacks are the app's). dcfg/io: the
 * Ping360 driver for a live link, or NULL for a source that pushes beams itself (replay).
 * max_sweeps: 0 = no limit. Returns HOST_OK, or HOST_ERR_CONFIG with the failing field in err.
 */
HOST_CHECK int app_init(struct app *a, const struct sonar_pipeline_config *pcfg, const struct sonar_ping360_config *dcfg,
                        const struct sonar_ping360_io *io, const struct app_clock *clock, float speed_of_sound,
                        long max_sweeps, char *err, size_t errlen);

/* Messages go to log(user, ...). */
void app_set_log(struct app *a, app_log_fn log, void *user);

/* A message for people through the app's log (nothing when it has none). */
void app_say(const struct app *a, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* Adds a sink (kept by pointer). Returns HOST_OK or SONAR_ERR_FULL. */
HOST_CHECK int app_add_sink(struct app *a, struct app_sink *s);

/*
 * One raw beam from any source: every sink taking raw beams gets it, then it goes through the
 * pipeline (its foreground to sinks taking that stage, its sweep's detections to every sink).
 * Returns HOST_OK, or SONAR_ERR_ARG when the pipeline refused it (counted; the sinks had it).
 */
HOST_CHECK int app_push(struct app *a, const struct app_beam *b);

/*
 * A source that detects elsewhere (the co-processor) hands over what it got: a sweep's detections
 * (to every sink, counted as a sweep, --sweeps honoured), a raw beam (to the sinks only, not the
 * pipeline), a status (to every sink as it is).
 */
void app_detections(struct app *a, const struct sonar_detections *d);
void app_forward(struct app *a, const struct app_beam *b);
void app_send_status(struct app *a, const struct app_status *s);

/*
 * One sample of the vehicle's pose from any source (MAVLink, LCM, a pose file, a recording's
 * rows). Beams look their pose up by time from these (sonar_pose_at), and so do detections.
 * Returns HOST_OK, or SONAR_ERR_RANGE when the ring refused it (out of order, a jump, a bad
 * value: counted in the ring, the reason in why when why is not NULL).
 */
HOST_CHECK int app_pose(struct app *a, const struct sonar_pose *p, const char **why);

/* Ends the open sweep (end of a recording, shutdown). Returns HOST_OK or a core error. */
HOST_CHECK int app_finish(struct app *a);

/*
 * Live link: bytes as they arrived. Frames go to the driver; its beams to app_push. Returns
 * APP_LINK_NONE, APP_LINK_LOST (give the link up; reconnect after a->backoff_us) or
 * APP_LINK_STOPPED (motor_off acknowledged). Stops early, with bytes left, on LOST or STOPPED.
 */
int app_link_bytes(struct app *a, const uint8_t *buf, size_t len, int64_t now_us);

/* Live link: the transport opened (probe the device), or was lost. Fresh framing either way. */
HOST_CHECK int app_link_up(struct app *a, int64_t now_us);
void app_link_down(struct app *a, int64_t now_us);

/* Live link: driver timers. Returns as app_link_bytes. app_deadline: when to call it next (us). */
int app_link_poll(struct app *a, int64_t now_us);
int64_t app_deadline(const struct app *a);

/* Live link: motor_off. Returns 1 when already stopped (nothing to wait for), 0 when waiting, < 0 on error. */
int app_link_stop(struct app *a, int64_t now_us);

/* Collects the counters into *s and sends it to every sink (app_send_status). link_state: the driver's, or SONAR_P360_CONNECTING. */
void app_report_status(struct app *a, int link_state, struct app_status *s);

/*
 * SIGHUP: pcfg (copied) takes over at the next sweep (sonar_pipeline_reconfigure). Returns
 * HOST_OK, or HOST_ERR_CONFIG with the failing field in err (the running settings stay).
 */
HOST_CHECK int app_reconfigure(struct app *a, const struct sonar_pipeline_config *pcfg, char *err, size_t errlen);

/* Fills s->pose from the app's poses and pipeline. */
void app_pose_status(const struct app *a, struct app_status *s);

/* Sum of every sink's failed calls. */
unsigned long app_sink_errors(const struct app *a);

#endif
