/* err.h -- the one error enum of the sonar core, and the unused-result check; no RAM. */
#ifndef SONAR_ERR_H
#define SONAR_ERR_H

/* Fallible functions return int: >= 0 success (a count where documented), < 0 an enum sonar_err. */
enum sonar_err {
    SONAR_OK = 0,
    SONAR_ERR_ARG = -1,      /* a pointer is NULL or a config value is outside its documented range */
    SONAR_ERR_LENGTH = -2,   /* a payload length does not match the message's fields */
    SONAR_ERR_SPACE = -3,    /* the caller's output buffer is too small */
    SONAR_ERR_ID = -4,       /* the frame is not the message the decoder handles */
    SONAR_ERR_RANGE = -5,    /* a wire or physical value is outside what the device supports */
    SONAR_ERR_FULL = -6,     /* a fixed capacity was reached; the excess was counted and dropped */
    SONAR_ERR_STATE = -7     /* the call is not valid in the object's current state */
};

#if defined(__GNUC__) || defined(__clang__)
#define SONAR_CHECK __attribute__((warn_unused_result))
#else
#define SONAR_CHECK
#endif

/* A limit macro's value as text, for the config checks' static "field: rule" messages. */
#define SONAR_STR_(x) #x
#define SONAR_STR(x) SONAR_STR_(x)

/* Returns a static, NUL-terminated name for err ("ok", "bad argument", ...); never NULL. */
const char *sonar_err_str(int err);

#endif
