/* csv.h -- reader and writer of the study's per-angle CSV rows (sec, nsec, angle, samples...), with line-numbered errors; ~1.1 MB per reader (line and read buffers). */
#ifndef SONARD_CSV_H
#define SONARD_CSV_H

#include <stdint.h>
#include <stdio.h>

#include "sonar/config.h"

#define CSV_LINE_MAX 65536

/*
 * Accepted forms (any mix of commas and blanks between samples):
 *   sec,nsec,angle,"s0 s1 s2 ..."        the study's form, samples in one quoted field
 *   sec,nsec,angle,s0,s1,s2,...          samples spread across columns
 *   sec.nsec,angle,...                   timestamp combined
 * An optional header line (first field not a number) is skipped; '...' tokens and '[' ']' are
 * ignored. Fields `key=value` after the samples carry metadata (range_m, sample_period,
 * speed_of_sound, gain, transmit_duration, transmit_frequency); unknown keys are ignored.
 */
struct csv_row {
    int64_t sec;
    uint32_t nsec;
    uint16_t angle; /* gradians 0..399 */
    uint16_t n;
    uint8_t samples[SONAR_MAX_SAMPLES];
    /* metadata, < 0 when absent */
    double range_m, sample_period, speed_of_sound, gain, transmit_duration, transmit_frequency;
};

struct csv_reader {
    FILE *f;
    int owned;
    const char *path;
    unsigned long line;     /* line number of the row last returned */
    unsigned long good;
    unsigned long bad;
    uint16_t expect_n;      /* samples per row, fixed by the first good row */
    int seen_data;
    char buf[CSV_LINE_MAX + 64]; /* the tokenizer reads up to 63 bytes past the NUL */
    char iobuf[1 << 20];
};

/* Opens path ("-" = stdin). Returns 0, or -1 with errno set. */
int csv_open(struct csv_reader *r, const char *path);
void csv_close(struct csv_reader *r);

/*
 * Reads the next row. Returns 1 with *row filled; 0 at end of file; -1 for a malformed row, with
 * a reason in err (the caller prints path:line: reason and goes on).
 */
int csv_next(struct csv_reader *r, struct csv_row *row, char *err, size_t errlen);

/* Metadata written after the study's four columns; a value < 0 is left out. */
struct csv_meta {
    double range_m, gain, sample_period, transmit_duration, transmit_frequency, speed_of_sound;
};

/* A csv_meta with every field absent. */
struct csv_meta csv_meta_none(void);

/*
 * Writes one row in the study's form (samples in one quoted field), then `key=value` metadata
 * columns, so the study's loader still finds its four columns. meta may be NULL.
 */
int csv_write(FILE *f, int64_t sec, uint32_t nsec, uint16_t angle, const uint8_t *s, uint16_t n, const struct csv_meta *meta);

#endif
