/* mav_rx.c -- what the vehicle says: the autopilot found by its HEARTBEAT, its ATTITUDE and LOCAL_POSITION_NED as poses (their rate measured), COMMAND_ACKs to our interval requests; everything else counted and ignored; O(bytes). */
#define _GNU_SOURCE
#include "mav_internal.h"

#include <math.h>

#include "sonar/frame.h"

/*
 * A HEARTBEAT from component 1 of a system that says it is an autopilot (not MAV_AUTOPILOT_INVALID,
 * not a ground station) names the autopilot: the configured system, or the first one heard. Others
 * (ground stations, companions, a second autopilot on the link) are counted.
 */
static void heartbeat_in(struct mav *m, const mavlink_message_t *msg, int64_t now_mono)
{
    mavlink_heartbeat_t hb;
    mavlink_msg_heartbeat_decode(msg, &hb);
    if (msg->compid != MAV_COMP_ID_AUTOPILOT1 || hb.autopilot == MAV_AUTOPILOT_INVALID || hb.type == MAV_TYPE_GCS ||
        (m->cfg.autopilot != 0 && msg->sysid != m->cfg.autopilot) || (m->ap_sysid != 0 && msg->sysid != m->ap_sysid)) {
        m->n.hb_other++;
        return;
    }
    m->n.hb_autopilot++;
    if (m->ap_sysid == 0) {
        m->ap_sysid = msg->sysid;
        m->rate_t0 = now_mono;
        m->next_interval = now_mono; /* ask at once: without a ground station the streams may be at 1 Hz or off */
        app_say(m->app, "mavlink: autopilot system %u (type %u)%s", msg->sysid, hb.type,
                m->cfg.sysid == 0 ? "; sonard speaks as that system" : "");
    }
}

/* Closes the pose-rate window at now; a rate under 80 % of the one asked re-arms the request. */
static void close_window(struct mav *m, int64_t now_mono)
{
    m->pose_hz = (float)((double)m->rate_n * 1e6 / (double)(now_mono - m->rate_t0));
    m->rate_t0 = now_mono;
    m->rate_n = 0;
    if (m->cfg.pose_rate_hz > 0.0f && m->pose_hz < 0.8f * m->cfg.pose_rate_hz && m->next_interval == INT64_MAX)
        m->next_interval = now_mono;
}

/* The pose rate: ATTITUDEs per MAV_RATE_WINDOW_US. */
static void count_attitude(struct mav *m, int64_t now_mono)
{
    m->rate_n++;
    if (now_mono - m->rate_t0 >= MAV_RATE_WINDOW_US)
        close_window(m, now_mono);
}

static void ack_in(struct mav *m, const mavlink_message_t *msg)
{
    mavlink_command_ack_t a;
    mavlink_msg_command_ack_decode(msg, &a);
    if (a.command != MAV_CMD_SET_MESSAGE_INTERVAL || (a.target_system != 0 && a.target_system != mav_sysid(m))) {
        m->n.acks_other++;
        return;
    }
    if (a.result == MAV_RESULT_ACCEPTED) {
        m->n.interval_accepted++;
        return;
    }
    if (a.result == MAV_RESULT_IN_PROGRESS)
        return;
    m->n.interval_refused++;
    if (!m->refusal_said)
        app_warn(m->app, "mavlink: the autopilot refused SET_MESSAGE_INTERVAL (MAV_RESULT %u): the pose comes at %.1f Hz; "
                "raise its SRn_EXTRA1 and SRn_POSITION stream rates", a.result, (double)m->pose_hz);
    m->refusal_said = 1;
}

static void pose_in(struct mav *m, const mavlink_message_t *msg, int64_t now_wall, int64_t now_mono)
{
    if (msg->msgid == MAVLINK_MSG_ID_LOCAL_POSITION_NED) {
        mavlink_local_position_ned_t p;
        mavlink_msg_local_position_ned_decode(msg, &p);
        if (m->have_pos && now_wall - m->pos_us > MAV_POSITION_STALE_US)
            m->n.position_gaps++;
        m->have_pos = 1;
        m->north_m = p.x;
        m->east_m = p.y;
        m->pos_us = now_wall;
        m->n.positions++;
    } else {
        mavlink_attitude_t att;
        struct sonar_pose q;
        mavlink_msg_attitude_decode(msg, &att);
        m->n.attitudes++;
        count_attitude(m, now_mono);
        /* Yaw in radians, NED (clockwise from north): degrees; the position if fresh, else where it was last. */
        q.utime = now_wall;
        q.yaw_deg = (float)fmod((double)att.yaw * 180.0 / SONAR_PI + 360.0, 360.0);
        q.north_m = m->have_pos ? m->north_m : 0.0f;
        q.east_m = m->have_pos ? m->east_m : 0.0f;
        if (m->first_att_us == 0)
            m->first_att_us = now_wall;
        /*
         * Heading only (no LOCAL_POSITION_NED, a vehicle without a position estimate) once a second
         * has passed without one: sooner, a position arriving just after would look like a jump.
         */
        if (!m->have_pos && m->n.positions == 0 && now_wall - m->first_att_us < MAV_POSITION_STALE_US)
            return;
        if (app_pose(m->app, &q, NULL) != HOST_OK) {
            m->n.poses_refused++;
            return;
        }
        m->last_pose = q;
        m->have_last_pose = 1;
    }
}

static void handle(struct mav *m, const mavlink_message_t *msg, int64_t now_wall, int64_t now_mono)
{
    if (msg->sysid == mav_sysid(m) && msg->compid == m->cfg.compid) {
        m->n.rx_other++; /* our own, echoed by a router */
        return;
    }
    if (msg->msgid == MAVLINK_MSG_ID_HEARTBEAT) {
        heartbeat_in(m, msg, now_mono);
        return;
    }
    /* Everything else only from the autopilot, once its HEARTBEAT has said which it is. */
    if (m->ap_sysid == 0 || msg->sysid != m->ap_sysid || msg->compid != MAV_COMP_ID_AUTOPILOT1) {
        m->n.rx_other++;
        return;
    }
    if (msg->msgid == MAVLINK_MSG_ID_COMMAND_ACK)
        ack_in(m, msg);
    else if (msg->msgid == MAVLINK_MSG_ID_LOCAL_POSITION_NED || msg->msgid == MAVLINK_MSG_ID_ATTITUDE)
        pose_in(m, msg, now_wall, now_mono);
}

void mav_bytes(struct mav *m, const uint8_t *buf, size_t len, int64_t now_wall_us)
{
    struct rx *r = mav_rxs(m);
    int64_t now_mono = m->app != NULL ? app_mono_us(m->app) : 0;
    size_t i;
    for (i = 0; i < len; i++) {
        uint8_t f = mavlink_frame_char_buffer(&r->buf, &r->status, buf[i], &r->msg, &r->r_status);
        if (f == MAVLINK_FRAMING_OK) {
            m->n.rx_msgs++;
            handle(m, &r->msg, now_wall_us, now_mono);
        } else if (f == MAVLINK_FRAMING_BAD_CRC || f == MAVLINK_FRAMING_BAD_SIGNATURE) {
            /* A message this dialect lacks has no CRC extra to check: foreign, not corrupt. */
            if (mavlink_get_msg_entry(r->msg.msgid) == NULL)
                m->n.rx_foreign++;
            else
                m->n.rx_bad_crc++;
        }
    }
}

void mav_rx_timers(struct mav *m, int64_t now_mono)
{
    /* ATTITUDE stopped altogether: no message closes the window, so the timer does. */
    if (m->ap_sysid != 0 && now_mono - m->rate_t0 >= 2 * MAV_RATE_WINDOW_US)
        close_window(m, now_mono);
}

void mav_status(const struct mav *m, struct sonar_status *s)
{
    s->autopilot.sysid = m->ap_sysid;
    s->autopilot.pose_hz = m->pose_hz;
    s->autopilot.interval_requests = m->n.interval_requests;
    s->autopilot.interval_refused = m->n.interval_refused;
    s->autopilot.acks_other = m->n.acks_other;
    s->autopilot.pose_held = (uint32_t)m->holding;
    s->autopilot.od_sent = m->n.obstacle_distance;
    s->autopilot.od_withheld = m->n.od_withheld;
    s->autopilot.rx_other = m->n.rx_other + m->n.hb_other;
}
