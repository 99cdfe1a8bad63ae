/* publish.c -- encodes sonar_*_t (lcm-gen --c-no-pubsub) into the publisher's buffer and hands it to liblcm. */
#include "publish.h"

#include <lcm/lcm.h>
#include <stdio.h>
#include <string.h>

#include "sonar_beam_t.h"
#include "sonar_detections_t.h"
#include "sonar_status_t.h"

int publisher_open(struct publisher *p, const char *url, const char *prefix, char *err, size_t errlen)
{
    memset(p, 0, sizeof(*p));
    snprintf(p->beam, sizeof(p->beam), "%sSONAR_BEAM", prefix);
    snprintf(p->filtered, sizeof(p->filtered), "%sSONAR_BEAM_FILTERED", prefix);
    snprintf(p->detections, sizeof(p->detections), "%sSONAR_DETECTIONS", prefix);
    snprintf(p->status, sizeof(p->status), "%sSONAR_STATUS", prefix);
    p->lcm = lcm_create(url);
    if (p->lcm == NULL) {
        snprintf(err, errlen, "--lcm %s: LCM could not start this provider (for udpm: is there a multicast route?)",
                 url ? url : "(default)");
        return -1;
    }
    return 0;
}

static int send(struct publisher *p, const char *channel, int len)
{
    if (len < 0 || lcm_publish((lcm_t *)p->lcm, channel, p->buf, (unsigned)len) != 0) {
        p->errors++;
        return -1;
    }
    return 0;
}

int publish_beam(struct publisher *p, const struct publisher_beam *b, int filtered)
{
    sonar_beam_t m;
    m.utime = b->utime;
    m.angle = (int16_t)b->angle;
    m.gain = (int8_t)b->gain;
    m.sample_period = b->sample_period;
    m.transmit_duration = b->transmit_duration;
    m.transmit_frequency = b->transmit_frequency;
    m.speed_of_sound = b->speed_of_sound;
    m.range_m = b->range_m;
    m.stage = (int8_t)b->stage;
    m.number_of_samples = (int16_t)b->n;
    m.samples = (uint8_t *)(uintptr_t)b->samples; /* encode only reads it */
    return send(p, filtered ? p->filtered : p->beam, sonar_beam_t_encode(p->buf, 0, (int)sizeof(p->buf), &m));
}

int publish_detections(struct publisher *p, const struct sonar_detections *d)
{
    sonar_detection_t det[SONAR_MAX_CLUSTERS];
    sonar_detections_t m;
    unsigned i;
    for (i = 0; i < d->count; i++) {
        const struct sonar_detection *o = &d->det[i];
        det[i].x_m = o->x_m;
        det[i].y_m = o->y_m;
        det[i].range_m = o->range_m;
        det[i].bearing_deg = o->bearing_deg;
        det[i].area_m2 = o->area_m2;
        det[i].points = (int32_t)o->points;
        det[i].mean_intensity = o->mean_intensity;
        det[i].hull_count = o->hull_count;
        det[i].hull_x = (float *)(uintptr_t)o->hull_x;
        det[i].hull_y = (float *)(uintptr_t)o->hull_y;
    }
    m.utime = d->utime;
    m.sweep = (int32_t)d->sweep;
    m.beams = (int16_t)d->beams;
    m.count = d->count;
    m.detections = det;
    return send(p, p->detections, sonar_detections_t_encode(p->buf, 0, (int)sizeof(p->buf), &m));
}

int publish_status(struct publisher *p, const struct publisher_status *s)
{
    sonar_status_t m;
    m.utime = s->utime;
    m.link_state = s->link_state;
    m.link = (char *)(uintptr_t)s->link;
    m.fw_major = (int8_t)s->fw[0];
    m.fw_minor = (int8_t)s->fw[1];
    m.fw_patch = (int8_t)s->fw[2];
    m.frames = s->frames;
    m.checksum_errors = s->checksum_errors;
    m.resyncs = s->resyncs;
    m.timeouts = s->timeouts;
    m.retries = s->retries;
    m.nacks = s->nacks;
    m.reconnects = s->reconnects;
    m.beams = s->beams;
    m.sweeps = s->sweeps;
    m.last_sweep_s = s->last_sweep_s;
    m.beam_us_p50 = s->beam_us_p50;
    m.beam_us_p99 = s->beam_us_p99;
    return send(p, p->status, sonar_status_t_encode(p->buf, 0, (int)sizeof(p->buf), &m));
}

void publisher_close(struct publisher *p)
{
    if (p->lcm != NULL)
        lcm_destroy((lcm_t *)p->lcm);
    p->lcm = NULL;
}
