/* ping.c -- Ping Protocol v1 resyncing stream parser and Ping360 codec; O(1) per byte amortised, no heap. */
#include "sonar/ping.h"

#include <string.h>

#include "sonar/frame.h"

#include "le_internal.h"

int sonar_ping_parser_init(struct sonar_ping_parser *p, uint16_t max_payload)
{
    if (p == NULL || max_payload > SONAR_PING_MAX_PAYLOAD)
        return SONAR_ERR_ARG;
    memset(p, 0, sizeof(*p));
    p->max_payload = max_payload == 0 ? (uint16_t)SONAR_PING_MAX_PAYLOAD : max_payload;
    return SONAR_OK;
}

static uint16_t checksum(const uint8_t *b, size_t n)
{
    uint32_t s = 0;
    size_t i;
    for (i = 0; i < n; i++)
        s += b[i];
    return (uint16_t)(s & 0xffffu);
}

/* Drops n live bytes that are not part of a frame; one resync is counted per run of drops. */
static void drop(struct sonar_ping_parser *p, uint16_t n)
{
    p->head = (uint16_t)(p->head + n);
    p->counters.bytes_dropped += n;
    if (!p->in_garbage) {
        p->counters.resyncs++;
        p->in_garbage = 1;
    }
}

/* Moves as many input bytes into buf as fit, compacting first so a whole frame always fits. */
static void refill(struct sonar_ping_parser *p, const uint8_t **data, size_t *len)
{
    size_t room, take;
    if (p->head > 0) {
        memmove(p->buf, p->buf + p->head, (size_t)(p->tail - p->head));
        p->tail = (uint16_t)(p->tail - p->head);
        p->head = 0;
    }
    room = sizeof(p->buf) - p->tail;
    take = *len < room ? *len : room;
    if (take > 0) {
        memcpy(p->buf + p->tail, *data, take);
        p->tail = (uint16_t)(p->tail + take);
        *data += take;
        *len -= take;
    }
}

int sonar_ping_parser_next(struct sonar_ping_parser *p, const uint8_t **data, size_t *len,
                           struct sonar_ping_frame *frame)
{
    if (p == NULL || data == NULL || len == NULL || frame == NULL || (*data == NULL && *len > 0))
        return SONAR_ERR_ARG;
    p->head = (uint16_t)(p->head + p->pending);
    p->pending = 0;

    for (;;) {
        uint16_t avail = (uint16_t)(p->tail - p->head);
        const uint8_t *b = p->buf + p->head;
        uint16_t i, plen, need;

        /* Find "BR"; keep a trailing lone 'B' since its 'R' may be in the next chunk. */
        for (i = 0; i + 1 < avail; i++)
            if (b[i] == 'B' && b[i + 1] == 'R')
                break;
        if (i + 1 >= avail && !(avail > 0 && i == avail - 1 && b[i] == 'B'))
            i = avail;
        if (i > 0) {
            drop(p, i);
            continue;
        }
        if (avail < SONAR_PING_HEADER_LEN) {
            if (*len == 0)
                return 0;
            refill(p, data, len);
            continue;
        }
        plen = sonar_le16(b + 2);
        if (plen > p->max_payload) {
            p->counters.oversize++;
            drop(p, 1);
            continue;
        }
        need = (uint16_t)(SONAR_PING_OVERHEAD + plen);
        if (avail < need) {
            if (*len == 0)
                return 0;
            refill(p, data, len);
            continue;
        }
        if (checksum(b, (size_t)need - 2u) != sonar_le16(b + need - 2)) {
            p->counters.checksum_errors++;
            drop(p, 1);
            continue;
        }
        p->in_garbage = 0;
        p->counters.frames++;
        p->pending = need;
        frame->payload_len = plen;
        frame->id = sonar_le16(b + 4);
        frame->src = b[6];
        frame->dst = b[7];
        frame->payload = b + SONAR_PING_HEADER_LEN;
        return 1;
    }
}

int sonar_ping_decode_data(const struct sonar_ping_frame *f, struct sonar_ping360_data *out)
{
    struct sonar_ping360_data d;
    const uint8_t *q;
    uint16_t fixed;
    if (f == NULL || out == NULL || (f->payload == NULL && f->payload_len > 0))
        return SONAR_ERR_ARG;
    if (f->id != SONAR_PING360_DEVICE_DATA && f->id != SONAR_PING360_AUTO_DEVICE_DATA)
        return SONAR_ERR_ID;
    memset(&d, 0, sizeof(d));
    d.is_auto = f->id == SONAR_PING360_AUTO_DEVICE_DATA;
    fixed = d.is_auto ? 20u : 14u;
    if (f->payload_len < fixed)
        return SONAR_ERR_LENGTH;
    q = f->payload;
    d.mode = q[0];
    d.gain = q[1];
    d.angle = sonar_le16(q + 2);
    d.transmit_duration = sonar_le16(q + 4);
    d.sample_period = sonar_le16(q + 6);
    d.transmit_frequency = sonar_le16(q + 8);
    if (d.is_auto) {
        d.start_angle = sonar_le16(q + 10);
        d.stop_angle = sonar_le16(q + 12);
        d.num_steps = q[14];
        d.delay = q[15];
        d.number_of_samples = sonar_le16(q + 16);
        d.data_length = sonar_le16(q + 18);
    } else {
        d.number_of_samples = sonar_le16(q + 10);
        d.data_length = sonar_le16(q + 12);
    }
    /* The vector's own length prefix must account for every remaining byte. */
    if ((uint32_t)fixed + d.data_length != f->payload_len)
        return SONAR_ERR_LENGTH;
    if (d.angle > SONAR_GRAD_MAX)
        return SONAR_ERR_RANGE;
    d.data = q + fixed;
    *out = d;
    return SONAR_OK;
}

static int expect(const struct sonar_ping_frame *f, uint16_t id, uint16_t min_len, int exact)
{
    if (f == NULL || (f->payload == NULL && f->payload_len > 0))
        return SONAR_ERR_ARG;
    if (f->id != id)
        return SONAR_ERR_ID;
    if (exact ? f->payload_len != min_len : f->payload_len < min_len)
        return SONAR_ERR_LENGTH;
    return SONAR_OK;
}

int sonar_ping_decode_ack(const struct sonar_ping_frame *f, uint16_t *acked_id)
{
    int r = expect(f, SONAR_PING_ACK, 2, 1);
    if (r != SONAR_OK)
        return r;
    if (acked_id == NULL)
        return SONAR_ERR_ARG;
    *acked_id = sonar_le16(f->payload);
    return SONAR_OK;
}

int sonar_ping_decode_nack(const struct sonar_ping_frame *f, uint16_t *nacked_id, const char **msg, uint16_t *msg_len)
{
    int r = expect(f, SONAR_PING_NACK, 2, 0);
    if (r != SONAR_OK)
        return r;
    if (nacked_id == NULL || msg == NULL || msg_len == NULL)
        return SONAR_ERR_ARG;
    *nacked_id = sonar_le16(f->payload);
    *msg = (const char *)(f->payload + 2);
    *msg_len = (uint16_t)(f->payload_len - 2u);
    return SONAR_OK;
}

int sonar_ping_decode_ascii(const struct sonar_ping_frame *f, const char **text, uint16_t *text_len)
{
    int r = expect(f, SONAR_PING_ASCII_TEXT, 0, 0);
    if (r != SONAR_OK)
        return r;
    if (text == NULL || text_len == NULL)
        return SONAR_ERR_ARG;
    *text = (const char *)f->payload;
    *text_len = f->payload_len;
    return SONAR_OK;
}

int sonar_ping_decode_device_info(const struct sonar_ping_frame *f, struct sonar_ping_device_info *out)
{
    int r = expect(f, SONAR_PING_DEVICE_INFORMATION, 6, 1);
    if (r != SONAR_OK)
        return r;
    if (out == NULL)
        return SONAR_ERR_ARG;
    out->device_type = f->payload[0];
    out->device_revision = f->payload[1];
    out->fw_major = f->payload[2];
    out->fw_minor = f->payload[3];
    out->fw_patch = f->payload[4];
    return SONAR_OK;
}

int sonar_ping_decode_version(const struct sonar_ping_frame *f, struct sonar_ping_version *out)
{
    int r = expect(f, SONAR_PING_PROTOCOL_VERSION, 4, 1);
    if (r != SONAR_OK)
        return r;
    if (out == NULL)
        return SONAR_ERR_ARG;
    out->major = f->payload[0];
    out->minor = f->payload[1];
    out->patch = f->payload[2];
    return SONAR_OK;
}

int sonar_ping_encode(uint8_t *buf, size_t cap, uint16_t id, const uint8_t *payload, uint16_t payload_len)
{
    size_t total = (size_t)SONAR_PING_OVERHEAD + payload_len;
    if (buf == NULL || (payload == NULL && payload_len > 0))
        return SONAR_ERR_ARG;
    if (cap < total)
        return SONAR_ERR_SPACE;
    buf[0] = 'B';
    buf[1] = 'R';
    sonar_put_le16(buf + 2, payload_len);
    sonar_put_le16(buf + 4, id);
    buf[6] = 0;
    buf[7] = 0;
    if (payload_len > 0)
        memmove(buf + SONAR_PING_HEADER_LEN, payload, payload_len);
    sonar_put_le16(buf + total - 2, checksum(buf, total - 2));
    return (int)total;
}

int sonar_ping_encode_general_request(uint8_t *buf, size_t cap, uint16_t requested_id)
{
    uint8_t q[2];
    sonar_put_le16(q, requested_id);
    return sonar_ping_encode(buf, cap, SONAR_PING_GENERAL_REQUEST, q, sizeof(q));
}

int sonar_ping_encode_motor_off(uint8_t *buf, size_t cap)
{
    return sonar_ping_encode(buf, cap, SONAR_PING360_MOTOR_OFF, NULL, 0);
}

int sonar_ping_encode_reset(uint8_t *buf, size_t cap, uint8_t bootloader)
{
    uint8_t q[2];
    if (bootloader > 1)
        return SONAR_ERR_ARG;
    q[0] = bootloader;
    q[1] = 0;
    return sonar_ping_encode(buf, cap, SONAR_PING360_RESET, q, sizeof(q));
}

int sonar_ping_encode_transducer(uint8_t *buf, size_t cap, const struct sonar_ping360_transducer *t)
{
    uint8_t q[14];
    if (t == NULL || t->angle > SONAR_GRAD_MAX || t->transmit > 1u)
        return SONAR_ERR_ARG;
    q[0] = t->mode;
    q[1] = t->gain;
    sonar_put_le16(q + 2, t->angle);
    sonar_put_le16(q + 4, t->transmit_duration);
    sonar_put_le16(q + 6, t->sample_period);
    sonar_put_le16(q + 8, t->transmit_frequency);
    sonar_put_le16(q + 10, t->number_of_samples);
    q[12] = t->transmit;
    q[13] = 0;
    return sonar_ping_encode(buf, cap, SONAR_PING360_TRANSDUCER, q, sizeof(q));
}

int sonar_ping_encode_auto_transmit(uint8_t *buf, size_t cap, const struct sonar_ping360_auto_transmit *a)
{
    uint8_t q[16];
    if (a == NULL || a->start_angle > SONAR_GRAD_MAX || a->stop_angle > SONAR_GRAD_MAX || a->num_steps < 1u || a->num_steps > 10u ||
        a->delay > 100u)
        return SONAR_ERR_ARG;
    q[0] = a->mode;
    q[1] = a->gain;
    sonar_put_le16(q + 2, a->transmit_duration);
    sonar_put_le16(q + 4, a->sample_period);
    sonar_put_le16(q + 6, a->transmit_frequency);
    sonar_put_le16(q + 8, a->number_of_samples);
    sonar_put_le16(q + 10, a->start_angle);
    sonar_put_le16(q + 12, a->stop_angle);
    q[14] = a->num_steps;
    q[15] = a->delay;
    return sonar_ping_encode(buf, cap, SONAR_PING360_AUTO_TRANSMIT, q, sizeof(q));
}
