/* test_app.c -- the app core over a socketpair link with a fake clock and a capturing sink: beam records, detections, counters, sink failures, reload, the replay source and its bad rows. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <fcntl.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cmocka.h>

#include "app.h"
#include "source_link.h"
#include "source_replay.h"
#include "sonar/geometry.h"

#define N 200
#define STEP 10 /* 40 beams a turn */

static int64_t fake_ns;
static int64_t fake_mono(void *u) { (void)u; return fake_ns; }
static int64_t fake_wall(void *u) { (void)u; return 1700000000000000 + fake_ns / 1000; }

/* What the sinks saw. */
struct capture {
    int raw, fg, sweeps, statuses, fail;
    uint32_t sweep_no[16]; /* the sweep number of each sweep given */
    struct sonar_record last_raw;
    uint8_t last_raw_samples[N];
    int dets[16];
    struct sonar_status st;
};

static int cap_beam(void *self, const struct sonar_record *b)
{
    struct capture *c = self;
    if (b->stage == SONAR_STAGE_RAW) {
        c->raw++;
        c->last_raw = *b;
        memcpy(c->last_raw_samples, b->samples, b->n < N ? b->n : N);
    } else {
        c->fg++;
    }
    return c->fail ? -1 : 0;
}

static int cap_det(void *self, const struct sonar_detections *d, const struct sonar_tracker *tk, const struct msg_view *v)
{
    (void)tk;
    (void)v;
    struct capture *c = self;
    if (c->sweeps < 16) {
        c->dets[c->sweeps] = d->count;
        c->sweep_no[c->sweeps] = d->sweep;
    }
    c->sweeps++;
    return c->fail ? -1 : 0;
}

static int cap_status(void *self, const struct sonar_status *s)
{
    struct capture *c = self;
    c->statuses++;
    c->st = *s;
    return 0;
}

static struct app_storage app_mem;
static struct app *app;
static struct source_link src;
static struct capture cap;
static struct app_sink sink;
static int sv[2];

static struct sonar_pipeline_config pipe_cfg(void)
{
    struct sonar_pipeline_config p;
    sonar_pipeline_defaults(&p);
    p.background.mode = SONAR_BACKGROUND_OFF; /* the object is bright on black: found from the first sweep */
    return p;
}

static struct sonar_ping360_config dev_cfg(void)
{
    struct sonar_ping360_config c;
    memset(&c, 0, sizeof(c));
    c.range_m = 2.0f;
    c.speed_of_sound = 1500.0f;
    c.frequency = 750;
    c.step = STEP;
    c.full_circle = 1;
    c.samples = N;
    return c;
}

static void setup_app(long max_sweeps, uint8_t stages)
{
    struct sonar_pipeline_config p = pipe_cfg();
    struct sonar_ping360_config d = dev_cfg();
    struct app_clock clk = {fake_mono, fake_wall, NULL};
    struct sonar_ping360_io io = {source_link_send, source_link_break, &src, NULL, NULL};
    char err[256];
    memset(&cap, 0, sizeof(cap));
    memset(&sink, 0, sizeof(sink));
    sink.name = "capture";
    sink.self = &cap;
    sink.stages = stages;
    sink.beam = cap_beam;
    sink.detections = cap_det;
    sink.status = cap_status;
    fake_ns = 1000000000;
    assert_int_equal(socketpair(AF_UNIX, SOCK_STREAM, 0, sv), 0);
    assert_int_equal(fcntl(sv[0], F_SETFL, O_NONBLOCK), 0);
    assert_int_equal(fcntl(sv[1], F_SETFL, O_NONBLOCK), 0);
    assert_int_equal(source_link_parse(&src, "tcp:127.0.0.1:1", 0, err, sizeof(err)), HOST_OK);
    assert_int_equal(app_init(&app, &app_mem, &p, &d, &io, &clk, max_sweeps, err, sizeof(err)), HOST_OK);
    assert_int_equal(app_add_sink(app, &sink), HOST_OK);
    /* The socketpair stands in for the TCP connection source_link would open. */
    src.app = app;
    app_set_link(app, src.desc);
    src.link.fd = sv[0];
    assert_int_equal(app_device_up(app, fake_ns / 1000), SONAR_OK);
}

static void teardown_app(void)
{
    source_link_close(&src);
    close(sv[1]);
}

static void put_u16(uint8_t *p, uint16_t v)
{
    p[0] = (uint8_t)(v & 0xff);
    p[1] = (uint8_t)(v >> 8);
}

/* The fake device: answers every request waiting on its end with a reply; returns the requests answered. */
static int device_answer(int garbage, int corrupt)
{
    static struct sonar_ping_parser p;
    static int init;
    uint8_t in[4096], out[2048], pl[14 + N];
    ssize_t n = read(sv[1], in, sizeof(in));
    const uint8_t *q = in;
    size_t len;
    struct sonar_ping_frame f;
    int answered = 0;
    if (!init || garbage < 0) {
        assert_int_equal(sonar_ping_parser_init(&p, 0), SONAR_OK);
        init = 1;
    }
    if (n <= 0)
        return 0;
    len = (size_t)n;
    while (sonar_ping_parser_next(&p, &q, &len, &f) == 1) {
        int w;
        if (f.id == SONAR_PING_GENERAL_REQUEST) {
            uint8_t info[6] = {2, 0, 3, 3, 1, 0};
            w = sonar_ping_encode(out, sizeof(out), SONAR_PING_DEVICE_INFORMATION, info, 6);
        } else if (f.id == SONAR_PING360_TRANSDUCER) {
            uint16_t a = (uint16_t)(f.payload[2] | f.payload[3] << 8), i;
            memset(pl, 0, sizeof(pl));
            pl[1] = 1; /* gain */
            put_u16(pl + 2, a);
            put_u16(pl + 4, 20);
            put_u16(pl + 6, 533);
            put_u16(pl + 8, 750);
            put_u16(pl + 10, N);
            put_u16(pl + 12, N);
            for (i = 0; i < N; i++)
                pl[14 + i] = (uint8_t)(a >= 100 && a <= 140 && i >= 100 && i < 120 ? 200 : 5);
            w = sonar_ping_encode(out, sizeof(out), SONAR_PING360_DEVICE_DATA, pl, 14 + N);
        } else {
            continue; /* motor_off etc.: no reply needed here */
        }
        assert_true(w > 0);
        if (garbage > 0)
            assert_int_equal(write(sv[1], "\x01" "BRxx\xff\x00junk", 12), 12);
        if (corrupt > 0) {
            out[20] ^= 0x55; /* inside the payload: the checksum fails, the frame is dropped */
            corrupt--;
        }
        assert_int_equal(write(sv[1], out, (size_t)w), w);
        answered++;
    }
    return answered;
}

/* One exchange: the device answers, time moves on, the link source reads. */
static int step(int garbage, int corrupt)
{
    int k = device_answer(garbage, corrupt);
    fake_ns += 30000000; /* 30 ms a beam */
    source_link_ready(&src, POLLIN, fake_ns / 1000);
    (void)source_link_timers(&src, fake_ns / 1000);
    return k;
}

static void test_beams_carry_their_acquisition(void **state)
{
    int i;
    (void)state;
    (void)device_answer(-1, 0);
    setup_app(0, 1u << SONAR_STAGE_RAW);
    for (i = 0; i < 100; i++)
        (void)step(0, 0);
    assert_true(cap.raw >= 90);
    assert_int_equal(cap.fg, 0); /* the sink did not ask for the foreground */
    assert_int_equal(cap.last_raw.gain, 1);
    assert_int_equal(cap.last_raw.sample_period, 533);
    assert_int_equal(cap.last_raw.transmit_duration, 20);
    assert_int_equal(cap.last_raw.transmit_frequency, 750);
    assert_int_equal(cap.last_raw.n, N);
    assert_true(cap.last_raw.speed_of_sound == 1500.0f);
    assert_true(cap.last_raw.range_m == (float)sonar_geometry_range_m(533, N, 1500.0));
    assert_true(cap.last_raw.utime > 1700000000000000);
    assert_int_equal(cap.last_raw.angle % STEP, 0);
    assert_true(cap.sweeps >= 2);
    assert_int_equal(cap.dets[1], 1); /* the bright patch at 100..140 gradians */
    app_report_status(app, source_link_state(&src), &cap.st);
    assert_int_equal(cap.statuses, 1);
    assert_int_equal(cap.st.driver.beams, (uint32_t)cap.raw);
    assert_int_equal(cap.st.parser.frames, (uint32_t)cap.raw + 1); /* + device_information */
    assert_int_equal(cap.st.link_state, SONAR_P360_SCANNING);
    assert_string_equal(cap.st.link, "tcp:127.0.0.1:1");
    assert_int_equal(cap.st.fw[1], 3);
    teardown_app();
}

static void test_garbage_and_corrupt_frames_are_counted_not_published(void **state)
{
    int i, sent = 0;
    (void)state;
    (void)device_answer(-1, 0);
    setup_app(0, 1u << SONAR_STAGE_RAW | 1u << SONAR_STAGE_FOREGROUND);
    sent += step(0, 0); /* probe */
    for (i = 0; i < 60; i++)
        sent += step(1, i % 10 == 3);
    /* Each corrupt reply is lost: its request times out and is sent again. */
    for (i = 0; i < 20; i++) {
        fake_ns += 200000000;
        sent += step(0, 0);
    }
    app_report_status(app, source_link_state(&src), &cap.st);
    assert_true(cap.st.parser.checksum_errors >= 6);
    assert_true(cap.st.parser.bytes_dropped > 0);
    assert_true(cap.st.parser.resyncs > 0);
    assert_true(cap.st.driver.timeouts >= 1);
    assert_int_equal((int)cap.st.parser.frames, cap.raw + 1);
    assert_int_equal(cap.fg, cap.raw); /* every beam reached the foreground stage */
    assert_true(sent > cap.raw);
    teardown_app();
}

static void test_max_sweeps_then_beams_ignored(void **state)
{
    int i;
    (void)state;
    (void)device_answer(-1, 0);
    setup_app(2, 1u << SONAR_STAGE_RAW);
    for (i = 0; i < 200 && !app_done(app); i++)
        (void)step(0, 0);
    assert_int_equal(app_done(app), 1);
    assert_int_equal(cap.sweeps, 2);
    i = cap.raw;
    (void)step(0, 0);
    (void)step(0, 0);
    assert_int_equal(cap.raw, i);
    teardown_app();
}

/*
 * --track-late: a sink gets each sweep when the next one has come (relabelled by its revisions),
 * the last at app_finish; a sink marked live (the autopilot's) gets each at once all the same.
 */
static void test_track_late_holds_a_sweep_but_not_for_live_sinks(void **state)
{
    static struct capture now;
    static struct app_sink live;
    int i;
    (void)state;
    (void)device_answer(-1, 0);
    setup_app(0, 1u << SONAR_STAGE_RAW);
    memset(&now, 0, sizeof(now));
    live = sink;
    live.name = "autopilot";
    live.self = &now;
    live.stages = 0;
    live.live = 1;
    assert_int_equal(app_add_sink(app, &live), HOST_OK);
    app_set_track_late(app, 1);
    for (i = 0; i < 400 && now.sweeps < 3; i++)
        (void)step(0, 0);
    assert_int_equal(now.sweeps, 3);
    assert_int_equal(cap.sweeps, 2); /* one sweep behind */
    for (i = 0; i < 2; i++)
        assert_int_equal(cap.sweep_no[i], now.sweep_no[i]);
    assert_int_equal(app_finish(app), HOST_OK); /* ends the open sweep; the held one goes out, then the last */
    assert_int_equal(cap.sweeps, now.sweeps);
    assert_int_equal(cap.sweep_no[cap.sweeps - 1], now.sweep_no[now.sweeps - 1]);
    teardown_app();
}

static void test_sink_failures_are_counted(void **state)
{
    int i;
    (void)state;
    (void)device_answer(-1, 0);
    setup_app(0, 1u << SONAR_STAGE_RAW);
    cap.fail = 1;
    for (i = 0; i < 50; i++)
        (void)step(0, 0);
    app_report_status(app, source_link_state(&src), &cap.st);
    assert_int_equal(sink.errors, (unsigned long)(cap.raw + cap.sweeps));
    assert_int_equal(cap.st.sink_errors, (uint32_t)(cap.raw + cap.sweeps));
    teardown_app();
}

static void test_reconfigure_at_the_next_sweep_and_bad_config_kept_out(void **state)
{
    struct sonar_pipeline_config p = pipe_cfg();
    char err[256];
    int i, s0;
    (void)state;
    (void)device_answer(-1, 0);
    setup_app(0, 1u << SONAR_STAGE_RAW);
    for (i = 0; i < 90; i++)
        (void)step(0, 0);
    assert_int_equal(cap.dets[1], 1);
    p.detector.join_beams = 9;
    assert_int_equal(app_reconfigure(app, &p, err, sizeof(err)), HOST_ERR_CONFIG);
    assert_non_null(strstr(err, "join_beams: 1..8"));
    p = pipe_cfg();
    p.detector.min_points = 60000; /* nothing is that big */
    assert_int_equal(app_reconfigure(app, &p, err, sizeof(err)), HOST_OK);
    s0 = cap.sweeps;
    for (i = 0; i < 130; i++)
        (void)step(0, 0);
    assert_true(cap.sweeps >= s0 + 3);
    assert_int_equal(cap.dets[s0], 1);     /* the sweep open at the reload ends under the running rules */
    assert_int_equal(cap.dets[s0 + 1], 0); /* the next ones use the new ones */
    assert_int_equal(cap.dets[s0 + 2], 0);
    teardown_app();
}

static void test_link_lost_and_stop(void **state)
{
    int i;
    (void)state;
    (void)device_answer(-1, 0);
    setup_app(0, 1u << SONAR_STAGE_RAW);
    for (i = 0; i < 5; i++)
        (void)step(0, 0);
    /* The peer hangs up: the source drops the link and plans a reconnect. */
    close(sv[1]);
    sv[1] = open("/dev/null", O_RDONLY);
    source_link_ready(&src, POLLIN, fake_ns / 1000);
    assert_int_equal(src.link.fd, -1);
    assert_true(src.link.reopen_at > fake_ns / 1000 && src.link.reopen_at < INT64_MAX);
    assert_int_equal(app_device(app)->drv.counters.reconnects, 1);
    /* Stopping with no link is immediate. */
    source_link_stop(&src, fake_ns / 1000);
    assert_true(source_link_stopped(&src));
    teardown_app();
}

/* The replay source over an in-memory CSV. */
static void test_replay_source_rows_and_bad_rows(void **state)
{
    static struct source_replay r;
    struct sonar_pipeline_config p = pipe_cfg();
    struct app_clock clk = {fake_mono, fake_wall, NULL};
    char err[256], text[4096], msgs[2048];
    FILE *in, *errf;
    size_t k = 0;
    int a;
    (void)state;
    memset(&cap, 0, sizeof(cap));
    memset(&sink, 0, sizeof(sink));
    sink.self = &cap;
    sink.stages = 1u << SONAR_STAGE_RAW;
    sink.beam = cap_beam;
    sink.detections = cap_det;
    for (a = 0; a < 20; a++)
        k += (size_t)snprintf(text + k, sizeof(text) - k, "10,%d,%d,\"1 2 3 4 5 6 7 8\",range_m=3,gain=2\n", a * 1000, a);
    k += (size_t)snprintf(text + k, sizeof(text) - k, "9223372036854775,0,21,\"1 2 3 4 5 6 7 8\"\n");
    k += (size_t)snprintf(text + k, sizeof(text) - k, "10,0,22,\"1 2 3 4 5 6 7 8\",range_m=1e308\n");
    k += (size_t)snprintf(text + k, sizeof(text) - k, "10,0,23,\"1 2 3 4 5 6 7 8\",sample_period=1e30\n");
    k += (size_t)snprintf(text + k, sizeof(text) - k, "10,0,24,\"1 2 3 4 5 6 7 8\",speed_of_sound=nan\n");
    in = fmemopen(text, k, "r");
    errf = fmemopen(msgs, sizeof(msgs), "w");
    assert_non_null(in);
    assert_non_null(errf);
    assert_int_equal(app_init(&app, &app_mem, &p, NULL, NULL, &clk, 0, err, sizeof(err)), HOST_OK);
    assert_int_equal(app_add_sink(app, &sink), HOST_OK);
    source_replay_stream(&r, in, "mem.csv", -1.0, 1500.0);
    assert_int_equal(source_replay_run(&r, app, errf), 20);
    fclose(errf);
    fclose(in);
    assert_int_equal(cap.raw, 20);
    assert_int_equal(cap.last_raw.gain, 2);
    assert_int_equal(cap.last_raw.sample_period, -1);
    assert_true(cap.last_raw.range_m == 3.0f);
    assert_true(cap.last_raw.utime == 10000000 + 19);
    assert_int_equal(app_rows_bad(app), 4);
    assert_non_null(strstr(msgs, "mem.csv:21: timestamp seconds '9223372036854775' is not an integer"));
    assert_non_null(strstr(msgs, "mem.csv:22: metadata range_m=1e308 is not a number in 0..1000; row skipped"));
    assert_non_null(strstr(msgs, "mem.csv:23: metadata sample_period=1e30"));
    assert_non_null(strstr(msgs, "mem.csv:24: metadata speed_of_sound=nan"));
    assert_int_equal(cap.sweeps, 1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_beams_carry_their_acquisition),
        cmocka_unit_test(test_garbage_and_corrupt_frames_are_counted_not_published),
        cmocka_unit_test(test_max_sweeps_then_beams_ignored),
        cmocka_unit_test(test_sink_failures_are_counted),
        cmocka_unit_test(test_track_late_holds_a_sweep_but_not_for_live_sinks),
        cmocka_unit_test(test_reconfigure_at_the_next_sweep_and_bad_config_kept_out),
        cmocka_unit_test(test_link_lost_and_stop),
        cmocka_unit_test(test_replay_source_rows_and_bad_rows),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
