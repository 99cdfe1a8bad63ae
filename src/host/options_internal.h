/* options_internal.h -- the option table's value parsers (options_values.c) and the whole config's checks (options_check.c), shared with options.c only; no RAM. */
#ifndef SONARD_OPTIONS_INTERNAL_H
#define SONARD_OPTIONS_INTERNAL_H

#include <stddef.h>

#include "options.h"

/* OPT_CUSTOM parsers: store v into the struct sonard_options at base; HOST_OK or HOST_ERR_CONFIG naming the option with err. */
int options_parse_sonar(void *base, const char *v, char *err, size_t n);
int options_parse_coprocessor(void *base, const char *v, char *err, size_t n);
int options_parse_baud(void *base, const char *v, char *err, size_t n);
int options_parse_gain(void *base, const char *v, char *err, size_t n);
int options_parse_tx(void *base, const char *v, char *err, size_t n);
int options_parse_sector(void *base, const char *v, char *err, size_t n);
int options_parse_ignore(void *base, const char *v, char *err, size_t n);
int options_parse_median(void *base, const char *v, char *err, size_t n);
int options_parse_survey(void *base, const char *v, char *err, size_t n);

/*
 * options_check.c: the whole configuration after parsing: fills the defaults that follow --background and
 * refuses options that cannot go together. HOST_OK, or HOST_ERR_CONFIG with err naming the option (and its
 * --config file and line when it came from one).
 */
int options_check_whole(struct sonard_options *o, char *err, size_t errlen);

#endif
