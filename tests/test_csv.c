/* test_csv.c -- the study's CSV forms, metadata, and a named reason for every malformed row. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "csv.h"

static struct csv_reader rd;
static struct csv_row row;
static char path[64];

static void write_file(const char *text)
{
    int fd;
    FILE *f;
    strcpy(path, "/tmp/sonard-csv-XXXXXX");
    fd = mkstemp(path);
    assert_true(fd >= 0);
    f = fdopen(fd, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
    assert_int_equal(csv_open(&rd, path), 0);
}

static void done(void)
{
    csv_close(&rd);
    unlink(path);
}

static void test_study_forms(void **state)
{
    char err[128];
    (void)state;
    write_file("timestamp_sec,timestamp_nsec,angle,data\n"
               "1728153122,072070224,4,\"255 255 255  161 155 138  60 52 70\"\n"
               "1728153122,72070224,5,255,255,255,161,155,138,60,52,70\n"
               "1728153122.072070224,6,\"[255 255 255 ... 161 155 138 60 52 70]\"\n"
               "\n"
               "1728153123,5,7,255 255 255,161 155 138,60 52 70,range_m=2.5,gain=1\n");
    assert_int_equal(csv_next(&rd, &row, err, sizeof(err)), 1);
    assert_int_equal(rd.line, 2);
    assert_int_equal(row.sec, 1728153122);
    assert_int_equal(row.nsec, 72070224);
    assert_int_equal(row.angle, 4);
    assert_int_equal(row.n, 9);
    assert_int_equal(row.samples[3], 161);
    assert_int_equal(row.samples[8], 70);
    assert_true(row.range_m < 0);
    assert_int_equal(csv_next(&rd, &row, err, sizeof(err)), 1);
    assert_int_equal(row.angle, 5);
    assert_int_equal(row.n, 9);
    assert_int_equal(csv_next(&rd, &row, err, sizeof(err)), 1);
    assert_int_equal(row.nsec, 72070224);
    assert_int_equal(row.angle, 6);
    assert_int_equal(row.samples[0], 255);
    assert_int_equal(row.samples[8], 70);
    assert_int_equal(csv_next(&rd, &row, err, sizeof(err)), 1);
    assert_int_equal(rd.line, 6);
    assert_int_equal(row.nsec, 5);
    assert_true(row.range_m == 2.5);
    assert_true(row.gain == 1.0);
    assert_int_equal(csv_next(&rd, &row, err, sizeof(err)), 0);
    assert_int_equal(rd.good, 4);
    assert_int_equal(rd.bad, 0);
    done();
}

static void expect_bad(const char *want)
{
    char err[128];
    assert_int_equal(csv_next(&rd, &row, err, sizeof(err)), HOST_ERR_ROW);
    if (strstr(err, want) == NULL)
        fail_msg("line %lu: got '%s', want '%s'", rd.line, err, want);
}

static void test_bad_rows_named_and_skipped(void **state)
{
    char err[128];
    static char text[16384];
    size_t n;
    int i;
    (void)state;
    strcpy(text, "1,0,1,\"1 2 3\"\n"
                 "1,0,2,\"1 2 x\"\n"
                 "1,0,3,\"1 2 300\"\n"
                 "1,0,4,\"1 2\"\n"
                 "1,0,400,\"1 2 3\"\n"
                 "1,1000000000,5,\"1 2 3\"\n"
                 "1.x,6,\"1 2 3\"\n"
                 "1,0,7\n"
                 "1,0,8,\"1 2 3\"\n");
    n = strlen(text);
    n += (size_t)sprintf(text + n, "1,0,9,\"");
    for (i = 0; i < SONAR_MAX_SAMPLES + 1; i++)
        n += (size_t)sprintf(text + n, "1 ");
    strcpy(text + n, "\"\n1,0,10,\"4 5 6\"\n");
    write_file(text);
    assert_int_equal(csv_next(&rd, &row, err, sizeof(err)), 1);
    expect_bad("sample 3 'x' is not a number");
    assert_int_equal(rd.line, 2);
    expect_bad("sample 3 is 300, outside 0..255");
    expect_bad("2 samples, but the file's first row had 3");
    expect_bad("angle '400' is not an integer 0..399");
    expect_bad("nanoseconds '1000000000'");
    expect_bad("timestamp '1.x' is not sec.nsec");
    expect_bad("no samples");
    assert_int_equal(csv_next(&rd, &row, err, sizeof(err)), 1);
    assert_int_equal(row.angle, 8);
    expect_bad("more than 1200 samples");
    assert_int_equal(csv_next(&rd, &row, err, sizeof(err)), 1);
    assert_int_equal(row.angle, 10);
    assert_int_equal(rd.line, 11);
    assert_int_equal(csv_next(&rd, &row, err, sizeof(err)), 0);
    assert_int_equal(rd.good, 3);
    assert_int_equal(rd.bad, 8);
    done();
}

static void test_overlong_line(void **state)
{
    char err[128];
    static char text[CSV_LINE_MAX + 200];
    (void)state;
    memset(text, '1', sizeof(text));
    memcpy(text, "1,0,1,\"", 7);
    strcpy(text + CSV_LINE_MAX + 100, "\n1,0,2,\"9\"\n");
    write_file(text);
    expect_bad("line longer than");
    assert_int_equal(csv_next(&rd, &row, err, sizeof(err)), 1);
    assert_int_equal(row.angle, 2);
    assert_int_equal(rd.line, 2);
    done();
}

/* Random rows in every spelling the tokenizer accepts, against a plain strtoul reference. */
static void test_random_rows_match_reference(void **state)
{
    static char text[1 << 22];
    static uint8_t want[400][SONAR_MAX_SAMPLES];
    static const char *const seps[] = {" ", "  ", ",", " , ", "\t", "\" \"", " ... "};
    char err[128];
    size_t n = 0;
    int r, i;
    (void)state;
    srand(99);
    for (r = 0; r < 400; r++) {
        int quoted = rand() % 2;
        n += (size_t)sprintf(text + n, "%d,%d,%d,%s%s", 1700000000 + r, rand() % 1000000, r % 400, quoted ? "\"" : "",
                             rand() % 5 == 0 ? "[" : "");
        for (i = 0; i < 333; i++) {
            int v = rand() % 4 == 0 ? rand() % 10 : rand() % 256;
            want[r][i] = (uint8_t)v;
            n += (size_t)sprintf(text + n, rand() % 9 == 0 ? "%03d" : rand() % 50 == 0 ? "%04d" : "%d", v);
            if (i < 332)
                n += (size_t)sprintf(text + n, "%s", quoted ? " " : seps[rand() % 7]);
        }
        n += (size_t)sprintf(text + n, "%s%s%s\n", quoted ? "\"" : "", rand() % 3 == 0 ? ",range_m=7.5" : "",
                             rand() % 4 == 0 ? " " : "");
    }
    write_file(text);
    for (r = 0; r < 400; r++) {
        if (csv_next(&rd, &row, err, sizeof(err)) != 1)
            fail_msg("row %d: %s", r + 1, err);
        assert_int_equal(row.n, 333);
        assert_memory_equal(row.samples, want[r], 333);
    }
    assert_int_equal(csv_next(&rd, &row, err, sizeof(err)), 0);
    done();
}

static void test_writer_round_trip(void **state)
{
    char err[128];
    uint8_t s[5] = {0, 1, 128, 254, 255};
    FILE *f;
    int fd;
    (void)state;
    strcpy(path, "/tmp/sonard-csv-XXXXXX");
    fd = mkstemp(path);
    f = fdopen(fd, "w");
    struct csv_meta m = csv_meta_none();
    m.range_m = 12.0;
    m.gain = 1;
    m.sample_period = 888;
    m.speed_of_sound = 1480;
    assert_int_equal(csv_write(f, 1728153122, 72070224, 399, s, 5, &m), 0);
    fclose(f);
    assert_int_equal(csv_open(&rd, path), 0);
    assert_int_equal(csv_next(&rd, &row, err, sizeof(err)), 1);
    assert_int_equal(row.nsec, 72070224);
    assert_int_equal(row.angle, 399);
    assert_memory_equal(row.samples, s, 5);
    assert_true(row.range_m == 12.0);
    assert_true(row.gain == 1.0);
    assert_true(row.sample_period == 888.0);
    assert_true(row.speed_of_sound == 1480.0);
    assert_true(row.transmit_duration < 0);
    assert_int_equal(row.has_pose, 0);
    done();
}

/* The vehicle's pose rides on each row: written, read back, and half a pose refused by name. */
/* brping's form: 'angle;s0;s1;...' under a header, no timestamps; named, and timed by the caller. */
static void test_untimed_semicolon_form(void **state)
{
    char err[128];
    (void)state;
    write_file("Angle (gradian);Intensity (0-255)\n"
               "   150;76;152;201\n"
               "151;1;2;3;range_m=2\n"
               "152;1,5;2;3\n"
               "400;1;2;3\n"
               "153;1;2\n"
               "154;9;8;7\n");
    assert_string_equal(csv_format_name(&rd), "empty (no rows)");
    assert_int_equal(csv_next(&rd, &row, err, sizeof(err)), 1);
    assert_int_equal(rd.format, CSV_FORMAT_UNTIMED);
    assert_non_null(strstr(csv_format_name(&rd), "angle;samples"));
    assert_int_equal(row.timed, 0);
    assert_int_equal(row.sec, 0);
    assert_int_equal(row.angle, 150);
    assert_int_equal(row.n, 3);
    assert_int_equal(row.samples[0], 76);
    assert_int_equal(row.samples[2], 201);
    assert_int_equal(csv_next(&rd, &row, err, sizeof(err)), 1);
    assert_true(row.range_m == 2.0);
    expect_bad("not a number"); /* a decimal comma is no sample */
    expect_bad("angle '400'");
    expect_bad("2 samples");
    assert_int_equal(csv_next(&rd, &row, err, sizeof(err)), 1);
    assert_int_equal(row.angle, 154);
    assert_int_equal(rd.good, 3);
    assert_int_equal(rd.bad, 3);
    done();
    /* the study's form says so, and its rows are timed */
    write_file("1,0,4,\"1 2 3\"\n");
    assert_int_equal(csv_next(&rd, &row, err, sizeof(err)), 1);
    assert_int_equal(rd.format, CSV_FORMAT_STUDY);
    assert_int_equal(row.timed, 1);
    done();
}

static void test_pose_metadata(void **state)
{
    char err[160];
    uint8_t s[3] = {1, 2, 3};
    FILE *f;
    int fd;
    struct csv_meta m = csv_meta_none();
    (void)state;
    strcpy(path, "/tmp/sonard-csv-XXXXXX");
    fd = mkstemp(path);
    f = fdopen(fd, "w");
    m.range_m = 15.0;
    m.has_pose = 1;
    m.north_m = -12.5;
    m.east_m = 3.25;
    m.yaw_deg = 359.5;
    assert_int_equal(csv_write(f, 1728153122, 0, 7, s, 3, &m), 0);
    fputs("1728153122,100000000,8,\"1 2 3\",north_m=1,east_m=2\n", f);
    fputs("1728153122,200000000,9,\"1 2 3\",north_m=1,east_m=2,yaw_deg=400\n", f);
    fputs("1728153122,300000000,10,\"1 2 3\",yaw_deg=-90,north_m=0,east_m=0\n", f);
    fclose(f);
    assert_int_equal(csv_open(&rd, path), 0);
    assert_int_equal(csv_next(&rd, &row, err, sizeof(err)), 1);
    assert_true(row.has_pose && row.north_m == -12.5 && row.east_m == 3.25 && row.yaw_deg == 359.5);
    assert_true(row.range_m == 15.0);
    assert_int_equal(csv_next(&rd, &row, err, sizeof(err)), HOST_ERR_ROW);
    assert_non_null(strstr(err, "north_m, east_m and yaw_deg come together (yaw_deg missing)"));
    assert_int_equal(csv_next(&rd, &row, err, sizeof(err)), HOST_ERR_ROW);
    assert_non_null(strstr(err, "metadata yaw_deg=400 is not a number in -360..360"));
    assert_int_equal(csv_next(&rd, &row, err, sizeof(err)), 1);
    assert_true(row.has_pose && row.yaw_deg == -90.0);
    done();
}

/* A gzip-compressed recording is read as its text; one cut short yields its rows, then one named error. */
static void test_gzip_compressed(void **state)
{
    static const char text[] = "1,0,10,1 2 3 4\n1,5,11,5 6 7 8\n";
    char err[256], cmd[200], gz[80];
    unsigned char bytes[4096];
    size_t nb;
    FILE *f;
    int i;
    (void)state;
    write_file(text);
    csv_close(&rd);
    snprintf(gz, sizeof(gz), "%s.gz", path);
    snprintf(cmd, sizeof(cmd), "gzip -c %s > %s", path, gz);
    if (system(cmd) != 0) {
        unlink(path);
        skip(); /* no gzip on this machine: nothing to read it with either */
    }
    unlink(path);
    assert_int_equal(csv_open(&rd, gz), 0);
    for (i = 0; i < 2; i++) {
        assert_int_equal(csv_next(&rd, &row, err, sizeof(err)), 1);
        assert_int_equal(row.angle, 10 + i);
        assert_int_equal(row.samples[3], 4 + 4 * i);
    }
    assert_int_equal(csv_next(&rd, &row, err, sizeof(err)), 0);
    csv_close(&rd);
    /* Cut short: the rows gzip could give, then a named error, then the end. */
    f = fopen(gz, "rb");
    assert_non_null(f);
    nb = fread(bytes, 1, sizeof(bytes), f);
    fclose(f);
    assert_true(nb > 12);
    f = fopen(gz, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(bytes, 1, nb - 6, f), nb - 6); /* the trailer's CRC and length gone */
    fclose(f);
    assert_int_equal(csv_open(&rd, gz), 0);
    while ((i = csv_next(&rd, &row, err, sizeof(err))) == 1)
        ;
    assert_int_equal(i, HOST_ERR_ROW);
    assert_non_null(strstr(err, "truncated or corrupt"));
    assert_int_equal(csv_next(&rd, &row, err, sizeof(err)), 0);
    csv_close(&rd);
    /* Stopped early: closing reaps the child without waiting for it to finish. */
    assert_int_equal(csv_open(&rd, gz), 0);
    csv_close(&rd);
    /* The same bytes on a stream: one error naming them, not a garbage row per line. */
    f = fmemopen(bytes, nb, "r");
    assert_non_null(f);
    csv_open_stream(&rd, f, "stdin");
    assert_int_equal(csv_next(&rd, &row, err, sizeof(err)), HOST_ERR_ROW);
    assert_non_null(strstr(err, "gzip-compressed"));
    assert_int_equal(csv_next(&rd, &row, err, sizeof(err)), 0);
    assert_int_equal(rd.bad, 1);
    fclose(f);
    unlink(gz);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_study_forms),
        cmocka_unit_test(test_bad_rows_named_and_skipped),
        cmocka_unit_test(test_overlong_line),
        cmocka_unit_test(test_random_rows_match_reference),
        cmocka_unit_test(test_writer_round_trip),
        cmocka_unit_test(test_pose_metadata),
        cmocka_unit_test(test_untimed_semicolon_form),
        cmocka_unit_test(test_gzip_compressed),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
