/* test_cpframe.c -- co-processor frames: CRC-32 check value, round trip, every split, garbage and corrupt frames between good ones, oversize lengths, a frame inside a bad one. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "sonar/cpframe.h"

static struct sonar_cpf_parser p;

static void test_crc32_check_value(void **state)
{
    (void)state;
    /* The standard check value of CRC-32/ISO-HDLC over "123456789". */
    assert_int_equal(sonar_cpf_crc32(0, (const uint8_t *)"123456789", 9), 0xCBF43926u);
    /* Continuing over pieces equals one pass. */
    assert_int_equal(sonar_cpf_crc32(sonar_cpf_crc32(0, (const uint8_t *)"1234", 4), (const uint8_t *)"56789", 5),
                     0xCBF43926u);
}

static int feed(const uint8_t *b, size_t n, size_t chunk, uint8_t *channels, int max)
{
    int got = 0;
    size_t off = 0;
    while (off < n) {
        size_t take = chunk < n - off ? chunk : n - off, len = take;
        const uint8_t *in = b + off;
        struct sonar_cpf_frame f;
        while (sonar_cpf_next(&p, &in, &len, &f) == 1) {
            assert_true(f.len <= SONAR_CPF_MAX_PAYLOAD);
            if (got < max)
                channels[got] = f.channel;
            got++;
        }
        assert_int_equal(len, 0);
        off += take;
    }
    return got;
}

static void test_round_trip_every_split(void **state)
{
    uint8_t pl[300], buf[2 * 320], ch[4];
    size_t chunk;
    int n1, n2, i;
    (void)state;
    for (i = 0; i < 300; i++)
        pl[i] = (uint8_t)(i * 31 + 7);
    n1 = sonar_cpf_encode(buf, sizeof(buf), SONAR_CPF_DETECTIONS, pl, 300);
    assert_int_equal(n1, 309);
    n2 = sonar_cpf_encode(buf + n1, sizeof(buf) - (size_t)n1, SONAR_CPF_REPLY, NULL, 0);
    assert_int_equal(n2, 9);
    for (chunk = 1; chunk <= (size_t)(n1 + n2); chunk++) {
        sonar_cpf_parser_init(&p);
        assert_int_equal(feed(buf, (size_t)(n1 + n2), chunk, ch, 4), 2);
        assert_int_equal(ch[0], SONAR_CPF_DETECTIONS);
        assert_int_equal(ch[1], SONAR_CPF_REPLY);
        assert_int_equal(p.counters.bytes_dropped, 0);
    }
    /* The payload comes back byte for byte. */
    {
        const uint8_t *in = buf;
        size_t len = (size_t)n1;
        struct sonar_cpf_frame f;
        sonar_cpf_parser_init(&p);
        assert_int_equal(sonar_cpf_next(&p, &in, &len, &f), 1);
        assert_int_equal(f.len, 300);
        assert_memory_equal(f.payload, pl, 300);
    }
    assert_int_equal(sonar_cpf_encode(buf, 100, 1, pl, 300), SONAR_ERR_SPACE);
    assert_int_equal(sonar_cpf_encode(buf, sizeof(buf), 1, NULL, 5), SONAR_ERR_ARG);
}

static void test_garbage_corruption_and_oversize(void **state)
{
    static uint8_t stream[200000];
    uint8_t pl[64], ch[256];
    size_t n = 0;
    int i, good = 0, got;
    unsigned seed = 12345;
    (void)state;
    for (i = 0; i < 200; i++) {
        int k, r;
        seed = seed * 1103515245u + 12345u;
        /* junk biased towards the sync bytes */
        for (k = 0; k < (int)(seed >> 24) % 40; k++) {
            seed = seed * 1103515245u + 12345u;
            stream[n++] = (uint8_t)((seed >> 16) % 3 == 0 ? SONAR_CPF_SYNC0 : (seed >> 16) % 3 == 1 ? SONAR_CPF_SYNC1 : seed >> 8);
        }
        memset(pl, i, sizeof(pl));
        r = sonar_cpf_encode(stream + n, sizeof(stream) - n, (uint8_t)(i % 3 + 1), pl, (uint16_t)(i % 64));
        assert_true(r > 0);
        if (i % 7 == 3) {
            stream[n + 5 + (size_t)(i % 64) / 2] ^= 0x40; /* the payload, or with none the CRC: it fails */
        } else {
            good++;
        }
        n += (size_t)r;
    }
    /* An oversize header, then a good frame right after its first bytes. */
    stream[n++] = SONAR_CPF_SYNC0;
    stream[n++] = SONAR_CPF_SYNC1;
    stream[n++] = 1;
    stream[n++] = 0xff;
    stream[n++] = 0xff;
    n += (size_t)sonar_cpf_encode(stream + n, sizeof(stream) - n, 2, pl, 10);
    good++;
    sonar_cpf_parser_init(&p);
    got = feed(stream, n, 97, ch, 256);
    assert_int_equal(got, good);
    assert_true(p.counters.crc_errors >= 28);
    assert_true(p.counters.oversize >= 1); /* ours; the junk may hold more */
    assert_true(p.counters.bytes_dropped > 0);
}

static void test_frame_inside_a_bad_one(void **state)
{
    uint8_t buf[256], inner[40];
    const uint8_t *in;
    size_t len;
    struct sonar_cpf_frame f;
    int k;
    (void)state;
    /* A header claiming 100 bytes whose payload starts with a complete good frame; the CRC of the outer one fails. */
    k = sonar_cpf_encode(inner, sizeof(inner), SONAR_CPF_STATUS, (const uint8_t *)"hello", 5);
    buf[0] = SONAR_CPF_SYNC0;
    buf[1] = SONAR_CPF_SYNC1;
    buf[2] = 1;
    buf[3] = 100;
    buf[4] = 0;
    memcpy(buf + 5, inner, (size_t)k);
    memset(buf + 5 + k, 0x33, 100 - (size_t)k + 4);
    sonar_cpf_parser_init(&p);
    in = buf;
    len = 109;
    assert_int_equal(sonar_cpf_next(&p, &in, &len, &f), 1);
    assert_int_equal(f.channel, SONAR_CPF_STATUS);
    assert_int_equal(f.len, 5);
    assert_memory_equal(f.payload, "hello", 5);
    assert_int_equal(p.counters.crc_errors, 1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_crc32_check_value),
        cmocka_unit_test(test_round_trip_every_split),
        cmocka_unit_test(test_garbage_corruption_and_oversize),
        cmocka_unit_test(test_frame_inside_a_bad_one),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
