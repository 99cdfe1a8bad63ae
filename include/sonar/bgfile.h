/* bgfile.h -- a site's per-angle background (a survey of the empty site, or a learnt model) as a byte image: geometry, time, levels, spread, structure, version, CRC-32; no RAM beyond the caller's buffer. */
#ifndef SONAR_BGFILE_H
#define SONAR_BGFILE_H

#include <stddef.h>
#include <stdint.h>

#include "sonar/background.h"
#include "sonar/detector.h"
#include "sonar/err.h"

/*
 * The image, all integers little-endian:
 *   0  8  magic "SONARBG\n"
 *   8  2  version (SONAR_BGFILE_VERSION)
 *  10  2  angles: rows (SONAR_MAX_ANGLES of the build that wrote it)
 *  12  2  n: samples a row
 *  14  1  background mode it was learnt in (enum sonar_background_mode: per-angle or auto)
 *  15  1  median along range (1 = off, 3..9), 16  1  median2d (0, 3, 5): what the levels were filtered by
 *  17  1  gain setting of the beams it learnt from (0..2), 0xFF unknown
 *  18  1  flags: SONAR_BGFILE_SPREAD (a spread row follows each level row), SONAR_BGFILE_SURVEY (recorded by
 *         --survey: nothing moved, every angle of the sector looked at SONAR_SURVEY_MIN_LOOKS times)
 *  19  1  structure places (0..SONAR_MAX_CLUSTERS)
 *  20  4  range, mm
 *  24  4  speed of sound, mm/s (0 unknown)
 *  28  4  sweeps it learnt over
 *  32  8  when: the last beam it learnt from, us since the epoch (signed)
 *  40  4  angle offset of the places' frame, milligradians (signed)
 *  44  4  reserved, 0
 *  48     looks: `angles` bytes, the across-beam looks (1 byte), the across-beam row (n bytes),
 *         the levels: angles x n bytes, [the spread: angles x n bytes],
 *         the places: SONAR_BGFILE_PLACE bytes each (kind, vertices, 2 reserved, centroid x and y in mm
 *         as int32, then SONAR_MAX_HULL vertices as int32 mm pairs, the unused ones 0)
 *  end 4  CRC-32 (cpframe.h's) of every byte before it
 * A model learnt in the world frame (a moving sonar) is not an image: it is tied to where the vehicle was.
 */
#define SONAR_BGFILE_VERSION 2
#define SONAR_BGFILE_HEADER 48
#define SONAR_BGFILE_GAIN_UNKNOWN 0xFF
#define SONAR_BGFILE_SPREAD 0x01u
#define SONAR_BGFILE_SURVEY 0x02u
#define SONAR_BGFILE_PLACE (12 + 8 * SONAR_MAX_HULL)
/* The largest image this build reads or writes: SONAR_MAX_SAMPLES a row, a spread, every place. */
#define SONAR_BGFILE_MAX ((size_t)SONAR_BGFILE_HEADER + SONAR_MAX_ANGLES + 1u + SONAR_MAX_SAMPLES + \
                          2u * (size_t)SONAR_MAX_ANGLES * SONAR_MAX_SAMPLES + (size_t)SONAR_MAX_CLUSTERS * SONAR_BGFILE_PLACE + 4u)

/* What the model is a model of: checked against the beams before the model is used. */
struct sonar_bgfile_meta {
    uint16_t n;          /* samples a beam, 1..SONAR_MAX_SAMPLES */
    uint8_t mode;        /* SONAR_BACKGROUND_PER_ANGLE or SONAR_BACKGROUND_AUTO */
    uint8_t median;      /* the pipeline's median (1 or odd 3..9) ... */
    uint8_t median2d;    /* ... and median2d (0, 3, 5) */
    uint8_t gain;        /* 0..2, or SONAR_BGFILE_GAIN_UNKNOWN */
    uint8_t flags;       /* SONAR_BGFILE_SPREAD, SONAR_BGFILE_SURVEY */
    uint8_t places;      /* structure places, 0..SONAR_MAX_CLUSTERS */
    uint32_t range_mm;   /* the beams' range, 1..10^6 mm */
    uint32_t sound_mm_s; /* speed of sound, mm/s, 0 unknown */
    uint32_t sweeps;     /* sweeps learnt over */
    int64_t utime;       /* the last beam learnt from, us since the epoch */
    int32_t offset_mgrad; /* the angle offset of the places' frame, milligradians */
};

/* Where each part of an image lies, bytes from its start. */
struct sonar_bgfile_layout {
    size_t looks, across, levels, spread, places, crc, size;
};

/*
 * The layout of an image of n samples a row (1..SONAR_MAX_SAMPLES) with flags and places
 * (0..SONAR_MAX_CLUSTERS). Returns SONAR_OK or SONAR_ERR_ARG (nothing set).
 */
SONAR_CHECK int sonar_bgfile_layout(uint16_t n, uint8_t flags, uint8_t places, struct sonar_bgfile_layout *l);

/* Bytes of the image of a model of n samples a beam with no spread and no places, 0 for n out of range. */
size_t sonar_bgfile_size(uint16_t n);

/*
 * The bytes of in (len of them) that its header says the image holds: the rest, if any, is a block
 * after it (a clutter map, clutter.h). len when the header cannot say (sonar_bgfile_check then names
 * what is wrong).
 */
size_t sonar_bgfile_declared(const uint8_t *in, size_t len);

/* The header of m into out[0 .. SONAR_BGFILE_HEADER). */
void sonar_bgfile_put_header(uint8_t *out, const struct sonar_bgfile_meta *m);

/* Place i of the image's places: d's kind, centroid and hull (metres, thinned to SONAR_MAX_HULL) written at out. */
void sonar_bgfile_put_place(uint8_t *out, const struct sonar_detection *d);

/* Place i read back from at into d: kind, centroid, hull; the rest of d 0. */
void sonar_bgfile_get_place(const uint8_t *at, struct sonar_detection *d);

/* The CRC over out[0 .. l->crc) written at l->crc. */
void sonar_bgfile_seal(uint8_t *out, const struct sonar_bgfile_layout *l);

/*
 * Writes bg's model as an image into out (cap bytes), its header from m (m->n must be the model's;
 * no spread, no places: a learnt model). Returns the bytes written, or SONAR_ERR_STATE (an empty
 * model, one in the world frame, or a mode with no per-angle rows), SONAR_ERR_ARG (NULL, or m
 * disagrees with the model), SONAR_ERR_SPACE (cap too small).
 */
SONAR_CHECK int32_t sonar_bgfile_write(const struct sonar_background *bg, const struct sonar_bgfile_meta *m, uint8_t *out,
                                       size_t cap);

/*
 * Reads the header of an image of len bytes into *m after checking it whole: returns SONAR_OK, or
 * < 0 with *why naming what is wrong ("not a sonard background file", "version 1 (this build reads
 * 2)", "truncated", "checksum: the file is damaged", "geometry: ...", ...). why may be NULL.
 */
SONAR_CHECK int sonar_bgfile_check(const uint8_t *in, size_t len, struct sonar_bgfile_meta *m, const char **why);

/*
 * Loads a checked image's levels (sonar_bgfile_check first) into bg, whose mode must be per-angle
 * or auto: the rows, their looks and the across-beam row; learning may go on from there. Returns
 * SONAR_OK, or < 0 with *why set as above, bg then unchanged.
 */
SONAR_CHECK int sonar_bgfile_load(struct sonar_background *bg, const uint8_t *in, size_t len, const char **why);

#endif
