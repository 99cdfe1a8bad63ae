/* live.h -- the live daemon entry point. */
#ifndef SONARD_LIVE_H
#define SONARD_LIVE_H

#include "options.h"

/* Runs until the requested sweeps are done or SIGINT/SIGTERM; stops the head first. Returns the exit status. */
int live_run(struct sonard_options *o);

#endif
