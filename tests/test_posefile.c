/* test_posefile.c -- the --pose CSV: header by name, rows read ahead of the beams, bad and refused rows named by line. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "app.h"
#include "posefile.h"

static char path[64];
static struct app_storage app_mem;
static struct app *app;
static struct posefile pf;

static int64_t zero_ns(void *u)
{
    (void)u;
    return 0;
}

static void write_file(const char *text)
{
    FILE *f;
    int fd;
    strcpy(path, "/tmp/sonard-pose-XXXXXX");
    fd = mkstemp(path);
    assert_true(fd >= 0);
    f = fdopen(fd, "w");
    fputs(text, f);
    fclose(f);
}

static void start_app(void)
{
    struct sonar_pipeline_config c;
    struct app_clock clk = {zero_ns, zero_ns, NULL};
    char err[128];
    sonar_pipeline_defaults(&c);
    assert_int_equal(app_init(&app, &app_mem, &c, NULL, NULL, &clk, 0, err, sizeof(err)), HOST_OK);
}

static void test_header_by_name(void **state)
{
    char err[200];
    (void)state;
    write_file("yaw_deg, utime_us ,east_m,north_m,depth_m\n720,2000000,10,20,5\n");
    assert_int_equal(posefile_open(&pf, path, err, sizeof(err)), HOST_OK);
    start_app();
    posefile_feed(&pf, app, 3000000, NULL);
    assert_int_equal(pf.good, 1);
    assert_int_equal(app_poses(app)->n, 1);
    assert_true(app_poses(app)->s[0].utime == 2000000 && app_poses(app)->s[0].north_m == 20.0f && app_poses(app)->s[0].east_m == 10.0f);
    assert_true(app_poses(app)->s[0].yaw_deg == 0.0f); /* 720 degrees modulo 360 */
    posefile_close(&pf);
    unlink(path);
    write_file("utime_us,north_m,east_m\n1,2,3\n");
    assert_int_equal(posefile_open(&pf, path, err, sizeof(err)), HOST_ERR_CONFIG);
    assert_non_null(strstr(err, ":1: the header has no column yaw_deg"));
    unlink(path);
    write_file("");
    assert_int_equal(posefile_open(&pf, path, err, sizeof(err)), HOST_ERR_CONFIG);
    assert_non_null(strstr(err, ":1: empty"));
    unlink(path);
    assert_int_equal(posefile_open(&pf, "/nonexistent/p.csv", err, sizeof(err)), HOST_ERR_IO);
    assert_non_null(strstr(err, "/nonexistent/p.csv: "));
}

/* Samples are given only up to the time asked for; bad and refused rows are skipped and named. */
static void test_read_ahead_and_bad_rows(void **state)
{
    char err[200], out[2048];
    FILE *e = fmemopen(out, sizeof(out), "w");
    (void)state;
    write_file("utime_us,north_m,east_m,yaw_deg\n"
               "1000000,0,0,10\n"
               "1200000,0.1,0,11\n"
               "1200000,0.2,0,12\n"    /* 4: not later than the one before */
               "1400000,x,0,12\n"      /* 5: not a number */
               "1400000,0.2\n"         /* 6: too few fields */
               "1600000,90,0,13\n"     /* 7: 90 m in 0.4 s */
               "1.5,0,0,0\n"           /* 8: not whole microseconds */
               "\n"
               "1800000,0.3,0,14\n"
               "5000000,0.4,0,15\n");
    assert_int_equal(posefile_open(&pf, path, err, sizeof(err)), HOST_OK);
    start_app();
    posefile_feed(&pf, app, 1100000, e);
    assert_int_equal(pf.good, 1);
    posefile_feed(&pf, app, 2000000, e);
    assert_int_equal(pf.good, 3);
    assert_int_equal(pf.bad, 5);
    assert_int_equal(app_poses(app)->n, 3);
    posefile_feed(&pf, app, 9000000, e);
    assert_int_equal(pf.good, 4);
    fclose(e);
    assert_non_null(strstr(out, ":4: pose at 1.200000 s is not later than the pose before it; row skipped"));
    assert_non_null(strstr(out, ":5: north_m 'x' is not a number; row skipped"));
    assert_non_null(strstr(out, ":6: 2 fields, the header has 4; row skipped"));
    assert_non_null(strstr(out, ":7: pose at 1.600000 s is a jump from the pose before it"));
    assert_non_null(strstr(out, ":8: utime_us 1.5 is not whole microseconds since the epoch; row skipped"));
    posefile_close(&pf);
    unlink(path);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_header_by_name),
        cmocka_unit_test(test_read_ahead_and_bad_rows),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
