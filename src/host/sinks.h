/* sinks.h -- sonard's outputs, each an app_sink: LCM (behind a transmit function), CSV recording, JSON/text lines; every message is encoded into the sink's own buffer (sizeof(struct sink_lcm) = 17 008 B), no heap per message. */
#ifndef SONARD_SINKS_H
#define SONARD_SINKS_H

#include <stdio.h>

#include "app.h"

struct obsmap_read;

/* Sends one encoded message; returns 0 or < 0. lcm_publish in sonard, a capture in tests. */
typedef int (*sink_lcm_tx)(void *user, const char *channel, const uint8_t *buf, size_t len);

struct sink_lcm {
    struct app_sink sink;
    void *lcm;                 /* lcm_t when opened by sink_lcm_open */
    sink_lcm_tx tx;
    void *tx_user;
    char beam[64], filtered[64], detections[64], status[64], tracks[64], survey[64], clutter[64], obstacles[64];
    uint8_t buf[16384];
};

/*
 * Beams (SONAR_BEAM, and SONAR_BEAM_FILTERED when filtered), detections, tracks (SONAR_TRACKS,
 * after each SONAR_DETECTIONS when tracking), status, and with each status while a survey is loaded its structure
 * (SONAR_SURVEY), on prefix + channel, through tx(user, ...). prefix: at most 30 characters.
 */
void sink_lcm_init(struct sink_lcm *s, sink_lcm_tx tx, void *user, const char *prefix, int filtered);

/*
 * The obstacle map as SONAR_OBSTACLES (sonar.obstacles_t), an obsmap_out_fn with self the sink; a
 * failed send is counted in the sink's errors.
 */
void sink_lcm_obstacles(void *self, const struct obsmap_read *r);

/* The same over liblcm: url NULL for LCM's default. Returns HOST_OK or HOST_ERR_IO with err set. */
HOST_CHECK int sink_lcm_open(struct sink_lcm *s, const char *url, const char *prefix, int filtered, char *err, size_t errlen);
void sink_lcm_close(struct sink_lcm *s);

/*
 * What waits on lcm (an lcm_t: the sink's, or a source's own), handled without blocking, at most max
 * messages, so a flood on a subscription (SONAR_POSE, SONAR_CONTROL) cannot starve the sonar. Returns
 * the messages handled.
 */
int sink_lcm_handle_waiting(void *lcm, int max);

/* CSV recording of the beams of one stage, in the study's form plus metadata columns (csv.h). */
struct sink_csv {
    struct app_sink sink;
    FILE *f;
};

/* f: open for writing (owned by the caller). stage: enum sonar_stage. */
void sink_csv_init(struct sink_csv *s, FILE *f, int stage);

/* One JSON line (json) or readable text per sweep on f. */
struct sink_report {
    struct app_sink sink;
    FILE *f;
    int json;
};

void sink_report_init(struct sink_report *s, FILE *f, int json);

#endif
