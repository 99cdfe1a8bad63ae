/* options_values.c -- the values of sonard's options that have a form of their own (link URLs, baud, gain, transmit, sector, ignore arcs, median); no heap. */
#include "options_internal.h"
#include "blueos.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* serial:, udp: or tcp: for --sonar and --coprocessor (link.c checks the rest when it opens). */
static int link_url(const char *opt, const char *v, const char **field, char *err, size_t n)
{
    if (strncmp(v, "serial:", 7) != 0 && strncmp(v, "udp:", 4) != 0 && strncmp(v, "tcp:", 4) != 0) {
        snprintf(err, n, "--%s: '%s' is not serial:PATH[:BAUD], udp:HOST:PORT or tcp:HOST:PORT", opt, v);
        return HOST_ERR_CONFIG;
    }
    *field = v;
    return HOST_OK;
}

/* A link URL, or blueos[:HOST[:PORT]]: BlueOS's ping service names the sonar when sonard starts (blueos.c). */
int options_parse_sonar(void *base, const char *v, char *err, size_t n)
{
    char host[128];
    int port, r = blueos_spec(v, host, sizeof host, &port, err, n);
    if (r == 1) {
        ((struct sonard_options *)base)->sonar = v;
        return HOST_OK;
    }
    return r < 0 ? r : link_url("sonar", v, &((struct sonard_options *)base)->sonar, err, n);
}

int options_parse_coprocessor(void *base, const char *v, char *err, size_t n)
{
    return link_url("coprocessor", v, &((struct sonard_options *)base)->coprocessor, err, n);
}

int options_parse_baud(void *base, const char *v, char *err, size_t n)
{
    struct sonard_options *o = base;
    char *end;
    long b;
    if (strcmp(v, "auto") == 0) {
        o->baud = -1;
        return HOST_OK;
    }
    b = strtol(v, &end, 10);
    if (*v == '\0' || *end != '\0' || b < 1200 || b > 4000000) {
        snprintf(err, n, "--baud: '%s' is not a whole number in 1200..4000000 bits/s (or auto)", v);
        return HOST_ERR_CONFIG;
    }
    o->baud = b;
    return HOST_OK;
}

int options_parse_gain(void *base, const char *v, char *err, size_t n)
{
    struct sonard_options *o = base;
    if (strcmp(v, "auto") == 0) {
        o->gain_auto = 1;
        o->device.gain = 1; /* the middle: one step from either end */
        return HOST_OK;
    }
    if (strlen(v) != 1 || v[0] < '0' || v[0] > '2') {
        snprintf(err, n, "--gain: '%s' is not 0 (low), 1 (normal), 2 (high) or auto", v);
        return HOST_ERR_CONFIG;
    }
    o->gain_auto = 0;
    o->device.gain = (uint8_t)(v[0] - '0');
    return HOST_OK;
}

/* --transmit-duration: us 5..500, or auto (0: the driver's rule from range and sample period, geometry.h). */
int options_parse_tx(void *base, const char *v, char *err, size_t n)
{
    struct sonard_options *o = base;
    char *end;
    long us;
    if (strcmp(v, "auto") == 0) {
        o->device.transmit_duration = 0;
        return HOST_OK;
    }
    us = strtol(v, &end, 10);
    if (*v == '\0' || *end != '\0' || us < 5 || us > 500) {
        snprintf(err, n, "--transmit-duration: '%s' is not a whole number in 5..500 us (or auto)", v);
        return HOST_ERR_CONFIG;
    }
    o->device.transmit_duration = (uint16_t)us;
    return HOST_OK;
}

int options_parse_sector(void *base, const char *v, char *err, size_t n)
{
    struct sonard_options *o = base;
    unsigned s0, s1;
    char tail;
    if (strcmp(v, "full") == 0) {
        o->device.full_circle = 1;
        o->device.start_angle = 0;
        return HOST_OK;
    }
    if (sscanf(v, "%u:%u%c", &s0, &s1, &tail) != 2 || s0 > 399 || s1 > 399 || s0 == s1) {
        snprintf(err, n, "--sector: '%s' is not START:STOP in gradians 0..399 (START != STOP), or full", v);
        return HOST_ERR_CONFIG;
    }
    o->device.full_circle = 0;
    o->device.start_angle = (uint16_t)s0;
    o->device.stop_angle = (uint16_t)s1;
    return HOST_OK;
}

/* --ignore-deg FROM:TO, degrees clockwise from forward (0..360); repeatable, an arc may cross forward. */
int options_parse_ignore(void *base, const char *v, char *err, size_t n)
{
    struct sonard_options *o = base;
    double a, b;
    char tail;
    if (sscanf(v, "%lf:%lf%c", &a, &b, &tail) != 2 || !(a >= 0.0 && a <= 360.0 && b >= 0.0 && b <= 360.0)) {
        snprintf(err, n, "--ignore-deg: '%s' is not FROM:TO in degrees 0..360 clockwise from forward", v);
        return HOST_ERR_CONFIG;
    }
    if (o->n_ignore >= SONARD_MAX_IGNORE) {
        snprintf(err, n, "--ignore-deg %s: at most %d arcs", v, SONARD_MAX_IGNORE);
        return HOST_ERR_CONFIG;
    }
    o->ignore[o->n_ignore][0] = (float)a;
    o->ignore[o->n_ignore][1] = (float)b;
    o->n_ignore++;
    return HOST_OK;
}

int options_parse_median(void *base, const char *v, char *err, size_t n)
{
    struct sonard_options *o = base;
    char *end;
    long w;
    if (strcmp(v, "3x3") == 0 || strcmp(v, "5x5") == 0) {
        o->pipeline.median2d = (uint8_t)(v[0] - '0');
        return HOST_OK;
    }
    w = strtol(v, &end, 10);
    if (*v == '\0' || *end != '\0' || w < 1 || w > SONAR_MAX_MEDIAN) {
        snprintf(err, n, "--median: '%s' is not a whole number in 1..%d samples (odd), or 3x3 / 5x5", v, SONAR_MAX_MEDIAN);
        return HOST_ERR_CONFIG;
    }
    if (w % 2 == 0) {
        snprintf(err, n, "--median: '%s' is even; use 1 (off), 3, 5, 7, 9, 3x3 or 5x5", v);
        return HOST_ERR_CONFIG;
    }
    o->pipeline.median = (uint8_t)w;
    o->pipeline.median2d = 0;
    return HOST_OK;
}

/* survey: a whole number records that many sweeps into the survey's file (--survey N); anything else is the file. */
int options_parse_survey(void *base, const char *v, char *err, size_t n)
{
    struct sonard_options *o = base;
    const char *c = v;
    long sweeps;
    while (*c >= '0' && *c <= '9')
        c++;
    if (*v == '\0') {
        snprintf(err, n, "--survey: empty: give the survey's file, or the sweeps to record into it");
        return HOST_ERR_CONFIG;
    }
    if (*c != '\0') {
        o->survey = v;
        return HOST_OK;
    }
    sweeps = strtol(v, NULL, 10);
    if (sweeps < SONAR_SURVEY_MIN_LOOKS || sweeps > SONAR_SURVEY_MAX_LOOKS) {
        snprintf(err, n, "--survey: '%s' sweeps is not %d..%d: each cell must be looked at %d times to know its level and "
                         "spread (a sector scanned back and forth at a step that does not divide it looks at each angle "
                         "every other sweep: twice that)",
                 v, SONAR_SURVEY_MIN_LOOKS, SONAR_SURVEY_MAX_LOOKS, SONAR_SURVEY_MIN_LOOKS);
        return HOST_ERR_CONFIG;
    }
    o->survey_sweeps = sweeps;
    return HOST_OK;
}
