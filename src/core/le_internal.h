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

static inline uint32_t sonar_le32(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

static inline void sonar_put_le32(uint8_t *p, uint32_t v)
{
    sonar_put_le16(p, (uint16_t)(v & 0xffffu));
    sonar_put_le16(p + 2, (uint16_t)(v >> 16));
}

#endif
