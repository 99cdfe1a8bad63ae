/* bgfile.h -- a learnt per-angle background as a byte image (geometry, version, CRC-32) for a fixed installation to save and load; no RAM beyond the caller's buffer. */
#ifndef SONAR_BGFILE_H
#define SONAR_BGFILE_H

#include <stddef.h>
#include <stdint.h>

#include "sonar/background.h"
#include "sonar/err.h"

/*
 * The image, all integers little-endian:
 *   0  8  magic "SONARBG\n"
 *   8  2  version (SONAR_BGFILE_VERSION)
 *  10  2  angles: rows (SONAR_MAX_ANGLES of the build that wrote it)
 *  12  2  n: samples a row
 *  14  1  background mode (enum sonar_background_mode: per-angle or auto)
 *  15  1  median along range (1 = off, 3..9), 16  1  median2d (0, 3, 5): what the model's values were filtered by
 *  17  1  gain setting of the beams it learnt from (0..2), 0xFF unknown
 *  18  2  reserved, 0
 *  20  4  range, mm
 *  24  4  speed of sound, mm/s (0 unknown)
 *  28  4  sweeps it learnt over (information)
 *  32     visits: `angles` bytes, the across-beam visits (1 byte), the across-beam row (n bytes),
 *         then the rows: angles x n bytes
 *  end 4  CRC-32 (cpframe.h's) of every byte before it
 * A model learnt in the world frame (a moving sonar) is not an image: it is tied to where the vehicle was.
 */
#define SONAR_BGFILE_VERSION 1
#define SONAR_BGFILE_HEADER 32
#define SONAR_BGFILE_GAIN_UNKNOWN 0xFF

/* What the model is a model of: checked against the beams before the model is used. */
struct sonar_bgfile_meta {
    uint16_t n;          /* samples a beam, 1..SONAR_MAX_SAMPLES */
    uint8_t mode;        /* SONAR_BACKGROUND_PER_ANGLE or SONAR_BACKGROUND_AUTO */
    uint8_t median;      /* the pipeline's median (1 or odd 3..9) ... */
    uint8_t median2d;    /* ... and median2d (0, 3, 5) */
    uint8_t gain;        /* 0..2, or SONAR_BGFILE_GAIN_UNKNOWN */
    uint32_t range_mm;   /* the beams' range, 1..10^6 mm */
    uint32_t sound_mm_s; /* speed of sound, mm/s, 0 unknown */
    uint32_t sweeps;     /* sweeps learnt over */
};

/* Bytes of the image of a model of n samples a beam (n 1..SONAR_MAX_SAMPLES), 0 for n out of range. */
size_t sonar_bgfile_size(uint16_t n);

/*
 * Writes bg's model as an image into out (cap bytes), its header from m (m->n must be the model's).
 * Returns the bytes written, or SONAR_ERR_STATE (an empty model, one in the world frame, or a mode
 * with no per-angle rows), SONAR_ERR_ARG (NULL, or m disagrees with the model), SONAR_ERR_SPACE (cap
 * too small).
 */
SONAR_CHECK int32_t sonar_bgfile_write(const struct sonar_background *bg, const struct sonar_bgfile_meta *m, uint8_t *out,
                                       size_t cap);

/*
 * Reads the header of an image of len bytes into *m after checking it whole: returns SONAR_OK, or
 * < 0 with *why naming what is wrong ("not a sonard background file", "version 2 (this build reads
 * 1)", "truncated: 1200 of 482036 bytes", "checksum: the file is damaged", "400 angles x 1200
 * samples (this build holds 200 x 500)", ...). why may be NULL.
 */
SONAR_CHECK int sonar_bgfile_check(const uint8_t *in, size_t len, struct sonar_bgfile_meta *m, const char **why);

/*
 * Loads a checked image (sonar_bgfile_check first) into bg, whose mode must be the image's: the
 * rows, their visits and the across-beam row; learning goes on from there. Returns SONAR_OK, or <
 * 0 with *why set as above, bg then unchanged.
 */
SONAR_CHECK int sonar_bgfile_load(struct sonar_background *bg, const uint8_t *in, size_t len, const char **why);

#endif
