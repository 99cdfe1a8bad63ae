/* options.h -- sonard's command line and config file: parsing, validation with named errors, and the mapping onto the core's configs; no heap. */
#ifndef SONARD_OPTIONS_H
#define SONARD_OPTIONS_H

#include <stddef.h>

#include "sonar/ping360.h"
#include "sonar/pipeline.h"

struct sonard_options {
    const char *replay;         /* CSV file, "-" for stdin */
    const char *sonar;          /* live: serial:PATH[:BAUD] | udp:HOST:PORT | tcp:HOST:PORT */
    const char *csv_out;        /* export / recording file */
    const char *lcm_url;        /* NULL: LCM's default ($LCM_DEFAULT_URL, else udpm ttl=0) */
    char channel_prefix[32];
    int stage;                  /* enum sonar_stage exported to csv_out (replay) */
    double range_m;             /* < 0: replay takes it from the CSV metadata, else 2 m */
    double speed_of_sound;      /* m/s */
    long baud;                  /* serial: bits/s; 0 = from the URL or 115200; -1 = auto */
    long sweeps;                /* stop after this many sweeps; 0 = run until signalled */
    int json;
    int quiet;
    int publish_filtered;
    int no_lcm;
    struct sonar_ping360_config device;
    struct sonar_pipeline_config pipeline;
    char config_path[256]; /* the last --config file */
    char pool[8192]; /* strings read from the config file, which the fields above may point into */
};

/*
 * Fills defaults, reads --config FILE if given (key = value lines, keys being long option names),
 * then parses argv, which overrides the file. Returns 0 to run, 1 when --help/--version was
 * handled, -1 on a bad option or file (message in err, naming the option or file:line).
 */
int options_parse(int argc, char **argv, struct sonard_options *o, char *err, size_t errlen);

/* Writes the --help text. */
void options_usage(const char *prog);

#endif
