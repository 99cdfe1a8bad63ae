/* source_link.h -- the live source: a Ping360 on a serial, UDP or TCP link feeding the app core; reconnect with backoff, serial auto-baud; sizeof(struct source_link) = 768 B, and a 4 KB read buffer on the stack (link_serve_*). */
#ifndef SONARD_SOURCE_LINK_H
#define SONARD_SOURCE_LINK_H

#include "app.h"
#include "link.h"
#include "live.h"

struct source_link {
    struct link link;
    struct app *app;
    int stopping;         /* motor_off requested: do not reconnect */
    int stopped;          /* motor_off acknowledged, or the link is gone while stopping */
    char desc[160];
};

/*
 * Parses url (serial:PATH[:BAUD] | udp:HOST:PORT | tcp:HOST:PORT; baud > 0 overrides, -1 auto).
 * Returns HOST_OK or HOST_ERR_CONFIG with err naming the part. The driver needs the serial rate
 * for its timeouts: source_link_baud() gives it (0 for networks).
 */
HOST_CHECK int source_link_parse(struct source_link *s, const char *url, long baud, char *err, size_t errlen);
uint32_t source_link_baud(const struct source_link *s);

/* Binds the app (whose driver sends through source_link_send) and opens the link. */
void source_link_start(struct source_link *s, struct app *a, int64_t now_us);

/* The driver's transport: sonar_ping360_io callbacks with user = the source_link. */
int source_link_send(void *user, const uint8_t *buf, size_t len);
void source_link_break(void *user);

/* For poll(): the descriptor (-1 when closed) and the events wanted. */
int source_link_fd(const struct source_link *s, short *events);

/* poll() said revents on the descriptor. */
void source_link_ready(struct source_link *s, short revents, int64_t now_us);

/* Timers (driver deadlines, reconnect, line break). Returns when to call it next. */
int64_t source_link_timers(struct source_link *s, int64_t now_us);

/* motor_off; source_link_stopped() says when it is done (acknowledged, or given up). */
void source_link_stop(struct source_link *s, int64_t now_us);
int source_link_stopped(const struct source_link *s);

/* The state for SONAR_STATUS: the driver's, or SONAR_P360_CONNECTING while a TCP connect runs. */
int source_link_state(const struct source_link *s);

void source_link_close(struct source_link *s);

/* The live loop's view of it. */
void source_link_live(struct source_link *s, struct live_source *out);

#endif
