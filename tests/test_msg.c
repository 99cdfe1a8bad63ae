/* test_msg.c -- every LCM mapping in src/msg round-trips: a record with distinct values through its message, the wire and back; the configuration checked whole by the core on the way in. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <string.h>

/* The generated types include stdlib.h: before cmocka.h, which redefines malloc under UNIT_TESTING. */
#include "msg.h"

#include <cmocka.h>

static uint8_t wire[65536];

static void beam_round_trip(void **state)
{
    static uint8_t samples[300];
    struct sonar_record b, back;
    sonar_beam_t m, in;
    int n, i;
    (void)state;
    for (i = 0; i < 300; i++)
        samples[i] = (uint8_t)(i * 7);
    memset(&b, 0, sizeof(b));
    b.utime = 1700000000123456;
    b.angle = 399;
    b.n = 300;
    b.gain = 2;
    b.sample_period = 40000;
    b.transmit_duration = 500;
    b.transmit_frequency = 750;
    b.speed_of_sound = 1480.5f;
    b.range_m = 29.75f;
    b.stage = SONAR_STAGE_FOREGROUND;
    b.has_pose = 1;
    b.north_m = -12.25f;
    b.east_m = 3.5f;
    b.yaw_deg = 271.0f;
    b.samples = samples;
    msg_beam(&b, &m);
    n = sonar_beam_t_encode(wire, 0, (int)sizeof(wire), &m);
    assert_true(n > 300);
    assert_int_equal(sonar_beam_t_decode(wire, 0, n, &in), n);
    msg_beam_in(&in, &back);
    assert_true(back.utime == b.utime);
    assert_int_equal(back.angle, 399);
    assert_int_equal(back.n, 300);
    assert_int_equal(back.gain, 2);
    assert_int_equal(back.sample_period, 40000); /* the wire holds all 16 bits of a period (int32) */
    assert_int_equal(back.transmit_duration, 500);
    assert_int_equal(back.transmit_frequency, 750);
    assert_true(back.speed_of_sound == b.speed_of_sound && back.range_m == b.range_m);
    assert_int_equal(back.stage, SONAR_STAGE_FOREGROUND);
    assert_int_equal(back.has_pose, 1);
    assert_true(back.north_m == b.north_m && back.east_m == b.east_m && back.yaw_deg == b.yaw_deg);
    assert_memory_equal(back.samples, samples, 300);
    sonar_beam_t_decode_cleanup(&in);
    /* Without a pose, the pose fields go out as 0 whatever the record held. */
    b.has_pose = 0;
    msg_beam(&b, &m);
    assert_true(m.has_pose == 0 && m.north_m == 0.0f && m.east_m == 0.0f && m.yaw_deg == 0.0f);
}

static void status_round_trip(void **state)
{
    struct sonar_status s, back;
    sonar_status_t m, in;
    uint32_t *w;
    size_t k;
    int n;
    (void)state;
    memset(&s, 0, sizeof(s));
    s.utime = 42;
    s.link_state = SONAR_P360_AUTO;
    s.link = "coprocessor:uart0";
    s.fw[0] = 3;
    s.fw[1] = 3;
    s.fw[2] = 7;
    /* Every 32-bit counter gets its own value: a field mapped to the wrong place shows. */
    s.parser.frames = 101;
    s.parser.checksum_errors = 102;
    s.parser.resyncs = 103;
    s.parser.oversize = 104;
    s.parser.bytes_dropped = 105;
    s.driver.timeouts = 106;
    s.driver.retries = 107;
    s.driver.nacks = 108;
    s.driver.reconnects = 109;
    s.driver.beams = 110;
    s.driver.off_angle = 111;
    s.sweeps = 112;
    s.beams_rejected = 113;
    s.rows_bad = 114;
    s.sink_errors = 115;
    s.last_sweep_s = 6.5f;
    s.beam_us_p50 = 31.0f;
    s.beam_us_p99 = 95.0f;
    s.stack_used = 3000;
    s.tracker.live = 4;
    s.tracker.ended = 116;
    s.tracker.bad_detections = 117;
    s.tracker.clock_back = 118;
    s.tracker.overflow = 119;
    s.tracker.dropped = 149;
    s.tracker.out_of_order = 150;
    s.tracker.revisions = 151;
    s.tracker.hyp_overflow = 152;
    s.tracker.activity_unplaced = 153;
    s.tracker.clutter.looks = 154;
    s.tracker.clutter.cells_seen = 155;
    s.tracker.clutter.site = 0.0125f;
    s.tracker.clutter.per_look = 3.5f;
    s.tracker.clutter.peak = 0.25f;
    s.tracker.clutter.peak_range_m = 1.5f;
    s.tracker.clutter.peak_bearing_g = 232.0f;
    s.pose.state = SONAR_POSE_STALE;
    s.pose.accepted = 120;
    s.pose.out_of_order = 121;
    s.pose.jumps = 122;
    s.pose.bad = 123;
    s.pose.stale = 124;
    s.pose.world_sweeps = 125;
    s.pose.body_sweeps = 126;
    s.coproc.rx_crc_errors = 127;
    s.coproc.tx_dropped = 128;
    s.coproc.config_refused = 129;
    s.coproc.frames_bad = 130;
    s.autopilot.sysid = 42;
    s.autopilot.pose_hz = 9.5f;
    s.autopilot.interval_requests = 131;
    s.autopilot.interval_refused = 132;
    s.autopilot.acks_other = 133;
    s.autopilot.pose_held = 1;
    s.autopilot.od_sent = 134;
    s.autopilot.od_withheld = 135;
    s.autopilot.rx_other = 136;
    s.acq.gain = 2;
    s.acq.gain_auto = 1;
    s.acq.gain_changes = 137;
    s.acq.gain_refused = 138;
    s.acq.background_restarts = 139;
    s.scan.mode = SONAR_SCAN_FOLLOW;
    s.scan.interleave = 3;
    s.scan.target_pings = 140;
    s.scan.surveil_pings = 141;
    s.scan.late_looks = 142;
    s.scan.targets_dropped = 143;
    s.structure.places = 144;
    s.structure.learnt = 145;
    s.structure.promoted = 146;
    s.structure.detections = 147;
    s.structure.restarts = 148;
    s.survey.state = SONAR_SURVEY_UNFIT;
    s.survey.why = SONAR_SURVEY_TURNED;
    s.survey.fixed = 1;
    s.survey.utime = 1733390000123456;
    s.survey.sweeps = 153;
    s.survey.turn_grad = -12;
    s.survey.unfits = 154;
    s.survey.agree16 = 5;
    s.survey.standout1000 = 23;
    s.survey.nplaces = 6; /* the places themselves go on SONAR_SURVEY */
    s.control.on = 1;
    s.control.seq = 155;
    s.control.result = SONAR_CONTROL_REFUSED;
    s.control.said = "a survey is being recorded";
    s.control.rec = SONAR_CONTROL_REC_RECORDING;
    s.control.rec_sweeps = 156;
    s.control.rec_of = 157;
    s.control.rec_said = "";
    msg_status(&s, &m);
    n = sonar_status_t_encode(wire, 0, (int)sizeof(wire), &m);
    assert_true(n > 0);
    assert_int_equal(sonar_status_t_decode(wire, 0, n, &in), n);
    msg_status_in(&in, &back);
    assert_string_equal(back.link, "coprocessor:uart0");
    back.link = s.link;
    assert_string_equal(back.control.said, "a survey is being recorded");
    assert_string_equal(back.control.rec_said, "");
    back.control.said = s.control.said;
    back.control.rec_said = s.control.rec_said;
    s.pose.thinned = 0; /* the one counter SONAR_STATUS does not carry */
    assert_memory_equal(&back, &s, sizeof(s));
    sonar_status_t_decode_cleanup(&in);
    /* No two counters share a value, so none was written twice. */
    w = &s.parser.frames;
    for (k = 0; k < sizeof(s.parser) / 4; k++)
        assert_int_equal(w[k], 101 + k);
    /* Out-of-range counters on the way in are held, not wrapped. */
    m.frames = -5;
    m.beams = (int64_t)1 << 40;
    msg_status_in(&m, &back);
    assert_int_equal(back.parser.frames, 0);
    assert_int_equal(back.driver.beams, 4294967295u);
}

/* The survey's structure on SONAR_SURVEY: each place's kind, centroid and hull; none without a survey's places. */
static void survey_places(void **state)
{
    struct sonar_status s;
    struct sonar_detection places[2];
    sonar_detection_t det[SONAR_MAX_CLUSTERS];
    sonar_survey_t m, in;
    int n;
    (void)state;
    memset(&s, 0, sizeof(s));
    memset(places, 0, sizeof(places));
    places[0].kind = SONAR_DET_STRUCTURE;
    places[0].x_m = -14.5f;
    places[0].hull_count = 2;
    places[0].hull_x[1] = 3.0f;
    places[1].kind = SONAR_DET_OBJECT;
    places[1].y_m = 8.0f;
    s.utime = 7;
    s.survey.state = SONAR_SURVEY_IN_USE;
    s.survey.fixed = 1;
    s.survey.utime = 5;
    s.survey.sweeps = 20;
    s.survey.nplaces = 2;
    s.survey.places = places;
    msg_survey(&s, det, &m);
    n = sonar_survey_t_encode(wire, 0, (int)sizeof(wire), &m);
    assert_true(n > 0);
    assert_int_equal(sonar_survey_t_decode(wire, 0, n, &in), n);
    assert_int_equal(in.count, 2);
    assert_int_equal(in.state, SONAR_SURVEY_IN_USE);
    assert_int_equal(in.fixed, 1);
    assert_int_equal(in.recorded_utime, 5);
    assert_int_equal(in.sweeps, 20);
    assert_int_equal(in.places[0].kind, SONAR_DET_STRUCTURE);
    assert_true(in.places[0].x_m == -14.5f && in.places[0].hull_count == 2 && in.places[0].hull_x[1] == 3.0f);
    assert_true(in.places[1].y_m == 8.0f);
    sonar_survey_t_decode_cleanup(&in);
    s.survey.places = NULL; /* a co-processor's status: the count, no places */
    msg_survey(&s, det, &m);
    assert_int_equal(m.count, 0);
}

static void pose_round_trip(void **state)
{
    struct sonar_pose p = {1700000000000001, -1.5f, 2.25f, 359.5f}, back;
    sonar_pose_t m, in;
    int n;
    (void)state;
    msg_pose(&p, &m);
    n = sonar_pose_t_encode(wire, 0, (int)sizeof(wire), &m);
    assert_int_equal(sonar_pose_t_decode(wire, 0, n, &in), n);
    msg_pose_in(&in, &back);
    assert_true(back.utime == p.utime && back.north_m == p.north_m && back.east_m == p.east_m && back.yaw_deg == p.yaw_deg);
}

/* A configuration unlike the defaults in every field the message carries. */
static void odd_config(struct sonar_ping360_config *d, struct sonar_pipeline_config *p)
{
    memset(d, 0, sizeof(*d));
    d->range_m = 17.5f;
    d->speed_of_sound = 1490.0f;
    d->samples = 800;
    d->transmit_duration = 120;
    d->gain = 2;
    d->frequency = 800;
    d->start_angle = 50;
    d->stop_angle = 350;
    d->step = 3;
    d->full_circle = 0;
    d->use_auto = 1;
    d->baud = 115200;
    sonar_pipeline_defaults(p);
    p->median = 7;
    p->median2d = 0;
    p->max_step = 40;
    p->background.mode = SONAR_BACKGROUND_PER_ANGLE;
    p->background.warmup = 5;
    p->background.step = 3;
    p->background.margin = 9;
    p->detector.threshold_mode = SONAR_DET_GLOBAL;
    p->detector.cfar.across = 0;
    p->detector.cfar.cut = 2;
    p->detector.cfar.guard = 3;
    p->detector.cfar.train = 6;
    p->detector.cfar.rank16 = 12;
    p->detector.cfar.scale = 2.5f;
    p->detector.cfar.floor = 9;
    p->detector.threshold_k = 2.75f;
    p->detector.min_threshold = 33;
    p->detector.max_clusters = 7;
    p->detector.iterations = 9;
    p->detector.join_beams = 3;
    p->detector.min_points = 21;
    p->detector.min_area_m2 = 0.125f;
    p->detector.min_footprints = 2.5f;
    p->structure_s = 45.0f;
    p->detector.join_m = 0.7f;
    p->detector.angle_offset = 100.0f;
    p->detector.min_beams = 2;
    p->detector.max_extent_m = 4.5f;
    p->detector.split_points = 900;
    p->detector.min_range_m = 0.6f;
    p->detector.max_aspect = 5.0f;
    p->detector.track_m = 1.25f;
    p->detector.track_points = 11;
    p->track = 1;
    p->tracker.accel_mps2 = 0.35f;
    p->tracker.manoeuvre_mps2 = 1.5f;
    p->tracker.meas_m = 0.4f;
    p->tracker.speed0_mps = 1.1f;
    p->tracker.max_speed_mps = 4.0f;
    p->tracker.gate = 12.0f;
    p->tracker.confirm_m = 2;
    p->tracker.confirm_n = 4;
    p->tracker.max_misses = 6;
    p->tracker.max_dt_s = 25.0f;
}

static void config_round_trip(void **state)
{
    struct sonar_ping360_config d, d2;
    struct sonar_pipeline_config p, p2;
    sonar_config_t m, in;
    uint16_t every = 0;
    int n;
    (void)state;
    odd_config(&d, &p);
    assert_null(sonar_ping360_config_check(&d));
    assert_null(sonar_pipeline_config_check(&p));
    msg_config(&d, &p, 25, &m);
    n = sonar_config_t_encode(wire, 0, (int)sizeof(wire), &m);
    assert_int_equal(sonar_config_t_decode(wire, 0, n, &in), n);
    sonar_pipeline_defaults(&p2); /* what the firmware starts from */
    msg_config_in(&in, 115200, &d2, &p2, &every);
    assert_memory_equal(&d2, &d, sizeof(d));
    assert_memory_equal(&p2, &p, sizeof(p)); /* same callbacks (the defaults'), every other field carried */
    assert_int_equal(every, 25);
}

static void config_bad_values_are_refused_by_name(void **state)
{
    struct sonar_ping360_config d, d2;
    struct sonar_pipeline_config p, p2;
    sonar_config_t m;
    uint16_t every;
    const char *why;
    (void)state;
    odd_config(&d, &p);
    sonar_pipeline_defaults(&p2);
    msg_config(&d, &p, 0, &m);
    /* A value that does not fit its field must not wrap into a valid one. */
    m.min_threshold = 256 + 40; /* int16 on the wire, a byte in the core */
    msg_config_in(&m, 115200, &d2, &p2, &every);
    assert_non_null(why = sonar_pipeline_config_check(&p2));
    assert_non_null(strstr(why, "min_threshold"));
    msg_config(&d, &p, 0, &m);
    m.cfar_cut = -1;
    m.threshold_mode = SONAR_DET_CFAR; /* CFAR settings are checked when CFAR is used */
    msg_config_in(&m, 115200, &d2, &p2, &every);
    assert_non_null(why = sonar_pipeline_config_check(&p2));
    assert_non_null(strstr(why, "cut"));
    msg_config(&d, &p, 0, &m);
    m.step = -3;
    msg_config_in(&m, 115200, &d2, &p2, &every);
    assert_non_null(why = sonar_ping360_config_check(&d2));
    assert_non_null(strstr(why, "step"));
    msg_config(&d, &p, 0, &m);
    m.beam_every = -1;
    msg_config_in(&m, 115200, &d2, &p2, &every);
    assert_int_equal(every, 0);
}

static void detections_round_trip(void **state)
{
    static struct sonar_detections d, back;
    sonar_detection_t det[SONAR_MAX_CLUSTERS];
    sonar_detections_t m, in;
    unsigned i, v;
    int n;
    (void)state;
    memset(&d, 0, sizeof(d));
    d.utime = 99;
    d.sweep = 12;
    d.beams = 400;
    d.threshold = 77;
    d.runs = 31;
    d.groups = 5;
    d.count = 3;
    for (i = 0; i < 3; i++) {
        struct sonar_detection *o = &d.det[i];
        o->utime = 1000 + i;
        o->x_m = 1.0f + (float)i;
        o->y_m = -2.0f - (float)i;
        o->range_m = 3.0f + (float)i;
        o->bearing_deg = 10.0f * (float)i;
        o->area_m2 = 0.5f + (float)i;
        o->points = 40 + i;
        o->mean_intensity = 100.0f + (float)i;
        o->kind = (uint8_t)(i == 1 ? SONAR_DET_STRUCTURE : SONAR_DET_OBJECT);
        o->hull_count = (uint8_t)(3 + i);
        for (v = 0; v < o->hull_count; v++) {
            o->hull_x[v] = (float)(i * 10 + v);
            o->hull_y[v] = -(float)(i * 10 + v);
        }
    }
    msg_detections(&d, NULL, det, &m);
    n = sonar_detections_t_encode(wire, 0, (int)sizeof(wire), &m);
    assert_int_equal(sonar_detections_t_decode(wire, 0, n, &in), n);
    msg_detections_in(&in, &back);
    sonar_detections_t_decode_cleanup(&in);
    assert_memory_equal(&back, &d, sizeof(d));
}

static void tracks_carry_the_tracker(void **state)
{
    static struct sonar_tracker tk;
    static struct sonar_detections d;
    sonar_track_t t[SONAR_MAX_TRACKS];
    sonar_tracks_t m, in;
    struct msg_revisions rv;
    int n;
    (void)state;
    memset(&tk, 0, sizeof(tk));
    memset(&d, 0, sizeof(d));
    d.utime = 5000000;
    d.sweep = 4;
    tk.n = 2;
    tk.t[0].id = 7;
    tk.t[0].state = SONAR_TRACK_CONFIRMED;
    tk.t[0].utime = 4000000;
    tk.t[0].px = 1.5f;
    tk.t[0].py = -2.5f;
    tk.t[0].vx = 0.25f;
    tk.t[0].vy = -0.75f;
    tk.t[0].pa = 0.09f;
    tk.t[0].age = 9;
    tk.t[0].hits = 8;
    tk.t[0].misses = 1;
    tk.t[0].det = 2;
    tk.t[0].mode = SONAR_TRACK_RESTING;
    tk.t[0].kind = SONAR_TRACK_KIND_RESTING;
    tk.t[0].mu[SONAR_TRK_CV] = 51;
    tk.t[0].mu[SONAR_TRK_MANOEUVRE] = 0;
    tk.t[0].mu[SONAR_TRK_REST] = 204;
    tk.t[0].activity = SONAR_ACT_STANDING;
    tk.t[0].echo_corr = 57;
    tk.t[0].alarms = SONAR_ALARM_STILL;
    tk.t[0].existence = 0.625f;
    tk.t[1].echo_corr = SONAR_ACT_NO_CORR;
    tk.t[1].id = 4000000000u; /* beyond int32: held at its largest */
    tk.t[1].det = -1;
    tk.t[1].kind = SONAR_TRACK_KIND_STILL;
    tk.nrev = 2; /* the track published last sweep as 3 is 7, and 7 was not there */
    tk.rev[0].from = 3;
    tk.rev[0].to = 7;
    tk.rev[1].from = 7;
    tk.rev[1].to = 0;
    msg_tracks(&tk, &d, NULL, t, &rv, &m);
    n = sonar_tracks_t_encode(wire, 0, (int)sizeof(wire), &m);
    assert_int_equal(sonar_tracks_t_decode(wire, 0, n, &in), n);
    assert_int_equal(in.count, 2);
    assert_int_equal(in.sweep, 4);
    assert_int_equal(in.tracks[0].id, 7);
    assert_int_equal(in.tracks[0].state, SONAR_TRACK_CONFIRMED);
    assert_true(in.tracks[0].x_m == 1.5f && in.tracks[0].y_m == -2.5f);
    assert_true(in.tracks[0].vx_mps == 0.25f && in.tracks[0].vy_mps == -0.75f);
    assert_true(in.tracks[0].cov_xx == 0.09f && in.tracks[0].cov_yy == 0.09f && in.tracks[0].cov_xy == 0.0f);
    assert_int_equal(in.tracks[0].world, 0);
    assert_int_equal(in.tracks[0].age, 9);
    assert_int_equal(in.tracks[0].hits, 8);
    assert_int_equal(in.tracks[0].misses, 1);
    assert_int_equal(in.tracks[0].detection, 2);
    assert_int_equal(in.tracks[1].id, 2147483647);
    assert_int_equal(in.tracks[1].detection, -1);
    assert_int_equal(in.tracks[0].mode, SONAR_TRACK_RESTING);
    assert_int_equal(in.tracks[0].kind, SONAR_TRACK_KIND_RESTING);
    assert_true(fabsf(in.tracks[0].p_moving - 0.2f) < 1e-6f && fabsf(in.tracks[0].p_rest - 0.8f) < 1e-6f);
    assert_true(in.tracks[0].p_manoeuvre == 0.0f);
    assert_int_equal(in.tracks[1].kind, SONAR_TRACK_KIND_STILL);
    assert_int_equal(in.tracks[0].activity, SONAR_ACT_STANDING);
    assert_true(fabsf(in.tracks[0].echo_corr - 0.57f) < 1e-6f);
    assert_int_equal(in.tracks[0].alarms, SONAR_ALARM_STILL);
    assert_true(in.tracks[0].existence == 0.625f);
    assert_int_equal(in.tracks[1].activity, SONAR_ACT_UNKNOWN);
    assert_true(isnan(in.tracks[1].echo_corr)); /* none yet */
    assert_int_equal(in.tracks[1].alarms, 0);
    assert_int_equal(in.revisions, 2);
    assert_int_equal(in.revised_from[0], 3);
    assert_int_equal(in.revised_to[0], 7);
    assert_int_equal(in.revised_from[1], 7);
    assert_int_equal(in.revised_to[1], 0);
    sonar_tracks_t_decode_cleanup(&in);
}

/* The clutter map with a status: every cell as the tracker reads it, band by band; none without a map. */
static void clutter_map(void **state)
{
    static struct sonar_clutter map;
    float density[SONAR_CLUTTER_BANDS * SONAR_CLUTTER_SECTORS];
    struct sonar_status s;
    sonar_clutter_t m, in;
    int i, n;
    (void)state;
    memset(&s, 0, sizeof(s));
    assert_int_equal(msg_clutter(&s, density, &m), 0);
    sonar_clutter_init(&map);
    for (i = 0; i < 20; i++) {
        sonar_clutter_teach(&map, 0.0f, 5.0f, 1.0f); /* gradian 100 at 5 m: band 5 of 15 m, sector 6 */
        assert_int_equal(sonar_clutter_look(&map, NULL, 0.0f, 15.0f), SONAR_OK);
    }
    s.utime = 77;
    s.tracker.map = &map;
    sonar_clutter_summarise(&map, &s.tracker.clutter);
    assert_int_equal(msg_clutter(&s, density, &m), 1);
    n = sonar_clutter_t_encode(wire, 0, (int)sizeof(wire), &m);
    assert_true(n > 0);
    assert_int_equal(sonar_clutter_t_decode(wire, 0, n, &in), n);
    assert_true(in.utime == 77 && in.looks == 20 && in.range_m == 15.0f);
    assert_int_equal(in.bands, SONAR_CLUTTER_BANDS);
    assert_int_equal(in.sectors, SONAR_CLUTTER_SECTORS);
    assert_int_equal(in.cells, SONAR_CLUTTER_BANDS * SONAR_CLUTTER_SECTORS);
    assert_true(in.density[5 * SONAR_CLUTTER_SECTORS + 6] == sonar_clutter_cell(&map, 5, 6));
    for (i = 0; i < in.cells; i++)
        if (i != 5 * SONAR_CLUTTER_SECTORS + 6)
            assert_true(in.density[i] < in.density[5 * SONAR_CLUTTER_SECTORS + 6]);
    assert_true(in.site == s.tracker.clutter.site && in.per_look == s.tracker.clutter.per_look);
    sonar_clutter_t_decode_cleanup(&in);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(beam_round_trip),
        cmocka_unit_test(status_round_trip),
        cmocka_unit_test(survey_places),
        cmocka_unit_test(clutter_map),
        cmocka_unit_test(pose_round_trip),
        cmocka_unit_test(config_round_trip),
        cmocka_unit_test(config_bad_values_are_refused_by_name),
        cmocka_unit_test(detections_round_trip),
        cmocka_unit_test(tracks_carry_the_tracker),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
