/* median.h -- 1-D median along a beam and K x K median over adjacent beams, bit-exact with OpenCV medianBlur (replicated edges); RAM: sizeof(struct sonar_median2d) = 6 120 B, K rows of SONAR_MAX_SAMPLES + K - 1 B and 16 B of metadata each, plus 16 B. */
#ifndef SONAR_MEDIAN_H
#define SONAR_MEDIAN_H

#include <stdint.h>

#include "sonar/config.h"
#include "sonar/err.h"

/*
 * out[j] = median of in[clamp(j - w/2 .. j + w/2)], the edge samples replicated; equals
 * cv::medianBlur on a 1 x n image. window: odd, 3..SONAR_MAX_MEDIAN; n: 1..65535. in and out
 * must not overlap. Returns SONAR_OK or SONAR_ERR_ARG. Cost: a branchless selection network
 * (3, 8, 14 or 24 compare-exchanges) per sample; stack: n + 8 bytes. n <= SONAR_MAX_SAMPLES.
 */
SONAR_CHECK int sonar_median_1d(const uint8_t *in, uint8_t *out, uint16_t n, uint8_t window);

/* Metadata carried with a row through the 2-D filter's delay line. */
struct sonar_median_row {
    int64_t utime;
    uint16_t angle;
    uint16_t tag; /* caller's, returned unchanged */
};

/*
 * K x K median over the rows of one sweep (rows = beams in arrival order, columns = samples), the
 * study's scipy median_filter with OpenCV's replicated border: equals cv::medianBlur on the sweep
 * matrix. Row i comes out when row i + K/2 arrives, or at sonar_median2d_flush.
 */
/* Replicated border samples kept on each side of a stored row. */
#define SONAR_MEDIAN2D_PAD (SONAR_MAX_MEDIAN2D / 2)

struct sonar_median2d {
    uint8_t ring[SONAR_MAX_MEDIAN2D][SONAR_MAX_SAMPLES + 2 * SONAR_MEDIAN2D_PAD]; /* rows, border included */
    struct sonar_median_row meta[SONAR_MAX_MEDIAN2D];
    uint32_t pushed;  /* rows pushed this sweep */
    uint32_t released; /* rows released this sweep */
    uint16_t n;       /* samples per row this sweep */
    uint8_t k;
};

/* Starts an empty sweep. k: 3 or 5 (<= SONAR_MAX_MEDIAN2D). Returns SONAR_OK or SONAR_ERR_ARG. */
SONAR_CHECK int sonar_median2d_init(struct sonar_median2d *m, uint8_t k);

/*
 * Adds one row of n samples (1..SONAR_MAX_SAMPLES; every row of a sweep must have the same n).
 * Returns 1 and writes the filtered row (n bytes) to out and its metadata to *out_meta when one
 * is ready, 0 when none is yet, or SONAR_ERR_ARG (bad n, or n differs from the sweep's).
 */
SONAR_CHECK int sonar_median2d_push(struct sonar_median2d *m, const uint8_t *row, uint16_t n,
                                    const struct sonar_median_row *meta, uint8_t *out,
                                    struct sonar_median_row *out_meta);

/* Ends the sweep: returns 1 and writes the next delayed row, until 0 (then the sweep is empty). */
SONAR_CHECK int sonar_median2d_flush(struct sonar_median2d *m, uint8_t *out, struct sonar_median_row *out_meta);

#endif
