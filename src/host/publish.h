/* publish.h -- LCM publishing of beams, detections and status; every message is encoded into a buffer inside struct publisher (no heap per message). */
#ifndef SONARD_PUBLISH_H
#define SONARD_PUBLISH_H

#include <stdint.h>

#include "sonar/detector.h"
#include "sonar/ping.h"

struct publisher_status {
    int64_t utime;
    int8_t link_state;
    const char *link;
    uint8_t fw[3];
    int64_t frames, checksum_errors, resyncs, timeouts, retries, nacks, reconnects, beams, sweeps;
    float last_sweep_s, beam_us_p50, beam_us_p99;
};

struct publisher_beam {
    int64_t utime;
    uint16_t angle;
    uint8_t gain;
    uint16_t sample_period, transmit_duration, transmit_frequency, n;
    float speed_of_sound, range_m;
    int stage;
    const uint8_t *samples;
};

struct publisher {
    void *lcm; /* lcm_t */
    char beam[64], filtered[64], detections[64], status[64];
    uint8_t buf[16384];
    unsigned long errors;
};

/* url: NULL for LCM's default. prefix: prepended to every channel. Returns 0, or -1 with err set. */
int publisher_open(struct publisher *p, const char *url, const char *prefix, char *err, size_t errlen);
int publish_beam(struct publisher *p, const struct publisher_beam *b, int filtered);
int publish_detections(struct publisher *p, const struct sonar_detections *d);
int publish_status(struct publisher *p, const struct publisher_status *s);
void publisher_close(struct publisher *p);

#endif
