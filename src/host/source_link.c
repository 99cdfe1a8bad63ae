/* source_link.c -- the Ping360 on a link (link.c's lifecycle) feeding the app core: the probe on connect, the device's backoff, serial auto-baud; bounded reads per wake. */
#include "source_link.h"

#include <poll.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

/* Messages go through the app's log; the link has none before it is bound to an app. */
#define say(s, ...) ((s)->app != NULL ? app_say((s)->app, __VA_ARGS__) : (void)0)
#define warn(s, ...) ((s)->app != NULL ? app_warn((s)->app, __VA_ARGS__) : (void)0)

int source_link_parse(struct source_link *s, const char *url, long baud, char *err, size_t errlen)
{
    memset(s, 0, sizeof(*s));
    if (link_parse(&s->link, "--sonar", url, LINK_ALLOW_SERIAL | LINK_ALLOW_UDP | LINK_ALLOW_TCP, baud, err, errlen) != HOST_OK)
        return HOST_ERR_CONFIG;
    link_describe(&s->link, s->desc, sizeof(s->desc));
    return HOST_OK;
}

uint32_t source_link_baud(const struct source_link *s)
{
    return s->link.kind == LINK_SERIAL ? (uint32_t)s->link.baud : 0u;
}

int source_link_send(void *user, const uint8_t *buf, size_t len)
{
    struct source_link *s = user;
    return link_write(&s->link, buf, len) == 0 ? HOST_OK : HOST_ERR_IO;
}

void source_link_break(void *user)
{
    struct source_link *s = user;
    link_line_break(&s->link, app_mono_us(s->app));
}

/* The driver's state (down before the app has one). */
static int link_device_state(const struct source_link *s)
{
    const struct sonar_device *d = app_device(s->app);
    return d != NULL ? sonar_device_state(d) : SONAR_P360_DOWN;
}

/* Gives the link up: closed now, reopened after the device's delay (sonar_device_down's policy; serial auto-baud: the next rate at once). */
static void drop(struct source_link *s, int64_t now, const char *why)
{
    int state = link_device_state(s);
    int was_probing = state == SONAR_P360_PROBING || state == SONAR_P360_DOWN;
    uint32_t backoff = app_device_down(s->app, now);
    if (s->stopping) {
        link_close(&s->link);
        s->stopped = 1;
        return;
    }
    if (was_probing && s->link.autobaud && link_next_baud(&s->link) == HOST_OK) {
        link_lost(&s->link, now, 0);
        say(s, "no answer; trying %ld baud", s->link.baud);
        return;
    }
    link_lost(&s->link, now, backoff);
    warn(s, "link lost (%s); reconnecting in %.2f s", why, backoff * 1e-6);
}

static void handle(struct source_link *s, int ev, int64_t now)
{
    if (ev == APP_DEVICE_LOST)
        drop(s, now, "no reply");
    else if (ev == APP_DEVICE_STOPPED)
        s->stopped = 1;
}

/* The link's callbacks (link_serve_*): up probes the device, bytes go to it, a loss is dropped with its delay. */
static void ep_up(void *self, int64_t now)
{
    struct source_link *s = self;
    link_describe(&s->link, s->desc, sizeof(s->desc));
    if (app_device_up(s->app, now) != HOST_OK)
        drop(s, now, "write failed");
}

static void ep_failed(void *self, const char *err, int64_t now)
{
    struct source_link *s = self;
    (void)now;
    warn(s, "%s; retrying in %g s", err, LINK_RETRY_US * 1e-6);
}

/* Read on until the device has something to say, or until the app has its sweeps, so that signals, timers and
 * --sweeps are served (while stopping it reads on: motor_off's ack comes this way). */
static int ep_bytes(void *self, const uint8_t *buf, size_t n, int64_t now)
{
    struct source_link *s = self;
    const int was_done = app_done(s->app);
    int ev = app_device_bytes(s->app, buf, n, now);
    if (ev != APP_DEVICE_NONE) {
        handle(s, ev, now);
        return 0;
    }
    return was_done || !app_done(s->app);
}

static void ep_lost(void *self, int64_t now, const char *why)
{
    drop(self, now, why);
}

static const struct link_endpoint_ops endpoint = {ep_up, ep_failed, ep_bytes, ep_lost, 0};

void source_link_start(struct source_link *s, struct app *a, int64_t now_us)
{
    s->app = a;
    app_set_link(a, s->desc);
    (void)source_link_timers(s, now_us);
}

int source_link_fd(const struct source_link *s, short *events)
{
    return link_poll_fd(&s->link, events);
}

void source_link_ready(struct source_link *s, short revents, int64_t now)
{
    link_serve_fd(&s->link, revents, now, &endpoint, s);
}

int64_t source_link_timers(struct source_link *s, int64_t now)
{
    int64_t wake, t;
    if (s->link.fd < 0 && s->stopping) {
        s->stopped = 1;
        return INT64_MAX;
    }
    if (s->link.fd >= 0 && !s->link.connecting)
        handle(s, app_device_poll(s->app, now), now);
    wake = link_serve_timers(&s->link, now, &endpoint, s); /* reopens when due, steps a line break */
    if (s->link.fd >= 0 && (t = app_deadline(s->app)) < wake)
        wake = t;
    return wake;
}

void source_link_stop(struct source_link *s, int64_t now)
{
    int r;
    s->stopping = 1;
    if (s->link.fd < 0 || s->link.connecting) {
        s->stopped = 1;
        return;
    }
    say(s, link_device_state(s) == SONAR_P360_PASSIVE ? "stopping (passive: the head is its driver's; nothing sent)"
                                                      : "stopping: motor_off");
    r = app_device_stop(s->app, now);
    if (r != 0) /* already stopped, or the request could not be sent */
        s->stopped = 1;
}

int source_link_stopped(const struct source_link *s)
{
    return s->stopped;
}

int source_link_state(const struct source_link *s)
{
    return s->link.fd >= 0 && s->link.connecting ? SONAR_P360_CONNECTING : link_device_state(s);
}

void source_link_close(struct source_link *s)
{
    link_close(&s->link);
}

static void v_start(void *s, struct app *a, int64_t now) { source_link_start(s, a, now); }
static int v_fd(const void *s, short *ev) { return source_link_fd(s, ev); }
static void v_ready(void *s, short rev, int64_t now) { source_link_ready(s, rev, now); }
static int64_t v_timers(void *s, int64_t now) { return source_link_timers(s, now); }
static void v_stop(void *s, int64_t now) { source_link_stop(s, now); }
static int v_stopped(const void *s) { return source_link_stopped(s); }
static int v_state(const void *s) { return source_link_state(s); }
static void v_close(void *s) { source_link_close(s); }

static const struct live_source_ops ops = {{v_start, v_fd, v_ready, v_timers, v_close}, v_stop, v_stopped, v_state};

void source_link_live(struct source_link *s, struct live_source *out)
{
    out->ops = &ops;
    out->self = s;
}
