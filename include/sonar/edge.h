/* edge.h -- a beam's strongest echo beyond the ring-down, and its leading edge (the first echo at least half as strong, from the CFAR's block sums); O(n) and O(n/8) a beam, no state, no RAM. */
#ifndef SONAR_EDGE_H
#define SONAR_EDGE_H

#include <stdint.h>

/*
 * The sample of the strongest level of s[from .. n), its first if several; from when from >= n.
 * s: n levels (0..255), read only.
 */
uint16_t sonar_edge_strongest(const uint8_t *s, uint16_t from, uint16_t n);

/*
 * The leading edge of a beam, over its 8-sample block means (sums: sonar_cfar_sums of s, n samples):
 * the first block from the ring-down's end (from) at least half as strong as the strongest block there,
 * after the level has been at most a quarter of it (an edge rises out of quieter water: the ring-down's
 * tail, or anything across from, is passed first), and in that block the first sample at least half
 * as strong; n when there is none, or no block's mean reaches 2. *strongest gets the strongest block's
 * mean (0..255). Where the water is closed by a wall (a tank, a pool, a quay) it is the wall on every
 * beam that no nearer object overshadows, and it moves smoothly from beam to beam along the wall; a
 * person or a buoy before the wall takes it over on its own beams, a body's depth or more nearer.
 */
uint16_t sonar_edge_leading(const uint8_t *s, const uint16_t *sums, uint16_t from, uint16_t n, uint8_t *strongest);

#endif
