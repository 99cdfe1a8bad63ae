/* feed_autopilot.c -- sonar-feed's autopilot: ATTITUDE and LOCAL_POSITION_NED of the scene's vehicle over MAVLink to a loopback UDP port, every 50 ms. */
#define _GNU_SOURCE
#include "feed.h"

/* The autopilot: ATTITUDE and LOCAL_POSITION_NED of the scene's vehicle now, as system 1, component 1. */
void feed_send_pose(struct feed *f)
{
    mavlink_message_t msg;
    uint8_t buf[MAVLINK_MAX_PACKET_LEN];
    double n, e, yaw, t = f->scene_t0 > 0.0 ? feed_now() - f->scene_t0 : 0.0;
    uint32_t ms = (uint32_t)(t * 1000.0);
    uint16_t len;
    scene_vehicle_at(&f->scene, t, &n, &e, &yaw);
    mavlink_msg_attitude_pack_status(1, MAV_COMP_ID_AUTOPILOT1, &f->mstatus, &msg, ms, 0.0f, 0.0f,
                                     (float)((yaw > 180.0 ? yaw - 360.0 : yaw) * 3.14159265358979323846 / 180.0), 0.0f,
                                     0.0f, 0.0f);
    len = mavlink_msg_to_send_buffer(buf, &msg);
    if (send(f->mfd, buf, len, MSG_DONTWAIT) == (ssize_t)len)
        f->poses_sent++;
    mavlink_msg_local_position_ned_pack_status(1, MAV_COMP_ID_AUTOPILOT1, &f->mstatus, &msg, ms, (float)n, (float)e,
                                               0.0f, 0.0f, 0.0f, 0.0f);
    len = mavlink_msg_to_send_buffer(buf, &msg);
    (void)send(f->mfd, buf, len, MSG_DONTWAIT); /* best effort, like a telemetry link */
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
