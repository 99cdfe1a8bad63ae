/* mav.c -- the MAVLink endpoint (code mavgen generated from pymavlink's ardupilotmega dialect): its configuration, its link (udpin, udpout, serial) in the live loop, its timers and summary; what comes in is mav_rx.c's, what goes out mav_tx.c's. */
#define _GNU_SOURCE
#include "mav_internal.h"

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

#include "sonar/frame.h"
#include "sonar/pipeline.h"

int mav_init(struct mav *m, const struct mav_config *cfg, char *err, size_t errlen)
{
    memset(m, 0, sizeof(*m));
    m->cfg = *cfg;
    m->link.fd = -1;
    if (!(cfg->rate_hz >= 1.0f && cfg->rate_hz <= 50.0f)) {
        snprintf(err, errlen, "--mavlink-rate: %g is not in 1..50 messages a second", (double)cfg->rate_hz);
        return HOST_ERR_CONFIG;
    }
    if (cfg->compid == 0) {
        snprintf(err, errlen, "--mavlink-compid: 1..255");
        return HOST_ERR_CONFIG;
    }
    if (!(cfg->pose_rate_hz == 0.0f || (cfg->pose_rate_hz >= 1.0f && cfg->pose_rate_hz <= 50.0f))) {
        snprintf(err, errlen, "--mavlink-pose-rate: %g is not 0 (never ask) or 1..50 a second", (double)cfg->pose_rate_hz);
        return HOST_ERR_CONFIG;
    }
    if (cfg->n_ignore > MAV_MAX_IGNORE) {
        snprintf(err, errlen, "--ignore-deg: at most %d arcs", MAV_MAX_IGNORE);
        return HOST_ERR_CONFIG;
    }
    m->next_interval = INT64_MAX; /* armed when the autopilot's HEARTBEAT is heard */
    if (strncmp(cfg->url, "udpin:", 6) == 0) {
        m->kind = MAV_UDPIN;
        /* link_parse checks the form; the message here adds an example */
        if (link_parse(&m->link, "--mavlink", cfg->url, LINK_ALLOW_LISTEN, 0, err, errlen) != HOST_OK) {
            snprintf(err, errlen, "--mavlink %s: udpin:ADDR:PORT with a port 1..65535, e.g. udpin:0.0.0.0:14660", cfg->url);
            return HOST_ERR_CONFIG;
        }
    } else if (strncmp(cfg->url, "udpout:", 7) == 0) {
        m->kind = MAV_UDPOUT;
        if (link_parse(&m->link, "--mavlink", cfg->url, LINK_ALLOW_UDP, 0, err, errlen) != HOST_OK) {
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
    return obsmap_init(&m->map, (const float (*)[2])cfg->ignore, cfg->n_ignore, err, errlen);
}

static void fill(const void *self, struct sonar_status *s)
{
    mav_status(self, s);
}

int mav_attach(struct mav *m, struct app *a)
{
    m->app = a;
    m->sink.name = "mavlink";
    m->sink.self = m;
    m->sink.stages = 1u << SONAR_STAGE_MEDIAN;
    m->sink.live = 1;
    m->sink.beam = mav_sink_beam;
    m->sink.detections = mav_sink_detections;
    m->sink.fill = fill;
    if (obsmap_bind(&m->map, a) != HOST_OK)
        return HOST_ERR_CONFIG;
    return app_add_sink(a, &m->sink);
}

/* ---- the live loop's source ---- */

/* The link's callbacks (link_serve_*): up and failed said once each way, datagrams decoded, a serial port unplugged reopened. */
static void ep_up(void *self, int64_t now)
{
    struct mav *m = self;
    (void)now;
    if (m->down)
        app_say(m->app, "--mavlink %s: open", m->desc);
    m->down = 0;
}

static void ep_failed(void *self, const char *err, int64_t now)
{
    struct mav *m = self;
    (void)now;
    if (!m->down)
        app_warn(m->app, "--mavlink %s: %s; running without the autopilot, retrying every %g s", m->desc, err,
                 LINK_RETRY_US * 1e-6);
    m->down = 1;
}

static void remember(struct mav *m, const struct sockaddr_storage *a, socklen_t len, int64_t now_mono);

static int ep_bytes(void *self, const uint8_t *buf, size_t n, int64_t now)
{
    struct mav *m = self;
    if (m->kind == MAV_UDPIN)
        remember(m, &m->link.from, m->link.from_len, now);
    /* Each datagram its own receive time: two poses read in one wake are not one instant. */
    mav_bytes(m, buf, n, app_wall_us(m->app));
    return 1;
}

/* A UDP socket's errors are soft (the endpoint's ops say so): only a serial port is lost, and opened again in a second. */
static void ep_lost(void *self, int64_t now, const char *why)
{
    struct mav *m = self;
    (void)why;
    link_lost(&m->link, now, LINK_RETRY_US);
}

static const struct link_endpoint_ops endpoint = {ep_up, ep_failed, ep_bytes, ep_lost, 1};

static void mav_start(void *self, struct app *a, int64_t now)
{
    struct mav *m = self;
    (void)a;
    m->t0_us = now;
    m->next_hb = now;
    m->next_od = now;
    (void)link_serve_timers(&m->link, now, &endpoint, m);
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

static void mav_ready(void *self, short revents, int64_t now)
{
    link_serve_fd(&((struct mav *)self)->link, revents, now, &endpoint, self);
}

static int64_t mav_timers(void *self, int64_t now)
{
    struct mav *m = self;
    int64_t period = (int64_t)(1e6 / (double)m->cfg.rate_hz);
    if (now >= m->next_hb) {
        mav_heartbeat(m, now);
        m->next_hb = now + 1000000;
    }
    mav_rx_timers(m, now);
    mav_ask_pose(m, now);
    if (now >= m->next_od) {
        mav_send_obstacles(m, now);
        /* On a fixed grid from the start, not from this call: a late wake does not slow the rate. */
        m->next_od += period;
        if (m->next_od <= now)
            m->next_od = now + period;
    }
    {
        int64_t w = m->next_hb < m->next_od ? m->next_hb : m->next_od, l;
        if (m->next_interval < w)
            w = m->next_interval;
        l = link_serve_timers(&m->link, now, &endpoint, m);
        return l < w ? l : w;
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
             "%u from others); autopilot system %u, pose %.1f Hz, %u interval requests (%u accepted, %u refused), "
             "%u other acks, %u other heartbeats, %u pose holds; out %u OBSTACLE_DISTANCE (%u withheld), "
             "%u OBSTACLE_DISTANCE_3D, %u HEARTBEAT (%u dropped); echo to message mean %.1f ms, max %.1f ms",
             m->desc, m->n.rx_msgs, m->n.attitudes, m->n.positions, m->n.poses_refused, m->n.rx_bad_crc,
             m->n.rx_foreign, m->n.rx_other, m->ap_sysid, (double)m->pose_hz, m->n.interval_requests,
             m->n.interval_accepted, m->n.interval_refused, m->n.acks_other, m->n.hb_other, m->n.pose_holds,
             m->n.obstacle_distance, m->n.od_withheld, m->n.obstacle_3d, m->n.heartbeats, m->n.tx_dropped,
             m->lat_n ? m->lat_sum_ms / m->lat_n : 0.0, m->lat_max_ms);
}
