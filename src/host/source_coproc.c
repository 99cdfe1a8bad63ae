/* source_coproc.c -- co-processor frames in (detections, status, beams, replies), the configuration out; resync on garbage, a corrupt frame counted and dropped, never published; O(bytes). */
#include "source_coproc.h"

#include <poll.h>
#include <stdio.h>
#include <string.h>

#include "msg.h"
#include "sonar_beam_t.h"
#include "sonar_config_t.h"
#include "sonar_detections_t.h"
#include "sonar_status_t.h"

#define say(s, ...) ((s)->app != NULL ? app_say((s)->app, __VA_ARGS__) : (void)0)

static int build_config(struct source_coproc *s, const struct sonard_options *o, char *err, size_t errlen)
{
    const struct sonar_ping360_config *d = &o->device;
    const struct sonar_pipeline_config *p = &o->pipeline;
    uint8_t msg[400];
    sonar_config_t c;
    int n;
    memset(&c, 0, sizeof(c));
    c.range_m = d->range_m;
    c.speed_of_sound = d->speed_of_sound;
    c.samples = (int16_t)d->samples;
    c.transmit_duration = (int16_t)d->transmit_duration;
    c.gain = (int8_t)d->gain;
    c.frequency = (int16_t)d->frequency;
    c.start_angle = (int16_t)d->start_angle;
    c.stop_angle = (int16_t)d->stop_angle;
    c.step = (int8_t)d->step;
    c.full_circle = (int8_t)d->full_circle;
    c.use_auto = (int8_t)d->use_auto;
    c.baud = 115200;
    c.median = (int8_t)p->median;
    c.median2d = (int8_t)p->median2d;
    c.max_step = (int16_t)p->max_step;
    c.bg_mode = (int8_t)p->background.mode;
    c.bg_warmup = (int8_t)p->background.warmup;
    c.bg_step = (int8_t)p->background.step;
    c.bg_margin = (int8_t)p->background.margin;
    c.threshold_mode = (int8_t)p->detector.threshold_mode;
    c.cfar_across = (int8_t)p->detector.cfar.across;
    c.cfar_cut = (int8_t)p->detector.cfar.cut;
    c.cfar_guard = (int8_t)p->detector.cfar.guard;
    c.cfar_train = (int8_t)p->detector.cfar.train;
    c.cfar_rank16 = (int8_t)p->detector.cfar.rank16;
    c.cfar_scale = p->detector.cfar.scale;
    c.cfar_floor = p->detector.cfar.floor;
    c.threshold_k = p->detector.threshold_k;
    c.min_threshold = p->detector.min_threshold;
    c.max_clusters = p->detector.max_clusters;
    c.iterations = p->detector.iterations;
    c.link_beams = p->detector.link_beams;
    c.min_points = p->detector.min_points;
    c.link_m = p->detector.link_m;
    c.angle_offset = p->detector.angle_offset;
    c.min_beams = p->detector.min_beams;
    c.max_extent_m = p->detector.max_extent_m;
    c.split_points = p->detector.split_points;
    c.min_range_m = p->detector.min_range_m;
    c.max_aspect = p->detector.max_aspect;
    c.track_m = p->detector.track_m;
    c.track_points = p->detector.track_points;
    c.track = p->track != 0;
    c.track_accel_mps2 = p->tracker.accel_mps2;
    c.track_manoeuvre_mps2 = p->tracker.manoeuvre_mps2;
    c.track_meas_m = p->tracker.meas_m;
    c.track_speed0_mps = p->tracker.speed0_mps;
    c.track_max_speed_mps = p->tracker.max_speed_mps;
    c.track_gate = p->tracker.gate;
    c.track_confirm_m = (int8_t)p->tracker.confirm_m;
    c.track_confirm_n = (int8_t)p->tracker.confirm_n;
    c.track_max_misses = (int16_t)p->tracker.max_misses;
    c.track_max_dt_s = p->tracker.max_dt_s;
    c.beam_every = (int16_t)o->coproc_beams;
    n = sonar_config_t_encode(msg, 0, (int)sizeof(msg), &c);
    if (n < 0 || (s->config_len = sonar_cpf_encode(s->config, sizeof(s->config), SONAR_CPF_CONFIG, msg, (uint16_t)n)) < 0) {
        snprintf(err, errlen, "--coprocessor: the configuration does not fit a frame");
        return HOST_ERR_CONFIG;
    }
    return HOST_OK;
}

int source_coproc_parse(struct source_coproc *s, const char *url, const struct sonard_options *o, char *err, size_t errlen)
{
    memset(s, 0, sizeof(*s));
    s->reconnect_at = INT64_MAX;
    sonar_cpf_parser_init(&s->parser);
    if (link_parse(&s->link, url, o->baud, err, errlen) != HOST_OK)
        return HOST_ERR_CONFIG;
    link_describe(&s->link, s->desc, sizeof(s->desc));
    return build_config(s, o, err, errlen);
}

static void send_config(struct source_coproc *s, int64_t now)
{
    s->config_at = now + COPROC_CONFIG_RETRY_US;
    if (link_write(&s->link, s->config, (size_t)s->config_len) != HOST_OK)
        say(s, "co-processor: the configuration could not be sent; retrying");
}

static void lost(struct source_coproc *s, int64_t now, const char *why)
{
    link_close(&s->link);
    s->configured = 0;
    sonar_cpf_parser_init(&s->parser);
    if (s->stopping) {
        s->stopped = 1;
        return;
    }
    s->reconnect_at = now + 1000000;
    say(s, "co-processor link lost (%s); reconnecting in 1 s", why);
}

static void try_open(struct source_coproc *s, int64_t now)
{
    char err[256];
    s->reconnect_at = INT64_MAX;
    if (link_open(&s->link, now, err, sizeof(err)) != HOST_OK) {
        s->reconnect_at = now + 1000000;
        say(s, "%s; retrying in 1 s", err);
        return;
    }
    if (!s->link.connecting)
        send_config(s, now);
}

static void on_status(struct source_coproc *s, const sonar_status_t *m)
{
    struct app_status st;
    memset(&st, 0, sizeof(st));
    st.utime = m->utime;
    st.link_state = m->link_state;
    st.link = s->desc;
    st.fw[0] = (uint8_t)m->fw_major;
    st.fw[1] = (uint8_t)m->fw_minor;
    st.fw[2] = (uint8_t)m->fw_patch;
    st.parser.frames = (uint32_t)m->frames;
    st.parser.checksum_errors = (uint32_t)m->checksum_errors;
    st.parser.resyncs = (uint32_t)m->resyncs;
    st.parser.oversize = (uint32_t)m->oversize;
    st.parser.bytes_dropped = (uint32_t)m->bytes_dropped;
    st.driver.timeouts = (uint32_t)m->timeouts;
    st.driver.retries = (uint32_t)m->retries;
    st.driver.nacks = (uint32_t)m->nacks;
    st.driver.reconnects = (uint32_t)m->reconnects;
    st.driver.stale = (uint32_t)m->stale;
    st.driver.beams = (uint32_t)m->beams;
    st.sweeps = (uint32_t)m->sweeps;
    st.beams_rejected = (uint32_t)m->beams_rejected;
    st.stack_used = m->stack_used < 0 ? 0u : (uint32_t)m->stack_used;
    /* The link's own health, as the host sees it, rides in the counters the firmware leaves free. */
    st.rows_bad = s->parser.counters.crc_errors + s->decode_errors;
    st.sink_errors = (uint32_t)m->sink_errors + (uint32_t)app_sink_errors(s->app);
    app_pose_status(s->app, &st); /* the pose is the host's own */
    app_send_status(s->app, &st);
}

static void frame(struct source_coproc *s, const struct sonar_cpf_frame *f, int64_t now)
{
    (void)now;
    switch (f->channel) {
    case SONAR_CPF_REPLY:
        if (f->len >= 2 && memcmp(f->payload, "ok", 2) == 0) {
            if (!s->configured)
                say(s, "co-processor on %s: configuration accepted", s->desc);
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
        struct app_beam b;
        if (!s->configured)
            break;
        if (sonar_beam_t_decode(f->payload, 0, f->len, &m) < 0) {
            s->decode_errors++;
            break;
        }
        b.utime = m.utime;
        b.angle = (uint16_t)m.angle;
        b.n = (uint16_t)m.number_of_samples;
        b.gain = m.gain;
        b.sample_period = m.sample_period;
        b.transmit_duration = m.transmit_duration;
        b.transmit_frequency = m.transmit_frequency;
        b.speed_of_sound = m.speed_of_sound;
        b.range_m = m.range_m;
        b.stage = SONAR_STAGE_RAW;
        b.has_pose = 0;
        b.north_m = b.east_m = b.yaw_deg = 0.0f;
        b.samples = m.samples;
        app_forward(s->app, &b);
        sonar_beam_t_decode_cleanup(&m);
        break;
    }
    default:
        break;
    }
}

static void readable(struct source_coproc *s, int64_t now)
{
    uint8_t buf[4096];
    int reads;
    const int was_done = s->app->sweeps_done;
    for (reads = 0; reads < 16 && !(!was_done && s->app->sweeps_done) && !s->stopped; reads++) {
        ssize_t n = link_read(&s->link, buf, sizeof(buf));
        const uint8_t *in = buf;
        size_t len;
        struct sonar_cpf_frame f;
        if (n < 0) {
            lost(s, now, "closed");
            return;
        }
        if (n == 0)
            return;
        len = (size_t)n;
        while (sonar_cpf_next(&s->parser, &in, &len, &f) == 1)
            frame(s, &f, now);
    }
}

static void v_start(void *self, struct app *a, int64_t now)
{
    struct source_coproc *s = self;
    s->app = a;
    a->link = s->desc;
    try_open(s, now);
}

static int v_fd(const void *self, short *events)
{
    const struct source_coproc *s = self;
    *events = (short)(s->link.connecting ? POLLOUT : POLLIN);
    return s->link.fd;
}

static void v_ready(void *self, short revents, int64_t now)
{
    struct source_coproc *s = self;
    char err[256];
    if (s->link.fd < 0)
        return;
    if (s->link.connecting && (revents & (POLLOUT | POLLERR | POLLHUP))) {
        if (link_finish_connect(&s->link, err, sizeof(err)) != HOST_OK) {
            link_close(&s->link);
            s->reconnect_at = now + 1000000;
            say(s, "%s; retrying in 1 s", err);
        } else {
            send_config(s, now);
        }
    } else if (revents & POLLIN) {
        readable(s, now);
    } else if (revents & (POLLERR | POLLHUP | POLLNVAL)) {
        lost(s, now, "hung up");
    }
}

static int64_t v_timers(void *self, int64_t now)
{
    struct source_coproc *s = self;
    if (s->link.fd < 0 && !s->stopping && now >= s->reconnect_at)
        try_open(s, now);
    if (s->link.fd >= 0 && !s->link.connecting && !s->configured && now >= s->config_at)
        send_config(s, now); /* the firmware did not answer: the frame may have been lost */
    return s->link.fd >= 0 && !s->configured && s->config_at < s->reconnect_at ? s->config_at : s->reconnect_at;
}

static void v_stop(void *self, int64_t now)
{
    struct source_coproc *s = self;
    (void)now;
    /* The firmware keeps the sonar running; stopping the head is its decision, not the viewer's. */
    s->stopping = s->stopped = 1;
}

static int v_stopped(const void *self) { return ((const struct source_coproc *)self)->stopped; }

static int v_state(const void *self)
{
    const struct source_coproc *s = self;
    return s->link.fd < 0 ? SONAR_P360_DOWN : s->link.connecting ? SONAR_P360_CONNECTING : SONAR_P360_SCANNING;
}

static void v_close(void *self)
{
    struct source_coproc *s = self;
    link_close(&s->link);
}

static const struct live_source_ops ops = {v_start, v_fd, v_ready, v_timers, v_stop, v_stopped, v_state, v_close, 1};

void source_coproc_live(struct source_coproc *s, struct live_source *out)
{
    out->ops = &ops;
    out->self = s;
}
