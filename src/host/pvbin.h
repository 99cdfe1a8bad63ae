/* pvbin.h -- reader of Ping Viewer sensor logs (.bin): records parsed from a buffer, Ping360 beams written as CSV rows; no heap. */
#ifndef SONARD_PVBIN_H
#define SONARD_PVBIN_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "csv.h"
#include "herr.h"
#include "sonar/ping.h"

struct pvbin_stats {
    uint32_t records, beams, skipped;
    struct sonar_ping_counters parser;
};

/*
 * Converts the log in buf[0..size) (the whole file; name for messages). start: epoch seconds of
 * the log's first record; c: speed of sound, m/s (for range_m). Beams go to out as CSV rows;
 * problems to errf (NULL: silent), each naming the record and byte. Every length and time field
 * is bounded before use; reading stops at the first truncated record, keeping the beams before
 * it. Returns HOST_OK (see st->beams), HOST_ERR_CONFIG (not a log, bad header) or HOST_ERR_IO.
 */
HOST_CHECK int pvbin_convert(const uint8_t *buf, size_t size, const char *name, double start, double c, FILE *out,
                             FILE *errf, struct pvbin_stats *st);

#endif
