/* live.h -- the live daemon's poll loop: the link source, a signalfd (INT, TERM, HUP) and timers; no state of its own beyond the loop. */
#ifndef SONARD_LIVE_H
#define SONARD_LIVE_H

#include "app.h"

/* Called on SIGHUP; returns HOST_OK or an error it has already reported (the running settings stay). */
typedef int (*live_reload_fn)(void *user);

/* What the loop needs of every source: a descriptor, its events, timers, a close; one const table per kind. */
struct live_io_ops {
    void (*start)(void *self, struct app *a, int64_t now_us);
    int (*fd)(const void *self, short *events);          /* -1 when closed */
    void (*ready)(void *self, short revents, int64_t now_us);
    int64_t (*timers)(void *self, int64_t now_us);       /* returns when to call it next */
    void (*close)(void *self);
};

/* The primary source (the sonar, or a co-processor): it is also stopped, and its state reported. */
struct live_source_ops {
    struct live_io_ops io;
    void (*stop)(void *self, int64_t now_us);
    int (*stopped)(const void *self);
    int (*state)(const void *self); /* enum sonar_ping360_state for status; NULL: the source sends status itself */
};

struct live_source {
    const struct live_source_ops *ops;
    void *self;
};

/* A source served alongside (poses in, the autopilot's link): read and timed, never waited for. */
struct live_aux {
    const struct live_io_ops *ops;
    void *self;
};

#define LIVE_MAX_AUX 4

/*
 * Stalls: stretches when sonard was not running though it had asked to be (a paused VM, a stopped process, a starved
 * CPU): an iteration's wall time beyond its CPU time and its poll's timeout, when LIVE_STALL_MIN_US or more. The time
 * lost is given back to the source's timers (a reply that came, or comes just after, is read before its request is
 * declared timed out); the sinks' timers are not held (their messages are late already).
 */
#define LIVE_STALL_MIN_US 25000
struct live_stalls {
    uint32_t n;         /* stalls seen */
    int64_t total_us;   /* their time */
    int64_t longest_us;
};

/*
 * Runs the loop until the app has its sweeps or SIGINT/SIGTERM arrives, then stops the source
 * (motor_off, at most 1.5 s) and sends a last status. aux (naux <= LIVE_MAX_AUX, may be NULL when
 * 0): other sources served alongside (the autopilot's MAVLink), whose stop is never waited for.
 * stalls (may be NULL): filled with the host's stalls over the run. Returns HOST_OK or HOST_ERR_IO (signalfd).
 */
HOST_CHECK int live_run(struct app *a, const struct live_source *src, const struct live_aux *aux, unsigned naux,
                        live_reload_fn reload, void *reload_user, struct live_stalls *stalls);

#endif
