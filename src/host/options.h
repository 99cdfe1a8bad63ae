/* options.h -- sonard's command line: parsing, validation with named errors, and the mapping onto the core's configs; no heap. */
#ifndef SONARD_OPTIONS_H
#define SONARD_OPTIONS_H

#include <stddef.h>

#include "sonar/pipeline.h"

struct sonard_options {
    const char *replay;      /* CSV file, "-" for stdin */
    const char *csv_out;     /* export file */
    int stage;               /* enum sonar_stage exported to csv_out */
    double range_m;          /* < 0: take it from the CSV metadata, else 2 m */
    double speed_of_sound;   /* m/s */
    int json;
    int quiet;
    struct sonar_pipeline_config pipeline;
};

/* Fills defaults, then parses argv. Returns 0 to run, 1 when --help/--version was handled, -1 on a
 * bad option (message written to err as "option: what is wrong"). */
int options_parse(int argc, char **argv, struct sonard_options *o, char *err, size_t errlen);

/* Writes the --help text. */
void options_usage(const char *prog);

#endif
