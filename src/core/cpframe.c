/* cpframe.c -- co-processor frames: CRC-32 by nibble table (64 B of flash), an O(1)-amortised per byte parser that resyncs byte by byte; no heap. */
#include "sonar/cpframe.h"

#include <string.h>

#include "le_internal.h"

static const uint32_t crc_nibble[16] = {
    0x00000000u, 0x1DB71064u, 0x3B6E20C8u, 0x26D930ACu, 0x76DC4190u, 0x6B6B51F4u, 0x4DB26158u, 0x5005713Cu,
    0xEDB88320u, 0xF00F9344u, 0xD6D6A3E8u, 0xCB61B38Cu, 0x9B64C2B0u, 0x86D3D2D4u, 0xA00AE278u, 0xBDBDF21Cu};

uint32_t sonar_cpf_crc32(uint32_t crc, const uint8_t *p, size_t n)
{
    crc = ~crc;
    while (n--) {
        crc ^= *p++;
        crc = (crc >> 4) ^ crc_nibble[crc & 15u];
        crc = (crc >> 4) ^ crc_nibble[crc & 15u];
    }
    return ~crc;
}

int sonar_cpf_encode(uint8_t *buf, size_t cap, uint8_t channel, const uint8_t *payload, uint16_t len)
{
    uint32_t crc;
    if (buf == NULL || len > SONAR_CPF_MAX_PAYLOAD || (len > 0 && payload == NULL))
        return SONAR_ERR_ARG;
    if (cap < (size_t)len + SONAR_CPF_OVERHEAD)
        return SONAR_ERR_SPACE;
    buf[0] = SONAR_CPF_SYNC0;
    buf[1] = SONAR_CPF_SYNC1;
    buf[2] = channel;
    sonar_put_le16(buf + 3, len);
    if (len > 0)
        memmove(buf + SONAR_CPF_HEADER, payload, len);
    crc = sonar_cpf_crc32(0, buf + 2, (size_t)len + 3u);
    sonar_put_le16(buf + SONAR_CPF_HEADER + len, (uint16_t)(crc & 0xffffu));
    sonar_put_le16(buf + SONAR_CPF_HEADER + len + 2, (uint16_t)(crc >> 16));
    return (int)len + (int)SONAR_CPF_OVERHEAD;
}

void sonar_cpf_parser_init(struct sonar_cpf_parser *p)
{
    memset(p, 0, sizeof(*p));
}

static int known_channel(uint8_t c)
{
    return c == SONAR_CPF_DETECTIONS || c == SONAR_CPF_STATUS || c == SONAR_CPF_BEAM || c == SONAR_CPF_CONFIG ||
           c == SONAR_CPF_REPLY;
}

/*
 * Drops the first byte of the assembled bytes and keeps the rest from the next sync on: an "A5 5C"
 * pair, or a lone A5 at the very end (its 5C may still come).
 */
static void resync(struct sonar_cpf_parser *p)
{
    uint16_t i;
    for (i = 1; i < p->have; i++)
        if (p->buf[i] == SONAR_CPF_SYNC0 && (i + 1u == p->have || p->buf[i + 1u] == SONAR_CPF_SYNC1))
            break;
    p->counters.bytes_dropped += i;
    memmove(p->buf, p->buf + i, (size_t)(p->have - i));
    p->have = (uint16_t)(p->have - i);
}

int sonar_cpf_next(struct sonar_cpf_parser *p, const uint8_t **data, size_t *len, struct sonar_cpf_frame *f)
{
    if (p->ready) {
        /* Bytes after the returned frame (found while rescanning a bad one) are kept. */
        memmove(p->buf, p->buf + p->ready_len, (size_t)(p->have - p->ready_len));
        p->have = (uint16_t)(p->have - p->ready_len);
        p->ready = 0;
    }
    for (;;) {
        uint16_t plen;
        uint32_t need, crc, got;
        /* The header first; a wrong sync byte is skipped at once. */
        while (p->have < SONAR_CPF_HEADER && *len > 0) {
            uint8_t b = **data;
            if ((p->have == 0 && b != SONAR_CPF_SYNC0) || (p->have == 1 && b != SONAR_CPF_SYNC1)) {
                p->counters.bytes_dropped++;
                if (p->have == 1) {
                    p->have = 0;
                    continue; /* b may be the sync's first byte: look at it again */
                }
                (*data)++;
                (*len)--;
                continue;
            }
            p->buf[p->have++] = b;
            (*data)++;
            (*len)--;
        }
        if (p->have < SONAR_CPF_HEADER)
            return 0;
        plen = sonar_le16(p->buf + 3);
        if (!known_channel(p->buf[2])) {
            resync(p);
            continue;
        }
        if (plen > SONAR_CPF_MAX_PAYLOAD) {
            p->counters.oversize++;
            resync(p);
            continue;
        }
        need = (uint32_t)plen + SONAR_CPF_OVERHEAD;
        if (p->have < need) {
            size_t take = need - p->have < *len ? (size_t)(need - p->have) : *len;
            memcpy(p->buf + p->have, *data, take);
            p->have = (uint16_t)(p->have + take);
            *data += take;
            *len -= take;
            if (p->have < need)
                return 0;
        }
        crc = sonar_cpf_crc32(0, p->buf + 2, (size_t)plen + 3u);
        got = (uint32_t)sonar_le16(p->buf + SONAR_CPF_HEADER + plen) |
              (uint32_t)sonar_le16(p->buf + SONAR_CPF_HEADER + plen + 2) << 16;
        if (crc != got) {
            p->counters.crc_errors++;
            /* The rest of the bad frame may hold a good one: rescan it from its second byte. */
            resync(p);
            continue;
        }
        p->counters.frames++;
        p->ready = 1;
        p->ready_len = (uint16_t)need;
        f->channel = p->buf[2];
        f->len = plen;
        f->payload = p->buf + SONAR_CPF_HEADER;
        return 1;
    }
}
