/* kmeans.h -- deterministic weighted k-means (farthest-point seeding, bounded Lloyd iterations) on integer points; no RAM beyond the caller's arrays. */
#ifndef SONAR_KMEANS_H
#define SONAR_KMEANS_H

#include <stdint.h>

#include "sonar/err.h"
#include "sonar/frame.h" /* struct sonar_xy: the centres */

#define SONAR_KMEANS_MAX_K 64
#define SONAR_KMEANS_SKIP 0xFFu /* label of a point with weight 0 */

/*
 * Coordinates are bounded: |x|, |y| <= SONAR_KMEANS_MAX_COORD (sonard's millimetres reach 10^6), so
 * a difference fits an int32 and a squared distance an int64. Every entry point refuses points and
 * centres outside the bound with SONAR_ERR_ARG.
 */
#define SONAR_KMEANS_MAX_COORD (1L << 26)

/* A point in integer units (sonard uses mm) with a weight (cells it stands for). */
struct sonar_point {
    int32_t x;
    int32_t y;
    uint32_t w; /* 0 = ignore the point */
};


/*
 * Farthest-point (maximin) seeding: the first weighted point, then repeatedly the point farthest
 * from its nearest centre (lowest index on ties). k: 1..SONAR_KMEANS_MAX_K. Returns the number of
 * centres written (fewer than k when there are fewer distinct points), or SONAR_ERR_ARG.
 */
SONAR_CHECK int sonar_kmeans_seed(const struct sonar_point *pts, uint16_t n, struct sonar_xy *c, uint8_t k);

/*
 * Lloyd's algorithm from the k centres in c: assign each point to its nearest centre (lowest
 * index on ties), then move each centre to the weighted mean of its points (rounded to nearest;
 * an empty centre stays). Runs at most `iterations` rounds (1..255) and stops early once no label
 * changes. labels[i] gets 0..k-1, or SONAR_KMEANS_SKIP for w == 0. Squared distances are exact in
 * int64. Returns the rounds run, or SONAR_ERR_ARG.
 */
SONAR_CHECK int sonar_kmeans_lloyd(const struct sonar_point *pts, uint16_t n, uint8_t *labels,
                                   struct sonar_xy *c, uint8_t k, uint8_t iterations);

/*
 * Lloyd's algorithm kept inside parts: centre j belongs to part[j] (any tag), and a point may only
 * move between centres of the part its entry label names. On entry labels[i] is a centre of point
 * i's part (0..k-1; ignored when w == 0). Otherwise as sonar_kmeans_lloyd: nearest centre of the
 * part, lowest index on ties; at most `iterations` rounds (1..255), early stop when nothing moves.
 * With one centre per part it only computes each part's centroid; with several it cuts a part.
 * Returns the rounds run, or SONAR_ERR_ARG (also for an entry label >= k on a weighted point).
 */
SONAR_CHECK int sonar_kmeans_lloyd_within(const struct sonar_point *pts, uint16_t n, uint8_t *labels,
                                          struct sonar_xy *c, const uint8_t *part, uint8_t k,
                                          uint8_t iterations);

/* Sum over points of w * squared distance to the centre of its label (OpenCV's "compactness"). */
double sonar_kmeans_inertia(const struct sonar_point *pts, uint16_t n, const uint8_t *labels,
                            const struct sonar_xy *c);

#endif
