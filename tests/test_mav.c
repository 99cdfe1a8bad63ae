/* test_mav.c -- the MAVLink endpoint without a socket: poses from ATTITUDE and LOCAL_POSITION_NED, what is ignored and counted, OBSTACLE_DISTANCE encoded and decoded back. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "ardupilotmega/mavlink.h"
#include "mav.h"

static struct app_storage app_mem;
static struct app *app;
static struct mav m;
static int64_t wall = 1700000000000000;

static int64_t mono(void *u)
{
    (void)u;
    return 5000000000; /* 5 s after boot, in ns */
}

static int64_t wall_now(void *u)
{
    (void)u;
    return wall;
}

static void setup_mav(void)
{
    struct sonar_pipeline_config c;
    struct app_clock clk = {mono, wall_now, NULL};
    struct mav_config mc = {"udpin:127.0.0.1:14550", 1, 158, 1, 20.0f, 0.0f, 0.0f};
    char err[200];
    sonar_pipeline_defaults(&c);
    assert_int_equal(app_init(&app, &app_mem, &c, NULL, NULL, &clk, 0, err, sizeof(err)), HOST_OK);
    assert_int_equal(mav_init(&m, &mc, err, sizeof(err)), HOST_OK);
    assert_int_equal(mav_attach(&m, app), HOST_OK);
    m.t0_us = 1000000;
}

/* Packs msg from (sys, comp) and feeds it, optionally with its last byte (the CRC) flipped. */
static void feed_msg(mavlink_message_t *msg, int corrupt)
{
    uint8_t buf[MAVLINK_MAX_PACKET_LEN];
    uint16_t n = mavlink_msg_to_send_buffer(buf, msg);
    if (corrupt)
        buf[n - 1] ^= 0x5a;
    mav_bytes(&m, buf, n, wall);
}

static void test_poses_in(void **state)
{
    mavlink_status_t st;
    mavlink_message_t msg;
    struct sonar_pose p;
    (void)state;
    setup_mav();
    memset(&st, 0, sizeof(st));
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
    assert_true(od.increment == 5 && od.increment_f == 5.0f && od.angle_offset == 0.0f);
    assert_true(od.frame == MAV_FRAME_BODY_FRD && od.sensor_type == MAV_DISTANCE_SENSOR_ULTRASOUND);
    assert_true(od.min_distance == 50 && od.max_distance == 1000);
    assert_int_equal(od.distances[0], 390); /* the return over samples 78 to 80 starts at 78: 3.90 m */
    assert_int_equal(od.distances[36], 1001); /* clear: max + 1 */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_poses_in),
        cmocka_unit_test(test_obstacle_distance_encoded),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
