/* mav_tx.c -- what sonard says to the autopilot: HEARTBEAT, the obstacle map as OBSTACLE_DISTANCE (fail-closed, ArduPilot's faces contiguous, own echoes masked), OBSTACLE_DISTANCE_3D per track, the pose rate asked for; O(72) a message. */
#define _GNU_SOURCE
#include "mav_internal.h"

#include <math.h>
#include <string.h>

#include "sonar/frame.h"
#include "sonar/pipeline.h"

/*
 * ArduPilot reduces OBSTACLE_DISTANCE to eight 45-degree faces centred on 0, 45, ... degrees and
 * keeps, for each run of consecutive entries in one face, the nearest; a face visited twice in one
 * message keeps the second run. With entry j centred on 5 j - 20 degrees (angle_offset -20), face
 * k is entries 9 k .. 9 k + 8: one run each, the first face starting the message.
 */
#define FACE_SECTORS 9
#define OD_ANGLE_OFFSET (-(float)(FACE_SECTORS / 2) * (float)SONAR_OBS_SECTOR_DEG)

void mav_send(struct mav *m, const mavlink_message_t *msg, int64_t now_mono)
{
    uint8_t buf[MAVLINK_MAX_PACKET_LEN];
    uint16_t len = mavlink_msg_to_send_buffer(buf, msg);
    int sent = 0, k;
    if (m->kind == MAV_UDPIN) {
        for (k = 0; k < MAV_PEERS; k++) {
            if (m->peer[k].len == 0 || now_mono - m->peer[k].seen_us > MAV_PEER_US)
                continue;
            if (link_send_to(&m->link, buf, len, &m->peer[k].addr, m->peer[k].len) == HOST_OK)
                sent = 1;
        }
    } else if (m->link.fd >= 0) {
        sent = link_write(&m->link, buf, len) == HOST_OK;
    }
    if (sent)
        m->n.tx_msgs++;
    else
        m->n.tx_dropped++;
}

static uint32_t boot_ms(const struct mav *m, int64_t now_mono)
{
    return (uint32_t)((now_mono - m->t0_us) / 1000);
}

void mav_heartbeat(struct mav *m, int64_t now_mono)
{
    mavlink_message_t msg;
    mavlink_msg_heartbeat_pack_status(mav_sysid(m), m->cfg.compid, mav_txs(m), &msg, MAV_TYPE_ONBOARD_CONTROLLER,
                                      MAV_AUTOPILOT_INVALID, 0, 0, MAV_STATE_ACTIVE);
    mav_send(m, &msg, now_mono);
    m->n.heartbeats++;
}

/*
 * SET_MESSAGE_INTERVAL for ATTITUDE and LOCAL_POSITION_NED, to the autopilot, every
 * MAV_INTERVAL_RETRY_US until a full window has the pose at 80 % of the rate asked or more:
 * their streams are per link and a ground station normally sets them, so with none connected
 * they may come at 1 Hz or not at all.
 */
void mav_ask_pose(struct mav *m, int64_t now_mono)
{
    static const uint16_t ids[2] = {MAVLINK_MSG_ID_ATTITUDE, MAVLINK_MSG_ID_LOCAL_POSITION_NED};
    float interval_us;
    int i;
    if (m->cfg.pose_rate_hz <= 0.0f || m->ap_sysid == 0 || now_mono < m->next_interval)
        return;
    if (m->pose_hz >= 0.8f * m->cfg.pose_rate_hz) {
        m->next_interval = INT64_MAX; /* the rate is there; mav_rx.c re-arms it when the rate falls */
        return;
    }
    interval_us = 1e6f / m->cfg.pose_rate_hz;
    for (i = 0; i < 2; i++) {
        mavlink_message_t msg;
        mavlink_msg_command_long_pack_status(mav_sysid(m), m->cfg.compid, mav_txs(m), &msg, m->ap_sysid,
                                             MAV_COMP_ID_AUTOPILOT1, MAV_CMD_SET_MESSAGE_INTERVAL, 0, (float)ids[i],
                                             interval_us, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f);
        mav_send(m, &msg, now_mono);
        m->n.interval_requests++;
    }
    m->next_interval = now_mono + MAV_INTERVAL_RETRY_US;
}

/*
 * The vehicle's pose for the map's world points now: the app's, else the last one pushed for
 * MAV_POSE_HOLD_US after it (said once, counted) so the map's memory is not dropped the moment the
 * autopilot's stream hiccups; NULL past that.
 */
static const struct sonar_pose *pose_now(struct mav *m, int64_t now_wall, struct sonar_pose *q)
{
    if (m->app != NULL && app_pose_at(m->app, now_wall, q)) {
        m->holding = 0;
        return q;
    }
    if (m->have_last_pose && now_wall - m->last_pose.utime <= MAV_POSE_HOLD_US) {
        if (!m->holding) {
            m->n.pose_holds++;
            app_warn(m->app, "mavlink: the pose is stale; the obstacle map keeps the last one for up to %.0f s",
                    MAV_POSE_HOLD_US * 1e-6);
        }
        m->holding = 1;
        *q = m->last_pose;
        return q;
    }
    m->holding = 0;
    return NULL;
}

/*
 * The whole map as one OBSTACLE_DISTANCE: body FRD, cm, in the body frame at the vehicle's pose
 * now when there is one (obsmap_read: masked arcs unknown, nothing 0); entries reordered for the faces (above).
 */
static void pack_od(struct mav *m, mavlink_message_t *msg, int64_t now_wall, int64_t now_mono)
{
    uint16_t out[SONAR_OBS_SECTORS];
    struct obsmap_read r;
    struct sonar_pose q;
    int j;
    obsmap_read(&m->map, now_wall, pose_now(m, now_wall, &q), &r);
    for (j = 0; j < SONAR_OBS_SECTORS; j++)
        out[j] = r.dist_cm[(j - FACE_SECTORS / 2 + SONAR_OBS_SECTORS) % SONAR_OBS_SECTORS]; /* sector k: centred on 5 k degrees */
    mavlink_msg_obstacle_distance_pack_status(mav_sysid(m), m->cfg.compid, mav_txs(m), msg,
                                              (uint64_t)(now_mono - m->t0_us), MAV_DISTANCE_SENSOR_ULTRASOUND, out,
                                              SONAR_OBS_SECTOR_DEG, r.min_cm, r.max_cm, (float)SONAR_OBS_SECTOR_DEG,
                                              OD_ANGLE_OFFSET, MAV_FRAME_BODY_FRD);
}

size_t mav_obstacle_distance(struct mav *m, uint8_t *buf, int64_t now_wall_us, int64_t now_mono_us)
{
    mavlink_message_t msg;
    pack_od(m, &msg, now_wall_us, now_mono_us);
    return mavlink_msg_to_send_buffer(buf, &msg);
}

/*
 * Fail closed: with no beam for MAV_BEAM_STALE_US (the sonar unplugged, the link down, the head
 * stopped) nothing is sent, so ArduPilot marks the sensor NoData after its 0.5 s instead of letting
 * the map age into "clear" under a healthy-looking sensor.
 */
void mav_send_obstacles(struct mav *m, int64_t now_mono)
{
    mavlink_message_t msg;
    int64_t wall = app_wall_us(m->app);
    int stale = m->last_beam_us == 0 || wall - m->last_beam_us > MAV_BEAM_STALE_US;
    if (obsmap_beams(&m->map) == 0 && !m->withholding)
        return; /* nothing scanned yet: every sector would be unknown */
    if (m->cfg.fail_closed && stale) {
        if (!m->withholding)
            app_warn(m->app, "mavlink: no beam for %.2f s: OBSTACLE_DISTANCE withheld, the autopilot will mark the sonar "
                    "NoData", MAV_BEAM_STALE_US * 1e-6);
        m->withholding = 1;
        m->n.od_withheld++;
        return;
    }
    if (m->withholding)
        app_say(m->app, "mavlink: beams again: OBSTACLE_DISTANCE resumed");
    m->withholding = 0;
    pack_od(m, &msg, wall, now_mono);
    mav_send(m, &msg, now_mono);
    m->n.obstacle_distance++;
    if (m->unsent_us != 0) {
        double ms = (double)(wall - m->unsent_us) * 1e-3;
        m->lat_sum_ms += ms;
        m->lat_max_ms = ms > m->lat_max_ms ? ms : m->lat_max_ms;
        m->lat_n++;
        m->unsent_us = 0;
    }
}

int mav_sink_beam(void *self, const struct sonar_record *b)
{
    struct mav *m = self;
    int r;
    m->last_beam_us = app_wall_us(m->app);
    if ((r = obsmap_beam(&m->map, b)) != HOST_OK)
        return r;
    if (m->unsent_us == 0)
        m->unsent_us = m->last_beam_us;
    return HOST_OK;
}

/*
 * With --mavlink-3d on, one OBSTACLE_DISTANCE_3D per confirmed track, all with one time_boot_ms:
 * where it is at the sweep's end, in the body frame then. Its obstacle_id is the track's ID folded
 * into 1..65534 (ArduPilot reads 65535 as unknown; it ignores the ID anyway).
 */
int mav_sink_detections(void *self, const struct sonar_detections *d, const struct sonar_tracker *tk,
                        const struct msg_view *v)
{
    struct mav *m = self;
    int64_t now = app_mono_us(m->app);
    uint32_t t = boot_ms(m, now);
    struct obsmap_read r;
    uint8_t i;
    if (tk == NULL || !m->cfg.send_3d)
        return HOST_OK;
    obsmap_read(&m->map, d->utime, NULL, &r); /* only its min and max */
    for (i = 0; i < sonar_tracker_count(tk); i++) {
        const struct sonar_track *k = sonar_tracker_track(tk, i);
        mavlink_message_t msg;
        float x, y;
        if (k->state != SONAR_TRACK_CONFIRMED)
            continue;
        sonar_tracker_predict(k, d->utime, &x, &y);
        if (sonar_tracker_world(tk)) {
            float n = x, e = y;
            if (v == NULL || !v->have_pose)
                continue; /* a world track without the pose to place it: nothing honest to say */
            sonar_pose_to_body(&v->pose, n, e, &x, &y);
        }
        mavlink_msg_obstacle_distance_3d_pack_status(mav_sysid(m), m->cfg.compid, mav_txs(m), &msg, t,
                                                     MAV_DISTANCE_SENSOR_ULTRASOUND, MAV_FRAME_BODY_FRD,
                                                     (uint16_t)(1u + (k->id - 1u) % 65534u), x, y, 0.0f,
                                                     (float)r.min_cm / 100.0f, (float)r.max_cm / 100.0f);
        mav_send(m, &msg, now);
        m->n.obstacle_3d++;
    }
    return HOST_OK;
}
