/* test_control.c -- sonard --control (control.h): each command taken or refused with why, the rate limit, SONAR_CONTROL over LCM memq (and a message that is not one), a survey recorded from pushed beams while running, written and in use with no restart, a cancel, a refusal that keeps the survey in use, the status's control part. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>
#include <lcm/lcm.h>

#include "app.h"
#include "control.h"
#include "sonar_control_t.h"

#define N 200
#define STEP 4 /* 100 beams a turn */

static int64_t fake_ns;
static int64_t fake_mono(void *u) { (void)u; return fake_ns; }
static int64_t fake_wall(void *u) { (void)u; return 1700000000000000 + fake_ns / 1000; }

static struct app_storage mem;
static struct app *app;
static struct sonard_options opt;
static struct survey_run run; /* 4 MB: static, as sonard's */
static struct control ctl;
static lcm_t *lc;
static char path[64];

static int setup(void **state)
{
    struct sonar_pipeline_config p;
    struct app_clock clock = {fake_mono, fake_wall, NULL};
    char err[200];
    (void)state;
    fake_ns = 1000000000;
    sonar_pipeline_defaults(&p);
    p.background.mode = SONAR_BACKGROUND_PER_ANGLE;
    memset(&opt, 0, sizeof(opt));
    opt.pipeline = p;
    opt.speed_of_sound = 1500.0;
    snprintf(path, sizeof(path), "/tmp/sonard-test-control-%ld.sv", (long)getpid());
    unlink(path);
    opt.survey = path;
    assert_int_equal(app_init(&app, &mem, &p, NULL, NULL, &clock, 0, err, sizeof(err)), HOST_OK);
    lc = lcm_create("memq://");
    assert_non_null(lc);
    assert_int_equal(control_open(&ctl, lc, "", app, &opt, &run, err, sizeof(err)), HOST_OK);
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    lcm_destroy(lc);
    unlink(path);
    return 0;
}

/* One turn of flat beams (a still, empty site: every cell 40), each 10 ms after the last. */
static void turn(uint8_t level)
{
    static uint8_t s[N];
    struct sonar_record b;
    uint16_t a;
    memset(s, level, sizeof(s));
    for (a = 0; a < 400; a += STEP) {
        memset(&b, 0, sizeof(b));
        fake_ns += 10000000;
        b.utime = fake_wall(NULL);
        b.angle = a;
        b.n = N;
        b.range_m = 10.0f;
        b.speed_of_sound = 1500.0f;
        b.stage = SONAR_STAGE_RAW;
        b.samples = s;
        assert_int_equal(app_push(app, &b), HOST_OK);
    }
}

static struct sonar_status status(void)
{
    struct sonar_status s;
    memset(&s, 0, sizeof(s));
    app_host_status(app, &s);
    return s;
}

/* What is refused, and why; a refused command changes nothing. */
static void refusals(void **state)
{
    struct sonar_status s;
    (void)state;
    assert_int_equal(control_command(&ctl, 0, CONTROL_RECORD_SURVEY, 20, 1000000), SONAR_CONTROL_REFUSED);
    assert_non_null(strstr(ctl.said, "seq 0"));
    assert_int_equal(control_command(&ctl, 1, CONTROL_RECORD_SURVEY, 20, 1500000), SONAR_CONTROL_REFUSED);
    assert_non_null(strstr(ctl.said, "at most one a second"));
    assert_int_equal(control_command(&ctl, 2, 7, 20, 3000000), SONAR_CONTROL_REFUSED);
    assert_non_null(strstr(ctl.said, "command 7"));
    assert_int_equal(control_command(&ctl, 3, CONTROL_RECORD_SURVEY, 7, 5000000), SONAR_CONTROL_REFUSED);
    assert_non_null(strstr(ctl.said, "sweeps 7: a survey is 8..255"));
    assert_int_equal(control_command(&ctl, 4, CONTROL_RECORD_SURVEY, 256, 7000000), SONAR_CONTROL_REFUSED);
    assert_int_equal(control_command(&ctl, 5, CONTROL_CANCEL_SURVEY, 0, 9000000), SONAR_CONTROL_REFUSED);
    assert_non_null(strstr(ctl.said, "no survey is being recorded"));
    opt.survey = NULL;
    assert_int_equal(control_command(&ctl, 6, CONTROL_RECORD_SURVEY, 20, 11000000), SONAR_CONTROL_REFUSED);
    assert_non_null(strstr(ctl.said, "survey = PATH"));
    opt.survey = path;
    opt.gain_auto = 1;
    assert_int_equal(control_command(&ctl, 7, CONTROL_RECORD_SURVEY, 20, 13000000), SONAR_CONTROL_REFUSED);
    assert_non_null(strstr(ctl.said, "gain auto"));
    opt.gain_auto = 0;
    s = status();
    assert_int_equal(s.control.on, 1);
    assert_int_equal(s.control.seq, 7);
    assert_int_equal(s.control.result, SONAR_CONTROL_REFUSED);
    assert_int_equal(s.control.rec, SONAR_CONTROL_REC_NONE);
    assert_int_equal(ctl.refused, 8);
    assert_int_equal(access(path, F_OK), -1);
}

/* SONAR_CONTROL over LCM: decoded and answered; a message that is not a control_t is refused, counted. */
static void over_lcm(void **state)
{
    sonar_control_t m;
    uint8_t buf[64];
    int n;
    (void)state;
    memset(&m, 0, sizeof(m));
    m.seq = 11;
    m.command = CONTROL_CANCEL_SURVEY;
    n = sonar_control_t_encode(buf, 0, (int)sizeof(buf), &m);
    assert_true(n > 0);
    fake_ns += 2000000000;
    assert_int_equal(lcm_publish(lc, "SONAR_CONTROL", buf, (unsigned)n), 0);
    assert_true(lcm_handle_timeout(lc, 100) > 0);
    assert_int_equal(ctl.seq, 11);
    assert_int_equal(ctl.result, SONAR_CONTROL_REFUSED);
    assert_non_null(strstr(ctl.said, "no survey is being recorded"));
    assert_int_equal(lcm_publish(lc, "SONAR_CONTROL", "\x01garbage", 8), 0);
    assert_true(lcm_handle_timeout(lc, 100) > 0);
    assert_int_equal(ctl.bad, 1);
    assert_non_null(strstr(ctl.said, "not a sonar.control_t"));
}

/* Recorded while running: progress on the status, then written and in use with the app running on; a second
   command while it records is refused; a cancelled one writes nothing; the survey in use is kept. */
static void record_cancel(void **state)
{
    struct sonar_status s;
    int k;
    (void)state;
    turn(40); /* the sonar runs before the command */
    fake_ns += 2000000000;
    assert_int_equal(control_command(&ctl, 21, CONTROL_RECORD_SURVEY, 10, fake_ns / 1000), SONAR_CONTROL_TAKEN);
    fake_ns += 2000000000;
    assert_int_equal(control_command(&ctl, 22, CONTROL_RECORD_SURVEY, 10, fake_ns / 1000), SONAR_CONTROL_REFUSED);
    assert_non_null(strstr(ctl.said, "being recorded"));
    for (k = 0; k < 5; k++)
        turn(40);
    control_tick(&ctl);
    s = status();
    assert_int_equal(s.control.rec, SONAR_CONTROL_REC_RECORDING);
    assert_int_equal(s.control.rec_of, 10);
    assert_true(s.control.rec_sweeps >= 4 && s.control.rec_sweeps < 10);
    assert_int_equal(access(path, F_OK), -1);
    for (k = 0; k < 7; k++)
        turn(40);
    control_tick(&ctl);
    s = status();
    assert_int_equal(s.control.rec, SONAR_CONTROL_REC_WRITTEN);
    assert_non_null(strstr(s.control.rec_said, "written to"));
    assert_int_equal(access(path, F_OK), 0);
    assert_int_equal(app_survey(app)->state, SONAR_SURVEY_IN_USE);
    assert_int_equal(app_done(app), 0);
    /* another, cancelled: nothing written, the survey in use kept */
    fake_ns += 2000000000;
    assert_int_equal(control_command(&ctl, 23, CONTROL_RECORD_SURVEY, 10, fake_ns / 1000), SONAR_CONTROL_TAKEN);
    turn(40);
    turn(40);
    fake_ns += 2000000000;
    assert_int_equal(control_command(&ctl, 24, CONTROL_CANCEL_SURVEY, 0, fake_ns / 1000), SONAR_CONTROL_TAKEN);
    s = status();
    assert_int_equal(s.control.rec, SONAR_CONTROL_REC_CANCELLED);
    assert_non_null(strstr(s.control.rec_said, "nothing written"));
    turn(40);
    assert_int_equal(app_survey(app)->state, SONAR_SURVEY_IN_USE);
    /* one at another gain: refused when its sweeps are done, nothing written, the survey in use kept */
    fake_ns += 2000000000;
    assert_int_equal(control_command(&ctl, 25, CONTROL_RECORD_SURVEY, 8, fake_ns / 1000), SONAR_CONTROL_TAKEN);
    turn(40);
    {
        static uint8_t z[N];
        struct sonar_record b;
        memset(&b, 0, sizeof(b));
        memset(z, 40, sizeof(z));
        fake_ns += 10000000;
        b.utime = fake_wall(NULL);
        b.angle = 0;
        b.n = N;
        b.gain = 2;
        b.range_m = 10.0f;
        b.speed_of_sound = 1500.0f;
        b.stage = SONAR_STAGE_RAW;
        b.samples = z;
        assert_int_equal(app_push(app, &b), HOST_OK);
    }
    turn(40);
    control_tick(&ctl);
    s = status();
    assert_int_equal(s.control.rec, SONAR_CONTROL_REC_REFUSED);
    assert_non_null(strstr(s.control.rec_said, "gain changed"));
    assert_int_equal(app_done(app), 0);
    /* sonard stopping mid-recording: nothing written */
    fake_ns += 2000000000;
    assert_int_equal(control_command(&ctl, 26, CONTROL_RECORD_SURVEY, 8, fake_ns / 1000), SONAR_CONTROL_TAKEN);
    control_close(&ctl);
    assert_int_equal(ctl.rec, SONAR_CONTROL_REC_REFUSED);
    assert_non_null(strstr(ctl.rec_said, "sonard stopped"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(refusals),
        cmocka_unit_test(over_lcm),
        cmocka_unit_test(record_cancel),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
