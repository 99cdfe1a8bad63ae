/* mav.c -- the MAVLink endpoint with the code mavgen generated from pymavlink's ardupilotmega dialect: udpin/udpout/serial, the parser, poses in, the obstacle map out; O(bytes) a read, O(72) a message. */
#define _GNU_SOURCE
#include "mav.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <netdb.h>
#include <netinet/in.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "ardupilotmega/mavlink.h"
#include "sonar/frame.h"
#include "sonar/pipeline.h"

struct rx {
    mavlink_message_t buf, msg;
    mavlink_status_t status, r_status;
};

SONAR_STATIC_ASSERT(sizeof(struct rx) <= 1024, rx_fits);
SONAR_STATIC_ASSERT(sizeof(mavlink_status_t) <= 1024, tx_fits);

static struct rx *rxs(struct mav *m)
{
    return (struct rx *)(void *)m->rx.b;
}

static mavlink_status_t *txs(struct mav *m)
{
    return (mavlink_status_t *)(void *)m->tx.b;
}

/* Splits "HOST:PORT" (the last colon) into host and port, a number 1..65535. Returns 0, or -1. */
static int host_port(const char *s, char *host, size_t hn, char *port, size_t pn)
{
    const char *c = strrchr(s, ':');
    char *end;
    long p;
    if (c == NULL || c == s || c[1] == '\0' || (size_t)(c - s) >= hn || strlen(c + 1) >= pn)
        return -1;
    p = strtol(c + 1, &end, 10);
    if (*end != '\0' || p < 1 || p > 65535)
        return -1;
    memcpy(host, s, (size_t)(c - s));
    host[c - s] = '\0';
    strcpy(port, c + 1);
    return 0;
}

int mav_init(struct mav *m, const struct mav_config *cfg, char *err, size_t errlen)
{
    char host[128], port[16];
    memset(m, 0, sizeof(*m));
    m->cfg = *cfg;
    m->link.fd = -1;
    if (!(cfg->rate_hz >= 1.0f && cfg->rate_hz <= 50.0f)) {
        snprintf(err, errlen, "--mavlink-rate: %g is not in 1..50 messages a second", (double)cfg->rate_hz);
        return HOST_ERR_CONFIG;
    }
    if (cfg->sysid == 0 || cfg->compid == 0) {
        snprintf(err, errlen, "--mavlink-sysid and --mavlink-compid: 1..255");
        return HOST_ERR_CONFIG;
    }
    if (strncmp(cfg->url, "udpin:", 6) == 0) {
        m->kind = MAV_UDPIN;
        if (host_port(cfg->url + 6, host, sizeof(host), port, sizeof(port)) != 0 ||
            link_parse(&m->link, "--mavlink", cfg->url, LINK_ALLOW_LISTEN, 0, err, errlen) != HOST_OK) {
            snprintf(err, errlen, "--mavlink %s: udpin:ADDR:PORT with a port 1..65535, e.g. udpin:0.0.0.0:14660", cfg->url);
            return HOST_ERR_CONFIG;
        }
    } else if (strncmp(cfg->url, "udpout:", 7) == 0) {
        m->kind = MAV_UDPOUT;
        if (host_port(cfg->url + 7, host, sizeof(host), port, sizeof(port)) != 0 ||
            link_parse(&m->link, "--mavlink", cfg->url, LINK_ALLOW_UDP, 0, err, errlen) != HOST_OK) {
            snprintf(err, errlen, "--mavlink %s: udpout:HOST:PORT with a port 1..65535, e.g. udpout:192.168.2.1:14550",
                     cfg->url);
            return HOST_ERR_CONFIG;
        }
    } else if (strncmp(cfg->url, "serial:", 7) == 0) {
        m->kind = MAV_SERIAL;
        if (link_parse(&m->link, "--mavlink", cfg->url, LINK_ALLOW_SERIAL, 0, err, errlen) != HOST_OK)
            return HOST_ERR_CONFIG;
    } else {
        snprintf(err, errlen, "--mavlink %s: udpin:ADDR:PORT, udpout:HOST:PORT or serial:PATH[:BAUD]", cfg->url);
        return HOST_ERR_CONFIG;
    }
    snprintf(m->desc, sizeof(m->desc), "%s", cfg->url);
    {
        struct sonar_obstacle_config oc;
        sonar_obstacle_defaults(&oc);
        oc.min_range_m = cfg->min_range_m > SONAR_PIPE_NEAR_M ? cfg->min_range_m : SONAR_PIPE_NEAR_M;
        if (oc.min_range_m > 100.0f || sonar_obstacle_init(&m->obs, &oc) != SONAR_OK) {
            snprintf(err, errlen, "--min-range %g: too far for the obstacle map (0..100 m)", (double)cfg->min_range_m);
            return HOST_ERR_CONFIG;
        }
    }
    return HOST_OK;
}

/* ---- sending ---- */

/* One message to the endpoint: udpin answers every peer heard lately; the others send on their link. */
static void send_msg(struct mav *m, const mavlink_message_t *msg, int64_t now_mono)
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

static void heartbeat(struct mav *m, int64_t now_mono)
{
    mavlink_message_t msg;
    mavlink_msg_heartbeat_pack_status(m->cfg.sysid, m->cfg.compid, txs(m), &msg, MAV_TYPE_ONBOARD_CONTROLLER,
                                      MAV_AUTOPILOT_INVALID, 0, 0, MAV_STATE_ACTIVE);
    send_msg(m, &msg, now_mono);
    m->n.heartbeats++;
}

/* How old a sector may be: a little over one sweep (the last one's time; 40 s, the slowest, before any). */
static int64_t max_age(const struct mav *m)
{
    double s = m->app != NULL && app_last_sweep_s(m->app) > 0.0f ? (double)app_last_sweep_s(m->app) : 40.0;
    return (int64_t)(s * 1.2e6);
}

/*
 * The whole map as one OBSTACLE_DISTANCE: sector k centred on k x 5 degrees (angle_offset 0), body
 * FRD, cm, in the body frame at the vehicle's pose now when there is one.
 */
static void pack_od(struct mav *m, mavlink_message_t *msg, int64_t now_wall, int64_t now_mono)
{
    uint16_t dist[SONAR_OBS_SECTORS], mn, mx;
    struct sonar_pose q;
    int have = m->app != NULL && app_pose_at(m->app, now_wall, &q);
    sonar_obstacle_map(&m->obs, now_wall, max_age(m), have ? &q : NULL, dist, &mn, &mx);
    mavlink_msg_obstacle_distance_pack_status(m->cfg.sysid, m->cfg.compid, txs(m), msg,
                                              (uint64_t)(now_mono - m->t0_us), MAV_DISTANCE_SENSOR_ULTRASOUND, dist,
                                              SONAR_OBS_SECTOR_DEG, mn, mx, (float)SONAR_OBS_SECTOR_DEG, 0.0f,
                                              MAV_FRAME_BODY_FRD);
}

size_t mav_obstacle_distance(struct mav *m, uint8_t *buf, int64_t now_wall_us, int64_t now_mono_us)
{
    mavlink_message_t msg;
    pack_od(m, &msg, now_wall_us, now_mono_us);
    return mavlink_msg_to_send_buffer(buf, &msg);
}

static void obstacle_distance(struct mav *m, int64_t now_mono)
{
    mavlink_message_t msg;
    int64_t wall = app_wall_us(m->app);
    if (m->obs.beams == 0)
        return; /* nothing scanned yet: every sector would be unknown */
    pack_od(m, &msg, wall, now_mono);
    send_msg(m, &msg, now_mono);
    m->n.obstacle_distance++;
    if (m->unsent_us != 0) {
        double ms = (double)(wall - m->unsent_us) * 1e-3;
        m->lat_sum_ms += ms;
        m->lat_max_ms = ms > m->lat_max_ms ? ms : m->lat_max_ms;
        m->lat_n++;
        m->unsent_us = 0;
    }
}

/* ---- the sink: filtered beams into the map, confirmed tracks out ---- */

static int sink_beam(void *self, const struct sonar_record *b)
{
    struct mav *m = self;
    float bearing = ((float)b->angle + m->cfg.angle_offset) * (float)SONAR_DEG_PER_GRAD;
    struct sonar_pose q;
    q.utime = b->utime;
    q.north_m = b->north_m;
    q.east_m = b->east_m;
    q.yaw_deg = b->yaw_deg;
    if (sonar_obstacle_beam(&m->obs, b->utime, bearing, b->has_pose ? &q : NULL, b->samples, b->n, b->range_m) != SONAR_OK)
        return HOST_ERR_IO;
    if (m->unsent_us == 0)
        m->unsent_us = app_wall_us(m->app);
    return HOST_OK;
}

/*
 * One OBSTACLE_DISTANCE_3D per confirmed track, all with one time_boot_ms: where it is at the
 * sweep's end, in the body frame then (a world track predicted there and brought back through the
 * vehicle's pose at that time).
 */
static int sink_detections(void *self, const struct sonar_detections *d, const struct sonar_tracker *tk,
                           const struct msg_view *v)
{
    struct mav *m = self;
    int64_t now = app_mono_us(m->app);
    uint32_t t = boot_ms(m, now);
    uint16_t mn, mx, dist[SONAR_OBS_SECTORS];
    uint8_t i;
    if (tk == NULL)
        return HOST_OK;
    sonar_obstacle_map(&m->obs, d->utime, max_age(m), NULL, dist, &mn, &mx); /* only its min and max */
    for (i = 0; i < tk->n; i++) {
        const struct sonar_track *k = &tk->t[i];
        mavlink_message_t msg;
        float x, y;
        if (k->state != SONAR_TRACK_CONFIRMED)
            continue;
        sonar_tracker_predict(k, d->utime, &x, &y);
        if (tk->world) {
            float n = x, e = y;
            if (v == NULL || !v->have_pose)
                continue; /* a world track without the pose to place it: nothing honest to say */
            sonar_pose_to_body(&v->pose, n, e, &x, &y);
        }
        mavlink_msg_obstacle_distance_3d_pack_status(m->cfg.sysid, m->cfg.compid, txs(m), &msg, t,
                                                     MAV_DISTANCE_SENSOR_ULTRASOUND, MAV_FRAME_BODY_FRD,
                                                     (uint16_t)(k->id & 0xffffu), x, y, 0.0f, (float)mn / 100.0f,
                                                     (float)mx / 100.0f);
        send_msg(m, &msg, now);
        m->n.obstacle_3d++;
    }
    return HOST_OK;
}

int mav_attach(struct mav *m, struct app *a)
{
    m->app = a;
    m->sink.name = "mavlink";
    m->sink.self = m;
    m->sink.stages = 1u << SONAR_STAGE_MEDIAN;
    m->sink.beam = sink_beam;
    m->sink.detections = sink_detections;
    return app_add_sink(a, &m->sink);
}

/* ---- receiving ---- */

static void handle(struct mav *m, const mavlink_message_t *msg, int64_t now_wall)
{
    int from_autopilot = msg->compid == MAV_COMP_ID_AUTOPILOT1 && (m->cfg.autopilot == 0 || msg->sysid == m->cfg.autopilot);
    if (!from_autopilot || (msg->sysid == m->cfg.sysid && msg->compid == m->cfg.compid)) {
        m->n.rx_other++;
        return;
    }
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
    } else if (msg->msgid == MAVLINK_MSG_ID_ATTITUDE) {
        mavlink_attitude_t att;
        struct sonar_pose q;
        mavlink_msg_attitude_decode(msg, &att);
        m->n.attitudes++;
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
        if (app_pose(m->app, &q, NULL) != HOST_OK)
            m->n.poses_refused++;
    }
}

void mav_bytes(struct mav *m, const uint8_t *buf, size_t len, int64_t now_wall_us)
{
    struct rx *r = rxs(m);
    size_t i;
    for (i = 0; i < len; i++) {
        uint8_t f = mavlink_frame_char_buffer(&r->buf, &r->status, buf[i], &r->msg, &r->r_status);
        if (f == MAVLINK_FRAMING_OK) {
            m->n.rx_msgs++;
            handle(m, &r->msg, now_wall_us);
        } else if (f == MAVLINK_FRAMING_BAD_CRC || f == MAVLINK_FRAMING_BAD_SIGNATURE) {
            /* A message this dialect lacks has no CRC extra to check: foreign, not corrupt. */
            if (mavlink_get_msg_entry(r->msg.msgid) == NULL)
                m->n.rx_foreign++;
            else
                m->n.rx_bad_crc++;
        }
    }
}

/* ---- the live loop's source ---- */

static void mav_read(struct mav *m, int64_t now);

/* What the link did: up (said once it was down), failed (said once; it retries), readable, gone. */
static void on_link(struct mav *m, int ev, const char *err, int64_t now)
{
    if (ev == LINK_EV_UP && m->down) {
        app_say(m->app, "--mavlink %s: open", m->desc);
        m->down = 0;
    } else if (ev == LINK_EV_FAILED && !m->down) {
        app_say(m->app, "--mavlink %s: %s; running without the autopilot, retrying every second", m->desc, err);
        m->down = 1;
    } else if (ev == LINK_EV_DATA) {
        mav_read(m, now);
    } else if (ev == LINK_EV_HUNGUP) {
        if (m->kind == MAV_SERIAL)
            link_lost(&m->link, now, LINK_RETRY_US); /* unplugged: opened again in a second */
        else
            mav_read(m, now); /* a UDP socket's error (ICMP: nobody there yet) is read and forgotten */
    }
}

static void mav_start(void *self, struct app *a, int64_t now)
{
    struct mav *m = self;
    char err[200];
    (void)a;
    m->t0_us = now;
    m->next_hb = now;
    m->next_od = now;
    on_link(m, link_service_timers(&m->link, now, err, sizeof(err)), err, now);
}

static int mav_fd(const void *self, short *events)
{
    const struct mav *m = self;
    return link_poll_fd(&m->link, events);
}

/* A udpin sender: remembered (the newest replaces the stalest) so that it is answered. */
static void remember(struct mav *m, const struct sockaddr_storage *a, socklen_t len, int64_t now_mono)
{
    int k, slot = 0;
    for (k = 0; k < MAV_PEERS; k++) {
        if (m->peer[k].len == len && memcmp(&m->peer[k].addr, a, len) == 0) {
            m->peer[k].seen_us = now_mono;
            return;
        }
        if (m->peer[k].seen_us < m->peer[slot].seen_us)
            slot = k;
    }
    m->peer[slot].addr = *a;
    m->peer[slot].len = len;
    m->peer[slot].seen_us = now_mono;
}

static void mav_read(struct mav *m, int64_t now)
{
    uint8_t buf[2048];
    int reads;
    for (reads = 0; reads < LINK_READS; reads++) {
        /* Each datagram its own receive time: two poses read in one wake are not one instant. */
        int64_t wall = app_wall_us(m->app);
        ssize_t r = link_read(&m->link, buf, sizeof(buf));
        if (r == HOST_ERR_CLOSED && m->kind == MAV_SERIAL) {
            link_lost(&m->link, now, LINK_RETRY_US); /* unplugged: opened again in a second */
            return;
        }
        if (r <= 0)
            return; /* udpout: nobody listening there yet (ICMP) is no loss, it may come */
        if (m->kind == MAV_UDPIN)
            remember(m, &m->link.from, m->link.from_len, now);
        mav_bytes(m, buf, (size_t)r, wall);
    }
}

static void mav_ready(void *self, short revents, int64_t now)
{
    struct mav *m = self;
    char err[200];
    on_link(m, link_service_fd(&m->link, revents, now, err, sizeof(err)), err, now);
}

static int64_t mav_timers(void *self, int64_t now)
{
    struct mav *m = self;
    int64_t period = (int64_t)(1e6 / (double)m->cfg.rate_hz);
    if (now >= m->next_hb) {
        heartbeat(m, now);
        m->next_hb = now + 1000000;
    }
    if (now >= m->next_od) {
        obstacle_distance(m, now);
        /* On a fixed grid from the start, not from this call: a late wake does not slow the rate. */
        m->next_od += period;
        if (m->next_od <= now)
            m->next_od = now + period;
    }
    {
        char err[200];
        int64_t w = m->next_hb < m->next_od ? m->next_hb : m->next_od;
        on_link(m, link_service_timers(&m->link, now, err, sizeof(err)), err, now);
        return link_wake(&m->link) < w ? link_wake(&m->link) : w;
    }
}

static void mav_close(void *self)
{
    struct mav *m = self;
    link_close(&m->link);
}

static const struct live_io_ops mav_ops = {mav_start, mav_fd, mav_ready, mav_timers, mav_close};

void mav_live(struct mav *m, struct live_aux *out)
{
    out->ops = &mav_ops;
    out->self = m;
}

void mav_summary(const struct mav *m, char *buf, size_t n)
{
    snprintf(buf, n,
             "mavlink %s: in %u messages (%u attitudes, %u positions, %u poses refused, %u bad CRC, %u foreign, "
             "%u from others); out %u OBSTACLE_DISTANCE, %u OBSTACLE_DISTANCE_3D, %u HEARTBEAT (%u dropped); "
             "echo to message mean %.1f ms, max %.1f ms",
             m->desc, m->n.rx_msgs, m->n.attitudes, m->n.positions, m->n.poses_refused, m->n.rx_bad_crc,
             m->n.rx_foreign, m->n.rx_other, m->n.obstacle_distance, m->n.obstacle_3d, m->n.heartbeats,
             m->n.tx_dropped, m->lat_n ? m->lat_sum_ms / m->lat_n : 0.0, m->lat_max_ms);
}
