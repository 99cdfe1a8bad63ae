/* app.h -- sonard's app core: owns the device core and the pipeline; sources push beam records in, each sink maps a record once; RAM: sizeof(struct app_storage) = 1 101 376 B, the pipeline, its background and a survey's spread plus APP_STORAGE_REST. */
#ifndef SONARD_APP_H
#define SONARD_APP_H

#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include "herr.h"
#include "sonar/gain.h"
#include "sonar/detector.h"
#include "sonar/device.h"
#include "sonar/pipeline.h"
#include "sonar/pose.h"
#include "sonar/status.h"
#include "sonar/survey.h"
#include "view.h"

#define APP_MAX_SINKS 8
#define APP_PROC_RING 1024 /* per-beam processing times kept for the percentiles */
#define APP_BLANK_SAID 3   /* blank beams said one by one; after that every 1000th */
#define APP_STORAGE_REST 65536 /* the app beyond its pipeline (app.c checks it at compile time) */

/* An output. Any callback may be NULL. Each returns HOST_OK or < 0 (counted in errors). */
struct app_sink {
    const char *name;
    void *self;
    uint8_t stages; /* bit (1 << stage) for each stage of beams it takes */
    uint8_t live;   /* 1: each sweep at once even with --track-late (the autopilot: an obstacle is not held back) */
    int (*beam)(void *self, const struct sonar_record *b);
    /* d: one sweep; tk: the tracks after it, or NULL when tracking is off; v: both in both frames */
    int (*detections)(void *self, const struct sonar_detections *d, const struct sonar_tracker *tk,
                      const struct msg_view *v);
    int (*status)(void *self, const struct sonar_status *s);
    /* Adds the sink's own counters to a status the app is about to send (the autopilot's); may be NULL. */
    void (*fill)(const void *self, struct sonar_status *s);
    unsigned long errors; /* failed calls, kept by the app */
    unsigned long n_beams, n_detections, n_statuses; /* calls that succeeded, kept by the app */
};

/* Clocks, injected so tests can drive time. mono_ns: monotonic; wall_us: us since the epoch. */
struct app_clock {
    int64_t (*mono_ns)(void *user);
    int64_t (*wall_us)(void *user);
    void *user;
};

/* How much a message for people matters: sonard's --log-level shows those at or below its level. */
enum app_level { APP_ERROR = 0, APP_WARN = 1, APP_INFO = 2, APP_DEBUG = 3 };

/* Messages for people (stderr in sonard, so the journal under systemd); NULL to drop them. */
typedef void (*app_log_fn)(void *user, int level, const char *fmt, va_list ap);

/* What the device core said, for a live source: nothing, give the link up (reconnect after app_device_down), stopped. */
enum app_device_event { APP_DEVICE_NONE = 0, APP_DEVICE_LOST = 1, APP_DEVICE_STOPPED = 2 };

/*
 * The app: opaque outside app*.c (app_internal.h). Caller-allocated, no heap: an app lives in a
 * struct app_storage (the pipeline, its background, its tracks' echo windows and APP_STORAGE_REST bytes; static or inside a static
 * struct, never on a small stack), and app_init hands out the app in it.
 */
struct app;
struct app_storage {
    union { int64_t i; double d; void *p; } align_;
    struct sonar_pipeline pipe_;
    struct sonar_background bg_;
    struct sonar_survey_spread spread_;
    struct sonar_activity act_;
    struct sonar_clutter clutter_;
    unsigned char rest_[APP_STORAGE_REST];
};


/*
 * Sets up an app in *mem and gives it in *out. pcfg: pipeline config (copied; its callbacks are
 * the app's). dcfg/io: the Ping360 on a live link (the device core, sonar/device.h), or NULL for
 * a source that pushes beams itself (replay, co-processor). max_sweeps: 0 = no limit. Returns
 * HOST_OK, or HOST_ERR_CONFIG with the failing field in err (*out untouched).
 */
HOST_CHECK int app_init(struct app **out, struct app_storage *mem, const struct sonar_pipeline_config *pcfg,
                        const struct sonar_ping360_config *dcfg, const struct sonar_ping360_io *io,
                        const struct app_clock *clock, long max_sweeps, char *err, size_t errlen);

/*
 * Steers the live sonar with the scan planner (scan.h): cfg's mode, revisit_s and surveil_s; the
 * sector, step and ping time come from the device's settings (a ping: the timing model less the
 * head's travel). Follow mode asks the planner for every request's angle, with the confirmed
 * tracks' predicted bearings (sonar_pipeline_targets); sweep mode leaves the driver's own
 * stepping, byte for byte. Call after app_init with a device. Returns HOST_OK or HOST_ERR_CONFIG
 * with the failing field in err.
 */
HOST_CHECK int app_set_scan(struct app *a, const struct sonar_scan_config *cfg, char *err, size_t errlen);

/*
 * --gain auto on the live sonar (gain.h): cfg's rules, starting at the device's gain. Each live
 * beam is counted; at each sweep's end the setting may change for the requests that follow (never
 * mid-sector), said and on SONAR_STATUS; a change the sonar does not take (a whole sweep of beams
 * still at the old gain) stops auto gain, said. Returns HOST_OK or HOST_ERR_CONFIG naming the field.
 */
HOST_CHECK int app_set_gain_auto(struct app *a, const struct sonar_gain_config *cfg, char *err, size_t errlen);

/* Messages go to log(user, ...). */
void app_set_log(struct app *a, app_log_fn log, void *user);

/*
 * late 1: the sinks get each sweep's detections and tracks one sweep late, when the next sweep's
 * look has revised what it would (deferred association), with no revisions of their own, but for
 * those marked live (the autopilot's), which get each at once; 0 (the default): every sink at once,
 * with revisions of the sweep before said. app_finish gives the last one.
 */
void app_set_track_late(struct app *a, int late);

/* A message for people through the app's log (nothing when it has none): app_say at APP_INFO (what happens), app_warn at APP_WARN (what went wrong and what sonard does about it). */
void app_say(const struct app *a, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
void app_warn(const struct app *a, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* What the status calls the source ("tcp:127.0.0.1:5000", "replay:FILE"); kept by pointer. */
void app_set_link(struct app *a, const char *desc);

/* Adds a sink (kept by pointer). Returns HOST_OK or HOST_ERR_FULL. */
HOST_CHECK int app_add_sink(struct app *a, struct app_sink *s);

/* The i-th sink added, or NULL past the last. */
const struct app_sink *app_sink_at(const struct app *a, unsigned i);

/*
 * One raw beam from any source: every sink taking raw beams gets it, then it goes through the
 * pipeline (its foreground to sinks taking that stage, its sweep's detections to every sink).
 * Returns HOST_OK, or HOST_ERR_REFUSED when the pipeline refused it (counted; the sinks had it).
 */
HOST_CHECK int app_push(struct app *a, const struct sonar_record *b);

/* A source skipped a malformed input row (counted in status rows_bad). */
void app_row_bad(struct app *a);

/*
 * A source that detects elsewhere (the co-processor) hands over what it got: a sweep's detections
 * (to every sink, counted as a sweep, --sweeps honoured), a raw beam (to the sinks only, not the
 * pipeline), a status (to every sink as it is).
 */
void app_detections(struct app *a, const struct sonar_detections *d);
void app_forward(struct app *a, const struct sonar_record *b);
void app_send_status(struct app *a, const struct sonar_status *s);

/*
 * One sample of the vehicle's pose from any source (MAVLink, LCM, a pose file, a recording's
 * rows). Beams look their pose up by time from these (sonar_pose_at), and so do detections.
 * Returns HOST_OK, or HOST_ERR_REFUSED when the ring refused it (out of order, a jump, a bad
 * value: counted in the ring, the reason in why when why is not NULL).
 */
HOST_CHECK int app_pose(struct app *a, const struct sonar_pose *p, const char **why);

/* The vehicle's pose at t (us since the epoch) from the app's poses: 1 and *q, or 0 when none is near (sonar_pose_at). */
int app_pose_at(const struct app *a, int64_t t, struct sonar_pose *q);

/* Every pose source's samples, read-only (sonar_pose_at and the ring's counters). */
const struct sonar_pose_ring *app_poses(const struct app *a);

/* The output frame now (sonar_pipeline_frame): angle offset in gradians, min range in metres. */
void app_frame(const struct app *a, float *angle_offset, float *min_range_m);

/* Ends the open sweep (end of a recording, shutdown). Returns HOST_OK or a core error. */
HOST_CHECK int app_finish(struct app *a);

/* The app's clocks: monotonic us, and us since the epoch. */
int64_t app_mono_us(const struct app *a);
int64_t app_wall_us(const struct app *a);

/* Sweeps sent to the sinks; 1 once the --sweeps asked for are done (later beams are ignored). */
uint32_t app_sweeps(const struct app *a);
int app_done(const struct app *a);

/* Beams the pipeline refused, and rows the sources skipped, so far. */
uint32_t app_beams_rejected(const struct app *a);
/* Beams the pipeline skipped as blank (every sample 0 or 255) and left out as interference streaks, since the start. */
uint32_t app_blank_beams(const struct app *a);
uint32_t app_interference_beams(const struct app *a);
uint32_t app_rows_bad(const struct app *a);

/* Seconds the last sweep took (0 before the second). */
float app_last_sweep_s(const struct app *a);

/*
 * A site's survey, or a recorded background (a bgfile.h image of len bytes, a clutter map after it
 * or not (app_clutter_image; one that does not decode is said and learnt afresh), read by the caller and
 * kept by it for the app's life: it is taken back from there when the beams fit it again after a
 * misfit): checked whole, its filters against the running configuration; then the angles it knows
 * are judged against it (sonar_pipeline_load_background), and every beam and sweep against its
 * setting and structure, a misfit said and learnt afresh from. Call before the first beam. Returns
 * HOST_OK, or HOST_ERR_CONFIG with err naming what is wrong (nothing changed).
 */
HOST_CHECK int app_background_load(struct app *a, const uint8_t *img, size_t len, char *err, size_t errlen);

/*
 * The learnt model as a bgfile.h image into out (cap bytes), the clutter map after it (app_clutter_image).
 * Returns its length, or < 0 with err
 * saying why: HOST_ERR_STATE (no beam yet, the model is in the world frame, or a survey is in use:
 * nothing was learnt over it), HOST_ERR_REFUSED (out too small).
 */
HOST_CHECK int32_t app_background_image(const struct app *a, uint8_t *out, size_t cap, char *err, size_t errlen);

/*
 * The site's clutter map (clutter.h's bytes, SONAR_CLUTTER_WIRE of them) into out (cap bytes), for a
 * survey or background file to carry after its image. Returns the bytes written, 0 when nothing is
 * learnt yet (no look taken), or SONAR_ERR_SPACE.
 */
HOST_CHECK int32_t app_clutter_image(const struct app *a, uint8_t *out, size_t cap);

/* The survey as it is now: its state, why, meta and places (sonar/survey.h). */
const struct sonar_survey *app_survey(const struct app *a);

/*
 * A survey recorded (--survey N, or --control's while running): every beam after the median goes into
 * rec (the caller's, sonar_survey_rec_init'd), every sweep's tracks too (a move refuses it); NULL stops.
 * The recording's refusals are rec's (rec->why); with ends_run one also ends the run (app_done).
 */
void app_record_survey(struct app *a, struct sonar_survey_rec *rec, int ends_run);

/* The survey's or recorded background's image the app holds (app_background_load's), NULL with none. */
const uint8_t *app_survey_image(const struct app *a);

/* The pipeline, read-only (tools that inspect the background: sonar-wallfit). */
const struct sonar_pipeline *app_pipeline(const struct app *a);

/* The device core on a live link, read-only (its state and counters), or NULL without one. */
const struct sonar_device *app_device(const struct app *a);

/*
 * The device on a live link: bytes as they arrived. Frames go to the device core; its beams to app_push. Returns
 * APP_DEVICE_NONE, APP_DEVICE_LOST (give the link up: app_device_down says when to reconnect) or
 * APP_DEVICE_STOPPED (motor_off acknowledged). Stops early, with bytes left, on LOST or STOPPED.
 */
int app_device_bytes(struct app *a, const uint8_t *buf, size_t len, int64_t now_us);

/*
 * The device on a live link: the transport opened (probe the device: HOST_OK or the send error), or was lost
 * (fresh framing; returns the reconnect delay in us, never 0: sonar_device_down's policy).
 */
HOST_CHECK int app_device_up(struct app *a, int64_t now_us);
uint32_t app_device_down(struct app *a, int64_t now_us);

/* The device on a live link: driver timers. Returns as app_device_bytes. app_deadline: when to call it next (us). */
int app_device_poll(struct app *a, int64_t now_us);
int64_t app_deadline(const struct app *a);

/* The device on a live link: motor_off. Returns 1 when already stopped (nothing to wait for), 0 when waiting, < 0 on error. */
int app_device_stop(struct app *a, int64_t now_us);

/* Collects the counters into *s and sends it to every sink (app_send_status). link_state: the driver's, or SONAR_P360_CONNECTING. */
void app_report_status(struct app *a, int link_state, struct sonar_status *s);

/*
 * SIGHUP: pcfg (copied) takes over at the next sweep (sonar_pipeline_reconfigure). Returns
 * HOST_OK, or HOST_ERR_CONFIG with the failing field in err (the running settings stay).
 */
HOST_CHECK int app_reconfigure(struct app *a, const struct sonar_pipeline_config *pcfg, char *err, size_t errlen);

/*
 * Fills what only this process knows, whoever made the rest of *s (this app or a co-processor's
 * frame): sink_errors, pose (its poses and sweeps per frame), tracker (its tracker makes
 * SONAR_TRACKS), and each sink's own counters (the autopilot's). Other fields are left as they are.
 */
void app_host_status(const struct app *a, struct sonar_status *s);

/* Sum of every sink's failed calls. */
unsigned long app_sink_errors(const struct app *a);

#endif
