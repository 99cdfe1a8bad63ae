/* source_coproc.c -- co-processor frames in (detections, status, beams, replies), the configuration out; resync on garbage, a corrupt frame counted and dropped, never published; O(bytes). */
#include "source_coproc.h"

#include <stdio.h>
#include <string.h>

#include "msg.h"
#include "sonar_beam_t.h"
#include "sonar_config_t.h"
#include "sonar_detections_t.h"
#include "sonar_status_t.h"

#define say(s, ...) ((s)->app != NULL ? app_say((s)->app, __VA_ARGS__) : (void)0)
#define warn(s, ...) ((s)->app != NULL ? app_warn((s)->app, __VA_ARGS__) : (void)0)

static int build_config(struct source_coproc *s, const struct source_coproc_config *cc, char *err, size_t errlen)
{
    uint8_t msg[400];
    sonar_config_t c;
    int n;
    msg_config(cc->device, cc->pipeline, cc->beam_every, &c);
    n = sonar_config_t_encode(msg, 0, (int)sizeof(msg), &c);
    if (n < 0 || (s->config_len = sonar_cpf_encode(s->config, sizeof(s->config), SONAR_CPF_CONFIG, msg, (uint16_t)n)) < 0) {
        snprintf(err, errlen, "--coprocessor: the configuration does not fit a frame");
        return HOST_ERR_CONFIG;
    }
    return HOST_OK;
}

int source_coproc_parse(struct source_coproc *s, const char *url, const struct source_coproc_config *cc, char *err, size_t errlen)
{
    memset(s, 0, sizeof(*s));
    s->config_at = INT64_MAX;
    sonar_cpf_parser_init(&s->parser);
    if (link_parse(&s->link, "--coprocessor", url, LINK_ALLOW_SERIAL | LINK_ALLOW_UDP | LINK_ALLOW_TCP, cc->baud, err,
                   errlen) != HOST_OK)
        return HOST_ERR_CONFIG;
    link_describe(&s->link, s->desc, sizeof(s->desc));
    return build_config(s, cc, err, errlen);
}

static void send_config(struct source_coproc *s, int64_t now)
{
    s->config_at = now + COPROC_CONFIG_RETRY_US;
    if (link_write(&s->link, s->config, (size_t)s->config_len) != HOST_OK)
        warn(s, "co-processor: the configuration could not be sent; retrying");
}

int source_coproc_reconfigure(struct source_coproc *s, const struct source_coproc_config *cc, int64_t now, char *err,
                              size_t errlen)
{
    if (build_config(s, cc, err, errlen) != HOST_OK)
        return HOST_ERR_CONFIG;
    s->reloading = 1;
    s->configured = 0;
    if (s->link.fd >= 0 && !s->link.connecting)
        send_config(s, now);
    return HOST_OK;
}

static void lost(struct source_coproc *s, int64_t now, const char *why)
{
    s->configured = 0;
    s->config_at = INT64_MAX;
    sonar_cpf_parser_init(&s->parser);
    if (s->stopping) {
        link_close(&s->link);
        s->stopped = 1;
        return;
    }
    link_lost(&s->link, now, LINK_RETRY_US);
    warn(s, "co-processor link lost (%s); reconnecting in %g s", why, LINK_RETRY_US * 1e-6);
}

static void on_status(struct source_coproc *s, const sonar_status_t *m)
{
    struct sonar_status st;
    msg_status_in(m, &st);
    st.link = s->desc;
    /* The host's own side of it: the link's bad frames, its sinks, its poses. */
    st.coproc.frames_bad = s->parser.counters.crc_errors + s->decode_errors;
    app_host_status(s->app, &st);
    app_send_status(s->app, &st);
}

static void frame(struct source_coproc *s, const struct sonar_cpf_frame *f, int64_t now)
{
    (void)now;
    switch (f->channel) {
    case SONAR_CPF_REPLY:
        if (f->len >= 9 && memcmp(f->payload, "warning: ", 9) == 0) {
            /* Something the firmware cannot do with what the sonar sends (not the configuration): said, run on. */
            warn(s, "co-processor: %.*s", (int)f->len - 9, (const char *)f->payload + 9);
        } else if (f->len >= 2 && memcmp(f->payload, "ok", 2) == 0) {
            if (!s->configured)
                say(s, "co-processor on %s: configuration accepted%s", s->desc, s->reloading ? " (SIGHUP)" : "");
            s->configured = 1;
            s->reloading = 0;
            s->config_at = INT64_MAX;
        } else if (s->reloading) {
            /* The firmware keeps what it runs: so does sonard. */
            warn(s, "SIGHUP: the co-processor refused the configuration: %.*s; it keeps its running settings",
                     (int)f->len, (const char *)f->payload);
            s->reloading = 0;
            s->configured = 1;
            s->config_at = INT64_MAX;
        } else {
            snprintf(s->why, sizeof(s->why), "%.*s", (int)f->len, (const char *)f->payload);
            s->refused = 1;
            fprintf(stderr, "sonard: co-processor refused the configuration: %s\n", s->why);
            s->stopping = s->stopped = 1;
        }
        break;
    case SONAR_CPF_DETECTIONS: {
        sonar_detections_t m;
        struct sonar_detections d;
        if (!s->configured) {
            s->dropped_before_config++; /* from the settings before ours */
            break;
        }
        if (sonar_detections_t_decode(f->payload, 0, f->len, &m) < 0) {
            s->decode_errors++;
            break;
        }
        msg_detections_in(&m, &d);
        sonar_detections_t_decode_cleanup(&m);
        app_detections(s->app, &d);
        break;
    }
    case SONAR_CPF_STATUS: {
        sonar_status_t m;
        if (sonar_status_t_decode(f->payload, 0, f->len, &m) < 0) {
            s->decode_errors++;
            break;
        }
        on_status(s, &m);
        sonar_status_t_decode_cleanup(&m);
        break;
    }
    case SONAR_CPF_BEAM: {
        sonar_beam_t m;
        struct sonar_record b;
        if (!s->configured)
            break;
        if (sonar_beam_t_decode(f->payload, 0, f->len, &m) < 0) {
            s->decode_errors++;
            break;
        }
        msg_beam_in(&m, &b);
        b.has_pose = 0; /* the vehicle's pose is the host's: app_forward looks it up */
        app_forward(s->app, &b);
        sonar_beam_t_decode_cleanup(&m);
        break;
    }
    default:
        break;
    }
}

/* The link's callbacks (link_serve_*): up sends the configuration, frames go in, a loss waits LINK_RETRY_US. */
static void ep_up(void *self, int64_t now)
{
    send_config(self, now);
}

static void ep_failed(void *self, const char *err, int64_t now)
{
    struct source_coproc *s = self;
    (void)now;
    warn(s, "%s; retrying in %g s", err, LINK_RETRY_US * 1e-6);
}

/* Frames to their owners; reading stops once the app has its sweeps (signals, timers and --sweeps are served). */
static int ep_bytes(void *self, const uint8_t *buf, size_t n, int64_t now)
{
    struct source_coproc *s = self;
    const int was_done = app_done(s->app);
    const uint8_t *in = buf;
    struct sonar_cpf_frame f;
    while (sonar_cpf_next(&s->parser, &in, &n, &f) == 1)
        frame(s, &f, now);
    return !s->stopped && (was_done || !app_done(s->app));
}

static void ep_lost(void *self, int64_t now, const char *why)
{
    lost(self, now, why);
}

static const struct link_endpoint_ops endpoint = {ep_up, ep_failed, ep_bytes, ep_lost, 0};

static int64_t v_timers(void *self, int64_t now)
{
    struct source_coproc *s = self;
    if (s->link.fd < 0 && s->stopping)
        return INT64_MAX;
    (void)link_serve_timers(&s->link, now, &endpoint, s);
    if (s->link.fd >= 0 && !s->link.connecting && !s->configured && now >= s->config_at)
        send_config(s, now); /* the firmware did not answer: the frame may have been lost */
    return s->link.fd >= 0 && !s->configured && s->config_at < link_wake(&s->link) ? s->config_at : link_wake(&s->link);
}

static void v_start(void *self, struct app *a, int64_t now)
{
    struct source_coproc *s = self;
    s->app = a;
    app_set_link(a, s->desc);
    (void)v_timers(s, now);
}

static int v_fd(const void *self, short *events)
{
    const struct source_coproc *s = self;
    return link_poll_fd(&s->link, events);
}

static void v_ready(void *self, short revents, int64_t now)
{
    struct source_coproc *s = self;
    link_serve_fd(&s->link, revents, now, &endpoint, s);
}

static void v_stop(void *self, int64_t now)
{
    struct source_coproc *s = self;
    (void)now;
    /* The firmware keeps the sonar running; stopping the head is its decision, not the viewer's. */
    s->stopping = s->stopped = 1;
}

static int v_stopped(const void *self) { return ((const struct source_coproc *)self)->stopped; }

static void v_close(void *self)
{
    struct source_coproc *s = self;
    link_close(&s->link);
}

/* No state: the firmware's status frames are the status. */
static const struct live_source_ops ops = {{v_start, v_fd, v_ready, v_timers, v_close}, v_stop, v_stopped, NULL};

void source_coproc_live(struct source_coproc *s, struct live_source *out)
{
    out->ops = &ops;
    out->self = s;
}
