/* app.c -- the app core: beam records -> pipeline -> sinks, sweeps, poses, reloads; O(sinks) per record on top of the pipeline, no heap. */
#include "app_internal.h"

#include <inttypes.h>
#include <stdio.h>
#include <string.h>

/* struct app_storage must hold a struct app: a negative array size stops the build when it does not. */
typedef char app_storage_fits[sizeof(struct app) <= sizeof(struct app_storage) ? 1 : -1];

static void say_at(const struct app *a, int level, const char *fmt, va_list ap)
{
    if (a->log != NULL)
        a->log(a->log_user, level, fmt, ap);
}

void app_say(const struct app *a, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    say_at(a, APP_INFO, fmt, ap);
    va_end(ap);
}

void app_warn(const struct app *a, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    say_at(a, APP_WARN, fmt, ap);
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

static void sinks_beam(struct app *a, const struct sonar_record *b)
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
    struct sonar_record r;
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

void app_set_track_late(struct app *a, int late)
{
    a->late.on = late != 0;
    a->late.have = 0;
}

/* The sweep to the sinks: those marked live (or all, live 2) get it; live 0: the others. */
static void give(struct app *a, const struct sonar_detections *d, const struct sonar_tracker *tk, const struct msg_view *v,
                 int live)
{
    unsigned i;
    for (i = 0; i < a->nsinks; i++) {
        struct app_sink *s = a->sinks[i];
        if (s->detections == NULL || (live != 2 && (s->live != 0) != (live != 0)))
            continue;
        tally(s, s->detections(s->self, d, tk, v), &s->n_detections);
    }
}

/* --track-late: holds this sweep (its detections, tracks and view) until the next one's revisions. */
static void late_hold(struct app *a, const struct sonar_detections *d, const struct sonar_tracker *tk)
{
    a->late.det = *d;
    a->late.trk = *tk;
    a->late.view = a->view;
    a->late.have = 1;
}

static void to_sinks(struct app *a, const struct sonar_detections *d, const struct sonar_tracker *tk)
{
    int64_t now = a->clock.mono_ns(a->clock.user);
    int late = a->late.on && tk != NULL;
    a->sweeps++;
    msg_view_of(&a->pipe, &a->view); /* d is the pipeline's own out, tk its tracker */
    if (a->sweep_t0 != 0)
        a->last_sweep_s = (float)((double)(now - a->sweep_t0) * 1e-9);
    a->sweep_t0 = now;
    if (a->max_sweeps > 0 && a->sweeps >= (uint32_t)a->max_sweeps)
        a->sweeps_done = 1;
    if (!late) {
        give(a, d, tk, &a->view, 2);
        return;
    }
    /*
     * One sweep late: the autopilot's sinks get this sweep now; the others the one held back,
     * relabelled by this one's revisions (none on the first); this one is held in its place.
     */
    give(a, d, tk, &a->view, 1);
    if (a->late.have) {
        uint8_t kept[SONAR_MAX_TRACKS];
        msg_view_keep(&a->late.view, kept, sonar_tracker_relabel(&a->late.trk, tk, kept));
        give(a, &a->late.det, &a->late.trk, &a->late.view, 0);
    }
    late_hold(a, d, tk);
}

/* The last look's alarms raised and cleared, each said once (docs/activity.md). */
static void say_alarms(const struct app *a, const struct sonar_detections *d)
{
    static const char *const what[] = {"", "struggle", "still", "struggle and still"};
    unsigned k, n;
    const struct sonar_alarm_event *e = sonar_activity_events(&a->act, &n);
    for (k = 0; k < n; k++, e++) {
        const char *frame = d->world ? "north %.1f m, east %.1f m" : "x %.1f m, y %.1f m";
        char at[64];
        snprintf(at, sizeof(at), frame, (double)e->x_m, (double)e->y_m);
        if (e->alarms & ~e->was)
            app_warn(a, "alarm: track %u: %s alarm raised at sweep %u, at %s", (unsigned)e->id,
                     what[(e->alarms & ~e->was) & 3u], (unsigned)d->sweep, at);
        if (e->was & ~e->alarms)
            app_warn(a, "alarm: track %u: %s alarm cleared at sweep %u (%s), at %s", (unsigned)e->id,
                     what[(e->was & ~e->alarms) & 3u], (unsigned)d->sweep, e->gone ? "the track ended" : "its cause went", at);
    }
}

static void on_sweep(void *user, const struct sonar_detections *d)
{
    struct app *a = user;
    app_gain_sweep(a, d->sweep);
    /* A refused --survey N ends the run: nothing more can make it a survey; its end says why. */
    if (a->rec != NULL && a->rec_ends_run && a->rec->why != SONAR_SURVEY_OK)
        a->sweeps_done = 1;
    if (sonar_pipeline_structure_promoted(&a->pipe) != a->structure_said) {
        unsigned n = sonar_pipeline_structure_count(&a->pipe);
        a->structure_said = sonar_pipeline_structure_promoted(&a->pipe);
        app_say(a, "structure: %u place%s learnt as structure at sweep %u (there since the first look and still for "
                   "%.0f s): learnt into the background, reported as structure, not objects",
                n, n == 1 ? "" : "s", (unsigned)d->sweep, (double)sonar_pipeline_running(&a->pipe)->structure_s);
    }
    {
        /* Deferred association out of room: said once a run and again each time the count doubles. */
        struct sonar_status st;
        memset(&st, 0, sizeof(st));
        sonar_status_tracking(&st, &a->pipe);
        if (st.tracker.hyp_overflow > 2u * a->hyp_overflow_said) {
            a->hyp_overflow_said = st.tracker.hyp_overflow;
            app_say(a, "tracker: %u alternative assignment%s did not fit the %d hypotheses kept (SONAR_TRK_HYPOTHESES) by "
                       "sweep %u: for them the sweep's assignment was final at once (track_hyp_overflow on SONAR_STATUS)",
                    (unsigned)st.tracker.hyp_overflow, st.tracker.hyp_overflow == 1 ? "" : "s", SONAR_TRK_HYPOTHESES,
                    (unsigned)d->sweep);
        }
    }
    say_alarms(a, d);
    to_sinks(a, d, sonar_pipeline_tracker(&a->pipe));
}

int app_init(struct app **out, struct app_storage *mem, const struct sonar_pipeline_config *pcfg,
             const struct sonar_ping360_config *dcfg, const struct sonar_ping360_io *io, const struct app_clock *clock,
             long max_sweeps, char *err, size_t errlen)
{
    struct app *a = (struct app *)(void *)mem; /* the storage is only ever used as this */
    struct sonar_pose_limits lim;
    const char *why;
    memset(a, 0, sizeof(*a));
    a->clock = *clock;
    a->max_sweeps = max_sweeps;
    a->link = "";
    a->last_gain = -1;
    a->pcfg[0] = *pcfg;
    a->pcfg[0].on_beam = on_stage;
    a->pcfg[0].on_sweep = on_sweep;
    a->pcfg[0].user = a;
    if ((why = sonar_pipeline_config_check(&a->pcfg[0])) != NULL || sonar_pipeline_init(&a->pipe, &a->bg, &a->pcfg[0]) != SONAR_OK) {
        snprintf(err, errlen, "pipeline configuration: %s", why ? why : "invalid");
        return HOST_ERR_CONFIG;
    }
    sonar_pose_limits_default(&lim);
    if (sonar_pose_init(&a->poses, &lim) != SONAR_OK) {
        snprintf(err, errlen, "pose limits: invalid");
        return HOST_ERR_CONFIG;
    }
    sonar_pipeline_set_poses(&a->pipe, &a->poses);
    if (sonar_activity_init(&a->act) != SONAR_OK)
        return HOST_ERR_CONFIG;
    sonar_pipeline_set_activity(&a->pipe, &a->act);
    sonar_clutter_init(&a->clutter);
    sonar_pipeline_set_clutter(&a->pipe, &a->clutter);
    sonar_survey_init(&a->survey, &a->spread, a->survey_places);
    sonar_pipeline_set_survey(&a->pipe, &a->survey);
    if (dcfg != NULL) {
        int r;
        if ((why = sonar_ping360_config_check(dcfg)) != NULL) {
            snprintf(err, errlen, "device configuration: %s", why);
            return HOST_ERR_CONFIG;
        }
        if ((r = sonar_device_init(&a->dev, dcfg, io)) != SONAR_OK) {
            snprintf(err, errlen, "--range %.1f m with --samples %u cannot be set on a Ping360 (sample period outside "
                                  "80..40000 ticks of 25 ns): %s", (double)dcfg->range_m, dcfg->samples, sonar_err_str(r));
            return HOST_ERR_CONFIG;
        }
        a->have_dev = 1;
    }
    *out = a;
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
        return HOST_ERR_FULL;
    s->errors = s->n_beams = s->n_detections = s->n_statuses = 0;
    a->sinks[a->nsinks++] = s;
    return HOST_OK;
}

int app_pose(struct app *a, const struct sonar_pose *p, const char **why)
{
    const char *w = sonar_pose_push_why(&a->poses, p);
    if (w == NULL)
        return HOST_OK;
    if (why != NULL)
        *why = w;
    return HOST_ERR_REFUSED;
}

/* The beam's pose: the source's (kept for the detections too), else looked up; says when it goes stale or comes back. */
static void beam_pose(struct app *a, struct sonar_record *b)
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
    state = b->has_pose ? SONAR_POSE_OK : sonar_pose_accepted(&a->poses) > 0 ? SONAR_POSE_STALE : SONAR_POSE_NONE;
    if (state == SONAR_POSE_STALE && a->pose_state != SONAR_POSE_STALE) {
        a->pose_stale++;
        app_warn(a, "pose: stale (none within 1 s of the beam at %.3f s): body-frame processing until it returns",
                (double)b->utime * 1e-6);
    } else if (state == SONAR_POSE_OK && a->pose_state != SONAR_POSE_OK) {
        app_say(a, "pose: %s at %.3f s: detections and tracks in the world frame",
                a->pose_state == SONAR_POSE_STALE ? "back" : "known", (double)b->utime * 1e-6);
    }
    a->pose_state = state;
}

int app_push(struct app *a, const struct sonar_record *b)
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
    sonar_device_beam(b, &pb); /* with its gain: the pipeline restarts its background on a change */
    t0 = a->clock.mono_ns(a->clock.user);
    {
        uint32_t changes = sonar_pipeline_geometry_changes(&a->pipe), gains = sonar_pipeline_gain_restarts(&a->pipe);
        uint32_t blanks = sonar_pipeline_blank_beams(&a->pipe), streaks = sonar_pipeline_interference_beams(&a->pipe);
        int was_gain = sonar_pipeline_gain(&a->pipe);
        float was_m;
        uint16_t was_n;
        sonar_pipeline_geometry(&a->pipe, &was_n, &was_m);
        if ((r = sonar_pipeline_push(&a->pipe, &pb)) != SONAR_OK) {
            a->beams_rejected++;
            return host_err_of(r);
        }
        a->last_gain = (int16_t)sonar_pipeline_gain(&a->pipe);
        if (sonar_pipeline_gain_restarts(&a->pipe) != gains) {
            a->bg_restarts++;
            app_say(a, "gain %d from the beam at %.3f s (was %d): the background restarts at every angle and learns "
                    "afresh over its warm-up (structure too)", (int)pb.gain, (double)pb.utime * 1e-6, was_gain);
        }
        if (sonar_pipeline_blank_beams(&a->pipe) != blanks && (blanks < APP_BLANK_SAID || (blanks + 1u) % 1000u == 0u))
            app_say(a, "beam at %u gradians (%.3f s): all %u samples %u: skipped (%s); blank beams so far: %" PRIu32 "%s",
                    (unsigned)pb.angle, (double)pb.utime * 1e-6, pb.n, (unsigned)pb.samples[0],
                    pb.samples[0] ? "saturated" : "nothing heard", blanks + 1u,
                    blanks + 1u == APP_BLANK_SAID ? " (said again every 1000th)" : "");
        if (streaks == 0 && sonar_pipeline_interference_beams(&a->pipe) != 0)
            app_warn(a, "beam at %u gradians (%.3f s) stands out along most of its length, unlike the beam before it: "
                    "interference (another sonar, a modem, the thrusters), left out of the background and the detector; "
                    "such beams are counted in SONAR_STATUS interference_beams and not said again",
                    (unsigned)pb.angle, (double)pb.utime * 1e-6);
        if (sonar_pipeline_geometry_changes(&a->pipe) != changes)
            app_say(a, "range: %u samples over %.2f m from the beam at %.3f s (was %u over %.2f m): the sweep was cut "
                    "there and the background (and its structure) starts afresh",
                    pb.n, (double)pb.range_m, (double)pb.utime * 1e-6, was_n, (double)was_m);
    }
    a->proc_us[a->nproc++ % APP_PROC_RING] = (float)((double)(a->clock.mono_ns(a->clock.user) - t0) * 1e-3);
    app_survey_watch(a);
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
    to_sinks(a, sonar_pipeline_detections(&a->pipe), sonar_pipeline_tracker(&a->pipe));
}

void app_forward(struct app *a, const struct sonar_record *b)
{
    struct sonar_record r;
    if (a->sweeps_done)
        return;
    r = *b;
    beam_pose(a, &r);
    sinks_beam(a, &r);
}

void app_send_status(struct app *a, const struct sonar_status *s)
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
    int r = host_err_of(sonar_pipeline_finish(&a->pipe));
    if (a->late.on && a->late.have) {
        give(a, &a->late.det, &a->late.trk, &a->late.view, 0); /* no look comes after it: its IDs are final */
        a->late.have = 0;
    }
    return r;
}

const struct sonar_pose_ring *app_poses(const struct app *a)
{
    return &a->poses;
}

void app_frame(const struct app *a, float *angle_offset, float *min_range_m)
{
    sonar_pipeline_frame(&a->pipe, angle_offset, min_range_m);
}

int app_pose_at(const struct app *a, int64_t t, struct sonar_pose *q)
{
    return sonar_pose_at(&a->poses, t, q);
}

int app_reconfigure(struct app *a, const struct sonar_pipeline_config *pcfg, char *err, size_t errlen)
{
    /* The spare slot is the one the pipeline is not running on (it may hold a pending reload). */
    struct sonar_pipeline_config *spare = sonar_pipeline_running(&a->pipe) == &a->pcfg[0] ? &a->pcfg[1] : &a->pcfg[0];
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
