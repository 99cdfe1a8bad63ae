/* feed_autopilot.c -- sonar-feed's autopilot: an ArduPilot stand-in on a loopback UDP port: HEARTBEAT, the scene's vehicle as ATTITUDE and LOCAL_POSITION_NED at 1 Hz until SET_MESSAGE_INTERVAL asks otherwise (answered with COMMAND_ACK). */
#define _GNU_SOURCE
#include "feed.h"

static void send_msg(struct feed *f, const mavlink_message_t *msg)
{
    uint8_t buf[MAVLINK_MAX_PACKET_LEN];
    uint16_t len = mavlink_msg_to_send_buffer(buf, msg);
    (void)send(f->mfd, buf, len, MSG_DONTWAIT); /* best effort, like a telemetry link */
}

/*
 * SET_MESSAGE_INTERVAL (COMMAND_LONG to system 1 or to all) for ATTITUDE or LOCAL_POSITION_NED,
 * as ArduPilot does: param2 the interval in us, -1 off, 0 the default; answered with COMMAND_ACK.
 */
static void command_in(struct feed *f, const mavlink_message_t *in)
{
    mavlink_command_long_t c;
    mavlink_message_t msg;
    uint8_t result = MAV_RESULT_ACCEPTED;
    mavlink_msg_command_long_decode(in, &c);
    if (c.target_system != 1 && c.target_system != 0)
        return;
    if (c.command != MAV_CMD_SET_MESSAGE_INTERVAL) {
        result = MAV_RESULT_UNSUPPORTED;
    } else if (f->mav_refuse) {
        result = MAV_RESULT_DENIED;
        f->intervals_refused++;
    } else {
        double s = c.param2 < 0.0f ? 0.0 : c.param2 == 0.0f ? 1.0 / f->mav_rate0 : (double)c.param2 * 1e-6;
        if ((int)c.param1 == MAVLINK_MSG_ID_ATTITUDE)
            f->att_s = s;
        else if ((int)c.param1 == MAVLINK_MSG_ID_LOCAL_POSITION_NED)
            f->pos_s = s;
        else
            result = MAV_RESULT_UNSUPPORTED;
        if (result == MAV_RESULT_ACCEPTED)
            f->intervals_set++;
    }
    mavlink_msg_command_ack_pack_status(1, MAV_COMP_ID_AUTOPILOT1, &f->mstatus, &msg, c.command, result, 0, 0,
                                        in->sysid, in->compid);
    send_msg(f, &msg);
    f->acks_sent++;
}

/*
 * The autopilot at now: what came in read (the interval commands), HEARTBEAT each second (a
 * submarine's ArduPilot, system 1, component 1), and the scene's vehicle as ATTITUDE and
 * LOCAL_POSITION_NED when their intervals are due. Sets f->next_pose to the next due time.
 */
void feed_autopilot(struct feed *f, double now)
{
    uint8_t buf[2048];
    ssize_t got;
    mavlink_message_t msg;
    double n, e, yaw, t = f->scene_t0 > 0.0 ? now - f->scene_t0 : 0.0;
    uint32_t ms = (uint32_t)(t * 1000.0);
    while ((got = recv(f->mfd, buf, sizeof(buf), MSG_DONTWAIT)) > 0) {
        ssize_t i;
        for (i = 0; i < got; i++)
            if (mavlink_frame_char_buffer(&f->mrx_buf, &f->mrx_status, buf[i], &f->mrx_msg, &f->mrx_rstatus) ==
                    MAVLINK_FRAMING_OK &&
                f->mrx_msg.msgid == MAVLINK_MSG_ID_COMMAND_LONG)
                command_in(f, &f->mrx_msg);
    }
    scene_vehicle_at(&f->scene, t, &n, &e, &yaw);
    if (now >= f->next_hb) {
        mavlink_msg_heartbeat_pack_status(1, MAV_COMP_ID_AUTOPILOT1, &f->mstatus, &msg, MAV_TYPE_SUBMARINE,
                                          MAV_AUTOPILOT_ARDUPILOTMEGA, 0, 0, MAV_STATE_ACTIVE);
        send_msg(f, &msg);
        f->next_hb = now + 1.0;
    }
    if (f->att_s > 0.0 && now >= f->next_att) {
        mavlink_msg_attitude_pack_status(1, MAV_COMP_ID_AUTOPILOT1, &f->mstatus, &msg, ms, 0.0f, 0.0f,
                                         (float)((yaw > 180.0 ? yaw - 360.0 : yaw) * 3.14159265358979323846 / 180.0),
                                         0.0f, 0.0f, 0.0f);
        send_msg(f, &msg);
        f->poses_sent++;
        f->next_att = now + f->att_s;
    }
    if (f->pos_s > 0.0 && now >= f->next_pos) {
        mavlink_msg_local_position_ned_pack_status(1, MAV_COMP_ID_AUTOPILOT1, &f->mstatus, &msg, ms, (float)n, (float)e,
                                                   0.0f, 0.0f, 0.0f, 0.0f);
        send_msg(f, &msg);
        f->next_pos = now + f->pos_s;
    }
    f->next_pose = f->next_hb;
    if (f->att_s > 0.0 && f->next_att < f->next_pose)
        f->next_pose = f->next_att;
    if (f->pos_s > 0.0 && f->next_pos < f->next_pose)
        f->next_pose = f->next_pos;
    if (f->next_pose > now + 0.02)
        f->next_pose = now + 0.02; /* also how soon a command is read */
}

int feed_open_mavlink(struct feed *f)
{
    struct sockaddr_in a;
    char host[64];
    int port;
    if (sscanf(f->mavlink, "udpout:%63[^:]:%d", host, &port) != 2 || port <= 0 || port > 65535) {
        fprintf(stderr, "sonar_feed: --mavlink %s: udpout:HOST:PORT\n", f->mavlink);
        return -1;
    }
    memset(&a, 0, sizeof(a));
    a.sin_family = AF_INET;
    a.sin_port = htons((uint16_t)port);
    if (inet_pton(AF_INET, host, &a.sin_addr) != 1 || ntohl(a.sin_addr.s_addr) >> 24 != 127) {
        fprintf(stderr, "sonar_feed: --mavlink %s: a loopback address (127.x.x.x)\n", f->mavlink);
        return -1;
    }
    if ((f->mfd = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK, 0)) < 0 || connect(f->mfd, (struct sockaddr *)&a, sizeof(a)) != 0) {
        perror("sonar_feed: --mavlink");
        return -1;
    }
    return 0;
}
