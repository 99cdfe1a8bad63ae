/* herr.c -- the host's error codes: their names, and the one translation from the core's; no RAM. */
#include "herr.h"

int host_err_of(int sonar_err)
{
    switch (sonar_err) {
    case SONAR_ERR_FULL: return HOST_ERR_FULL;
    case SONAR_ERR_STATE: return HOST_ERR_STATE;
    default: return sonar_err >= 0 ? sonar_err : HOST_ERR_REFUSED;
    }
}

const char *host_err_str(int err)
{
    switch (err) {
    case HOST_ERR_IO: return "input/output error";
    case HOST_ERR_CONFIG: return "bad configuration";
    case HOST_ERR_PUBLISH: return "could not publish";
    case HOST_ERR_CLOSED: return "link closed";
    case HOST_ERR_ROW: return "malformed row";
    case HOST_ERR_FULL: return "no room";
    case HOST_ERR_STATE: return "not now";
    case HOST_ERR_REFUSED: return "refused by the core";
    default: return sonar_err_str(err);
    }
}
