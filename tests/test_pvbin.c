/* test_pvbin.c -- Ping Viewer logs built in memory: beams across records and junk become CSV rows at the records' times; a foreign file, a bad time, a cut record and a beam of another length each named, the beams before them kept. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "pvbin.h"

#include <cmocka.h>

struct log {
    uint8_t b[65536];
    size_t n;
};

static void be32(struct log *l, uint32_t v)
{
    l->b[l->n++] = (uint8_t)(v >> 24);
    l->b[l->n++] = (uint8_t)(v >> 16);
    l->b[l->n++] = (uint8_t)(v >> 8);
    l->b[l->n++] = (uint8_t)v;
}

/* A QString as Qt writes it: UTF-16BE with a byte length. */
static void qstring(struct log *l, const char *s)
{
    size_t i, k = strlen(s);
    be32(l, (uint32_t)(2 * k));
    for (i = 0; i < k; i++) {
        l->b[l->n++] = 0;
        l->b[l->n++] = (uint8_t)s[i];
    }
}

static void header(struct log *l, uint32_t type)
{
    static const char *const meta[] = {"36168c2", "2026-12-03T08:00:00", "", "Linux", "6"};
    int i;
    l->n = 0;
    qstring(l, "PingViewer sensor log file");
    be32(l, 1);
    for (i = 0; i < 5; i++)
        qstring(l, meta[i]);
    be32(l, 1);
    be32(l, type);
}

static void record(struct log *l, const char *time, const uint8_t *chunk, size_t n)
{
    qstring(l, time);
    be32(l, (uint32_t)n);
    memcpy(l->b + l->n, chunk, n);
    l->n += n;
}

/* A device_data (2300) frame of n samples at angle, every sample = angle. */
static size_t beam(uint8_t *out, uint16_t angle, uint16_t n)
{
    uint8_t p[14 + 1200];
    uint16_t i;
    int len;
    memset(p, 0, 14);
    p[1] = 1;                      /* gain */
    p[2] = (uint8_t)angle;
    p[3] = (uint8_t)(angle >> 8);
    p[4] = 32;                     /* transmit duration, us */
    p[6] = 0xA0;                   /* sample period 0x00A0 = 160 ticks */
    p[8] = 0xEE;                   /* 750 kHz */
    p[9] = 0x02;
    p[10] = (uint8_t)n;
    p[11] = (uint8_t)(n >> 8);
    p[12] = (uint8_t)n;
    p[13] = (uint8_t)(n >> 8);
    for (i = 0; i < n; i++)
        p[14 + i] = (uint8_t)angle;
    len = sonar_ping_encode(out, 1300, 2300, p, (uint16_t)(14 + n));
    assert_true(len > 0);
    return (size_t)len;
}

/* The CSV rows written to f, one per line, into rows (count returned). */
static int rows_of(FILE *f, char rows[][64], int max)
{
    char line[8192];
    int k = 0;
    rewind(f);
    while (k < max && fgets(line, sizeof(line), f) != NULL)
        snprintf(rows[k++], 64, "%.63s", line);
    return k;
}

static void beams_across_records_at_their_times(void **state)
{
    static struct log l;
    uint8_t stream[4096];
    size_t n = 0;
    struct pvbin_stats st;
    char rows[8][64];
    FILE *out = tmpfile(), *err = tmpfile();
    (void)state;
    memcpy(stream, "\x13junk", 5); /* bytes before the first frame: resynced over */
    n = 5;
    n += beam(stream + n, 10, 200);
    n += beam(stream + n, 11, 200);
    n += beam(stream + n, 12, 200);
    header(&l, 2);
    /* Cut where the frames are not: the parser runs across records. */
    record(&l, "00:00:01.250", stream, 100);
    record(&l, "00:00:01.500", stream + 100, 300);
    record(&l, "00:00:02.001", stream + 400, n - 400);
    assert_int_equal(pvbin_convert(l.b, l.n, "t.bin", 1000.0, 1500.0, out, err, &st), HOST_OK);
    assert_int_equal(st.records, 3);
    assert_int_equal(st.beams, 3);
    assert_int_equal(st.skipped, 0);
    assert_true(st.parser.bytes_dropped >= 5);
    assert_int_equal(rows_of(out, rows, 8), 3);
    /* A beam (224 B) takes the time of the record its last byte came in: 1000 s + the record's clock. */
    assert_true(strncmp(rows[0], "1001,500000000,10,", 18) == 0);
    assert_true(strncmp(rows[1], "1002,001000000,11,", 18) == 0);
    assert_true(strncmp(rows[2], "1002,001000000,12,", 18) == 0);
    fclose(out);
    fclose(err);
}

static void midnight_wraps_to_the_next_day(void **state)
{
    static struct log l;
    uint8_t f[1300];
    size_t n;
    struct pvbin_stats st;
    char rows[4][64];
    FILE *out = tmpfile();
    (void)state;
    header(&l, 2);
    n = beam(f, 5, 200);
    record(&l, "23:59:59.999", f, n);
    n = beam(f, 6, 200);
    record(&l, "00:00:00.001", f, n);
    assert_int_equal(pvbin_convert(l.b, l.n, "t.bin", 0.0, 1500.0, out, NULL, &st), HOST_OK);
    assert_int_equal(rows_of(out, rows, 4), 2);
    assert_true(strncmp(rows[0], "86399,999000000,5,", 18) == 0);
    assert_true(strncmp(rows[1], "86400,001000000,6,", 18) == 0);
    fclose(out);
}

/* What pvbin_convert said to errf. */
static const char *said(FILE *err, char *buf, size_t n)
{
    size_t k;
    rewind(err);
    k = fread(buf, 1, n - 1, err);
    buf[k] = '\0';
    return buf;
}

static void not_a_log_is_named(void **state)
{
    static struct log l;
    struct pvbin_stats st;
    char msg[512];
    FILE *out = tmpfile(), *err = tmpfile();
    (void)state;
    l.n = 0;
    qstring(&l, "something else");
    assert_int_equal(pvbin_convert(l.b, l.n, "x.bin", 0.0, 1500.0, out, err, &st), HOST_ERR_CONFIG);
    assert_non_null(strstr(said(err, msg, sizeof(msg)), "x.bin: not a Ping Viewer sensor log"));
    header(&l, 2);
    l.n -= 3; /* cut inside the sensor type */
    assert_int_equal(pvbin_convert(l.b, l.n, "x.bin", 0.0, 1500.0, out, err, &st), HOST_ERR_CONFIG);
    assert_non_null(strstr(said(err, msg, sizeof(msg)), "truncated header"));
    fclose(out);
    fclose(err);
}

static void bad_records_stop_and_keep_the_beams_before(void **state)
{
    static struct log l;
    uint8_t f[1300];
    size_t n;
    struct pvbin_stats st;
    char msg[1024];
    FILE *out = tmpfile(), *err = tmpfile();
    (void)state;
    header(&l, 2);
    n = beam(f, 1, 200);
    record(&l, "00:00:01.000", f, n);
    n = beam(f, 2, 300); /* another length among beams of 200: skipped, named */
    record(&l, "00:00:01.100", f, n);
    n = beam(f, 3, 200);
    record(&l, "00:00:01.200", f, n);
    record(&l, "25:00:00.000", f, n); /* not a time: stops */
    record(&l, "00:00:02.000", f, n);
    assert_int_equal(pvbin_convert(l.b, l.n, "b.bin", 0.0, 1500.0, out, err, &st), HOST_OK);
    assert_int_equal(st.beams, 2);
    assert_int_equal(st.skipped, 1);
    said(err, msg, sizeof(msg));
    assert_non_null(strstr(msg, "record 2: a beam of 300 samples among beams of 200; skipped"));
    assert_non_null(strstr(msg, "record 4 at byte"));
    assert_non_null(strstr(msg, "'25:00:00.000' is not hh:mm:ss.zzz"));
    /* A record whose length runs past the end: named, the beams before it kept. */
    header(&l, 2);
    n = beam(f, 1, 200);
    record(&l, "00:00:01.000", f, n);
    record(&l, "00:00:01.100", f, n);
    l.n -= 10;
    rewind(err);
    assert_int_equal(pvbin_convert(l.b, l.n, "c.bin", 0.0, 1500.0, out, err, &st), HOST_OK);
    assert_int_equal(st.beams, 1);
    assert_non_null(strstr(said(err, msg, sizeof(msg)), "record 2 truncated at byte"));
    fclose(out);
    fclose(err);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(beams_across_records_at_their_times),
        cmocka_unit_test(midnight_wraps_to_the_next_day),
        cmocka_unit_test(not_a_log_is_named),
        cmocka_unit_test(bad_records_stop_and_keep_the_beams_before),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
