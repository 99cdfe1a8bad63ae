/* app_device.c -- the app on a live link: bytes to the device core, its beams to app_push, its timers and stop; O(bytes) per call. */
#include "app_internal.h"

#include <stdio.h>

/* --passive: the driving program's settings as its beams show them; a change is said and counted (the pipeline cuts the sweep). */
static void passive_beam(struct app *a, const struct sonar_record *b)
{
    const struct sonar_record *p = &a->passive_last;
    if (a->passive_idle) {
        app_say(a, "passive: beams again after %.1f s", (double)(b->utime - p->utime) * 1e-6);
        a->passive_idle = 0;
    }
    if (p->n != 0 && (p->n != b->n || p->sample_period != b->sample_period || p->gain != b->gain)) {
        a->passive_changes++;
        app_say(a, "passive: the driving program changed its settings: range %.2f -> %.2f m, samples %u -> %u, gain %d -> %d",
                (double)p->range_m, (double)b->range_m, p->n, b->n, (int)p->gain, (int)b->gain);
    }
    a->passive_last = *b;
    a->passive_last.samples = NULL;
}

static int on_event(struct app *a, struct sonar_device_event *ev)
{
    switch (ev->kind) {
    case SONAR_P360_EV_READY: {
        uint8_t fw[3];
        int streaming = sonar_device_state(&a->dev) == SONAR_P360_AUTO;
        sonar_device_firmware(&a->dev, fw);
        app_say(a, "Ping360 firmware %u.%u.%u on %s", fw[0], fw[1], fw[2], a->link);
        if (sonar_device_state(&a->dev) == SONAR_P360_PASSIVE) {
            app_say(a, "passive: using the beams another program draws; sending nothing that moves or sets the head");
            return APP_DEVICE_NONE;
        }
        app_say(a, "scanning (%s)", streaming ? "auto_transmit" : "stepping");
        if (a->have_scan && streaming && !a->scan_said) {
            app_say(a, "--scan follow: the sonar steps itself in auto_transmit mode, so the planner cannot steer it; "
                       "sweeping (use --mode step to follow)");
            a->scan_said = 1;
        }
        return APP_DEVICE_NONE;
    }
    case SONAR_P360_EV_IDLE:
        a->passive_idle = 1;
        app_warn(a, "passive: no beam for %.1f s: the program driving the head stopped, or the bridge dropped us "
                    "(asking the device again each second)", SONAR_P360_IDLE_US * 1e-6);
        return APP_DEVICE_NONE;
    case SONAR_P360_EV_BEAM:
        ev->beam.utime = app_wall_us(a); /* a live beam is timed by its receipt */
        if (sonar_device_state(&a->dev) == SONAR_P360_PASSIVE)
            passive_beam(a, &ev->beam);
        if (a->have_gain_auto && !a->gain_off)
            sonar_gain_beam(&a->gain, ev->beam.samples, ev->beam.n, (uint8_t)ev->beam.gain);
        if (app_push(a, &ev->beam) != HOST_OK)
            return APP_DEVICE_NONE; /* counted in beams_rejected; the sinks still had the raw beam */
        return APP_DEVICE_NONE;
    case SONAR_P360_EV_LINK_LOST:
        return APP_DEVICE_LOST;
    case SONAR_P360_EV_STOPPED:
        return APP_DEVICE_STOPPED;
    default:
        return APP_DEVICE_NONE;
    }
}

int app_device_bytes(struct app *a, const uint8_t *buf, size_t len, int64_t now_us)
{
    const uint8_t *in = buf;
    struct sonar_device_event ev;
    while (sonar_device_bytes(&a->dev, &in, &len, now_us, &ev) == 1) {
        int r = on_event(a, &ev);
        if (r != APP_DEVICE_NONE)
            return r;
    }
    return APP_DEVICE_NONE;
}

int app_device_up(struct app *a, int64_t now_us)
{
    return sonar_device_up(&a->dev, now_us);
}

uint32_t app_device_down(struct app *a, int64_t now_us)
{
    return sonar_device_down(&a->dev, now_us);
}

int app_device_poll(struct app *a, int64_t now_us)
{
    struct sonar_device_event ev;
    if (!a->have_dev || sonar_device_poll(&a->dev, now_us, &ev) != 1)
        return APP_DEVICE_NONE;
    return on_event(a, &ev);
}

int64_t app_deadline(const struct app *a)
{
    return a->have_dev ? sonar_device_deadline(&a->dev) : INT64_MAX;
}

int app_device_stop(struct app *a, int64_t now_us)
{
    int r = sonar_device_stop(&a->dev, now_us);
    if (r != SONAR_OK)
        return r;
    return sonar_device_state(&a->dev) == SONAR_P360_STOPPED;
}

const struct sonar_device *app_device(const struct app *a)
{
    return a->have_dev ? &a->dev : NULL;
}

/* The driver's next_angle: the planner, with the tracks predicted to the wall clock now. */
static uint16_t next_angle(void *user, int64_t now_us)
{
    struct app *a = user;
    struct sonar_scan_target t[SONAR_SCAN_MAX_TARGETS];
    unsigned n = sonar_pipeline_targets(&a->pipe, app_wall_us(a), t, SONAR_SCAN_MAX_TARGETS);
    return sonar_scan_next(&a->scan, t, n, now_us);
}

int app_set_scan(struct app *a, const struct sonar_scan_config *cfg, char *err, size_t errlen)
{
    struct sonar_scan_config c = *cfg;
    const struct sonar_ping360_config *d = sonar_device_config(&a->dev);
    const char *why;
    if (!a->have_dev) {
        snprintf(err, errlen, "--scan: no sonar to steer");
        return HOST_ERR_CONFIG;
    }
    if (c.mode == SONAR_SCAN_SWEEP)
        return HOST_OK;
    c.start_angle = d->start_angle;
    c.stop_angle = d->stop_angle;
    c.full_circle = d->full_circle;
    c.step = d->step;
    c.ping_us = sonar_ping360_model_us(1, d->range_m, d->speed_of_sound, d->baud, sonar_device_samples(&a->dev)) - SONAR_SCAN_GRAD_US;
    if ((why = sonar_scan_config_check(&c)) != NULL || sonar_scan_init(&a->scan, &c) != SONAR_OK) {
        snprintf(err, errlen, "--scan follow: %s", why ? why : "invalid");
        return HOST_ERR_CONFIG;
    }
    a->have_scan = 1;
    sonar_device_set_planner(&a->dev, next_angle, a);
    return HOST_OK;
}

static const char *gain_name(int g)
{
    return g == 0 ? "low" : g == 1 ? "normal" : g == 2 ? "high" : "unknown";
}

int app_set_gain_auto(struct app *a, const struct sonar_gain_config *cfg, char *err, size_t errlen)
{
    struct sonar_gain_config c = *cfg;
    const char *why;
    if (!a->have_dev) {
        snprintf(err, errlen, "--gain auto: no sonar to set");
        return HOST_ERR_CONFIG;
    }
    c.start = sonar_device_config(&a->dev)->gain;
    if ((why = sonar_gain_config_check(&c)) != NULL || sonar_gain_init(&a->gain, &c) != SONAR_OK) {
        snprintf(err, errlen, "--gain auto: %s", why ? why : "invalid");
        return HOST_ERR_CONFIG;
    }
    a->have_gain_auto = 1;
    return HOST_OK;
}

void app_gain_sweep(struct app *a, uint32_t sweep)
{
    int r, was = a->gain.gain;
    if (!a->have_gain_auto || a->gain_off)
        return;
    if (a->gain.samples == 0 && a->gain.other > 0 && a->gain.changes > 0) {
        /* A whole sweep and not one beam at the setting asked: the sonar keeps its own. */
        a->gain_off = 1;
        a->gain_refused++;
        if (a->last_gain >= 0 && a->last_gain <= SONAR_GAIN_MAX)
            (void)!sonar_device_set_gain(&a->dev, a->last_gain); /* ask for what it gives (0..2: taken) */
        app_warn(a, "gain auto: the sonar kept its gain for a whole sweep though %s was asked; auto gain off",
                gain_name(was));
        return;
    }
    if ((r = sonar_gain_sweep_end(&a->gain)) < 0)
        return;
    if (sonar_device_set_gain(&a->dev, r) != SONAR_OK)
        return; /* sonar_gain_sweep_end gives 0..2 */
    app_say(a, "gain auto: %s -> %s after sweep %u (%.2f %% of its samples saturated, median %u)", gain_name(was),
            gain_name(r), (unsigned)sweep, (double)a->gain.last_sat * 100.0, a->gain.last_median);
}
