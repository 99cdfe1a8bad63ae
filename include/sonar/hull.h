/* hull.h -- Andrew's monotone-chain convex hull on int32 points with exact int64 cross products; no RAM beyond the caller's arrays. */
#ifndef SONAR_HULL_H
#define SONAR_HULL_H

#include <stdint.h>

#include "sonar/err.h"
#include "sonar/frame.h" /* struct sonar_xy */


/*
 * Sorts pts[0..n) in place (heapsort: no recursion, no heap) by x then y, and writes the hull to
 * out, counter-clockwise in a y-up frame, starting at the lowest-x (then lowest-y) point.
 * Collinear points on edges and duplicates are dropped. |x|, |y| must be < 2^30. cap: room in
 * out, at least 2n (the chains may hold that many before they pop). Returns the vertex count (1 for a single distinct point, 2 for a
 * segment), or SONAR_ERR_ARG / SONAR_ERR_SPACE.
 */
SONAR_CHECK int sonar_hull_build(struct sonar_xy *pts, uint16_t n, struct sonar_xy *out, uint16_t cap);

/* Twice the signed area (shoelace) of the polygon; positive when counter-clockwise. */
int64_t sonar_hull_area2(const struct sonar_xy *poly, uint16_t n);

/* The hull's diameter: its widest pair of vertices apart, in its points' units (0 for n < 2). O(n^2). */
int64_t sonar_hull_diameter(const struct sonar_xy *hull, uint16_t n);

/*
 * The hull's least width (hull: n vertices in order, as sonar_hull_build writes them): the least, over
 * its edges, of its farthest vertex from the edge's line, in its points' units; 0 for n < 3. O(n^2).
 */
int64_t sonar_hull_width(const struct sonar_xy *hull, uint16_t n);

#endif
