/* ping360.c -- Ping360 driver: probe, stepping or auto-transmit sweeps, adaptive timeouts, retries, NACKs, stop; O(1) per event, no heap, no OS calls. */
#include "sonar/ping360.h"

#include <string.h>

#include "sonar/frame.h"
#include "sonar/geometry.h"

#define NO_DEADLINE INT64_MAX
#define PROBE_TIMEOUT_US 300000   /* general_request is specified at 50 ms; allow a slow bridge */
#define PROBE_ATTEMPTS 5
#define REHOME_US 4000000         /* the documented worst case after the head re-homes */
#define IDLE_REHOME_US 30000000   /* the motor switches off after 30 s idle, then re-homes */
#define SCAN_ATTEMPTS 4           /* consecutive timeouts before the link is given up */
#define NACK_LIMIT 3              /* consecutive NACKs before probing again */
#define STOP_TIMEOUT_US 200000
#define STOP_ATTEMPTS 3
#define BACKOFF_MIN_US 250000
#define BACKOFF_MAX_US 5000000

const char *sonar_ping360_config_check(const struct sonar_ping360_config *c)
{
    if (!(c->range_m >= 1.0f && c->range_m <= 60.0f))
        return "range_m: 1..60 metres";
    if (!(c->speed_of_sound >= 1300.0f && c->speed_of_sound <= 1700.0f))
        return "speed_of_sound: 1300..1700 m/s";
    if (c->samples != 0 && (c->samples < SONAR_DEVICE_MIN_SAMPLES || c->samples > SONAR_DEVICE_MAX_SAMPLES))
        return "samples: 0 (automatic) or 200..1200";
    if (c->transmit_duration != 0 && (c->transmit_duration < SONAR_MIN_TX_US || c->transmit_duration > SONAR_MAX_TX_US))
        return "transmit_duration: 0 (automatic) or 5..500 us";
    if (c->gain > 2)
        return "gain: 0 low, 1 normal, 2 high";
    if (c->frequency < 500 || c->frequency > 1000)
        return "frequency: 500..1000 kHz";
    if (c->start_angle > SONAR_GRAD_MAX || c->stop_angle > SONAR_GRAD_MAX)
        return "start_angle, stop_angle: 0..399 gradians";
    if (c->step < 1 || c->step > 50)
        return "step: 1..50 gradians";
    if (c->use_auto && c->step > 10)
        return "step: 1..10 gradians with auto_transmit";
    if (!c->full_circle && c->start_angle == c->stop_angle)
        return "stop_angle: differs from start_angle in a sector";
    return NULL;
}

const char *sonar_ping360_state_str(int state)
{
    static const char *const names[] = {"down", "connecting", "probing", "scanning", "auto", "stopping", "stopped", "passive"};
    return state >= 0 && state <= SONAR_P360_PASSIVE ? names[state] : "unknown";
}

int sonar_ping360_init(struct sonar_ping360 *d, const struct sonar_ping360_config *cfg,
                       const struct sonar_ping360_io *io)
{
    const struct sonar_ping360_config *c = cfg;
    uint16_t n;
    int r;
    if (d == NULL || c == NULL || io == NULL || io->send == NULL)
        return SONAR_ERR_ARG;
    if (sonar_ping360_config_check(c) != NULL)
        return SONAR_ERR_ARG;
    memset(d, 0, sizeof(*d));
    d->cfg = *c;
    d->io = *io;
    n = c->samples ? c->samples : sonar_geometry_max_samples(c->range_m, c->speed_of_sound);
    if (n == 0)
        return SONAR_ERR_RANGE;
    if ((r = sonar_geometry_sample_period(c->range_m, n, c->speed_of_sound, &d->sample_period)) != SONAR_OK)
        return r;
    d->samples = n;
    d->tx_us = c->transmit_duration ? c->transmit_duration
                                    : sonar_geometry_transmit_duration(c->range_m, c->speed_of_sound, d->sample_period);
    d->span = c->full_circle ? SONAR_GRAD_TURN : (uint16_t)((c->stop_angle + SONAR_GRAD_TURN - c->start_angle) % SONAR_GRAD_TURN);
    d->angle = d->from = c->start_angle;
    d->dir = 1;
    d->state = SONAR_P360_DOWN;
    d->deadline = NO_DEADLINE;
    d->backoff_us = BACKOFF_MIN_US;
    d->expected_us = sonar_ping360_beam_time_us(d);
    return SONAR_OK;
}

uint32_t sonar_ping360_model_us(unsigned step, float range_m, float speed_of_sound, uint32_t baud, uint16_t samples)
{
    double us = 19400.0 + (double)SONAR_P360_GRAD_US * (step ? step : 1u) + 2.0 * (double)range_m / (double)speed_of_sound * 1e6;
    if (baud > 0) /* 10 bits a byte: the reply (10 + 14 + samples) and the 24-byte request */
        us += 10.0 * (24.0 + 24.0 + samples) * 1e6 / (double)baud;
    return (uint32_t)us;
}

uint32_t sonar_ping360_beam_time_us(const struct sonar_ping360 *d)
{
    return sonar_ping360_model_us(d->cfg.step, d->cfg.range_m, d->cfg.speed_of_sound, d->cfg.baud, d->samples);
}

/*
 * Adaptive: the model or the measured latency, whichever is longer, plus half of it (>= 15 ms),
 * and the head's travel beyond a step when a planner moves it further (6 ms a gradian).
 */
static int64_t timeout_us(const struct sonar_ping360 *d, int64_t now)
{
    uint32_t base = d->observed_us > d->expected_us ? d->observed_us : d->expected_us;
    int gap = (int)sonar_frame_gap(d->from, d->angle) - (int)d->cfg.step;
    int64_t t = (int64_t)base + (base / 2 > 15000u ? base / 2 : 15000u) + (gap > 0 ? (int64_t)SONAR_P360_GRAD_US * gap : 0);
    /* First command, long idle, or repeated silence: the head may be re-homing. */
    if (d->last_rx == 0 || now - d->last_rx > IDLE_REHOME_US || d->attempts >= 2)
        t += REHOME_US;
    return t;
}

static int send_request(struct sonar_ping360 *d, int64_t now)
{
    uint8_t buf[40];
    int n;
    if (d->state == SONAR_P360_AUTO) {
        struct sonar_ping360_auto_transmit a;
        a.mode = 1;
        a.gain = d->cfg.gain;
        a.transmit_duration = d->tx_us;
        a.sample_period = d->sample_period;
        a.transmit_frequency = d->cfg.frequency;
        a.number_of_samples = d->samples;
        a.start_angle = d->cfg.full_circle ? 0 : d->cfg.start_angle;
        a.stop_angle = d->cfg.full_circle ? SONAR_GRAD_MAX : d->cfg.stop_angle;
        a.num_steps = d->cfg.step;
        a.delay = 0;
        n = sonar_ping_encode_auto_transmit(buf, sizeof(buf), &a);
    } else {
        struct sonar_ping360_transducer t;
        t.mode = 1;
        t.gain = d->cfg.gain;
        t.angle = d->angle;
        t.transmit_duration = d->tx_us;
        t.sample_period = d->sample_period;
        t.transmit_frequency = d->cfg.frequency;
        t.number_of_samples = d->samples;
        t.transmit = 1;
        n = sonar_ping_encode_transducer(buf, sizeof(buf), &t);
    }
    if (n < 0)
        return n;
    d->sent_at = now;
    d->deadline = now + timeout_us(d, now);
    return d->io.send(d->io.user, buf, (size_t)n);
}

/* A general_request for device_information: the probe, and in passive mode the hello. */
static int send_info_request(struct sonar_ping360 *d)
{
    uint8_t buf[16];
    int n = sonar_ping_encode_general_request(buf, sizeof(buf), SONAR_PING_DEVICE_INFORMATION);
    return n < 0 ? n : d->io.send(d->io.user, buf, (size_t)n);
}

static int send_probe(struct sonar_ping360 *d, int64_t now)
{
    d->state = SONAR_P360_PROBING;
    d->sent_at = now;
    d->deadline = now + PROBE_TIMEOUT_US;
    return send_info_request(d);
}

static int send_motor_off(struct sonar_ping360 *d, int64_t now)
{
    uint8_t buf[16];
    int n = sonar_ping_encode_motor_off(buf, sizeof(buf));
    if (n < 0)
        return n;
    d->deadline = now + STOP_TIMEOUT_US;
    return d->io.send(d->io.user, buf, (size_t)n);
}

/* Passive: a device_information request, the one message that changes nothing on the head; a bridge counts its sender as a client. */
static int send_hello(struct sonar_ping360 *d, int64_t now)
{
    d->last_hello = now;
    d->counters.hellos++;
    return send_info_request(d);
}

int sonar_ping360_connected(struct sonar_ping360 *d, int64_t now)
{
    if (d == NULL)
        return SONAR_ERR_ARG;
    d->attempts = 0;
    d->nack_run = 0;
    if (d->cfg.passive) {
        d->state = SONAR_P360_PASSIVE;
        d->last_beam = now;
        d->idle = 0;
        d->deadline = now + SONAR_P360_HELLO_US / 2;
        return send_hello(d, now);
    }
    return send_probe(d, now);
}

/* 1 with *info when f is our device's device_information; another device's (a bridge relays every device's replies to every client) is counted, 0. */
static int own_info(struct sonar_ping360 *d, const struct sonar_ping_frame *f, struct sonar_ping_device_info *info)
{
    if (sonar_ping_decode_device_info(f, info) != SONAR_OK)
        return 0;
    if (info->device_type != 0 && info->device_type != SONAR_PING_DEVICE_PING360) {
        d->counters.foreign++;
        return 0;
    }
    return 1;
}

/* The probe answered: the firmware known, scanning (or auto_transmit on firmware newer than 3.3.0) starts. */
static int probed(struct sonar_ping360 *d, const struct sonar_ping_device_info *info, int64_t now, struct sonar_ping360_event *ev)
{
    int newer = info->fw_major > 3 || (info->fw_major == 3 && (info->fw_minor > 3 || (info->fw_minor == 3 && info->fw_patch > 0)));
    d->info = *info;
    d->have_info = 1;
    d->attempts = 0;
    d->nack_run = 0;
    d->backoff_us = BACKOFF_MIN_US;
    d->state = d->cfg.use_auto && newer ? SONAR_P360_AUTO : SONAR_P360_SCANNING;
    ev->kind = SONAR_P360_EV_READY;
    if (d->state == SONAR_P360_SCANNING && d->io.next_angle != NULL)
        d->angle = d->from = (uint16_t)(d->io.next_angle(d->io.plan_user, now) % SONAR_GRAD_TURN);
    return send_request(d, now);
}

/* Passive: every reply at whatever angle and settings the driving program chose. */
static int passive_frame(struct sonar_ping360 *d, const struct sonar_ping_frame *f, int64_t now, struct sonar_ping360_event *ev)
{
    struct sonar_ping360_data data;
    if (f->id == SONAR_PING_DEVICE_INFORMATION) {
        struct sonar_ping_device_info info;
        if (!own_info(d, f, &info))
            return SONAR_OK;
        d->info = info;
        if (!d->have_info)
            ev->kind = SONAR_P360_EV_READY;
        d->have_info = 1;
        return SONAR_OK;
    }
    if (f->id >= SONAR_PING1D_FIRST_ID && f->id <= SONAR_PING1D_LAST_ID) {
        d->counters.foreign++;
        return SONAR_OK;
    }
    if ((f->id != SONAR_PING360_DEVICE_DATA && f->id != SONAR_PING360_AUTO_DEVICE_DATA) ||
        sonar_ping_decode_data(f, &data) != SONAR_OK)
        return SONAR_OK;
    if (data.data_length == 0) {
        d->counters.off_angle++;
        return SONAR_OK;
    }
    d->counters.beams++;
    d->last_beam = now;
    d->idle = 0;
    ev->kind = SONAR_P360_EV_BEAM;
    ev->data = data;
    return SONAR_OK;
}

/* Passive timers: idle after SONAR_P360_IDLE_US without a beam; a hello when nothing at all came for SONAR_P360_HELLO_US (at most one a period). */
static int passive_poll(struct sonar_ping360 *d, int64_t now, struct sonar_ping360_event *ev)
{
    d->deadline = now + SONAR_P360_HELLO_US / 4;
    if (!d->idle && now - d->last_beam >= (int64_t)SONAR_P360_IDLE_US) {
        d->idle = 1;
        d->counters.idles++;
        ev->kind = SONAR_P360_EV_IDLE;
    }
    if (now - d->last_rx >= (int64_t)SONAR_P360_HELLO_US && now - d->last_hello >= (int64_t)SONAR_P360_HELLO_US)
        return send_hello(d, now);
    return SONAR_OK;
}

static void give_up(struct sonar_ping360 *d, struct sonar_ping360_event *ev)
{
    d->state = SONAR_P360_DOWN;
    d->deadline = NO_DEADLINE;
    d->counters.reconnects++;
    if (ev != NULL) {
        ev->kind = SONAR_P360_EV_LINK_LOST;
        ev->backoff_us = d->backoff_us;
    }
    d->backoff_us = d->backoff_us * 2u > BACKOFF_MAX_US ? BACKOFF_MAX_US : d->backoff_us * 2u;
}

void sonar_ping360_link_lost(struct sonar_ping360 *d, int64_t now)
{
    (void)now;
    if (d != NULL && d->state != SONAR_P360_DOWN && d->state != SONAR_P360_STOPPED)
        give_up(d, NULL);
}

/* Next angle of a stepping sweep: the planner's, or full turns, or bouncing between the sector's ends. */
static void advance(struct sonar_ping360 *d, int64_t now)
{
    d->from = d->angle;
    if (d->io.next_angle != NULL) {
        d->angle = (uint16_t)(d->io.next_angle(d->io.plan_user, now) % SONAR_GRAD_TURN);
        return;
    }
    d->pos = sonar_frame_sweep_advance(d->pos, &d->dir, d->span, d->cfg.step, d->cfg.full_circle);
    d->angle = (uint16_t)((d->cfg.start_angle + d->pos) % SONAR_GRAD_TURN);
}

static void measured(struct sonar_ping360 *d, int64_t latency)
{
    uint32_t l = latency < 0 ? 0u : latency > 60000000 ? 60000000u : (uint32_t)latency;
    d->observed_us = d->observed_us == 0 ? l : (d->observed_us * 3u + l) / 4u;
}

int sonar_ping360_handle(struct sonar_ping360 *d, const struct sonar_ping_frame *f, int64_t now,
                         struct sonar_ping360_event *ev)
{
    if (d == NULL || f == NULL || ev == NULL)
        return SONAR_ERR_ARG;
    ev->kind = SONAR_P360_EV_NONE;
    d->last_rx = now;
    if (d->state == SONAR_P360_PASSIVE)
        return passive_frame(d, f, now, ev);
    switch (f->id) {
    case SONAR_PING_DEVICE_INFORMATION: {
        struct sonar_ping_device_info info;
        if (!own_info(d, f, &info) || d->state != SONAR_P360_PROBING)
            return SONAR_OK;
        return probed(d, &info, now, ev);
    }
    case SONAR_PING360_DEVICE_DATA:
    case SONAR_PING360_AUTO_DEVICE_DATA: {
        struct sonar_ping360_data data;
        int want_auto = d->state == SONAR_P360_AUTO;
        if ((d->state != SONAR_P360_SCANNING && !want_auto) || sonar_ping_decode_data(f, &data) != SONAR_OK)
            return SONAR_OK;
        /* Trust the reply, not the request, but only a reply to what is pending counts. */
        if (data.is_auto != want_auto || data.data_length == 0 || (!want_auto && data.angle != d->angle)) {
            d->counters.off_angle++;
            return SONAR_OK;
        }
        measured(d, now - d->sent_at);
        d->attempts = 0;
        d->nack_run = 0;
        d->counters.beams++;
        ev->kind = SONAR_P360_EV_BEAM;
        ev->data = data;
        if (want_auto) {
            /* The stream goes on by itself: only re-arm the watchdog. */
            d->sent_at = now;
            d->deadline = now + timeout_us(d, now);
            return SONAR_OK;
        }
        advance(d, now);
        return send_request(d, now);
    }
    case SONAR_PING_NACK: {
        uint16_t id, ml;
        const char *msg;
        if (sonar_ping_decode_nack(f, &id, &msg, &ml) != SONAR_OK)
            return SONAR_OK;
        (void)msg;
        d->counters.nacks++;
        if (d->state != SONAR_P360_SCANNING && d->state != SONAR_P360_AUTO)
            return SONAR_OK;
        if (++d->nack_run >= NACK_LIMIT) {
            d->nack_run = 0;
            return send_probe(d, now);
        }
        d->counters.retries++;
        return send_request(d, now);
    }
    case SONAR_PING_ACK: {
        uint16_t id;
        if (d->state == SONAR_P360_STOPPING && sonar_ping_decode_ack(f, &id) == SONAR_OK &&
            id == SONAR_PING360_MOTOR_OFF) {
            d->state = SONAR_P360_STOPPED;
            d->deadline = NO_DEADLINE;
            ev->kind = SONAR_P360_EV_STOPPED;
        }
        return SONAR_OK;
    }
    default:
        if (f->id >= SONAR_PING1D_FIRST_ID && f->id <= SONAR_PING1D_LAST_ID)
            d->counters.foreign++; /* an echosounder's message set (distance, profile ...) */
        return SONAR_OK; /* protocol_version, ascii_text and others need nothing */
    }
}

int sonar_ping360_poll(struct sonar_ping360 *d, int64_t now, struct sonar_ping360_event *ev)
{
    if (d == NULL || ev == NULL)
        return SONAR_ERR_ARG;
    ev->kind = SONAR_P360_EV_NONE;
    if (now < d->deadline)
        return SONAR_OK;
    if (d->state == SONAR_P360_PASSIVE)
        return passive_poll(d, now, ev);
    d->attempts++;
    switch (d->state) {
    case SONAR_P360_PROBING:
        d->counters.timeouts++;
        if (d->attempts >= PROBE_ATTEMPTS) {
            give_up(d, ev);
            return SONAR_OK;
        }
        /* A line break restarts the device's baud-rate detection on serial links. */
        if (d->io.line_break != NULL)
            d->io.line_break(d->io.user);
        return send_probe(d, now);
    case SONAR_P360_SCANNING:
    case SONAR_P360_AUTO:
        d->counters.timeouts++;
        if (d->attempts >= SCAN_ATTEMPTS) {
            give_up(d, ev);
            return SONAR_OK;
        }
        d->counters.retries++;
        if (d->attempts >= 2 && d->io.line_break != NULL)
            d->io.line_break(d->io.user);
        return send_request(d, now);
    case SONAR_P360_STOPPING:
        if (d->attempts >= STOP_ATTEMPTS) {
            d->state = SONAR_P360_STOPPED;
            d->deadline = NO_DEADLINE;
            ev->kind = SONAR_P360_EV_STOPPED;
            return SONAR_OK;
        }
        return send_motor_off(d, now);
    default:
        d->deadline = NO_DEADLINE;
        return SONAR_OK;
    }
}

int64_t sonar_ping360_deadline(const struct sonar_ping360 *d)
{
    return d == NULL ? NO_DEADLINE : d->deadline;
}

int sonar_ping360_stop(struct sonar_ping360 *d, int64_t now)
{
    if (d == NULL)
        return SONAR_ERR_ARG;
    /* Passive: the head is not ours to stop. */
    if (d->state == SONAR_P360_DOWN || d->state == SONAR_P360_STOPPED || d->cfg.passive) {
        d->state = SONAR_P360_STOPPED;
        d->deadline = NO_DEADLINE;
        return SONAR_OK;
    }
    /* A line break is the documented way to end auto-transmit on serial; motor_off works on every link. */
    if (d->state == SONAR_P360_AUTO && d->io.line_break != NULL)
        d->io.line_break(d->io.user);
    d->state = SONAR_P360_STOPPING;
    d->attempts = 0;
    return send_motor_off(d, now);
}
