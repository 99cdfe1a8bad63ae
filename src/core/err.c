/* err.c -- names of the core's error codes; ~200 B of const strings. */
#include "sonar/err.h"

const char *sonar_err_str(int err)
{
    switch (err) {
    case SONAR_OK: return "ok";
    case SONAR_ERR_ARG: return "bad argument";
    case SONAR_ERR_LENGTH: return "payload length does not match the message";
    case SONAR_ERR_SPACE: return "output buffer too small";
    case SONAR_ERR_ID: return "unexpected message id";
    case SONAR_ERR_RANGE: return "value out of range";
    case SONAR_ERR_FULL: return "capacity reached";
    case SONAR_ERR_STATE: return "invalid in this state";
    default: return err > 0 ? "ok" : "unknown error";
    }
}
