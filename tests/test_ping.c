/* test_ping.c -- Ping Protocol codec: ping.md's worked bytes, resync on garbage, split chunks, length checks. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "sonar/ping.h"

static void expect_bytes(const uint8_t *got, int n, const uint8_t *want, size_t wn)
{
    assert_int_equal(n, (int)wn);
    assert_memory_equal(got, want, wn);
}

static void test_worked_requests(void **state)
{
    uint8_t b[64];
    static const uint8_t pv[] = {0x42, 0x52, 0x02, 0x00, 0x06, 0x00, 0x00, 0x00, 0x05, 0x00, 0xa1, 0x00};
    static const uint8_t di[] = {0x42, 0x52, 0x02, 0x00, 0x06, 0x00, 0x00, 0x00, 0x04, 0x00, 0xa0, 0x00};
    static const uint8_t dd[] = {0x42, 0x52, 0x02, 0x00, 0x06, 0x00, 0x00, 0x00, 0xfc, 0x08, 0xa0, 0x01};
    static const uint8_t mo[] = {0x42, 0x52, 0x00, 0x00, 0x57, 0x0b, 0x00, 0x00, 0xf6, 0x00};
    static const uint8_t rs[] = {0x42, 0x52, 0x02, 0x00, 0x28, 0x0a, 0x00, 0x00, 0x00, 0x00, 0xc8, 0x00};
    (void)state;
    expect_bytes(b, sonar_ping_encode_general_request(b, sizeof(b), SONAR_PING_PROTOCOL_VERSION), pv, sizeof(pv));
    expect_bytes(b, sonar_ping_encode_general_request(b, sizeof(b), SONAR_PING_DEVICE_INFORMATION), di, sizeof(di));
    expect_bytes(b, sonar_ping_encode_general_request(b, sizeof(b), SONAR_PING360_DEVICE_DATA), dd, sizeof(dd));
    expect_bytes(b, sonar_ping_encode_motor_off(b, sizeof(b)), mo, sizeof(mo));
    expect_bytes(b, sonar_ping_encode_reset(b, sizeof(b), 0), rs, sizeof(rs));
    assert_int_equal(sonar_ping_encode_reset(b, sizeof(b), 2), SONAR_ERR_ARG);
}

static void test_worked_transducer_and_auto(void **state)
{
    uint8_t b[64];
    static const uint8_t tr[] = {0x42, 0x52, 0x0e, 0x00, 0x29, 0x0a, 0x00, 0x00, 0x01, 0x00, 0xc8, 0x00, 0x0b, 0x00,
                                 0x58, 0x00, 0xee, 0x02, 0xb0, 0x04, 0x01, 0x00, 0xa6, 0x03};
    static const uint8_t at[] = {0x42, 0x52, 0x10, 0x00, 0x2a, 0x0a, 0x00, 0x00, 0x01, 0x00, 0x0b, 0x00, 0x58,
                                 0x00, 0xee, 0x02, 0xb0, 0x04, 0x00, 0x00, 0x8f, 0x01, 0x01, 0x00, 0x71, 0x03};
    struct sonar_ping360_transducer t = {1, 0, 200, 11, 88, 750, 1200, 1};
    struct sonar_ping360_auto_transmit a = {1, 0, 11, 88, 750, 1200, 0, 399, 1, 0};
    (void)state;
    expect_bytes(b, sonar_ping_encode_transducer(b, sizeof(b), &t), tr, sizeof(tr));
    expect_bytes(b, sonar_ping_encode_auto_transmit(b, sizeof(b), &a), at, sizeof(at));
    assert_int_equal(sonar_ping_encode_transducer(b, 23, &t), SONAR_ERR_SPACE);
    t.angle = 400;
    assert_int_equal(sonar_ping_encode_transducer(b, sizeof(b), &t), SONAR_ERR_ARG);
    a.num_steps = 11;
    assert_int_equal(sonar_ping_encode_auto_transmit(b, sizeof(b), &a), SONAR_ERR_ARG);
}

static const uint8_t device_data_4[] = {0x42, 0x52, 0x12, 0x00, 0xfc, 0x08, 0x02, 0x00, 0x01, 0x00, 0xc8, 0x00, 0x0b, 0x00,
                                        0x58, 0x00, 0xee, 0x02, 0x04, 0x00, 0x04, 0x00, 0x0a, 0x14, 0x1e, 0x28, 0x34, 0x04};

static void test_decode_device_data(void **state)
{
    struct sonar_ping_parser p;
    struct sonar_ping_frame f;
    struct sonar_ping360_data d;
    const uint8_t *in = device_data_4;
    size_t len = sizeof(device_data_4);
    (void)state;
    assert_int_equal(sonar_ping_parser_init(&p, 0), SONAR_OK);
    assert_int_equal(sonar_ping_parser_next(&p, &in, &len, &f), 1);
    assert_int_equal(f.id, 2300);
    assert_int_equal(f.src, 2);
    assert_int_equal(sonar_ping_decode_data(&f, &d), SONAR_OK);
    assert_int_equal(d.mode, 1);
    assert_int_equal(d.angle, 200);
    assert_int_equal(d.transmit_duration, 11);
    assert_int_equal(d.sample_period, 88);
    assert_int_equal(d.transmit_frequency, 750);
    assert_int_equal(d.number_of_samples, 4);
    assert_int_equal(d.data_length, 4);
    assert_int_equal(d.data[0], 10);
    assert_int_equal(d.data[3], 40);
    assert_int_equal(d.is_auto, 0);
    assert_int_equal(sonar_ping_parser_next(&p, &in, &len, &f), 0);
    assert_int_equal(p.counters.frames, 1);
    assert_int_equal(p.counters.resyncs, 0);
}

/* Builds a device_data frame with n samples of value v at angle a into b; returns its length. */
static int frame_data(uint8_t *b, size_t cap, uint16_t a, uint16_t n, uint8_t v)
{
    uint8_t q[14 + 1200];
    q[0] = 1;
    q[1] = 0;
    q[2] = (uint8_t)(a & 0xff);
    q[3] = (uint8_t)(a >> 8);
    memset(q + 4, 0, 6);
    q[10] = (uint8_t)(n & 0xff);
    q[11] = (uint8_t)(n >> 8);
    q[12] = q[10];
    q[13] = q[11];
    memset(q + 14, v, n);
    return sonar_ping_encode(b, cap, SONAR_PING360_DEVICE_DATA, q, (uint16_t)(14 + n));
}

/* Feeds stream in chunks of `chunk` bytes (0 = random 1..97) and records the angles decoded. */
static int parse_all(const uint8_t *s, size_t n, size_t chunk, uint16_t *angles, int max, struct sonar_ping_parser *p)
{
    struct sonar_ping_frame f;
    int got = 0;
    size_t off = 0;
    assert_int_equal(sonar_ping_parser_init(p, 0), SONAR_OK);
    while (off < n) {
        size_t c = chunk ? chunk : (size_t)(1 + rand() % 97);
        const uint8_t *in = s + off;
        size_t len = c < n - off ? c : n - off;
        off += len;
        while (sonar_ping_parser_next(p, &in, &len, &f) == 1) {
            struct sonar_ping360_data d;
            assert_int_equal(sonar_ping_decode_data(&f, &d), SONAR_OK);
            if (got < max)
                angles[got] = d.angle;
            got++;
        }
        assert_int_equal(len, 0);
    }
    return got;
}

static void test_split_chunks(void **state)
{
    static uint8_t s[4 * 1300];
    uint16_t ang[8];
    size_t n = 0;
    size_t chunk;
    struct sonar_ping_parser p;
    int i;
    (void)state;
    for (i = 0; i < 4; i++)
        n += (size_t)frame_data(s + n, sizeof(s) - n, (uint16_t)(i * 100), 1200, (uint8_t)i);
    for (chunk = 0; chunk <= 1300; chunk = chunk ? chunk * 3 : 1) {
        memset(ang, 0, sizeof(ang));
        assert_int_equal(parse_all(s, n, chunk, ang, 8, &p), 4);
        for (i = 0; i < 4; i++)
            assert_int_equal(ang[i], i * 100);
        assert_int_equal(p.counters.checksum_errors + p.counters.resyncs + p.counters.oversize, 0);
    }
}

/* ping.md §1: the stream on which brping recovers 1 of 3 frames. */
static void test_crafted_stream_recovers_all(void **state)
{
    static uint8_t s[4096];
    uint8_t fr[64];
    uint16_t ang[8];
    struct sonar_ping_parser p;
    size_t n = 0;
    int fl;
    (void)state;
    /* 1: an odd number of 'B's before a frame */
    s[n++] = 'B';
    n += (size_t)frame_data(s + n, sizeof(s) - n, 1, 4, 7);
    /* 2: a real frame inside a bogus one whose checksum fails */
    s[n++] = 'B';
    s[n++] = 'R';
    s[n++] = 30;
    s[n++] = 0;
    s[n++] = 0xfc;
    s[n++] = 0x08;
    s[n++] = 0;
    s[n++] = 0;
    fl = frame_data(fr, sizeof(fr), 2, 4, 8);
    memcpy(s + n, fr, (size_t)fl);
    n += (size_t)fl;
    memset(s + n, 0x55, 20);
    n += 20;
    /* 3: a garbage header claiming 65 535 bytes right before a frame */
    s[n++] = 'B';
    s[n++] = 'R';
    s[n++] = 0xff;
    s[n++] = 0xff;
    n += (size_t)frame_data(s + n, sizeof(s) - n, 3, 4, 9);
    assert_int_equal(parse_all(s, n, 5, ang, 8, &p), 3);
    assert_int_equal(ang[0], 1);
    assert_int_equal(ang[1], 2);
    assert_int_equal(ang[2], 3);
    assert_true(p.counters.oversize >= 1);
    assert_true(p.counters.resyncs >= 2);
}

static void test_bad_checksum_then_frame(void **state)
{
    static uint8_t s[256];
    uint16_t ang[4];
    struct sonar_ping_parser p;
    size_t n;
    (void)state;
    n = (size_t)frame_data(s, sizeof(s), 10, 4, 1);
    s[n - 1] ^= 0x40; /* corrupt the checksum */
    n += (size_t)frame_data(s + n, sizeof(s) - n, 11, 4, 1);
    s[12] ^= 0x01; /* and a payload byte, so the first frame cannot pass */
    assert_int_equal(parse_all(s, n, 0, ang, 4, &p), 1);
    assert_int_equal(ang[0], 11);
    assert_int_equal(p.counters.checksum_errors, 1);
    assert_int_equal(p.counters.frames, 1);
}

static void test_random_garbage_between_frames(void **state)
{
    static uint8_t s[200000];
    static uint16_t ang[300];
    struct sonar_ping_parser p;
    size_t n = 0;
    int i, got;
    (void)state;
    srand(1234);
    for (i = 0; i < 100; i++) {
        int g = rand() % 300, j;
        for (j = 0; j < g; j++)
            s[n++] = (uint8_t)(rand() % 4 == 0 ? 'B' : rand() % 3 == 0 ? 'R' : rand());
        n += (size_t)frame_data(s + n, sizeof(s) - n, (uint16_t)i, (uint16_t)(200 + rand() % 1000), (uint8_t)i);
    }
    got = parse_all(s, n, 0, ang, 300, &p);
    /* Every genuine frame comes out, in order (a garbage frame with a valid checksum is vanishingly rare). */
    assert_int_equal(got, 100);
    for (i = 0; i < 100; i++)
        assert_int_equal(ang[i], i);
}

static void test_output_untouched_when_incomplete(void **state)
{
    struct sonar_ping_parser p;
    struct sonar_ping_frame f, before;
    const uint8_t *in = device_data_4;
    size_t len = sizeof(device_data_4) - 1;
    (void)state;
    memset(&f, 0xA5, sizeof(f));
    before = f;
    assert_int_equal(sonar_ping_parser_init(&p, 0), SONAR_OK);
    assert_int_equal(sonar_ping_parser_next(&p, &in, &len, &f), 0);
    assert_memory_equal(&f, &before, sizeof(f));
    in = device_data_4 + sizeof(device_data_4) - 1;
    len = 1;
    assert_int_equal(sonar_ping_parser_next(&p, &in, &len, &f), 1);
    assert_int_equal(sonar_ping_parser_init(&p, SONAR_PING_MAX_PAYLOAD + 1), SONAR_ERR_ARG);
    assert_int_equal(sonar_ping_parser_next(&p, NULL, &len, &f), SONAR_ERR_ARG);
}

static void test_max_payload_limit(void **state)
{
    static uint8_t s[1400];
    struct sonar_ping_parser p;
    struct sonar_ping_frame f;
    const uint8_t *in = s;
    size_t len = (size_t)frame_data(s, sizeof(s), 5, 1200, 3);
    (void)state;
    assert_int_equal(sonar_ping_parser_init(&p, 1000), SONAR_OK);
    assert_int_equal(sonar_ping_parser_next(&p, &in, &len, &f), 0);
    assert_int_equal(p.counters.oversize, 1);
    assert_int_equal(p.counters.frames, 0);
}

static void test_decoder_length_checks(void **state)
{
    uint8_t pl[32] = {0};
    struct sonar_ping_frame f;
    struct sonar_ping360_data d;
    struct sonar_ping_device_info di;
    struct sonar_ping_version v;
    uint16_t id, ml;
    const char *msg;
    (void)state;
    f.payload = pl;
    f.src = f.dst = 0;
    /* device_data whose vector claims 4 bytes but carries 3 */
    f.id = SONAR_PING360_DEVICE_DATA;
    f.payload_len = 17;
    pl[12] = 4;
    memset(&d, 0x5A, sizeof(d));
    assert_int_equal(sonar_ping_decode_data(&f, &d), SONAR_ERR_LENGTH);
    assert_int_equal(d.mode, 0x5A);
    f.payload_len = 10;
    assert_int_equal(sonar_ping_decode_data(&f, &d), SONAR_ERR_LENGTH);
    /* angle 400 is not a Ping360 angle */
    f.payload_len = 18;
    pl[2] = 0x90;
    pl[3] = 0x01;
    assert_int_equal(sonar_ping_decode_data(&f, &d), SONAR_ERR_RANGE);
    /* auto_device_data: 20-byte fixed part, number_of_samples at 16 */
    memset(pl, 0, sizeof(pl));
    f.id = SONAR_PING360_AUTO_DEVICE_DATA;
    f.payload_len = 22;
    pl[2] = 7;
    pl[14] = 1;
    pl[16] = 2;
    pl[18] = 2;
    assert_int_equal(sonar_ping_decode_data(&f, &d), SONAR_OK);
    assert_int_equal(d.is_auto, 1);
    assert_int_equal(d.angle, 7);
    assert_int_equal(d.number_of_samples, 2);
    assert_int_equal(d.num_steps, 1);
    f.payload_len = 21;
    assert_int_equal(sonar_ping_decode_data(&f, &d), SONAR_ERR_LENGTH);
    /* fixed-size messages */
    f.id = SONAR_PING_ACK;
    f.payload_len = 2;
    pl[0] = 0x57;
    pl[1] = 0x0b;
    assert_int_equal(sonar_ping_decode_ack(&f, &id), SONAR_OK);
    assert_int_equal(id, 2903);
    f.payload_len = 3;
    assert_int_equal(sonar_ping_decode_ack(&f, &id), SONAR_ERR_LENGTH);
    f.id = SONAR_PING_NACK;
    f.payload_len = 5;
    memcpy(pl + 2, "bad", 3);
    assert_int_equal(sonar_ping_decode_nack(&f, &id, &msg, &ml), SONAR_OK);
    assert_int_equal(ml, 3);
    assert_memory_equal(msg, "bad", 3);
    f.payload_len = 1;
    assert_int_equal(sonar_ping_decode_nack(&f, &id, &msg, &ml), SONAR_ERR_LENGTH);
    f.id = SONAR_PING_DEVICE_INFORMATION;
    f.payload_len = 6;
    pl[0] = 2;
    pl[2] = 3;
    pl[3] = 3;
    pl[4] = 8;
    assert_int_equal(sonar_ping_decode_device_info(&f, &di), SONAR_OK);
    assert_int_equal(di.device_type, 2);
    assert_int_equal(di.fw_patch, 8);
    f.payload_len = 5;
    assert_int_equal(sonar_ping_decode_device_info(&f, &di), SONAR_ERR_LENGTH);
    f.id = SONAR_PING_PROTOCOL_VERSION;
    f.payload_len = 4;
    pl[0] = 1;
    pl[1] = 1;
    pl[2] = 0;
    assert_int_equal(sonar_ping_decode_version(&f, &v), SONAR_OK);
    assert_int_equal(v.minor, 1);
    assert_int_equal(sonar_ping_decode_data(&f, &d), SONAR_ERR_ID);
    f.id = SONAR_PING_ASCII_TEXT;
    f.payload_len = 3;
    assert_int_equal(sonar_ping_decode_ascii(&f, &msg, &ml), SONAR_OK);
    assert_int_equal(ml, 3);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_worked_requests),
        cmocka_unit_test(test_worked_transducer_and_auto),
        cmocka_unit_test(test_decode_device_data),
        cmocka_unit_test(test_split_chunks),
        cmocka_unit_test(test_crafted_stream_recovers_all),
        cmocka_unit_test(test_bad_checksum_then_frame),
        cmocka_unit_test(test_random_garbage_between_frames),
        cmocka_unit_test(test_output_untouched_when_incomplete),
        cmocka_unit_test(test_max_payload_limit),
        cmocka_unit_test(test_decoder_length_checks),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
