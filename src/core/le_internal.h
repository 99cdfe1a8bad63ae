/* le_internal.h -- explicit little-endian load/store of wire bytes; inline, no RAM. */
#ifndef SONAR_LE_INTERNAL_H
#define SONAR_LE_INTERNAL_H

#include <stdint.h>

static inline uint16_t sonar_le16(const uint8_t *p)
{
    return (uint16_t)(p[0] | (p[1] << 8));
}

static inline void sonar_put_le16(uint8_t *p, uint16_t v)
{
    p[0] = (uint8_t)(v & 0xffu);
    p[1] = (uint8_t)(v >> 8);
}

#endif
