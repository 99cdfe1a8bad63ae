/* mav.h -- the autopilot's MAVLink endpoint: its HEARTBEAT, ATTITUDE and LOCAL_POSITION_NED in (the pose asked for at a rate), OBSTACLE_DISTANCE (fail-closed, ArduPilot's faces contiguous), OBSTACLE_DISTANCE_3D and HEARTBEAT out; sizeof(struct mav) = 28 672 B, most of it the obstacle map (obsmap.h). */
#ifndef SONARD_MAV_H
#define SONARD_MAV_H

#include <stddef.h>
#include <stdint.h>
#include <sys/socket.h>

#include "app.h"
#include "link.h"
#include "live.h"
#include "obsmap.h"

#define MAV_PEERS 4                 /* udpin: the senders answered, each for MAV_PEER_US after it was last heard */
#define MAV_PEER_US 10000000
#define MAV_POSITION_STALE_US 1000000 /* without LOCAL_POSITION_NED for this long: heading only, at the last position */
#define MAV_MAX_IGNORE OBSMAP_MAX_IGNORE /* --ignore-deg arcs */
#define MAV_BEAM_STALE_US 950000      /* fail closed: no OBSTACLE_DISTANCE once the newest beam is this old (1 s, less the last message's way) */
#define MAV_POSE_HOLD_US 5000000      /* a stale pose still places the map's remembered echoes for this long */
#define MAV_INTERVAL_RETRY_US 5000000 /* SET_MESSAGE_INTERVAL again this often until the pose comes at the rate */
#define MAV_RATE_WINDOW_US 2000000    /* the pose rate is measured over this window */

enum mav_kind { MAV_UDPIN = 0, MAV_UDPOUT = 1, MAV_SERIAL = 2 };

struct mav_config {
    const char *url;        /* udpin:ADDR:PORT | udpout:HOST:PORT | serial:PATH[:BAUD] */
    uint8_t sysid;          /* ours, 1..255; 0: the autopilot's (1 until its HEARTBEAT is heard) */
    uint8_t compid;         /* ours, 1..255 */
    uint8_t autopilot;      /* the system whose autopilot (component 1) gives the pose; 0: the first autopilot heard */
    float rate_hz;          /* OBSTACLE_DISTANCE, 1..50 a second (HEARTBEAT: 1 Hz) */
    float pose_rate_hz;     /* ATTITUDE and LOCAL_POSITION_NED asked of the autopilot at this rate, 1..50; 0: never ask */
    uint8_t fail_closed;    /* 1: no OBSTACLE_DISTANCE while no beam is newer than MAV_BEAM_STALE_US */
    uint8_t send_3d;        /* 1: OBSTACLE_DISTANCE_3D for each confirmed track */
    uint8_t n_ignore;       /* arcs of the vehicle's own echoes, ignore[i] = {from, to} in degrees clockwise from forward */
    float ignore[MAV_MAX_IGNORE][2];
};

/* Counters, all since the start. */
struct mav_counters {
    uint32_t rx_msgs;       /* good messages */
    uint32_t rx_bad_crc;    /* framed, with a CRC that failed */
    uint32_t rx_foreign;    /* framed, of a message this dialect (ardupilotmega) does not have */
    uint32_t rx_other;      /* good, but not from the autopilot (other systems, components, or ours echoed) */
    uint32_t attitudes, positions, poses_refused;
    uint32_t position_gaps;     /* LOCAL_POSITION_NED back after more than MAV_POSITION_STALE_US without */
    uint32_t tx_msgs, tx_dropped; /* sent; not sent (no peer yet, a full socket or serial buffer) */
    uint32_t obstacle_distance, obstacle_3d, heartbeats;
    uint32_t od_withheld;       /* OBSTACLE_DISTANCE not sent: fail closed (no fresh beam) */
    uint32_t hb_autopilot, hb_other; /* HEARTBEATs from the autopilot; from others (ground stations, a second autopilot) */
    uint32_t interval_requests, interval_accepted, interval_refused, acks_other;
    uint32_t pose_holds;        /* times the map went on with the last pose, the pose being stale */
};

struct mav {
    struct mav_config cfg;
    struct app *app;
    int kind;
    struct link link;           /* udpin (a listener), udpout, serial */
    int down;                   /* the link failed to open; said once until it opens */
    char desc[160];
    struct {
        struct sockaddr_storage addr;
        socklen_t len;
        int64_t seen_us;
    } peer[MAV_PEERS];
    /* The generated library's parser buffers and status (mavlink_message_t x 2, mavlink_status_t x 2)
       and the sender's status (its sequence number), kept opaque so that only mav.c needs its headers. */
    union {
        uint64_t align;
        unsigned char b[1024];
    } rx, tx;
    struct obsmap map;          /* the obstacle map, fed by the sink below */
    struct app_sink sink;       /* filtered beams into the map; tracks out as OBSTACLE_DISTANCE_3D */
    int64_t t0_us;              /* monotonic start, for time_boot_ms */
    int64_t next_hb, next_od;
    int have_pos;
    uint8_t ap_sysid;           /* the autopilot: the configured one, or the first whose HEARTBEAT was heard; 0: none yet */
    int64_t rate_t0;            /* start of the pose rate window (monotonic us), ... */
    uint32_t rate_n;            /* ... ATTITUDEs in it so far, ... */
    float pose_hz;              /* ... and the rate the last full window gave */
    int64_t next_interval;      /* when to ask for the pose rate again (monotonic us); INT64_MAX: satisfied */
    uint8_t refusal_said;       /* a refused request was said on stderr */
    int64_t last_beam_us;       /* wall time of the newest beam into the map; 0: none */
    int withholding;            /* fail closed now */
    struct sonar_pose last_pose; /* the newest pose pushed, for MAV_POSE_HOLD_US after it goes stale */
    int have_last_pose, holding;
    int64_t first_att_us;       /* wall time of the first ATTITUDE */
    float north_m, east_m;
    int64_t pos_us;
    int64_t unsent_us;          /* wall time of the oldest beam not yet in a sent OBSTACLE_DISTANCE; 0: none */
    double lat_sum_ms, lat_max_ms; /* echo to message, over the messages sent */
    uint32_t lat_n;
    struct mav_counters n;
};

/*
 * Initialises m from cfg: checks it (the URL forms, the ids, the rate), parses the URL and sets up
 * the obstacle map; opens nothing. Returns HOST_OK, or HOST_ERR_CONFIG with err naming the part.
 */
HOST_CHECK int mav_init(struct mav *m, const struct mav_config *cfg, char *err, size_t errlen);

/*
 * Binds the app: adds the sink. The map takes the pipeline's output frame (angle offset, min
 * range) from the app at each beam (app_frame), so it turns with the detections when a reload
 * takes over. Returns HOST_OK, HOST_ERR_CONFIG (the app's min range too far: obsmap_check_min_range
 * says why) or HOST_ERR_FULL. Open with the live loop (mav_live).
 */
HOST_CHECK int mav_attach(struct mav *m, struct app *a);

/* The loop's view: a descriptor to read, timers for HEARTBEAT and OBSTACLE_DISTANCE; it never blocks the sonar. */
void mav_live(struct mav *m, struct live_aux *out);

/* Adds the autopilot's counters to a status (the sink's fill). */
void mav_status(const struct mav *m, struct sonar_status *s);

/* One line of counters and latency for stderr at exit. */
void mav_summary(const struct mav *m, char *buf, size_t n);

/*
 * Feeds received bytes to the parser (the live source's read path; also for tests): poses to the
 * app, everything counted. now_wall_us: the receive time, which the poses take.
 */
void mav_bytes(struct mav *m, const uint8_t *buf, size_t len, int64_t now_wall_us);

/*
 * Encodes the whole obstacle map as one OBSTACLE_DISTANCE into buf (>= 280 B) at now (wall and
 * monotonic us), as it goes out: angle_offset -20 so that ArduPilot's eight 45-degree faces are
 * nine consecutive entries each, ignored arcs unknown (65535), no entry 0. Returns its length.
 * Exposed for tests.
 */
size_t mav_obstacle_distance(struct mav *m, uint8_t *buf, int64_t now_wall_us, int64_t now_mono_us);

#endif
