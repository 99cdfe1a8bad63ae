/* test_sinks.c -- each sink maps a record once: LCM (the obstacle map too) through a capturing transmit function (decoded back with the generated types), CSV rows, JSON lines; failures reported. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

/* The generated types include stdlib.h: before cmocka.h, which redefines malloc under UNIT_TESTING. */
#include "csv.h"
#include "obsmap.h"
#include "sinks.h"
#include "sonar_beam_t.h"
#include "sonar_detections_t.h"
#include "sonar_obstacles_t.h"
#include "sonar_status_t.h"
#include "sonar_tracks_t.h"

#include <cmocka.h>

struct sent {
    char channel[64][64];
    uint8_t buf[4][16384];
    size_t len[64];
    int n, fail;
};

static int capture_tx(void *user, const char *channel, const uint8_t *buf, size_t len)
{
    struct sent *s = user;
    if (s->fail)
        return -1;
    snprintf(s->channel[s->n % 64], 64, "%s", channel);
    memcpy(s->buf[s->n % 4], buf, len);
    s->len[s->n % 64] = len;
    s->n++;
    return 0;
}

static uint8_t samples[1200];

static struct sonar_record beam(uint8_t stage)
{
    struct sonar_record b;
    int i;
    memset(&b, 0, sizeof(b));
    for (i = 0; i < 1200; i++)
        samples[i] = (uint8_t)(i * 7);
    b.utime = 1700000000123456;
    b.angle = 399;
    b.n = 1200;
    b.gain = 2;
    b.sample_period = 533;
    b.transmit_duration = 64;
    b.transmit_frequency = 750;
    b.speed_of_sound = 1480.0f;
    b.range_m = 11.9925f;
    b.stage = stage;
    b.samples = samples;
    return b;
}

static void test_lcm_beam_round_trip(void **state)
{
    static struct sink_lcm s;
    static struct sent out;
    struct sonar_record b = beam(SONAR_STAGE_RAW);
    sonar_beam_t m;
    (void)state;
    memset(&out, 0, sizeof(out));
    sink_lcm_init(&s, capture_tx, &out, "PORT_", 1);
    assert_int_equal(s.sink.stages, (1u << SONAR_STAGE_RAW) | (1u << SONAR_STAGE_FOREGROUND));
    assert_int_equal(s.sink.beam(s.sink.self, &b), HOST_OK);
    b.stage = SONAR_STAGE_FOREGROUND;
    assert_int_equal(s.sink.beam(s.sink.self, &b), HOST_OK);
    assert_int_equal(out.n, 2);
    assert_string_equal(out.channel[0], "PORT_SONAR_BEAM");
    assert_string_equal(out.channel[1], "PORT_SONAR_BEAM_FILTERED");
    assert_true(sonar_beam_t_decode(out.buf[0], 0, (int)out.len[0], &m) > 0);
    assert_true(m.utime == 1700000000123456);
    assert_int_equal(m.angle, 399);
    assert_int_equal(m.gain, 2);
    assert_int_equal(m.sample_period, 533);
    assert_int_equal(m.transmit_duration, 64);
    assert_int_equal(m.transmit_frequency, 750);
    assert_true(m.speed_of_sound == 1480.0f);
    assert_true(m.range_m == 11.9925f);
    assert_int_equal(m.stage, 0);
    assert_int_equal(m.number_of_samples, 1200);
    assert_memory_equal(m.samples, samples, 1200);
    sonar_beam_t_decode_cleanup(&m);
    out.fail = 1;
    assert_int_equal(s.sink.beam(s.sink.self, &b), HOST_ERR_PUBLISH);
}

/* The obstacle map as SONAR_OBSTACLES: every sector, unknown and clear as they are, on the prefixed channel; a failed send counted. */
static void test_lcm_obstacles(void **state)
{
    static struct sink_lcm s;
    static struct sent out;
    struct obsmap_read r;
    sonar_obstacles_t m;
    int k;
    (void)state;
    memset(&out, 0, sizeof(out));
    sink_lcm_init(&s, capture_tx, &out, "PORT_", 0);
    r.utime = 1700000000123456;
    r.min_cm = 75;
    r.max_cm = 1200;
    for (k = 0; k < SONAR_OBS_SECTORS; k++)
        r.dist_cm[k] = (uint16_t)(k % 3 == 0 ? (int)SONAR_OBS_UNKNOWN : k % 3 == 1 ? 1201 : 75 + 10 * k);
    sink_lcm_obstacles(&s, &r);
    assert_int_equal(out.n, 1);
    assert_string_equal(out.channel[0], "PORT_SONAR_OBSTACLES");
    assert_true(sonar_obstacles_t_decode(out.buf[0], 0, (int)out.len[0], &m) > 0);
    assert_true(m.utime == 1700000000123456);
    assert_true(m.sector_deg == 5.0f);
    assert_int_equal(m.min_cm, 75);
    assert_int_equal(m.max_cm, 1200);
    assert_int_equal(m.count, SONAR_OBS_SECTORS);
    for (k = 0; k < SONAR_OBS_SECTORS; k++)
        assert_int_equal(m.distance_cm[k], r.dist_cm[k]);
    sonar_obstacles_t_decode_cleanup(&m);
    out.fail = 1;
    sink_lcm_obstacles(&s, &r);
    assert_int_equal(s.sink.errors, 1);
}

static void test_lcm_detections_and_status(void **state)
{
    static struct sink_lcm s;
    static struct sent out;
    static struct sonar_detections d;
    struct sonar_status st;
    static struct sonar_tracker tk;
    sonar_detections_t m;
    sonar_tracks_t mt;
    sonar_status_t ms;
    (void)state;
    memset(&out, 0, sizeof(out));
    memset(&d, 0, sizeof(d));
    memset(&st, 0, sizeof(st));
    sink_lcm_init(&s, capture_tx, &out, "", 0);
    assert_int_equal(s.sink.stages, 1u << SONAR_STAGE_RAW);
    d.sweep = 7;
    d.utime = 42;
    d.beams = 400;
    d.count = 2;
    d.det[1].x_m = 1.5f;
    d.det[1].points = 99;
    d.det[1].hull_count = 3;
    d.det[1].hull_y[2] = -2.25f;
    d.det[1].utime = 41;
    memset(&tk, 0, sizeof(tk));
    tk.n = 2;
    tk.t[1].id = 17;
    tk.t[1].state = SONAR_TRACK_COASTING;
    tk.t[1].px = 2.5f;
    tk.t[1].vy = -0.75f;
    tk.t[1].pa = 0.04f;
    tk.t[1].hits = 9;
    tk.t[1].det = -1;
    tk.t[0].det = 1;
    assert_int_equal(s.sink.detections(s.sink.self, &d, &tk, NULL), HOST_OK);
    assert_string_equal(out.channel[0], "SONAR_DETECTIONS");
    assert_string_equal(out.channel[1], "SONAR_TRACKS");
    assert_true(sonar_tracks_t_decode(out.buf[1], 0, (int)out.len[1], &mt) > 0);
    assert_int_equal(mt.sweep, 7);
    assert_int_equal(mt.count, 2);
    assert_int_equal(mt.tracks[1].id, 17);
    assert_int_equal(mt.tracks[1].state, 2);
    assert_true(mt.tracks[1].x_m == 2.5f && mt.tracks[1].vy_mps == -0.75f);
    assert_true(mt.tracks[1].world == 0 && mt.tracks[1].north_m == 0.0f);
    assert_true(mt.tracks[1].cov_xx == 0.04f && mt.tracks[1].cov_yy == 0.04f && mt.tracks[1].cov_xy == 0.0f);
    assert_int_equal(mt.tracks[1].hits, 9);
    assert_int_equal(mt.tracks[1].detection, -1);
    assert_int_equal(mt.tracks[0].detection, 1);
    sonar_tracks_t_decode_cleanup(&mt);
    assert_true(sonar_detections_t_decode(out.buf[0], 0, (int)out.len[0], &m) > 0);
    assert_int_equal(m.sweep, 7);
    assert_int_equal(m.count, 2);
    assert_true(m.detections[1].x_m == 1.5f);
    assert_int_equal(m.detections[1].points, 99);
    assert_int_equal(m.detections[1].utime, 41);
    assert_int_equal(m.detections[1].hull_count, 3);
    assert_true(m.detections[1].hull_y[2] == -2.25f);
    sonar_detections_t_decode_cleanup(&m);
    st.link_state = SONAR_P360_CONNECTING;
    st.link = "tcp:127.0.0.1:9";
    st.parser.oversize = 3;
    st.parser.bytes_dropped = 1234;
    st.driver.off_angle = 5;
    st.rows_bad = 6;
    st.sink_errors = 8;
    st.beams_rejected = 9;
    st.tracker.live = 3;
    st.tracker.overflow = 11;
    assert_int_equal(s.sink.status(s.sink.self, &st), HOST_OK);
    assert_string_equal(out.channel[2], "SONAR_STATUS");
    assert_true(sonar_status_t_decode(out.buf[2], 0, (int)out.len[2], &ms) > 0);
    assert_int_equal(ms.link_state, 1);
    assert_string_equal(ms.link, "tcp:127.0.0.1:9");
    assert_int_equal(ms.oversize, 3);
    assert_int_equal(ms.bytes_dropped, 1234);
    assert_int_equal(ms.off_angle, 5);
    assert_int_equal(ms.rows_bad, 6);
    assert_int_equal(ms.sink_errors, 8);
    assert_int_equal(ms.beams_rejected, 9);
    assert_int_equal(ms.tracks, 3);
    assert_int_equal(ms.track_overflow, 11);
    sonar_status_t_decode_cleanup(&ms);
}

static void test_csv_sink_writes_a_row_that_reads_back(void **state)
{
    static struct sink_csv s;
    static struct csv_reader r;
    static struct csv_row row;
    struct sonar_record b = beam(SONAR_STAGE_FOREGROUND);
    char text[8192], err[128];
    FILE *f = fmemopen(text, sizeof(text), "w");
    (void)state;
    assert_non_null(f);
    sink_csv_init(&s, f, SONAR_STAGE_FOREGROUND);
    assert_int_equal(s.sink.stages, 1u << SONAR_STAGE_FOREGROUND);
    b.n = 8;
    b.gain = -1; /* unknown: left out */
    assert_int_equal(s.sink.beam(s.sink.self, &b), HOST_OK);
    b.utime = -1500000; /* before the epoch: floor division keeps nsec in range */
    assert_int_equal(s.sink.beam(s.sink.self, &b), HOST_OK);
    fclose(f);
    assert_non_null(strstr(text, "1700000000,123456000,399,\"0 7 14 21 28 35 42 49\",range_m=11.9925,sample_period=533,"
                                 "transmit_duration=64,transmit_frequency=750,speed_of_sound=1480.0\n"));
    assert_null(strstr(text, "gain="));
    assert_non_null(strstr(text, "\n-2,500000000,399,"));
    f = fmemopen(text, strlen(text), "r");
    csv_open_stream(&r, f, "mem");
    assert_int_equal(csv_next(&r, &row, err, sizeof(err)), 1);
    assert_int_equal(row.n, 8);
    assert_true(row.sample_period == 533.0);
    assert_int_equal(csv_next(&r, &row, err, sizeof(err)), 1);
    assert_true(row.sec == -2 && row.nsec == 500000000u);
    fclose(f);
}

static void test_report_sink_json_line(void **state)
{
    static struct sink_report s;
    static struct sonar_detections d;
    static struct sonar_tracker tk;
    char text[4096];
    FILE *f = fmemopen(text, sizeof(text), "w");
    (void)state;
    memset(&d, 0, sizeof(d));
    d.sweep = 3;
    d.count = 1;
    d.det[0].x_m = 1.0f;
    d.det[0].points = 40;
    sink_report_init(&s, f, 1);
    assert_null(s.sink.beam);
    assert_int_equal(s.sink.detections(s.sink.self, &d, NULL, NULL), HOST_OK);
    assert_null(strstr(text, "tracks"));
    memset(&tk, 0, sizeof(tk));
    tk.n = 1;
    tk.t[0].id = 4;
    tk.t[0].state = SONAR_TRACK_CONFIRMED;
    tk.t[0].vx = 0.5f;
    tk.t[0].age = 6;
    tk.t[0].hits = 5;
    tk.t[0].utime = 4000000; /* still for 2 s at 4 s; the sweep ends at 5 s: 3 s */
    tk.t[0].still_ms = 2000;
    tk.t[0].mode = SONAR_TRACK_TURNING;
    tk.t[0].kind = SONAR_TRACK_KIND_MOVING;
    tk.t[0].activity = SONAR_ACT_STRUGGLING;
    tk.t[0].echo_corr = 12;
    tk.t[0].alarms = SONAR_ALARM_STRUGGLE | SONAR_ALARM_STILL;
    tk.t[0].existence = 0.987f;
    tk.nrev = 2; /* the track published last sweep as 4 was 9, and 9 was not there */
    tk.rev[0].from = 4;
    tk.rev[0].to = 9;
    tk.rev[1].from = 9;
    tk.rev[1].to = 0;
    d.utime = 5000000;
    assert_int_equal(s.sink.detections(s.sink.self, &d, &tk, NULL), HOST_OK);
    fclose(f);
    assert_non_null(strstr(text, "{\"sweep\":3,"));
    assert_non_null(strstr(text, "\"tracks\":[{\"id\":4,\"state\":\"confirmed\","));
    assert_non_null(strstr(text, "\"vx_mps\":0.500,"));
    assert_non_null(strstr(text, "\"age\":6,\"hits\":5,\"detection\":0,\"still_s\":3.0,\"existence\":0.987,\"mode\":\"turning\",\"kind\":\"moving\","
                                  "\"activity\":\"struggling\",\"echo_corr\":0.12,\"alarms\":[\"struggle\",\"still\"]}]"));
    assert_non_null(strstr(text, ",\"revisions\":[{\"id\":4,\"now\":9},{\"id\":9,\"now\":0}]}\n"));
    assert_non_null(strstr(text, "\"x_m\":1.000"));
    assert_non_null(strstr(text, "\"points\":40"));
    assert_non_null(strstr(text, "\"frame\":\"body\""));
    assert_null(strstr(text, "north_m"));
    assert_true(text[strlen(text) - 1] == '\n');
}

/* With a pose: the world positions beside the body ones, the frame and the vehicle's pose, in JSON and on LCM. */
static void test_sinks_world_view(void **state)
{
    static struct sink_report s;
    static struct sink_lcm l;
    static struct sent out;
    static struct sonar_detections d;
    static struct sonar_tracker tk;
    static struct msg_view v;
    sonar_detections_t md;
    sonar_tracks_t mt;
    char text[4096];
    FILE *f = fmemopen(text, sizeof(text), "w");
    (void)state;
    memset(&d, 0, sizeof(d));
    memset(&tk, 0, sizeof(tk));
    memset(&v, 0, sizeof(v));
    memset(&out, 0, sizeof(out));
    d.count = 2;
    d.world = 1;
    d.det[0].x_m = 1.0f;
    d.det[1].x_m = 2.0f; /* seen while the pose was unknown */
    v.world = 1;
    v.have_pose = 1;
    v.pose.north_m = 100.0f;
    v.pose.east_m = -20.0f;
    v.pose.yaw_deg = 90.0f;
    v.det_world[0] = 1;
    v.det_north[0] = 100.0f;
    v.det_east[0] = -19.0f;
    tk.world = 1;
    tk.n = 1;
    tk.t[0].id = 2;
    tk.t[0].px = 100.0f; /* world: north, east */
    tk.t[0].py = -19.0f;
    tk.t[0].vx = 0.5f;
    v.trk_x[0] = 1.0f; /* the same in the body frame */
    v.trk_vy[0] = -0.5f;
    sink_report_init(&s, f, 1);
    assert_int_equal(s.sink.detections(s.sink.self, &d, &tk, &v), HOST_OK);
    fclose(f);
    assert_non_null(strstr(text, "\"hull\":[],\"north_m\":100.000,\"east_m\":-19.000}"));
    assert_non_null(strstr(text, "\"mean_intensity\":0.0,\"hull\":[]}],\"frame\""));
    assert_non_null(strstr(text, "\"frame\":\"world\",\"pose\":{\"north_m\":100.000,\"east_m\":-20.000,\"yaw_deg\":90.00}"));
    assert_non_null(strstr(text, "\"x_m\":1.000,\"y_m\":0.000,\"vx_mps\":0.000,\"vy_mps\":-0.500,"));
    assert_non_null(strstr(text, "\"north_m\":100.000,\"east_m\":-19.000,\"vn_mps\":0.500,\"ve_mps\":0.000}]}"));
    sink_lcm_init(&l, capture_tx, &out, "", 0);
    assert_int_equal(l.sink.detections(l.sink.self, &d, &tk, &v), HOST_OK);
    assert_true(sonar_detections_t_decode(out.buf[0], 0, (int)out.len[0], &md) > 0);
    assert_true(md.world == 1 && md.north_m == 100.0f && md.yaw_deg == 90.0f);
    assert_true(md.detections[0].world == 1 && md.detections[0].east_m == -19.0f);
    assert_true(md.detections[1].world == 0 && md.detections[1].north_m == 0.0f);
    sonar_detections_t_decode_cleanup(&md);
    assert_true(sonar_tracks_t_decode(out.buf[1], 0, (int)out.len[1], &mt) > 0);
    assert_true(mt.tracks[0].world == 1 && mt.tracks[0].x_m == 1.0f && mt.tracks[0].vy_mps == -0.5f);
    assert_true(mt.tracks[0].north_m == 100.0f && mt.tracks[0].vn_mps == 0.5f);
    sonar_tracks_t_decode_cleanup(&mt);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_lcm_beam_round_trip),
        cmocka_unit_test(test_lcm_detections_and_status),
        cmocka_unit_test(test_lcm_obstacles),
        cmocka_unit_test(test_csv_sink_writes_a_row_that_reads_back),
        cmocka_unit_test(test_sinks_world_view),
        cmocka_unit_test(test_report_sink_json_line),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
