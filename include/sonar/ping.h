/* ping.h -- Ping Protocol v1 streaming parser, Ping360 decoders and encoders; RAM: sizeof(struct sonar_ping_parser) = 2 088 B, the payload (SONAR_PING_MAX_PAYLOAD) and 40 B; no heap. */
#ifndef SONAR_PING_H
#define SONAR_PING_H

#include <stddef.h>
#include <stdint.h>

#include "sonar/config.h"
#include "sonar/err.h"

/* Frame = 'B' 'R' u16 payload_length, u16 message_id, u8 src, u8 dst, payload, u16 checksum (all LE). */
#define SONAR_PING_HEADER_LEN 8u
#define SONAR_PING_OVERHEAD 10u

enum sonar_ping_id {
    SONAR_PING_ACK = 1,
    SONAR_PING_NACK = 2,
    SONAR_PING_ASCII_TEXT = 3,
    SONAR_PING_DEVICE_INFORMATION = 4,
    SONAR_PING_PROTOCOL_VERSION = 5,
    SONAR_PING_GENERAL_REQUEST = 6,
    SONAR_PING360_DEVICE_DATA = 2300,
    SONAR_PING360_AUTO_DEVICE_DATA = 2301,
    SONAR_PING360_RESET = 2600,
    SONAR_PING360_TRANSDUCER = 2601,
    SONAR_PING360_AUTO_TRANSMIT = 2602,
    SONAR_PING360_MOTOR_OFF = 2903
};

/* The echosounder's (Ping1D's) message ids: another device when they arrive on a Ping360's link. */
#define SONAR_PING1D_FIRST_ID 1000u
#define SONAR_PING1D_LAST_ID 1999u

/* device_information's device_type. */
enum sonar_ping_device_type { SONAR_PING_DEVICE_UNKNOWN = 0, SONAR_PING_DEVICE_PING1D = 1, SONAR_PING_DEVICE_PING360 = 2 };

/* One checked frame. payload points into the parser and is valid until the next parser call. */
struct sonar_ping_frame {
    uint16_t id;
    uint8_t src;
    uint8_t dst;
    uint16_t payload_len;
    const uint8_t *payload;
};

struct sonar_ping_counters {
    uint32_t frames;          /* frames with a good checksum */
    uint32_t checksum_errors; /* "BR" + plausible length whose checksum failed */
    uint32_t resyncs;         /* times the parser dropped bytes to find the next "BR" */
    uint32_t oversize;        /* headers whose payload_length exceeded the limit */
    uint32_t bytes_dropped;   /* bytes discarded by any of the above */
};

/* Parser state, owned by the caller. Holds at most one frame plus the bytes after it. */
struct sonar_ping_parser {
    uint8_t buf[SONAR_PING_MAX_PAYLOAD + SONAR_PING_OVERHEAD];
    uint16_t head;        /* first live byte of buf */
    uint16_t tail;        /* one past the last live byte */
    uint16_t pending;     /* bytes of the frame last returned, dropped on the next call */
    uint16_t max_payload; /* 0..SONAR_PING_MAX_PAYLOAD */
    uint8_t in_garbage;   /* 1 while a run of dropped bytes continues (one resync per run) */
    struct sonar_ping_counters counters;
};

/*
 * Initialises p. max_payload: largest payload accepted, 1..SONAR_PING_MAX_PAYLOAD (0 selects the
 * limit). Returns SONAR_OK or SONAR_ERR_ARG.
 */
SONAR_CHECK int sonar_ping_parser_init(struct sonar_ping_parser *p, uint16_t max_payload);

/*
 * Consumes bytes from *data (advancing *data and decreasing *len) until one frame is complete.
 * Returns 1 and fills *frame when a frame with a good checksum is found; returns 0 when every
 * input byte is consumed and more are needed (buffered bytes are kept). Call it again, with
 * *len == 0 if need be, until it returns 0: several frames may arrive in one chunk. Garbage, an
 * oversize length or a bad checksum drops one byte and rescans, so no valid frame after them is
 * lost. Never reads outside data[0..*len); *frame is written only when 1 is returned.
 */
SONAR_CHECK int sonar_ping_parser_next(struct sonar_ping_parser *p, const uint8_t **data, size_t *len,
                                       struct sonar_ping_frame *frame);

/* Ping360 device_data (2300) or auto_device_data (2301); data points into the frame. */
struct sonar_ping360_data {
    uint8_t mode;
    uint8_t gain;                /* 0 low, 1 normal, 2 high */
    uint16_t angle;              /* gradians, 0..399 */
    uint16_t transmit_duration;  /* us */
    uint16_t sample_period;      /* 25 ns ticks */
    uint16_t transmit_frequency; /* kHz */
    uint16_t number_of_samples;
    uint16_t start_angle;        /* auto only, gradians */
    uint16_t stop_angle;         /* auto only, gradians */
    uint8_t num_steps;           /* auto only */
    uint8_t delay;               /* auto only, ms */
    uint8_t is_auto;             /* 1 for 2301 */
    uint16_t data_length;
    const uint8_t *data;         /* data_length samples, nearest first */
};

/*
 * Decodes 2300 or 2301. Returns SONAR_OK; SONAR_ERR_ID for another message; SONAR_ERR_LENGTH when
 * payload_len != fixed part + data_length; SONAR_ERR_RANGE when angle > 399. *out untouched on error.
 */
SONAR_CHECK int sonar_ping_decode_data(const struct sonar_ping_frame *f, struct sonar_ping360_data *out);

/* ack (1): the acknowledged id. Returns SONAR_OK, SONAR_ERR_ID or SONAR_ERR_LENGTH (must be 2). */
SONAR_CHECK int sonar_ping_decode_ack(const struct sonar_ping_frame *f, uint16_t *acked_id);

/* nack (2): id and an unterminated message of *msg_len bytes in the frame. Length must be >= 2. */
SONAR_CHECK int sonar_ping_decode_nack(const struct sonar_ping_frame *f, uint16_t *nacked_id, const char **msg,
                                       uint16_t *msg_len);

/* ascii_text (3): unterminated text in the frame. Any length. */
SONAR_CHECK int sonar_ping_decode_ascii(const struct sonar_ping_frame *f, const char **text, uint16_t *text_len);

struct sonar_ping_device_info {
    uint8_t device_type; /* 0 unknown, 1 Ping Echosounder, 2 Ping360 */
    uint8_t device_revision;
    uint8_t fw_major;
    uint8_t fw_minor;
    uint8_t fw_patch;
};

/* device_information (4). Length must be 6. */
SONAR_CHECK int sonar_ping_decode_device_info(const struct sonar_ping_frame *f, struct sonar_ping_device_info *out);

struct sonar_ping_version {
    uint8_t major;
    uint8_t minor;
    uint8_t patch;
};

/* protocol_version (5). Length must be 4. */
SONAR_CHECK int sonar_ping_decode_version(const struct sonar_ping_frame *f, struct sonar_ping_version *out);

/*
 * Encoders write one complete frame (src = dst = 0) into buf[0..cap) and return its length in
 * bytes, or SONAR_ERR_SPACE if cap is too small, or SONAR_ERR_ARG for a NULL buf or a bad value.
 */
SONAR_CHECK int sonar_ping_encode(uint8_t *buf, size_t cap, uint16_t id, const uint8_t *payload, uint16_t payload_len);
SONAR_CHECK int sonar_ping_encode_general_request(uint8_t *buf, size_t cap, uint16_t requested_id);
SONAR_CHECK int sonar_ping_encode_motor_off(uint8_t *buf, size_t cap);
/* bootloader: 0 run the application after reset, 1 stay in the bootloader. */
SONAR_CHECK int sonar_ping_encode_reset(uint8_t *buf, size_t cap, uint8_t bootloader);

/* transducer (2601). Values are sent as given; angle must be <= 399, transmit 0 or 1. */
struct sonar_ping360_transducer {
    uint8_t mode;
    uint8_t gain;
    uint16_t angle;
    uint16_t transmit_duration;
    uint16_t sample_period;
    uint16_t transmit_frequency;
    uint16_t number_of_samples;
    uint8_t transmit;
};
SONAR_CHECK int sonar_ping_encode_transducer(uint8_t *buf, size_t cap, const struct sonar_ping360_transducer *t);

/* auto_transmit (2602). start/stop <= 399, num_steps 1..10, delay 0..100 ms. */
struct sonar_ping360_auto_transmit {
    uint8_t mode;
    uint8_t gain;
    uint16_t transmit_duration;
    uint16_t sample_period;
    uint16_t transmit_frequency;
    uint16_t number_of_samples;
    uint16_t start_angle;
    uint16_t stop_angle;
    uint8_t num_steps;
    uint8_t delay;
};
SONAR_CHECK int sonar_ping_encode_auto_transmit(uint8_t *buf, size_t cap, const struct sonar_ping360_auto_transmit *a);

#endif
