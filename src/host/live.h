/* live.h -- the live daemon's poll loop: the link source, a signalfd (INT, TERM, HUP) and timers; no state of its own beyond the loop. */
#ifndef SONARD_LIVE_H
#define SONARD_LIVE_H

#include "app.h"

/* Called on SIGHUP; returns HOST_OK or an error it has already reported (the running settings stay). */
typedef int (*live_reload_fn)(void *user);

/* A live source as the loop sees it: a descriptor, its events, timers, a stop; one const table per kind. */
struct live_source_ops {
    void (*start)(void *self, struct app *a, int64_t now_us);
    int (*fd)(const void *self, short *events);          /* -1 when closed */
    void (*ready)(void *self, short revents, int64_t now_us);
    int64_t (*timers)(void *self, int64_t now_us);       /* returns when to call it next */
    void (*stop)(void *self, int64_t now_us);
    int (*stopped)(const void *self);
    int (*state)(const void *self);                      /* enum sonar_ping360_state for status */
    void (*close)(void *self);
    int own_status;                                      /* the source sends status itself (co-processor) */
};

struct live_source {
    const struct live_source_ops *ops;
    void *self;
};

#define LIVE_MAX_AUX 4

/* For sources with nothing to stop or report (poses in, the autopilot's link): stop is a no-op, they are always stopped, state 0. */
void live_no_stop(void *self, int64_t now_us);
int live_always_stopped(const void *self);
int live_no_state(const void *self);

/*
 * Runs the loop until the app has its sweeps or SIGINT/SIGTERM arrives, then stops the source
 * (motor_off, at most 1.5 s) and sends a last status. aux (naux <= LIVE_MAX_AUX, may be NULL when
 * 0): other sources served alongside (the autopilot's MAVLink), whose stop is never waited for.
 * Returns HOST_OK or HOST_ERR_IO (signalfd).
 */
HOST_CHECK int live_run(struct app *a, const struct live_source *src, const struct live_source *aux, unsigned naux,
                        live_reload_fn reload, void *reload_user);

#endif
