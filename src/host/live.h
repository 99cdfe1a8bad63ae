/* live.h -- the live daemon's poll loop: the link source, a signalfd (INT, TERM, HUP) and timers; no state of its own beyond the loop. */
#ifndef SONARD_LIVE_H
#define SONARD_LIVE_H

#include "app.h"
#include "source_link.h"

/* Called on SIGHUP; returns HOST_OK or an error it has already reported (the running settings stay). */
typedef int (*live_reload_fn)(void *user);

/*
 * Runs the loop until the app has its sweeps or SIGINT/SIGTERM arrives, then stops the head
 * (motor_off, at most 1.5 s) and sends a last status. Returns HOST_OK or HOST_ERR_IO (signalfd).
 */
HOST_CHECK int live_run(struct app *a, struct source_link *src, live_reload_fn reload, void *reload_user);

#endif
