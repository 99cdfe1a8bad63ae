/* test_mav.c -- the MAVLink endpoint on a socketpair: the autopilot found by its HEARTBEAT, poses from it alone, the pose rate asked for and the answers counted, OBSTACLE_DISTANCE as ArduPilot reads it (faces, masked arcs, no 0, fail-closed), OBSTACLE_DISTANCE_3D's IDs. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cmocka.h>

#include "mav_internal.h" /* white-box: the send and receive steps, driven one by one */

static struct app_storage app_mem;
static struct app *app;
static struct mav m;
static int64_t wall = 1700000000000000;
static int64_t mono_ns = 5000000000; /* 5 s after boot */
static int sv[2] = {-1, -1};       /* sv[0]: the endpoint's link (udpout), sv[1]: the autopilot's end */

static int64_t mono(void *u)
{
    (void)u;
    return mono_ns;
}

static int64_t wall_now(void *u)
{
    (void)u;
    return wall;
}

/* The endpoint as sonard makes it, speaking on a socketpair (a udpout link) so that what it sends can be read. */
static void setup_cfg(const struct mav_config *mc)
{
    struct sonar_pipeline_config c;
    struct app_clock clk = {mono, wall_now, NULL};
    char err[200];
    sonar_pipeline_defaults(&c);
    assert_int_equal(app_init(&app, &app_mem, &c, NULL, NULL, &clk, 0, err, sizeof(err)), HOST_OK);
    assert_int_equal(mav_init(&m, mc, err, sizeof(err)), HOST_OK);
    assert_int_equal(mav_attach(&m, app), HOST_OK);
    m.t0_us = 1000000;
    if (sv[0] >= 0) {
        close(sv[0]);
        close(sv[1]);
    }
    assert_int_equal(socketpair(AF_UNIX, SOCK_DGRAM | SOCK_NONBLOCK, 0, sv), 0);
    m.kind = MAV_UDPOUT;
    m.link.kind = LINK_UDP;
    m.link.fd = sv[0];
}

static void default_cfg(struct mav_config *mc)
{
    memset(mc, 0, sizeof(*mc));
    mc->url = "udpin:127.0.0.1:14550";
    mc->compid = 158;
    mc->rate_hz = 10.0f;
    mc->pose_rate_hz = 10.0f;
    mc->fail_closed = 1;
}

static void setup_mav(void)
{
    struct mav_config mc;
    default_cfg(&mc);
    mc.autopilot = 1;
    setup_cfg(&mc);
}

/* The next message the endpoint sent, decoded: 1, or 0 when none is waiting. */
static int sent(mavlink_message_t *out)
{
    static mavlink_message_t rbuf;
    static mavlink_status_t st, rst;
    uint8_t buf[MAVLINK_MAX_PACKET_LEN];
    ssize_t n, i;
    while ((n = recv(sv[1], buf, sizeof(buf), 0)) > 0)
        for (i = 0; i < n; i++)
            if (mavlink_frame_char_buffer(&rbuf, &st, buf[i], out, &rst) == MAVLINK_FRAMING_OK)
                return 1;
    return 0;
}

static void heartbeat_from(uint8_t sys, uint8_t comp, uint8_t type, uint8_t autopilot);

/* Packs msg from (sys, comp) and feeds it, optionally with its last byte (the CRC) flipped. */
static void feed_msg(mavlink_message_t *msg, int corrupt)
{
    uint8_t buf[MAVLINK_MAX_PACKET_LEN];
    uint16_t n = mavlink_msg_to_send_buffer(buf, msg);
    if (corrupt)
        buf[n - 1] ^= 0x5a;
    mav_bytes(&m, buf, n, wall);
}

static void heartbeat_from(uint8_t sys, uint8_t comp, uint8_t type, uint8_t autopilot)
{
    mavlink_status_t st;
    mavlink_message_t msg;
    memset(&st, 0, sizeof(st));
    mavlink_msg_heartbeat_pack_status(sys, comp, &st, &msg, type, autopilot, 0, 0, MAV_STATE_ACTIVE);
    feed_msg(&msg, 0);
}

static void test_poses_in(void **state)
{
    mavlink_status_t st;
    mavlink_message_t msg;
    struct sonar_pose p;
    (void)state;
    setup_mav();
    memset(&st, 0, sizeof(st));
    heartbeat_from(1, 1, MAV_TYPE_SUBMARINE, MAV_AUTOPILOT_ARDUPILOTMEGA);
    assert_int_equal(m.ap_sysid, 1);
    /* An ATTITUDE alone is held back for a second, while a position may yet come. */
    mavlink_msg_attitude_pack_status(1, 1, &st, &msg, 10, 0, 0, 1.5707963f, 0, 0, 0);
    feed_msg(&msg, 0);
    assert_int_equal(app_poses(app)->n, 0);
    wall += 50000;
    mavlink_msg_local_position_ned_pack_status(1, 1, &st, &msg, 60, 12.5f, -3.0f, 0, 0, 0, 0);
    feed_msg(&msg, 0);
    mavlink_msg_attitude_pack_status(1, 1, &st, &msg, 60, 0, 0, -1.5707963f, 0, 0, 0);
    feed_msg(&msg, 0);
    assert_int_equal(app_poses(app)->n, 1);
    assert_int_equal(sonar_pose_at(app_poses(app), wall, &p), 1);
    assert_true(p.north_m == 12.5f && p.east_m == -3.0f && p.yaw_deg > 269.9f && p.yaw_deg < 270.1f);
    assert_int_equal(m.n.attitudes, 2);
    assert_int_equal(m.n.positions, 1);
    /* Ignored and counted: another system's, another component's, our own echoed, a broken CRC, a foreign id, noise. */
    wall += 50000;
    mavlink_msg_attitude_pack_status(7, 1, &st, &msg, 110, 0, 0, 0.5f, 0, 0, 0);
    feed_msg(&msg, 0);
    mavlink_msg_attitude_pack_status(1, 100, &st, &msg, 110, 0, 0, 0.5f, 0, 0, 0);
    feed_msg(&msg, 0);
    mavlink_msg_heartbeat_pack_status(1, 158, &st, &msg, MAV_TYPE_ONBOARD_CONTROLLER, MAV_AUTOPILOT_INVALID, 0, 0, 0);
    feed_msg(&msg, 0);
    assert_int_equal(m.n.rx_other, 3);
    mavlink_msg_attitude_pack_status(1, 1, &st, &msg, 110, 0, 0, 0.5f, 0, 0, 0);
    feed_msg(&msg, 1);
    assert_int_equal(m.n.rx_bad_crc, 1);
    {
        const uint8_t foreign[] = {0xfd, 2, 0, 0, 0, 9, 9, 0xde, 0xbc, 0x0a, 1, 2, 0x12, 0x34};
        const uint8_t noise[] = {0x00, 0xff, 0x13, 0x37, 0xfd};
        mav_bytes(&m, foreign, sizeof(foreign), wall);
        mav_bytes(&m, noise, sizeof(noise), wall);
    }
    assert_int_equal(m.n.rx_foreign, 1);
    assert_int_equal(app_poses(app)->n, 1);
    /* A pose that jumps 500 m in 50 ms is refused by the poses and counted here. */
    wall += 50000;
    mavlink_msg_local_position_ned_pack_status(1, 1, &st, &msg, 160, 512.5f, -3.0f, 0, 0, 0, 0);
    feed_msg(&msg, 0);
    mavlink_msg_attitude_pack_status(1, 1, &st, &msg, 160, 0, 0, 0.0f, 0, 0, 0);
    feed_msg(&msg, 0);
    assert_int_equal(m.n.poses_refused, 1);
}

/* The map's message: every field as ArduPilot reads it, decoded by the generated decoder. */
static void test_obstacle_distance_encoded(void **state)
{
    uint8_t s[200], buf[MAVLINK_MAX_PACKET_LEN];
    mavlink_message_t msg;
    mavlink_status_t st, rst;
    mavlink_message_t rbuf;
    mavlink_obstacle_distance_t od;
    size_t n, i;
    int a, got = 0;
    (void)state;
    setup_mav();
    memset(s, 10, sizeof(s));
    for (a = 0; a < 400; a++) /* two turns: the floor learns the noise, then a wall 4 m ahead */
        for (i = 0; i < 2; i++) {
            struct sonar_record b;
            memset(&b, 0, sizeof(b));
            memset(s + 78, (a < 10 || a > 390) && i == 1 ? 200 : 10, 3);
            b.utime = wall + (int64_t)(i * 400 + (size_t)a) * 10000;
            b.angle = (uint16_t)a;
            b.n = 200;
            b.range_m = 10.0f;
            b.stage = SONAR_STAGE_MEDIAN;
            b.samples = s;
            assert_int_equal(m.sink.beam(m.sink.self, &b), HOST_OK);
        }
    n = mav_obstacle_distance(&m, buf, wall + 8000000, 3000000);
    memset(&st, 0, sizeof(st));
    memset(&rst, 0, sizeof(rst));
    for (i = 0; i < n; i++)
        if (mavlink_frame_char_buffer(&rbuf, &st, buf[i], &msg, &rst) == MAVLINK_FRAMING_OK)
            got = 1;
    assert_true(got);
    assert_int_equal(msg.msgid, MAVLINK_MSG_ID_OBSTACLE_DISTANCE);
    assert_true(msg.sysid == 1 && msg.compid == 158);
    mavlink_msg_obstacle_distance_decode(&msg, &od);
    assert_true(od.time_usec == 2000000); /* since our start */
    /* entry j centred on 5 j - 20 degrees: ArduPilot's face k is entries 9 k .. 9 k + 8, one run each */
    assert_true(od.increment == 5 && od.increment_f == 5.0f && od.angle_offset == -20.0f);
    assert_true(od.frame == MAV_FRAME_BODY_FRD && od.sensor_type == MAV_DISTANCE_SENSOR_ULTRASOUND);
    assert_true(od.min_distance == 50 && od.max_distance == 1000);
    assert_int_equal(od.distances[4], 390); /* ahead (0 degrees): the return over samples 78 to 80 starts at 78: 3.90 m */
    assert_int_equal(od.distances[40], 1001); /* astern, clear: max + 1 */
    for (i = 0; i < 72; i++)
        assert_true(od.distances[i] != 0); /* ArduPilot takes 0 for invalid */
}

/*
 * Which system is the autopilot: the first component 1 whose HEARTBEAT says so; a ground station,
 * a companion and a second autopilot do not change it, and their poses are not taken. We speak as
 * the autopilot's system.
 */
static void test_identity(void **state)
{
    struct mav_config mc;
    mavlink_status_t st;
    mavlink_message_t msg;
    (void)state;
    default_cfg(&mc);
    setup_cfg(&mc);
    memset(&st, 0, sizeof(st));
    /* Before any autopilot: no pose taken, and sonard speaks as system 1. */
    mavlink_msg_attitude_pack_status(3, 1, &st, &msg, 10, 0, 0, 0.5f, 0, 0, 0);
    feed_msg(&msg, 0);
    assert_int_equal(m.n.attitudes, 0);
    heartbeat_from(255, 190, MAV_TYPE_GCS, MAV_AUTOPILOT_INVALID); /* a ground station */
    heartbeat_from(3, 191, MAV_TYPE_ONBOARD_CONTROLLER, MAV_AUTOPILOT_INVALID); /* a companion */
    assert_int_equal(m.ap_sysid, 0);
    assert_int_equal(m.n.hb_other, 2);
    heartbeat_from(3, 1, MAV_TYPE_GROUND_ROVER, MAV_AUTOPILOT_ARDUPILOTMEGA);
    assert_int_equal(m.ap_sysid, 3);
    heartbeat_from(9, 1, MAV_TYPE_QUADROTOR, MAV_AUTOPILOT_ARDUPILOTMEGA); /* a second autopilot on the link */
    assert_int_equal(m.ap_sysid, 3);
    assert_int_equal(m.n.hb_other, 3);
    mavlink_msg_attitude_pack_status(9, 1, &st, &msg, 10, 0, 0, 0.5f, 0, 0, 0);
    feed_msg(&msg, 0);
    assert_int_equal(m.n.attitudes, 0);
    mavlink_msg_attitude_pack_status(3, 1, &st, &msg, 10, 0, 0, 0.5f, 0, 0, 0);
    feed_msg(&msg, 0);
    assert_int_equal(m.n.attitudes, 1);
    /* Our HEARTBEAT now comes from system 3; a fixed --mavlink-sysid wins. */
    mav_heartbeat(&m, 6000000);
    assert_int_equal(sent(&msg), 1);
    assert_true(msg.msgid == MAVLINK_MSG_ID_HEARTBEAT && msg.sysid == 3 && msg.compid == 158);
    mc.sysid = 42;
    mc.autopilot = 9;
    setup_cfg(&mc);
    heartbeat_from(3, 1, MAV_TYPE_GROUND_ROVER, MAV_AUTOPILOT_ARDUPILOTMEGA);
    assert_int_equal(m.ap_sysid, 0); /* not the one asked for */
    heartbeat_from(9, 1, MAV_TYPE_QUADROTOR, MAV_AUTOPILOT_ARDUPILOTMEGA);
    assert_int_equal(m.ap_sysid, 9);
    mav_heartbeat(&m, 6000000);
    assert_int_equal(sent(&msg), 1);
    assert_int_equal(msg.sysid, 42);
}

/* SET_MESSAGE_INTERVAL at once for both streams, again every 5 s while the pose is slow, not once it comes; the answers counted. */
static void test_pose_rate_asked(void **state)
{
    mavlink_status_t st;
    mavlink_message_t msg;
    mavlink_command_long_t c;
    int k;
    (void)state;
    setup_mav();
    memset(&st, 0, sizeof(st));
    mono_ns = 10000000000;
    heartbeat_from(1, 1, MAV_TYPE_SUBMARINE, MAV_AUTOPILOT_ARDUPILOTMEGA);
    mav_ask_pose(&m, app_mono_us(app));
    assert_int_equal(m.n.interval_requests, 2);
    for (k = 0; k < 2; k++) {
        assert_int_equal(sent(&msg), 1);
        assert_int_equal(msg.msgid, MAVLINK_MSG_ID_COMMAND_LONG);
        mavlink_msg_command_long_decode(&msg, &c);
        assert_true(c.target_system == 1 && c.target_component == 1 && c.command == MAV_CMD_SET_MESSAGE_INTERVAL);
        assert_true(c.param1 == (k == 0 ? MAVLINK_MSG_ID_ATTITUDE : MAVLINK_MSG_ID_LOCAL_POSITION_NED));
        assert_true(c.param2 == 100000.0f); /* 10 Hz: 100 ms */
    }
    mav_ask_pose(&m, app_mono_us(app) + 4000000); /* not again within 5 s */
    assert_int_equal(m.n.interval_requests, 2);
    /* The answers: accepted, refused (said, counted), and one for another command. */
    mavlink_msg_command_ack_pack_status(1, 1, &st, &msg, MAV_CMD_SET_MESSAGE_INTERVAL, MAV_RESULT_ACCEPTED, 0, 0, 1, 158);
    feed_msg(&msg, 0);
    mavlink_msg_command_ack_pack_status(1, 1, &st, &msg, MAV_CMD_SET_MESSAGE_INTERVAL, MAV_RESULT_DENIED, 0, 0, 1, 158);
    feed_msg(&msg, 0);
    mavlink_msg_command_ack_pack_status(1, 1, &st, &msg, MAV_CMD_COMPONENT_ARM_DISARM, MAV_RESULT_ACCEPTED, 0, 0, 1, 158);
    feed_msg(&msg, 0);
    assert_int_equal(m.n.interval_accepted, 1);
    assert_int_equal(m.n.interval_refused, 1);
    assert_int_equal(m.n.acks_other, 1);
    /* Still slow after 5 s: asked again. Then 20 ATTITUDEs in 2 s (10 Hz): satisfied, not asked again. */
    mono_ns += 5000000000;
    mav_ask_pose(&m, app_mono_us(app));
    assert_int_equal(m.n.interval_requests, 4);
    for (k = 0; k <= 20; k++) {
        mono_ns += 100000000;
        wall += 100000;
        mavlink_msg_attitude_pack_status(1, 1, &st, &msg, 10, 0, 0, 0.0f, 0, 0, 0);
        feed_msg(&msg, 0);
    }
    assert_true(m.pose_hz >= 9.0f);
    mono_ns += 5000000000;
    mav_ask_pose(&m, app_mono_us(app));
    mav_ask_pose(&m, app_mono_us(app) + 6000000);
    assert_int_equal(m.n.interval_requests, 4);
}

/* A beam into the map at angle (gradians) with a return 4 m out, or none. */
static void beam_at(int64_t t, uint16_t angle, int echo)
{
    static uint8_t s[200];
    struct sonar_record b;
    memset(s, 10, sizeof(s));
    if (echo)
        memset(s + 78, 200, 3);
    memset(&b, 0, sizeof(b));
    b.utime = t;
    b.angle = angle;
    b.n = 200;
    b.range_m = 10.0f;
    b.stage = SONAR_STAGE_MEDIAN;
    b.samples = s;
    assert_int_equal(m.sink.beam(m.sink.self, &b), HOST_OK);
}

/* The map as one OBSTACLE_DISTANCE at wall time t (us; monotonic 3 s), decoded as an autopilot reads it. */
static void od_at(int64_t t, mavlink_obstacle_distance_t *od)
{
    uint8_t buf[MAVLINK_MAX_PACKET_LEN];
    mavlink_message_t msg, rbuf;
    mavlink_status_t st, rst;
    size_t n = mav_obstacle_distance(&m, buf, t, 3000000), i;
    memset(&st, 0, sizeof(st));
    memset(&rst, 0, sizeof(rst));
    for (i = 0; i < n; i++)
        (void)mavlink_frame_char_buffer(&rbuf, &st, buf[i], &msg, &rst);
    mavlink_msg_obstacle_distance_decode(&msg, od);
}

/* Fail closed: no OBSTACLE_DISTANCE once no beam has come for a second; it resumes with the beams. */
static void test_fail_closed(void **state)
{
    mavlink_message_t msg;
    int a;
    (void)state;
    setup_mav();
    for (a = 0; a < 400; a++)
        beam_at(wall, (uint16_t)a, 0);
    mav_send_obstacles(&m, 6000000);
    assert_int_equal(sent(&msg), 1);
    assert_int_equal(msg.msgid, MAVLINK_MSG_ID_OBSTACLE_DISTANCE);
    wall += 1100000; /* the sonar is unplugged: 1.1 s without a beam */
    mav_send_obstacles(&m, 7100000);
    assert_int_equal(sent(&msg), 0);
    assert_int_equal(m.n.od_withheld, 1);
    beam_at(wall, 0, 0);
    mav_send_obstacles(&m, 7200000);
    assert_int_equal(sent(&msg), 1);
    assert_int_equal(m.n.obstacle_distance, 2);
}

/*
 * A stale pose: for MAV_POSE_HOLD_US after the last one, the map's world echoes are placed with it
 * (said, counted, in the status), not dropped; after that they are.
 */
static void test_pose_held(void **state)
{
    mavlink_status_t st;
    mavlink_message_t msg;
    struct sonar_status status;
    uint8_t buf[MAVLINK_MAX_PACKET_LEN];
    mavlink_message_t rbuf;
    mavlink_status_t rst, rst2;
    mavlink_obstacle_distance_t od;
    size_t n, i;
    int a, known;
    (void)state;
    setup_mav();
    memset(&st, 0, sizeof(st));
    heartbeat_from(1, 1, MAV_TYPE_SUBMARINE, MAV_AUTOPILOT_ARDUPILOTMEGA);
    for (a = 0; a < 800; a++) { /* two turns with the pose: the floor learns the noise, then world echoes 3.9 m out */
        static uint8_t smp[200];
        struct sonar_record b;
        memset(smp, 10, sizeof(smp));
        if (a >= 400)
            memset(smp + 78, 200, 3);
        memset(&b, 0, sizeof(b));
        b.utime = wall + a * 1000;
        b.angle = (uint16_t)(a % 400);
        b.n = 200;
        b.range_m = 10.0f;
        b.stage = SONAR_STAGE_MEDIAN;
        b.has_pose = 1;
        b.samples = smp;
        assert_int_equal(m.sink.beam(m.sink.self, &b), HOST_OK);
    }
    wall += 800000;
    for (a = 0; a < 3; a++) { /* the autopilot's last poses: a position, then a pose every 50 ms */
        mavlink_msg_local_position_ned_pack_status(1, 1, &st, &msg, 10, 0.0f, 0.0f, 0, 0, 0, 0);
        feed_msg(&msg, 0);
        mavlink_msg_attitude_pack_status(1, 1, &st, &msg, 10, 0, 0, 0.0f, 0, 0, 0);
        feed_msg(&msg, 0);
        wall += 50000;
    }
    assert_int_equal(m.have_last_pose, 1);
    for (known = 0; known < 2; known++) {
        int64_t at = m.last_pose.utime + (known == 0 ? 3000000 : 6000000); /* stale (3 s), then past the hold (6 s) */
        int echoes = 0;
        n = mav_obstacle_distance(&m, buf, at, 9000000);
        memset(&rst, 0, sizeof(rst));
        memset(&rst2, 0, sizeof(rst2));
        for (i = 0; i < n; i++)
            (void)mavlink_frame_char_buffer(&rbuf, &rst, buf[i], &msg, &rst2);
        mavlink_msg_obstacle_distance_decode(&msg, &od);
        for (i = 0; i < 72; i++)
            echoes += od.distances[i] < 1000;
        if (known == 0) {
            assert_true(echoes > 0); /* held: the remembered echoes are still placed */
            assert_int_equal(m.holding, 1);
            assert_int_equal(m.n.pose_holds, 1);
            memset(&status, 0, sizeof(status));
            mav_status(&m, &status);
            assert_int_equal(status.autopilot.pose_held, 1);
        } else {
            assert_int_equal(echoes, 0); /* past the hold: no pose, no world echoes */
            assert_int_equal(m.holding, 0);
        }
    }
}

/* --ignore-deg: the vehicle's own echoes never enter the map, and the arc goes out unknown. */
static void test_ignored_arcs(void **state)
{
    struct mav_config mc;
    mavlink_obstacle_distance_t od;
    size_t i;
    int a, pass;
    (void)state;
    default_cfg(&mc);
    mc.n_ignore = 1;
    mc.ignore[0][0] = 170.0f; /* a tether astern, 170..190 degrees */
    mc.ignore[0][1] = 190.0f;
    setup_cfg(&mc);
    for (pass = 0; pass < 2; pass++)
        for (a = 0; a < 400; a++)
            beam_at(wall + (int64_t)(pass * 400 + a) * 10000, (uint16_t)a, pass == 1);
    od_at(wall + 8000000, &od);
    for (i = 0; i < 72; i++) {
        int deg = ((int)i - 4) * 5; /* entry i's centre */
        deg = (deg + 360) % 360;
        if (deg >= 170 && deg <= 190)
            assert_int_equal(od.distances[i], 65535);
        else
            assert_int_equal(od.distances[i], 390);
    }
}

/* The map handed out after a beam (sonard's SONAR_OBSTACLES). */
static struct obsmap_read handed;
static int n_handed;
static int64_t min_gap_us;

static void hand(void *user, const struct obsmap_read *r)
{
    (void)user;
    if (n_handed > 0 && r->utime - handed.utime < min_gap_us)
        min_gap_us = r->utime - handed.utime;
    handed = *r;
    n_handed++;
}

/*
 * SONAR_OBSTACLES carries OBSTACLE_DISTANCE's figures: the map handed out after a beam, read at that
 * beam's time, is the message's at that time, entry j being sector j - 4 (the faces), with its masked arc
 * unknown; and it is handed out at most every OBSMAP_OUT_US of beam time.
 */
static void test_obstacles_out_equal_od(void **state)
{
    struct mav_config mc;
    mavlink_obstacle_distance_t od;
    int a, j, echoes = 0;
    (void)state;
    default_cfg(&mc);
    mc.n_ignore = 1;
    mc.ignore[0][0] = 170.0f;
    mc.ignore[0][1] = 190.0f;
    setup_cfg(&mc);
    n_handed = 0;
    min_gap_us = INT64_MAX;
    obsmap_on_read(&m.map, hand, NULL);
    for (a = 0; a < 800; a++) { /* two turns, 10 ms a beam; echoes 3.9 m out in the second */
        beam_at(wall + (int64_t)a * 10000, (uint16_t)(a % 400), a >= 400);
    }
    /* About one each 100 ms of the 8 s (the masked arc's beams hand nothing out), never closer. */
    assert_true(n_handed >= 70 && n_handed <= 80);
    assert_true(min_gap_us >= OBSMAP_OUT_US);
    od_at(handed.utime, &od);
    for (j = 0; j < SONAR_OBS_SECTORS; j++) {
        assert_int_equal(od.distances[j], handed.dist_cm[(j - 4 + SONAR_OBS_SECTORS) % SONAR_OBS_SECTORS]);
        echoes += od.distances[j] == 390;
    }
    assert_true(echoes > 60);
    assert_int_equal(handed.dist_cm[36], SONAR_OBS_UNKNOWN); /* 180 degrees: the masked arc */
    assert_int_equal(od.min_distance, handed.min_cm);
    assert_int_equal(od.max_distance, handed.max_cm);
}

/* A reload's angle-offset and min-range reach the obstacle map through the pipeline (the detections turn by them too); a min-range too far is refused. */
static void test_retune(void **state)
{
    struct mav_config mc;
    struct sonar_pipeline_config pc;
    mavlink_obstacle_distance_t od;
    char err[160];
    int a, pass;
    (void)state;
    default_cfg(&mc);
    setup_cfg(&mc);
    assert_int_equal(obsmap_check_min_range(150.0f, err, sizeof(err)), HOST_ERR_CONFIG);
    assert_string_equal(err, "--min-range 150: too far for the obstacle map (0..100 m)");
    assert_int_equal(obsmap_check_min_range(100.0f, err, sizeof(err)), HOST_OK);
    sonar_pipeline_defaults(&pc);
    pc.detector.angle_offset = 100.0f; /* 100 gradians: 90 degrees */
    pc.detector.min_range_m = 1.0f;
    assert_int_equal(app_reconfigure(app, &pc, err, sizeof(err)), HOST_OK); /* no sweep open: at once */
    for (pass = 0; pass < 2; pass++)
        for (a = 0; a < 400; a++)
            beam_at(wall + (int64_t)(pass * 400 + a) * 10000, (uint16_t)a, pass == 1 && a >= 10 && a < 16);
    od_at(wall + 8000000, &od);
    /* an echo at head angles 10..15 gradians: 9..13.5 degrees ahead without the offset (entries 6, 7); turned by
       100 gradians it lies at 99..103.5 degrees (entries 24, 25) */
    assert_true(od.distances[24] == 390 || od.distances[25] == 390);
    assert_true(od.distances[6] != 390 && od.distances[7] != 390);
    assert_int_equal(od.min_distance, 100);
}

/* OBSTACLE_DISTANCE_3D only when asked, its IDs folded into 1..65534 (65535 reads as unknown). */
static void test_3d_ids(void **state)
{
    struct mav_config mc;
    static struct sonar_tracker tk;
    static struct sonar_detections d;
    mavlink_message_t msg;
    mavlink_obstacle_distance_3d_t o;
    (void)state;
    default_cfg(&mc);
    setup_cfg(&mc);
    memset(&tk, 0, sizeof(tk));
    memset(&d, 0, sizeof(d));
    d.utime = wall;
    tk.n = 2;
    tk.t[0].id = 65535;
    tk.t[0].state = SONAR_TRACK_CONFIRMED;
    tk.t[0].utime = wall;
    tk.t[0].px = 3.0f;
    tk.t[1].id = 7;
    tk.t[1].state = SONAR_TRACK_CONFIRMED;
    tk.t[1].utime = wall;
    assert_int_equal(m.sink.detections(m.sink.self, &d, &tk, NULL), HOST_OK);
    assert_int_equal(sent(&msg), 0); /* off by default */
    mc.send_3d = 1;
    setup_cfg(&mc);
    assert_int_equal(m.sink.detections(m.sink.self, &d, &tk, NULL), HOST_OK);
    assert_int_equal(sent(&msg), 1);
    mavlink_msg_obstacle_distance_3d_decode(&msg, &o);
    assert_int_equal(o.obstacle_id, 1);
    assert_true(o.frame == MAV_FRAME_BODY_FRD && o.x == 3.0f);
    assert_int_equal(sent(&msg), 1);
    mavlink_msg_obstacle_distance_3d_decode(&msg, &o);
    assert_int_equal(o.obstacle_id, 7);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_poses_in),
        cmocka_unit_test(test_obstacle_distance_encoded),
        cmocka_unit_test(test_identity),
        cmocka_unit_test(test_pose_rate_asked),
        cmocka_unit_test(test_fail_closed),
        cmocka_unit_test(test_pose_held),
        cmocka_unit_test(test_ignored_arcs),
        cmocka_unit_test(test_obstacles_out_equal_od),
        cmocka_unit_test(test_retune),
        cmocka_unit_test(test_3d_ids),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
