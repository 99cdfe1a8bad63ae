/* herr.h -- the host's error convention: the core's negative enum sonar_err, extended with host codes below it; no RAM. */
#ifndef SONARD_HERR_H
#define SONARD_HERR_H

#include "sonar/err.h"

/* Host functions return int: >= 0 success, < 0 an enum sonar_err or one of these. */
enum host_err {
    HOST_OK = SONAR_OK,
    HOST_ERR_IO = -32,      /* a file, socket or device call failed (errno kept where it says so) */
    HOST_ERR_CONFIG = -33,  /* an option or a config file is invalid; the message names it */
    HOST_ERR_PUBLISH = -34, /* a sink could not deliver a message (counted in status) */
    HOST_ERR_CLOSED = -35,  /* the peer closed the link, or the device is gone */
    HOST_ERR_ROW = -36      /* a malformed input row (CSV); the message names it and the reading goes on */
};

#define HOST_CHECK SONAR_CHECK

/* Name of any sonar_err or host_err code; never NULL. */
const char *host_err_str(int err);

#endif
