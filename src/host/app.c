/* app.c -- the app core: parser -> driver -> beam records -> pipeline -> sinks; counters and status; O(sinks) per record on top of the pipeline, no heap. */
#include "app.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sonar/geometry.h"

void app_say(const struct app *a, const char *fmt, ...)
{
    va_list ap;
    if (a->log == NULL)
        return;
    va_start(ap, fmt);
    a->log(a->log_user, fmt, ap);
    va_end(ap);
}

/* A sink call's result: a failure counted in errors, a success in *ok. */
static void tally(struct app_sink *s, int r, unsigned long *ok)
{
    if (r < 0)
        s->errors++;
    else
        (*ok)++;
}

static void sinks_beam(struct app *a, const struct app_beam *b)
{
    unsigned i;
    for (i = 0; i < a->nsinks; i++) {
        struct app_sink *s = a->sinks[i];
        if (s->beam == NULL || !(s->stages & (1u << b->stage)))
            continue;
        tally(s, s->beam(s->self, b), &s->n_beams);
    }
}

/* Pipeline callback: a stage's samples, with the acquisition of the beam in flight. */
static void on_stage(void *user, int stage, const struct sonar_beam *b)
{
    struct app *a = user;
    struct app_beam r;
    if (stage == SONAR_STAGE_RAW)
        return; /* app_push already gave the raw beam to the sinks, with all its metadata */
    r = a->cur;
    r.utime = b->utime;
    r.angle = b->angle; /* the 2-D median delays rows: the angle is the row's, not the input's */
    r.n = b->n;
    r.range_m = b->range_m;
    r.stage = (uint8_t)stage;
    r.samples = b->samples;
    sinks_beam(a, &r);
}

static void to_sinks(struct app *a, const struct sonar_detections *d, const struct sonar_tracker *tk)
{
    int64_t now = a->clock.mono_ns(a->clock.user);
    unsigned i;
    a->sweeps++;
    sonar_pipeline_view(&a->pipe, &a->view); /* d is the pipeline's own out, tk its tracker */
    if (a->sweep_t0 != 0)
        a->last_sweep_s = (float)((double)(now - a->sweep_t0) * 1e-9);
    a->sweep_t0 = now;
    for (i = 0; i < a->nsinks; i++) {
        struct app_sink *s = a->sinks[i];
        if (s->detections == NULL)
            continue;
        tally(s, s->detections(s->self, d, tk, &a->view), &s->n_detections);
    }
    if (a->max_sweeps > 0 && a->sweeps >= (uint32_t)a->max_sweeps)
        a->sweeps_done = 1;
}

static void on_sweep(void *user, const struct sonar_detections *d)
{
    struct app *a = user;
    to_sinks(a, d, a->pipe.cfg->track ? &a->pipe.trk : NULL);
}

int app_init(struct app *a, const struct sonar_pipeline_config *pcfg, const struct sonar_ping360_config *dcfg,
             const struct sonar_ping360_io *io, const struct app_clock *clock, float speed_of_sound, long max_sweeps,
             char *err, size_t errlen)
{
    const char *why;
    memset(a, 0, sizeof(*a));
    a->clock = *clock;
    a->speed_of_sound = speed_of_sound;
    a->max_sweeps = max_sweeps;
    a->link = "";
    a->pcfg[0] = *pcfg;
    a->pcfg[0].on_beam = on_stage;
    a->pcfg[0].on_sweep = on_sweep;
    a->pcfg[0].user = a;
    if ((why = sonar_pipeline_config_check(&a->pcfg[0])) != NULL || sonar_pipeline_init(&a->pipe, &a->pcfg[0]) != SONAR_OK) {
        snprintf(err, errlen, "pipeline configuration: %s", why ? why : "invalid");
        return HOST_ERR_CONFIG;
    }
    {
        struct sonar_pose_limits lim;
        sonar_pose_limits_default(&lim);
        if (sonar_pose_init(&a->poses, &lim) != SONAR_OK) {
            snprintf(err, errlen, "pose limits: invalid");
            return HOST_ERR_CONFIG;
        }
        sonar_pipeline_set_poses(&a->pipe, &a->poses);
    }
    if (sonar_ping_parser_init(&a->parser, 0) != SONAR_OK) {
        snprintf(err, errlen, "Ping parser: invalid limit");
        return HOST_ERR_CONFIG;
    }
    if (dcfg != NULL) {
        int r;
        if ((why = sonar_ping360_config_check(dcfg)) != NULL) {
            snprintf(err, errlen, "device configuration: %s", why);
            return HOST_ERR_CONFIG;
        }
        if ((r = sonar_ping360_init(&a->drv, dcfg, io)) != SONAR_OK) {
            snprintf(err, errlen, "--range %.1f m with --samples %u cannot be set on a Ping360 (sample period outside "
                                  "80..40000 ticks of 25 ns): %s", (double)dcfg->range_m, dcfg->samples, sonar_err_str(r));
            return HOST_ERR_CONFIG;
        }
        a->have_drv = 1;
    }
    return HOST_OK;
}

void app_set_log(struct app *a, app_log_fn log, void *user)
{
    a->log = log;
    a->log_user = user;
}

int app_add_sink(struct app *a, struct app_sink *s)
{
    if (a->nsinks >= APP_MAX_SINKS)
        return SONAR_ERR_FULL;
    s->errors = s->n_beams = s->n_detections = s->n_statuses = 0;
    a->sinks[a->nsinks++] = s;
    return HOST_OK;
}

int app_pose(struct app *a, const struct sonar_pose *p, const char **why)
{
    struct sonar_pose_ring *r = &a->poses;
    uint32_t ooo = r->out_of_order, jumps = r->jumps;
    if (sonar_pose_push(r, p) == SONAR_OK)
        return HOST_OK;
    if (why != NULL)
        *why = r->out_of_order != ooo ? "not later than the pose before it"
               : r->jumps != jumps   ? "a jump from the pose before it (faster than 50 m/s or 720 deg/s)"
                                     : "a value that is not a number or is beyond 10^6 m";
    return SONAR_ERR_RANGE;
}

/* The beam's pose: the source's (kept for the detections too), else looked up; says when it goes stale or comes back. */
static void beam_pose(struct app *a, struct app_beam *b)
{
    struct sonar_pose q;
    int state;
    if (b->has_pose) {
        q.utime = b->utime;
        q.north_m = b->north_m;
        q.east_m = b->east_m;
        q.yaw_deg = b->yaw_deg;
        if (app_pose(a, &q, NULL) != HOST_OK && !sonar_pose_at(&a->poses, b->utime, &q))
            b->has_pose = 0; /* refused, and nothing else known then: no pose */
    } else if (sonar_pose_at(&a->poses, b->utime, &q)) {
        b->has_pose = 1;
        b->north_m = q.north_m;
        b->east_m = q.east_m;
        b->yaw_deg = q.yaw_deg;
    }
    state = b->has_pose ? APP_POSE_OK : a->poses.accepted > 0 ? APP_POSE_STALE : APP_POSE_NONE;
    if (state == APP_POSE_STALE && a->pose_state != APP_POSE_STALE) {
        a->pose_stale++;
        app_say(a, "pose: stale (none within 1 s of the beam at %.3f s): body-frame processing until it returns",
                (double)b->utime * 1e-6);
    } else if (state == APP_POSE_OK && a->pose_state != APP_POSE_OK) {
        app_say(a, "pose: %s at %.3f s: detections and tracks in the world frame",
                a->pose_state == APP_POSE_STALE ? "back" : "known", (double)b->utime * 1e-6);
    }
    a->pose_state = state;
}

int app_push(struct app *a, const struct app_beam *b)
{
    struct sonar_beam pb;
    int64_t t0;
    int r;
    if (a->sweeps_done)
        return HOST_OK; /* after the sweeps asked for, beams still in flight are not a new sweep */
    a->cur = *b;
    a->cur.stage = SONAR_STAGE_RAW;
    beam_pose(a, &a->cur);
    sinks_beam(a, &a->cur);
    pb.utime = b->utime;
    pb.angle = b->angle;
    pb.n = b->n;
    pb.range_m = b->range_m;
    pb.samples = b->samples;
    t0 = a->clock.mono_ns(a->clock.user);
    {
        uint32_t changes = a->pipe.geometry_changes;
        float was_m = a->pipe.range_m;
        uint16_t was_n = a->pipe.n;
        if ((r = sonar_pipeline_push(&a->pipe, &pb)) != SONAR_OK) {
            a->beams_rejected++;
            return r;
        }
        if (a->pipe.geometry_changes != changes)
            app_say(a, "range: %u samples over %.2f m from the beam at %.3f s (was %u over %.2f m): the sweep was cut "
                    "there and the background starts afresh",
                    pb.n, (double)pb.range_m, (double)pb.utime * 1e-6, was_n, (double)was_m);
    }
    a->proc_us[a->nproc++ % APP_PROC_RING] = (float)((double)(a->clock.mono_ns(a->clock.user) - t0) * 1e-3);
    return HOST_OK;
}

void app_detections(struct app *a, const struct sonar_detections *d)
{
    if (a->sweeps_done)
        return;
    /*
     * Detections from elsewhere (a co-processor): located and tracked here. Which gradians its
     * sweep covered is not sent, so every track counts as in view (a sector scan coasts tracks
     * outside it).
     */
    if (sonar_pipeline_track(&a->pipe, d) != SONAR_OK)
        a->beams_rejected++;
    to_sinks(a, &a->pipe.out, a->pipe.cfg->track ? &a->pipe.trk : NULL);
}

void app_forward(struct app *a, const struct app_beam *b)
{
    struct app_beam r;
    if (a->sweeps_done)
        return;
    r = *b;
    beam_pose(a, &r);
    sinks_beam(a, &r);
}

void app_send_status(struct app *a, const struct app_status *s)
{
    unsigned i;
    for (i = 0; i < a->nsinks; i++) {
        struct app_sink *k = a->sinks[i];
        if (k->status == NULL)
            continue;
        tally(k, k->status(k->self, s), &k->n_statuses);
    }
}

int app_finish(struct app *a)
{
    return sonar_pipeline_finish(&a->pipe);
}

/* A device beam becomes a record: the driver's settings, the receive time, the range they give. */
static void device_beam(struct app *a, const struct sonar_ping360_data *d)
{
    struct app_beam b;
    b.utime = a->clock.wall_us(a->clock.user);
    b.angle = d->angle;
    b.n = d->data_length;
    b.gain = d->gain;
    b.sample_period = d->sample_period;
    b.transmit_duration = d->transmit_duration;
    b.transmit_frequency = d->transmit_frequency;
    b.speed_of_sound = a->speed_of_sound;
    b.range_m = (float)sonar_geometry_range_m(d->sample_period, d->data_length, a->speed_of_sound);
    b.stage = SONAR_STAGE_RAW;
    b.has_pose = 0;
    b.north_m = b.east_m = b.yaw_deg = 0.0f;
    b.samples = d->data;
    if (app_push(a, &b) != HOST_OK)
        return; /* counted in beams_rejected; the sinks still had the raw beam */
}

static int on_event(struct app *a, const struct sonar_ping360_event *ev)
{
    switch (ev->kind) {
    case SONAR_P360_EV_READY:
        app_say(a, "Ping360 firmware %u.%u.%u on %s", a->drv.info.fw_major, a->drv.info.fw_minor, a->drv.info.fw_patch,
            a->link);
        app_say(a, "scanning (%s)", a->drv.state == SONAR_P360_AUTO ? "auto_transmit" : "stepping");
        return APP_LINK_NONE;
    case SONAR_P360_EV_BEAM:
        device_beam(a, &ev->data);
        return APP_LINK_NONE;
    case SONAR_P360_EV_LINK_LOST:
        a->backoff_us = ev->backoff_us;
        return APP_LINK_LOST;
    case SONAR_P360_EV_STOPPED:
        return APP_LINK_STOPPED;
    default:
        return APP_LINK_NONE;
    }
}

int app_link_bytes(struct app *a, const uint8_t *buf, size_t len, int64_t now_us)
{
    const uint8_t *in = buf;
    struct sonar_ping_frame f;
    while (sonar_ping_parser_next(&a->parser, &in, &len, &f) == 1) {
        struct sonar_ping360_event ev;
        int r;
        if (sonar_ping360_handle(&a->drv, &f, now_us, &ev) != SONAR_OK)
            ev.kind = SONAR_P360_EV_NONE; /* a failed send: the request's timeout retries it */
        if ((r = on_event(a, &ev)) != APP_LINK_NONE)
            return r;
    }
    return APP_LINK_NONE;
}

/* Fresh framing for a new connection; the counters carry on. */
static void reset_parser(struct app *a)
{
    struct sonar_ping_counters c = a->parser.counters;
    if (sonar_ping_parser_init(&a->parser, 0) == SONAR_OK) /* cannot fail with these arguments */
        a->parser.counters = c;
}

int app_link_up(struct app *a, int64_t now_us)
{
    reset_parser(a);
    return sonar_ping360_connected(&a->drv, now_us);
}

void app_link_down(struct app *a, int64_t now_us)
{
    reset_parser(a);
    /* A driver that gave up itself already set backoff_us (APP_LINK_LOST); one that did not, now does. */
    if (a->drv.state != SONAR_P360_DOWN && a->drv.state != SONAR_P360_STOPPED) {
        sonar_ping360_link_lost(&a->drv, now_us);
        a->backoff_us = a->drv.backoff_us;
    }
}

int app_link_poll(struct app *a, int64_t now_us)
{
    struct sonar_ping360_event ev;
    if (!a->have_drv || sonar_ping360_poll(&a->drv, now_us, &ev) != SONAR_OK)
        return APP_LINK_NONE;
    return on_event(a, &ev);
}

int64_t app_deadline(const struct app *a)
{
    return a->have_drv ? sonar_ping360_deadline(&a->drv) : INT64_MAX;
}

int app_link_stop(struct app *a, int64_t now_us)
{
    int r = sonar_ping360_stop(&a->drv, now_us);
    if (r != SONAR_OK)
        return r;
    return a->drv.state == SONAR_P360_STOPPED;
}

static int cmpf(const void *x, const void *y)
{
    float p = *(const float *)x, q = *(const float *)y;
    return p < q ? -1 : p > q;
}

unsigned long app_sink_errors(const struct app *a)
{
    unsigned long e = 0;
    unsigned i;
    for (i = 0; i < a->nsinks; i++)
        e += a->sinks[i]->errors;
    return e;
}

void app_pose_status(const struct app *a, struct app_status *s)
{
    s->pose.state = a->pose_state;
    s->pose.accepted = a->poses.accepted;
    s->pose.out_of_order = a->poses.out_of_order;
    s->pose.jumps = a->poses.jumps;
    s->pose.bad = a->poses.bad;
    s->pose.thinned = a->poses.thinned;
    s->pose.stale = a->pose_stale;
    s->pose.world_sweeps = a->pipe.world_sweeps;
    s->pose.body_sweeps = a->pipe.body_sweeps;
}

void app_report_status(struct app *a, int link_state, struct app_status *s)
{
    unsigned n = (unsigned)(a->nproc < APP_PROC_RING ? a->nproc : APP_PROC_RING);
    memcpy(a->sorted, a->proc_us, n * sizeof(float));
    qsort(a->sorted, n, sizeof(float), cmpf);
    memset(s, 0, sizeof(*s));
    s->utime = a->clock.wall_us(a->clock.user);
    s->link_state = link_state;
    s->link = a->link;
    s->fw[0] = a->drv.info.fw_major;
    s->fw[1] = a->drv.info.fw_minor;
    s->fw[2] = a->drv.info.fw_patch;
    s->parser = a->parser.counters;
    s->driver = a->drv.counters;
    s->sweeps = a->sweeps;
    s->beams_rejected = a->beams_rejected;
    s->rows_bad = a->rows_bad;
    s->sink_errors = (uint32_t)app_sink_errors(a);
    s->last_sweep_s = a->last_sweep_s;
    s->beam_us_p50 = n ? a->sorted[n / 2] : 0.0f;
    s->beam_us_p99 = n ? a->sorted[(n * 99) / 100] : 0.0f;
    if (a->pipe.cfg->track) {
        s->tracker.live = a->pipe.trk.n;
        s->tracker.ended = a->pipe.trk.deleted;
        s->tracker.bad_detections = a->pipe.trk.bad_detections;
        s->tracker.clock_back = a->pipe.trk.clock_back;
        s->tracker.overflow = a->pipe.trk.overflow;
    }
    app_pose_status(a, s);
    app_send_status(a, s);
}

int app_reconfigure(struct app *a, const struct sonar_pipeline_config *pcfg, char *err, size_t errlen)
{
    /* The spare slot is the one the pipeline is not running on (it may hold a pending reload). */
    struct sonar_pipeline_config *spare = a->pipe.cfg == &a->pcfg[0] ? &a->pcfg[1] : &a->pcfg[0];
    struct sonar_pipeline_config c = *pcfg;
    const char *why;
    c.on_beam = on_stage;
    c.on_sweep = on_sweep;
    c.user = a;
    if ((why = sonar_pipeline_config_check(&c)) != NULL) {
        snprintf(err, errlen, "pipeline configuration: %s", why);
        return HOST_ERR_CONFIG;
    }
    *spare = c;
    if (sonar_pipeline_reconfigure(&a->pipe, spare) != SONAR_OK) {
        snprintf(err, errlen, "pipeline configuration: rejected");
        return HOST_ERR_CONFIG;
    }
    return HOST_OK;
}
