/* device.c -- parser bytes to the Ping360 driver, its beams to records; O(bytes) per call, no heap. */
#include "sonar/device.h"

#include <string.h>

#include "sonar/geometry.h"
#include "sonar/pipeline.h"

int sonar_device_init(struct sonar_device *d, const struct sonar_ping360_config *cfg, const struct sonar_ping360_io *io)
{
    int r;
    if (d == NULL)
        return SONAR_ERR_ARG;
    memset(d, 0, sizeof(*d));
    if ((r = sonar_ping_parser_init(&d->parser, 0)) != SONAR_OK)
        return r;
    return sonar_ping360_init(&d->drv, cfg, io);
}

/* The probe went out (nothing pending), or when to try again: the policy in device.h. */
static int probed(struct sonar_device *d, int r, int64_t now)
{
    d->reconnect_at = r == SONAR_OK ? 0 : now + (r == SONAR_ERR_SPACE ? SONAR_DEVICE_SPACE_RETRY_US : SONAR_DEVICE_RETRY_US);
    return r;
}

/* A loss: reconnect after backoff_us, or after SONAR_DEVICE_RETRY_US when the driver has none yet. */
static uint32_t lost(struct sonar_device *d, uint32_t backoff_us, int64_t now)
{
    d->backoff_us = backoff_us != 0 ? backoff_us : SONAR_DEVICE_RETRY_US;
    d->reconnect_at = now + d->backoff_us;
    return d->backoff_us;
}

int sonar_device_reconfigure(struct sonar_device *d, const struct sonar_ping360_config *cfg, int64_t now)
{
    struct sonar_ping360 fresh;
    int r;
    if ((r = sonar_ping360_init(&fresh, cfg, &d->drv.io)) != SONAR_OK)
        return r;
    fresh.counters = d->drv.counters;
    d->drv = fresh;
    return probed(d, sonar_ping360_connected(&d->drv, now), now);
}

/* A driver event for the caller: a beam becomes a raw record at the settings it was taken with. */
static int event(struct sonar_device *d, const struct sonar_ping360_event *pe, int64_t now, struct sonar_device_event *ev)
{
    struct sonar_record *b = &ev->beam;
    if (pe->kind == SONAR_P360_EV_NONE)
        return 0;
    ev->kind = pe->kind;
    ev->backoff_us = pe->kind == SONAR_P360_EV_LINK_LOST ? lost(d, pe->backoff_us, now) : pe->backoff_us;
    memset(b, 0, sizeof(*b));
    if (pe->kind == SONAR_P360_EV_BEAM) {
        const struct sonar_ping360_data *p = &pe->data;
        b->angle = p->angle;
        b->n = p->data_length;
        b->gain = p->gain;
        b->sample_period = p->sample_period;
        b->transmit_duration = p->transmit_duration;
        b->transmit_frequency = p->transmit_frequency;
        b->speed_of_sound = d->drv.cfg.speed_of_sound;
        b->range_m = (float)sonar_geometry_range_m(p->sample_period, p->data_length, d->drv.cfg.speed_of_sound);
        b->stage = SONAR_STAGE_RAW;
        b->samples = p->data;
    }
    return 1;
}

int sonar_device_bytes(struct sonar_device *d, const uint8_t **in, size_t *len, int64_t now, struct sonar_device_event *ev)
{
    struct sonar_ping_frame f;
    while (sonar_ping_parser_next(&d->parser, in, len, &f) == 1) {
        struct sonar_ping360_event pe;
        if (sonar_ping360_handle(&d->drv, &f, now, &pe) != SONAR_OK)
            pe.kind = SONAR_P360_EV_NONE; /* a request that did not fit: its timeout sends it again */
        if (event(d, &pe, now, ev))
            return 1;
    }
    return 0;
}

int sonar_device_poll(struct sonar_device *d, int64_t now, struct sonar_device_event *ev)
{
    struct sonar_ping360_event pe;
    if (sonar_ping360_poll(&d->drv, now, &pe) != SONAR_OK)
        return 0;
    return event(d, &pe, now, ev);
}

/* Fresh framing for a new connection; the counters carry on. */
static void reframe(struct sonar_device *d)
{
    struct sonar_ping_counters c = d->parser.counters;
    if (sonar_ping_parser_init(&d->parser, 0) == SONAR_OK) /* cannot fail with these arguments */
        d->parser.counters = c;
}

int sonar_device_up(struct sonar_device *d, int64_t now)
{
    reframe(d);
    return probed(d, sonar_ping360_connected(&d->drv, now), now);
}

uint32_t sonar_device_down(struct sonar_device *d, int64_t now)
{
    reframe(d);
    /* A driver that gave up itself already has its backoff; one that did not, now does. */
    if (d->drv.state != SONAR_P360_DOWN && d->drv.state != SONAR_P360_STOPPED) {
        sonar_ping360_link_lost(&d->drv, now);
        d->backoff_us = d->drv.backoff_us;
    }
    return lost(d, d->backoff_us, now);
}

int64_t sonar_device_reconnect_at(const struct sonar_device *d)
{
    return d->reconnect_at;
}

void sonar_device_firmware(const struct sonar_device *d, uint8_t fw[3])
{
    fw[0] = d->drv.info.fw_major;
    fw[1] = d->drv.info.fw_minor;
    fw[2] = d->drv.info.fw_patch;
}

int sonar_device_state(const struct sonar_device *d)
{
    return (int)d->drv.state;
}

int sonar_device_passive(const struct sonar_device *d)
{
    return d->drv.cfg.passive != 0;
}

const struct sonar_ping360_config *sonar_device_config(const struct sonar_device *d)
{
    return &d->drv.cfg;
}

uint16_t sonar_device_samples(const struct sonar_device *d)
{
    return d->drv.samples;
}

int sonar_device_set_gain(struct sonar_device *d, int gain)
{
    if (d == NULL || gain < 0 || gain > 2)
        return SONAR_ERR_ARG;
    d->drv.cfg.gain = (uint8_t)gain;
    return SONAR_OK;
}

void sonar_device_set_planner(struct sonar_device *d, uint16_t (*next_angle)(void *plan_user, int64_t now), void *plan_user)
{
    d->drv.io.next_angle = next_angle;
    d->drv.io.plan_user = plan_user;
}

int64_t sonar_device_deadline(const struct sonar_device *d)
{
    int64_t t = sonar_ping360_deadline(&d->drv);
    return d->reconnect_at != 0 && d->reconnect_at < t ? d->reconnect_at : t;
}

int sonar_device_stop(struct sonar_device *d, int64_t now)
{
    return sonar_ping360_stop(&d->drv, now);
}

void sonar_device_beam(const struct sonar_record *r, struct sonar_beam *b)
{
    b->utime = r->utime;
    b->angle = r->angle;
    b->n = r->n;
    b->range_m = r->range_m;
    b->samples = r->samples;
    b->gain = (int16_t)(r->gain >= 0 && r->gain <= 255 ? r->gain : -1);
}
