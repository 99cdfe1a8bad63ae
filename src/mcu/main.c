/* main.c -- the co-processor firmware: the core's Ping360 driver and pipeline on UART0, co-processor frames of LCM messages on UART1 (docs/coprocessor.md); no heap, no OS; RAM: struct fw ~ 545 KB at 400 x 1200. */
#include <string.h>

#include "board.h"
#include "msg.h"
#include "sonar/cpframe.h"
#include "sonar/geometry.h"
#include "sonar/ping360.h"
#include "sonar/pipeline.h"
#include "sonar_beam_t.h"
#include "sonar_config_t.h"
#include "sonar_status_t.h"

#define STATUS_US 1000000

struct fw {
    struct sonar_ping_parser sonar;  /* UART0 framing */
    struct sonar_cpf_parser host;    /* UART1 framing */
    struct sonar_ping360 drv;
    struct sonar_ping360_config dcfg;
    struct sonar_pipeline_config pcfg, next; /* running; a configuration being checked */
    struct sonar_pipeline pipe;
    uint16_t beam_every;             /* forward every Nth raw beam; 0 = none */
    uint32_t beams, sweeps, frames_dropped, config_errors, rejected;
    int64_t next_status, reconnect_at;
    /* One frame buffer: messages are encoded at its payload offset and framed in place (4 KB less RAM). */
    uint8_t out[SONAR_CPF_MAX_PAYLOAD + SONAR_CPF_OVERHEAD];
};

#define MSG(f) ((f)->out + SONAR_CPF_HEADER)
#define MSG_CAP ((int)SONAR_CPF_MAX_PAYLOAD)

static int sonar_send(void *user, const uint8_t *buf, size_t len)
{
    (void)user;
    /* A request that does not fit is not sent: the driver's timeout sends it again. */
    if (board_uart_room(BOARD_UART_SONAR) < len)
        return SONAR_ERR_SPACE;
    return board_uart_write(BOARD_UART_SONAR, buf, len) == len ? SONAR_OK : SONAR_ERR_SPACE;
}

/* A frame to the host, whole or not at all: a host that stops reading costs frames, never the loop. */
static void host_send(struct fw *f, uint8_t channel, int len)
{
    int n;
    if (len < 0 || (n = sonar_cpf_encode(f->out, sizeof(f->out), channel, MSG(f), (uint16_t)len)) < 0 ||
        board_uart_room(BOARD_UART_HOST) < (size_t)n) {
        f->frames_dropped++;
        return;
    }
    (void)board_uart_write(BOARD_UART_HOST, f->out, (size_t)n);
}

static void reply(struct fw *f, const char *what, const char *why)
{
    size_t a = strlen(what), b = why ? strlen(why) : 0;
    if (a + b + 2 > (size_t)MSG_CAP)
        return;
    memcpy(MSG(f), what, a);
    if (why != NULL) {
        MSG(f)[a] = ':';
        MSG(f)[a + 1] = ' ';
        memcpy(MSG(f) + a + 2, why, b);
        a += b + 2;
    }
    host_send(f, SONAR_CPF_REPLY, (int)a);
}

static void on_sweep(void *user, const struct sonar_detections *d)
{
    struct fw *f = user;
    sonar_detection_t det[SONAR_MAX_CLUSTERS];
    sonar_detections_t m;
    f->sweeps++;
    msg_detections(d, NULL, det, &m); /* the vehicle's pose is the host's */
    host_send(f, SONAR_CPF_DETECTIONS, sonar_detections_t_encode(MSG(f), 0, MSG_CAP, &m));
}

static void forward_beam(struct fw *f, const struct sonar_ping360_data *d, float range_m, int64_t utime)
{
    sonar_beam_t m;
    m.utime = utime;
    m.angle = (int16_t)d->angle;
    m.gain = (int8_t)d->gain;
    m.sample_period = (int16_t)d->sample_period;
    m.transmit_duration = (int16_t)d->transmit_duration;
    m.transmit_frequency = (int16_t)d->transmit_frequency;
    m.speed_of_sound = f->dcfg.speed_of_sound;
    m.range_m = range_m;
    m.stage = SONAR_STAGE_RAW;
    m.has_pose = 0; /* the vehicle's pose is the host's: it fills these in when it records the beam */
    m.north_m = m.east_m = m.yaw_deg = 0.0f;
    m.number_of_samples = (int16_t)d->data_length;
    m.samples = (uint8_t *)(uintptr_t)d->data;
    host_send(f, SONAR_CPF_BEAM, sonar_beam_t_encode(MSG(f), 0, MSG_CAP, &m));
}

static void beam_in(struct fw *f, const struct sonar_ping360_data *d, int64_t now)
{
    struct sonar_beam b;
    float range = (float)sonar_geometry_range_m(d->sample_period, d->data_length, f->dcfg.speed_of_sound);
    f->beams++;
    if (f->beam_every > 0 && f->beams % f->beam_every == 0)
        forward_beam(f, d, range, now);
    b.utime = now;
    b.angle = d->angle;
    b.n = d->data_length;
    b.range_m = range;
    b.samples = d->data;
    if (sonar_pipeline_push(&f->pipe, &b) != SONAR_OK)
        f->rejected++; /* bad geometry from the device: not processed, counted in status */
}

static void on_event(struct fw *f, const struct sonar_ping360_event *ev, int64_t now)
{
    if (ev->kind == SONAR_P360_EV_BEAM)
        beam_in(f, &ev->data, now);
    else if (ev->kind == SONAR_P360_EV_LINK_LOST)
        f->reconnect_at = now + ev->backoff_us; /* a UART cannot be reopened: probe again after the backoff */
}

static void status(struct fw *f, int64_t now)
{
    sonar_status_t m;
    memset(&m, 0, sizeof(m));
    m.utime = now;
    m.link_state = (int8_t)f->drv.state;
    m.link = (char *)(uintptr_t)"coprocessor:uart0";
    m.fw_major = (int8_t)f->drv.info.fw_major;
    m.fw_minor = (int8_t)f->drv.info.fw_minor;
    m.fw_patch = (int8_t)f->drv.info.fw_patch;
    m.frames = f->sonar.counters.frames;
    m.checksum_errors = f->sonar.counters.checksum_errors;
    m.resyncs = f->sonar.counters.resyncs;
    m.oversize = f->sonar.counters.oversize;
    m.bytes_dropped = f->sonar.counters.bytes_dropped;
    m.timeouts = f->drv.counters.timeouts;
    m.retries = f->drv.counters.retries;
    m.nacks = f->drv.counters.nacks;
    m.reconnects = f->drv.counters.reconnects;
    m.stale = f->drv.counters.stale;
    m.beams = f->drv.counters.beams;
    m.sweeps = f->sweeps;
    m.rows_bad = f->host.counters.crc_errors; /* frames from the host that failed their CRC */
    m.sink_errors = f->frames_dropped;        /* frames the host link could not take */
    m.beams_rejected = f->rejected;
    m.stack_used = (int32_t)board_stack_used();
    if (f->pipe.cfg != NULL && f->pipe.cfg->track) {
        m.tracks = (int16_t)f->pipe.trk.n;
        m.tracks_ended = f->pipe.trk.deleted;
        m.track_bad_detections = f->pipe.trk.bad_detections;
        m.track_clock_back = f->pipe.trk.clock_back;
        m.track_overflow = f->pipe.trk.overflow;
    }
    m.nacks += f->config_errors; /* configurations refused count as NACKs of the host's requests */
    host_send(f, SONAR_CPF_STATUS, sonar_status_t_encode(MSG(f), 0, MSG_CAP, &m));
}

static const struct sonar_ping360_io io = {sonar_send, NULL, NULL};

/* A wire integer into a narrower field; one that does not fit becomes `bad`, which the core's check refuses by name. */
static uint8_t to_u8(int32_t v, uint8_t bad)
{
    return v < 0 || v > 255 ? bad : (uint8_t)v;
}

static uint16_t to_u16(int32_t v, uint16_t bad)
{
    return v < 0 || v > 65535 ? bad : (uint16_t)v;
}

/* The host's sonar.config_t: checked whole with the core's checks, applied, or refused by name. */
static void configure(struct fw *f, const uint8_t *p, uint16_t len, int64_t now)
{
    struct sonar_ping360_config d;
    struct sonar_pipeline_config *next = &f->next;
    sonar_config_t c;
    const char *why;
    if (sonar_config_t_decode(p, 0, len, &c) < 0) {
        f->config_errors++;
        reply(f, "error", "config: not a sonar.config_t");
        return;
    }
    memset(&d, 0, sizeof(d));
    d.range_m = c.range_m;
    d.speed_of_sound = c.speed_of_sound;
    d.samples = (uint16_t)c.samples;
    d.transmit_duration = (uint16_t)c.transmit_duration;
    d.gain = (uint8_t)c.gain;
    d.frequency = (uint16_t)c.frequency;
    d.start_angle = (uint16_t)c.start_angle;
    d.stop_angle = (uint16_t)c.stop_angle;
    d.step = (uint8_t)c.step;
    d.full_circle = (uint8_t)(c.full_circle != 0);
    d.use_auto = (uint8_t)(c.use_auto != 0);
    d.baud = 115200;
    *next = f->pcfg;
    next->median = (uint8_t)c.median;
    next->median2d = (uint8_t)c.median2d;
    next->max_step = (uint16_t)c.max_step;
    next->background.mode = (uint8_t)c.bg_mode;
    next->background.warmup = (uint8_t)c.bg_warmup;
    next->background.step = (uint8_t)c.bg_step;
    next->background.margin = (uint8_t)c.bg_margin;
    next->detector.threshold_mode = (uint8_t)c.threshold_mode;
    next->detector.cfar.across = (uint8_t)c.cfar_across;
    next->detector.cfar.cut = (uint8_t)c.cfar_cut;
    next->detector.cfar.guard = (uint8_t)c.cfar_guard;
    next->detector.cfar.train = (uint8_t)c.cfar_train;
    next->detector.cfar.rank16 = (uint8_t)c.cfar_rank16;
    next->detector.cfar.scale = c.cfar_scale;
    next->detector.cfar.floor = to_u8(c.cfar_floor, 255);
    next->detector.threshold_k = c.threshold_k;
    next->detector.min_threshold = to_u8(c.min_threshold, 255);
    next->detector.max_clusters = to_u8(c.max_clusters, 0);
    next->detector.iterations = to_u8(c.iterations, 0);
    next->detector.link_beams = to_u8(c.link_beams, 0);
    next->detector.min_points = to_u16(c.min_points, 0);
    next->detector.link_m = c.link_m;
    next->detector.angle_offset = c.angle_offset;
    next->detector.min_beams = to_u8(c.min_beams, 255);
    next->detector.max_extent_m = c.max_extent_m;
    next->detector.split_points = to_u16(c.split_points, 65535);
    next->detector.min_range_m = c.min_range_m;
    next->detector.max_aspect = c.max_aspect;
    next->detector.track_m = c.track_m;
    next->detector.track_points = to_u16(c.track_points, 0);
    next->track = c.track ? 1u : 0u;
    next->tracker.accel_mps2 = c.track_accel_mps2;
    next->tracker.manoeuvre_mps2 = c.track_manoeuvre_mps2;
    next->tracker.meas_m = c.track_meas_m;
    next->tracker.speed0_mps = c.track_speed0_mps;
    next->tracker.max_speed_mps = c.track_max_speed_mps;
    next->tracker.gate = c.track_gate;
    next->tracker.confirm_m = to_u8(c.track_confirm_m, 0);
    next->tracker.confirm_n = to_u8(c.track_confirm_n, 0);
    next->tracker.max_misses = to_u8(c.track_max_misses, 0);
    next->tracker.max_dt_s = c.track_max_dt_s;
    /* Nothing changes unless all of it is valid. */
    if ((why = sonar_ping360_config_check(&d)) != NULL || (why = sonar_pipeline_config_check(next)) != NULL) {
        f->config_errors++;
        reply(f, "error", why);
        return;
    }
    if (memcmp(&d, &f->dcfg, sizeof(d)) != 0) {
        struct sonar_ping360 fresh;
        if (sonar_ping360_init(&fresh, &d, &io) != SONAR_OK) {
            f->config_errors++;
            reply(f, "error", "range_m, samples: no sample period of 80..40000 ticks gives them");
            return;
        }
        /* New acquisition settings: the counters carry on, the probe starts again. */
        fresh.counters = f->drv.counters;
        f->drv = fresh;
        f->dcfg = d;
        if (sonar_ping360_connected(&f->drv, now) != SONAR_OK)
            f->reconnect_at = now + 100000;
    }
    /* A configuration restarts processing: the open sweep is dropped, the background relearns and
     * sweeps count from 0, so everything after the reply comes from the new settings. */
    f->pcfg = *next;
    if (sonar_pipeline_init(&f->pipe, &f->pcfg) != SONAR_OK) {
        f->config_errors++;
        reply(f, "error", "pipeline: rejected");
        return;
    }
    f->sweeps = 0;
    f->beams = 0;
    f->beam_every = (uint16_t)(c.beam_every < 0 ? 0 : c.beam_every);
    reply(f, "ok", NULL);
}

static void host_in(struct fw *f, int64_t now)
{
    uint8_t buf[256];
    size_t n;
    while ((n = board_uart_read(BOARD_UART_HOST, buf, sizeof(buf))) > 0) {
        const uint8_t *in = buf;
        struct sonar_cpf_frame fr;
        while (sonar_cpf_next(&f->host, &in, &n, &fr) == 1)
            if (fr.channel == SONAR_CPF_CONFIG)
                configure(f, fr.payload, fr.len, now);
    }
}

static void sonar_in(struct fw *f, int64_t now)
{
    uint8_t buf[256];
    size_t n;
    while ((n = board_uart_read(BOARD_UART_SONAR, buf, sizeof(buf))) > 0) {
        const uint8_t *in = buf;
        struct sonar_ping_frame fr;
        while (sonar_ping_parser_next(&f->sonar, &in, &n, &fr) == 1) {
            struct sonar_ping360_event ev;
            if (sonar_ping360_handle(&f->drv, &fr, now, &ev) != SONAR_OK)
                ev.kind = SONAR_P360_EV_NONE; /* a request that did not fit: its timeout sends it again */
            on_event(f, &ev, now);
        }
    }
}

int main(void)
{
    static struct fw f; /* ~545 KB: the pipeline; main's own, not a shared global */
    int64_t now;
    board_init();
    memset(&f, 0, sizeof(f));
    if (sonar_ping_parser_init(&f.sonar, 0) != SONAR_OK)
        return 1;
    sonar_cpf_parser_init(&f.host);
    sonar_pipeline_defaults(&f.pcfg);
    f.pcfg.on_sweep = on_sweep;
    f.pcfg.user = &f;
    /* Until the host configures it: Ping Viewer's defaults, 2 m, full turns, stepping. */
    f.dcfg.range_m = 2.0f;
    f.dcfg.speed_of_sound = 1500.0f;
    f.dcfg.frequency = 750;
    f.dcfg.step = 1;
    f.dcfg.full_circle = 1;
    f.dcfg.baud = 115200;
    if (sonar_pipeline_init(&f.pipe, &f.pcfg) != SONAR_OK || sonar_ping360_init(&f.drv, &f.dcfg, &io) != SONAR_OK)
        return 1;
    now = board_micros();
    if (sonar_ping360_connected(&f.drv, now) != SONAR_OK)
        f.reconnect_at = now;
    f.next_status = now + STATUS_US;
    for (;;) {
        struct sonar_ping360_event ev;
        now = board_micros();
        sonar_in(&f, now);
        host_in(&f, now);
        if (f.reconnect_at != 0 && now >= f.reconnect_at) {
            f.reconnect_at = 0;
            if (sonar_ping360_connected(&f.drv, now) != SONAR_OK)
                f.reconnect_at = now + 100000;
        }
        if (sonar_ping360_poll(&f.drv, now, &ev) == SONAR_OK)
            on_event(&f, &ev, now);
        if (now >= f.next_status) {
            status(&f, now);
            f.next_status = now + STATUS_US;
        }
        board_uart_pump();
        board_idle();
    }
}
