/* edge.h -- a beam's strongest echo beyond the ring-down and its leading edge (the first echo at least half as strong); O(n) a beam, no state, no RAM. */
#ifndef SONAR_EDGE_H
#define SONAR_EDGE_H

#include <stdint.h>

/*
 * The sample of the strongest level of s[from .. n), its first if several; from when from >= n.
 * s: n levels (0..255), read only.
 */
uint16_t sonar_edge_strongest(const uint8_t *s, uint16_t from, uint16_t n);

/*
 * The leading edge of a beam: the first sample of s[from .. n) at least half as strong as the
 * strongest there (sonar_edge_strongest) after the level has been at most a quarter of it (an edge
 * rises out of quieter water: the ring-down's tail, or anything across from, is passed first); n
 * when there is none, or the beam holds no level above 1. Where the water is
 * closed by a wall (a tank, a pool, a quay) it is the wall on every beam that no nearer object
 * overshadows; it moves smoothly from beam to beam along the wall. A person or a buoy before the
 * wall takes it over on its own beams, a body's depth or more nearer. from: the ring-down's samples
 * (nothing nearer is judged), s as above; *strongest gets the strongest level there (0 for none).
 */
uint16_t sonar_edge_leading(const uint8_t *s, uint16_t from, uint16_t n, uint8_t *strongest);

#endif
