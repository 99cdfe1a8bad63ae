/* herr.h -- the host's error convention: the core's negative enum sonar_err, extended with host codes below it; no RAM. */
#ifndef SONARD_HERR_H
#define SONARD_HERR_H

#include "sonar/err.h"

/*
 * Host functions return int: >= 0 success, < 0 one of these. The core's codes stay inside the core
 * and the calls into it; host_err_of is the one translation at the boundary.
 */
enum host_err {
    HOST_OK = SONAR_OK,
    HOST_ERR_IO = -32,      /* a file, socket or device call failed (errno kept where it says so) */
    HOST_ERR_CONFIG = -33,  /* an option or a config file is invalid; the message names it */
    HOST_ERR_PUBLISH = -34, /* a sink could not deliver a message (counted in status) */
    HOST_ERR_CLOSED = -35,  /* the peer closed the link, or the device is gone */
    HOST_ERR_ROW = -36,     /* a malformed input row (CSV); the message names it and the reading goes on */
    HOST_ERR_FULL = -37,    /* a fixed table is full, or a list used up (sinks; every baud rate tried) */
    HOST_ERR_STATE = -38,   /* not now: nothing learnt yet, or a model that cannot be saved */
    HOST_ERR_REFUSED = -39  /* the core refused an input: a value outside what it takes (a beam, a pose) */
};

/* The core's code as the host says it: SONAR_OK (and counts >= 0) as they are, FULL, STATE, the rest REFUSED. */
int host_err_of(int sonar_err);

#define HOST_CHECK SONAR_CHECK

/* Name of a host_err code (or, for a caller that still holds one, a sonar_err); never NULL. */
const char *host_err_str(int err);

#endif
