/* cpframe.h -- the co-processor link's frame (docs/coprocessor.md): sync, channel, length, payload, CRC-32; encoder and an incremental, resyncing parser; RAM: sizeof(struct sonar_cpf_parser) = 4 128 B (one frame). */
#ifndef SONAR_CPFRAME_H
#define SONAR_CPFRAME_H

#include <stddef.h>
#include <stdint.h>

#include "sonar/err.h"

/*
 * Largest payload, bytes (a sonar.detections_t of 16 detections with 16-vertex hulls is ~2.5 KB;
 * a sonar.beam_t of 1200 samples ~1.3 KB). RAM: the parser holds one frame.
 */
#ifndef SONAR_CPF_MAX_PAYLOAD
#define SONAR_CPF_MAX_PAYLOAD 4096u
#endif

#define SONAR_CPF_SYNC0 0xA5u
#define SONAR_CPF_SYNC1 0x5Cu
#define SONAR_CPF_HEADER 5u   /* sync (2), channel (1), length (2, little-endian) */
#define SONAR_CPF_OVERHEAD 9u /* header + CRC-32 (4, little-endian) */

/* Channels: what the payload is. Messages are LCM-encoded (fingerprint first) unless noted. */
enum sonar_cpf_channel {
    SONAR_CPF_DETECTIONS = 1, /* fw -> host: sonar.detections_t, per sweep */
    SONAR_CPF_STATUS = 2,     /* fw -> host: sonar.status_t, once a second */
    SONAR_CPF_BEAM = 3,       /* fw -> host: sonar.beam_t, every Nth beam when asked */
    SONAR_CPF_CONFIG = 16,    /* host -> fw: sonar.config_t */
    SONAR_CPF_REPLY = 17      /* fw -> host: text, "ok" or "error: FIELD: RULE" */
};

struct sonar_cpf_frame {
    uint8_t channel;
    uint16_t len;
    const uint8_t *payload; /* inside the parser's buffer, valid until the next call */
};

struct sonar_cpf_counters {
    uint32_t frames;        /* frames with a good CRC */
    uint32_t crc_errors;    /* a complete frame whose CRC failed */
    uint32_t oversize;      /* headers whose length exceeded SONAR_CPF_MAX_PAYLOAD */
    uint32_t bytes_dropped; /* bytes skipped while looking for a sync */
};

struct sonar_cpf_parser {
    uint8_t buf[SONAR_CPF_MAX_PAYLOAD + SONAR_CPF_OVERHEAD];
    uint16_t have;  /* bytes of the frame being assembled */
    uint8_t ready;      /* buf starts with a returned frame of ready_len bytes: drop it at the next call */
    uint16_t ready_len;
    struct sonar_cpf_counters counters;
};

/* CRC-32 (IEEE 802.3, reflected, init and final xor 0xFFFFFFFF) of n bytes, continuing crc (0 to start). */
uint32_t sonar_cpf_crc32(uint32_t crc, const uint8_t *p, size_t n);

/*
 * Writes one frame into buf (cap bytes): returns its length (len + 9), SONAR_ERR_ARG (len over
 * the limit, NULL) or SONAR_ERR_SPACE. payload may be NULL when len is 0.
 */
SONAR_CHECK int sonar_cpf_encode(uint8_t *buf, size_t cap, uint8_t channel, const uint8_t *payload, uint16_t len);

/* Empties p; the counters start at 0. */
void sonar_cpf_parser_init(struct sonar_cpf_parser *p);

/*
 * Consumes bytes from *data (advancing it, decreasing *len) until a frame with a good CRC is
 * complete: returns 1 with *f filled, or 0 when every byte was consumed and more are needed. A
 * bad CRC, an unknown channel or an oversize length drops one byte and rescans, so a frame
 * starting inside a bad one is still found (call again with *len == 0 to drain what is buffered).
 * Bytes before a sync are counted as dropped. *f is written only when 1 is returned.
 */
SONAR_CHECK int sonar_cpf_next(struct sonar_cpf_parser *p, const uint8_t **data, size_t *len, struct sonar_cpf_frame *f);

#endif
