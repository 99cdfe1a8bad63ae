/* csv.h -- reader and writer of the study's per-angle CSV rows (sec, nsec, angle, samples...), with line-numbered errors; ~1.1 MB per reader (line and read buffers). */
#ifndef SONARD_CSV_H
#define SONARD_CSV_H

#include <stdint.h>
#include <stdio.h>

#include "herr.h"
#include "sonar/config.h"

#define CSV_LINE_MAX 65536

/*
 * Accepted forms (any mix of commas and blanks between samples):
 *   sec,nsec,angle,"s0 s1 s2 ..."        the study's form, samples in one quoted field
 *   sec,nsec,angle,s0,s1,s2,...          samples spread across columns
 *   sec.nsec,angle,...                   timestamp combined
 *   angle;s0;s1;...                      brping captures (Junayed et al.): ';'-separated, no
 *                                        timestamps, header "Angle (gradian);Intensity (0-255)"
 * The form is fixed by the file's first line: a ';' in it makes the file the untimed form
 * (csv_format_name says which was found); rows of that form have timed = 0 and sec = nsec = 0.
 * An optional header line (first field not a number) is skipped; '...' tokens and '[' ']' are
 * ignored. Fields `key=value` after the samples carry metadata (range_m, sample_period,
 * speed_of_sound, gain, transmit_duration, transmit_frequency, and the vehicle's pose at the beam:
 * north_m, east_m, yaw_deg, all three or none); unknown keys are ignored, and a known key with a
 * value outside its range (CSV_META_* below) rejects the row.
 * Seconds are bounded to +-CSV_MAX_SEC so that sec * 10^6 + nsec / 1000 fits an int64_t.
 * docs/csv-contract.md states the reader's guarantees.
 */
#define CSV_MAX_SEC 9223372036853LL /* INT64_MAX / 10^6 - 1 */
#define CSV_META_RANGE_MAX 1000.0    /* range_m, metres: (0, 1000] */
#define CSV_META_SOS_MIN 1000.0      /* speed_of_sound, m/s: 1000..2000 */
#define CSV_META_SOS_MAX 2000.0
#define CSV_META_U16_MAX 65535.0     /* sample_period, transmit_duration, transmit_frequency: 0..65535 */
#define CSV_META_NE_MAX 1.0e6        /* north_m, east_m: -10^6..10^6 metres (SONAR_POSE_COORD_MAX) */
#define CSV_META_YAW_MAX 360.0       /* yaw_deg: -360..360 degrees clockwise from north */
struct csv_row {
    int64_t sec;
    uint32_t nsec;
    uint16_t angle; /* gradians 0..399 */
    uint16_t n;
    int timed; /* 0: the row had no timestamp (the untimed form); the caller times it */
    uint8_t samples[SONAR_MAX_SAMPLES];
    /* metadata, < 0 when absent */
    double range_m, sample_period, speed_of_sound, gain, transmit_duration, transmit_frequency;
    int has_pose; /* north_m, east_m and yaw_deg were all given */
    double north_m, east_m, yaw_deg;
};

struct csv_reader {
    FILE *f;
    int owned;
    long gunzip;            /* pid of the gzip -dc reading a compressed file for us, else 0 */
    int stop;               /* the stream is not CSV (gzip data on a stream): end of rows */
    const char *path;
    unsigned long line;     /* line number of the row last returned */
    unsigned long good;
    unsigned long bad;
    uint16_t expect_n;      /* samples per row, fixed by the first good row */
    int seen_data;
    int format;             /* enum csv_format, fixed by the first line */
    char buf[CSV_LINE_MAX + 64]; /* the tokenizer reads up to 63 bytes past the NUL: zeroed per line */
    char iobuf[1 << 20];
};

enum csv_format { CSV_FORMAT_UNKNOWN = 0, CSV_FORMAT_STUDY, CSV_FORMAT_UNTIMED };

/* The form of the rows read so far, for messages: "study CSV (sec,nsec,angle,samples)" and so on. */
const char *csv_format_name(const struct csv_reader *r);

/*
 * Opens path ("-" = stdin). A gzip-compressed file (it starts 1f 8b; recordings are often kept as
 * .csv.gz) is read through a gzip -dc child; compressed data on stdin or a stream is reported by
 * csv_next and not parsed. Returns HOST_OK, or HOST_ERR_IO with errno set.
 */
int csv_open(struct csv_reader *r, const char *path);

/* Reads an open stream (not closed by csv_close); name is used in messages. */
void csv_open_stream(struct csv_reader *r, FILE *f, const char *name);
void csv_close(struct csv_reader *r);

/*
 * Reads the next row. Returns 1 with *row filled; 0 at end of file; HOST_ERR_ROW for a
 * malformed row, with a reason in err (the caller prints path:line: reason and goes on). Also
 * HOST_ERR_ROW, once, then 0: a compressed file whose gzip -dc failed (truncated or corrupt:
 * the rows before it were read), and gzip data where rows were expected on a stream.
 */
int csv_next(struct csv_reader *r, struct csv_row *row, char *err, size_t errlen);

/* Metadata written after the study's four columns; a value < 0 is left out. */
struct csv_meta {
    double range_m, gain, sample_period, transmit_duration, transmit_frequency, speed_of_sound;
    int has_pose; /* 1: write north_m, east_m, yaw_deg */
    double north_m, east_m, yaw_deg;
};

/* A csv_meta with every field absent. */
struct csv_meta csv_meta_none(void);

/*
 * Writes one row in the study's form (samples in one quoted field), then `key=value` metadata
 * columns, so the study's loader still finds its four columns. meta may be NULL. Returns HOST_OK
 * or HOST_ERR_IO.
 */
int csv_write(FILE *f, int64_t sec, uint32_t nsec, uint16_t angle, const uint8_t *s, uint16_t n, const struct csv_meta *meta);

#endif
