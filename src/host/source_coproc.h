/* source_coproc.h -- the co-processor source: frames from the firmware on a serial, TCP or UDP link, CRC-checked, decoded and republished through the app's sinks; the options are pushed to it as a sonar.config_t; sizeof(struct source_coproc) = 5 696 B (one frame and the link). */
#ifndef SONARD_SOURCE_COPROC_H
#define SONARD_SOURCE_COPROC_H

#include "app.h"
#include "link.h"
#include "live.h"
#include "sonar/pipeline.h"
#include "sonar/ping360.h"
#include "sonar/cpframe.h"

#define COPROC_CONFIG_RETRY_US 2000000 /* no reply: send the configuration again */

struct source_coproc {
    struct link link;
    struct app *app;
    struct sonar_cpf_parser parser;
    uint8_t config[512];    /* the encoded configuration frame */
    int config_len;
    int configured;         /* the firmware answered "ok": its detections count from now on */
    int refused;            /* it answered "error: ...": sonard stops, exit 2 */
    int stopping, stopped;
    int reloading;          /* a SIGHUP's configuration is out: a refusal keeps the running one, sonard goes on */
    int64_t config_at;       /* no answer by then: send the configuration again */
    uint32_t dropped_before_config, decode_errors;
    char desc[160];
    char why[256];          /* the refusal */
};

/* What the firmware is configured with (borrowed for the call: the frame is built at once). */
struct source_coproc_config {
    long baud;                                   /* the link's bit rate (serial), as --baud */
    const struct sonar_ping360_config *device;   /* acquisition */
    const struct sonar_pipeline_config *pipeline; /* filters, background, detector */
    uint16_t beam_every;                          /* --coprocessor-beams: every Nth raw beam sent up, 0 none */
};

/*
 * url as for --sonar; the configuration frame is built from cc. Returns HOST_OK or
 * HOST_ERR_CONFIG with err naming what is wrong.
 */
HOST_CHECK int source_coproc_parse(struct source_coproc *s, const char *url, const struct source_coproc_config *cc, char *err,
                                   size_t errlen);

/*
 * SIGHUP: the configuration built again from cc and sent (at once when the link is up, else when it
 * comes up). The firmware restarts its processing with it when it answers "ok" (its background
 * relearns, its sweeps count from 0); its detections until then are dropped as from the settings
 * before. A refusal is said and the firmware keeps its running settings. Returns HOST_OK or
 * HOST_ERR_CONFIG (the frame cannot be built: nothing sent, err says why).
 */
HOST_CHECK int source_coproc_reconfigure(struct source_coproc *s, const struct source_coproc_config *cc, int64_t now,
                                         char *err, size_t errlen);

/* The live loop's view of it (the firmware's status frames are republished as SONAR_STATUS). */
void source_coproc_live(struct source_coproc *s, struct live_source *out);

#endif
