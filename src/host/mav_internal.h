/* mav_internal.h -- what mav.c (endpoint, options, loop), mav_rx.c (what the vehicle says) and mav_tx.c (what we say) share; only they include it and the generated MAVLink headers. */
#ifndef SONARD_MAV_INTERNAL_H
#define SONARD_MAV_INTERNAL_H

#include "mav.h"

#include "ardupilotmega/mavlink.h"

struct rx {
    mavlink_message_t buf, msg;
    mavlink_status_t status, r_status;
};

SONAR_STATIC_ASSERT(sizeof(struct rx) <= 1024, rx_fits);
SONAR_STATIC_ASSERT(sizeof(mavlink_status_t) <= 1024, tx_fits);

static inline struct rx *mav_rxs(struct mav *m)
{
    return (struct rx *)(void *)m->rx.b;
}

static inline mavlink_status_t *mav_txs(struct mav *m)
{
    return (mavlink_status_t *)(void *)m->tx.b;
}

/* Our system id: the configured one, else the autopilot's once heard, else 1. */
static inline uint8_t mav_sysid(const struct mav *m)
{
    return m->cfg.sysid != 0 ? m->cfg.sysid : m->ap_sysid != 0 ? m->ap_sysid : 1;
}

/* mav_tx.c: one message to the endpoint (udpin: every peer heard lately), counted. */
void mav_send(struct mav *m, const mavlink_message_t *msg, int64_t now_mono);

/* mav_tx.c: HEARTBEAT; OBSTACLE_DISTANCE unless failing closed; SET_MESSAGE_INTERVAL while the pose is slow. */
void mav_heartbeat(struct mav *m, int64_t now_mono);
void mav_send_obstacles(struct mav *m, int64_t now_mono);
void mav_ask_pose(struct mav *m, int64_t now_mono);

/* mav_rx.c: the pose rate's window closed when ATTITUDE stops altogether. */
void mav_rx_timers(struct mav *m, int64_t now_mono);

/* mav_tx.c: the sink's callbacks (filtered beams into the map; confirmed tracks out). */
int mav_sink_beam(void *self, const struct sonar_record *b);
int mav_sink_detections(void *self, const struct sonar_detections *d, const struct sonar_tracker *tk,
                        const struct msg_view *v);

#endif
