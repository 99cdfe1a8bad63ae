/* device.h -- the Ping360 on a byte stream: Ping parser + driver + beam records, shared by the host's link and the firmware; RAM: struct sonar_device, the parser's buffer plus the driver (docs/sizes.md). */
#ifndef SONAR_DEVICE_H
#define SONAR_DEVICE_H

#include <stddef.h>
#include <stdint.h>

#include "sonar/err.h"
#include "sonar/ping.h"
#include "sonar/ping360.h"

/*
 * One beam and its acquisition: what a source hands on, whatever it came from (the device, a
 * recording, a co-processor frame). Unknown integer metadata is -1, unknown floats 0.
 */
struct sonar_record {
    int64_t utime;              /* us on the receiver's clock: since the epoch on a host, since boot on a board */
    uint16_t angle;             /* gradians 0..399 */
    uint16_t n;                 /* samples */
    int32_t gain;               /* 0 low, 1 normal, 2 high */
    int32_t sample_period;      /* 25 ns ticks */
    int32_t transmit_duration;  /* us */
    int32_t transmit_frequency; /* kHz */
    float speed_of_sound;       /* m/s */
    float range_m;              /* metres covered by the n samples */
    uint8_t stage;              /* enum sonar_stage (pipeline.h) */
    uint8_t has_pose;           /* 1: the vehicle's pose at utime below */
    float north_m, east_m;      /* local NED, metres */
    float yaw_deg;              /* heading, degrees clockwise from north */
    const uint8_t *samples;     /* n samples, borrowed: valid until the next call on their owner */
};

/* What the device did; kind is enum sonar_ping360_event_kind. */
struct sonar_device_event {
    int kind;
    struct sonar_record beam;   /* SONAR_P360_EV_BEAM: raw, no pose, utime 0 (the caller stamps its receive time) */
    uint32_t backoff_us;        /* SONAR_P360_EV_LINK_LOST: reconnect after this */
};

/*
 * The reconnect policy, one for host and firmware: after a loss, the transport is opened again
 * (sonar_device_up) after the driver's backoff (doubling to 5 s while nothing answers), or after
 * SONAR_DEVICE_RETRY_US when the driver has none yet; a probe that could not be sent because the
 * output was full is tried again after SONAR_DEVICE_SPACE_RETRY_US, any other send error after
 * SONAR_DEVICE_RETRY_US.
 */
#define SONAR_DEVICE_RETRY_US 1000000
#define SONAR_DEVICE_SPACE_RETRY_US 100000

struct sonar_device {
    struct sonar_ping_parser parser;
    struct sonar_ping360 drv;
    uint32_t backoff_us;   /* the delay before reconnecting after the last loss; 0 until one */
    int64_t reconnect_at;  /* when to open the transport again (us); 0: nothing pending */
};

/*
 * Sets up the parser and the driver (sonar_ping360_init: cfg copied, io kept by value). Returns
 * SONAR_OK, SONAR_ERR_ARG or SONAR_ERR_RANGE (no sample period of 80..40000 ticks gives the range
 * and samples). State: down.
 */
SONAR_CHECK int sonar_device_init(struct sonar_device *d, const struct sonar_ping360_config *cfg,
                                  const struct sonar_ping360_io *io);

/*
 * New acquisition settings on a running device: a fresh driver with the counters carried on,
 * probing again at now (us). Returns as sonar_device_init, or the probe's send error; on an
 * error other than a send error, nothing changes.
 */
SONAR_CHECK int sonar_device_reconfigure(struct sonar_device *d, const struct sonar_ping360_config *cfg, int64_t now);

/*
 * Feeds received bytes (advancing *in, decreasing *len) until the device has something to say.
 * Returns 1 with *ev filled (kind READY, BEAM, LINK_LOST or STOPPED; a beam's samples point into
 * the parser and live until the next call), or 0 when all the bytes are used. Call it again until
 * it returns 0. A request that could not be sent is retried by its timeout, not reported.
 */
SONAR_CHECK int sonar_device_bytes(struct sonar_device *d, const uint8_t **in, size_t *len, int64_t now,
                                   struct sonar_device_event *ev);

/* Runs the driver's timers at now (us). Returns 1 with *ev filled, as sonar_device_bytes, or 0. */
SONAR_CHECK int sonar_device_poll(struct sonar_device *d, int64_t now, struct sonar_device_event *ev);

/*
 * The transport opened: fresh framing (the counters carry on), then the probe. Returns SONAR_OK or
 * the send error (then sonar_device_reconnect_at says when to try again).
 */
SONAR_CHECK int sonar_device_up(struct sonar_device *d, int64_t now);

/*
 * The transport was lost: fresh framing; a driver that had not given up itself counts a
 * reconnect. Returns the reconnect delay in us (never 0): the one the driver gave with its
 * LINK_LOST, or its next backoff, or SONAR_DEVICE_RETRY_US when neither happened yet; the same
 * time is sonar_device_reconnect_at's.
 */
uint32_t sonar_device_down(struct sonar_device *d, int64_t now);

/*
 * When to open the transport again (us on the caller's clock), or 0 when nothing is pending: set
 * by a LINK_LOST event, sonar_device_down and a probe that could not be sent, by the policy above;
 * cleared when sonar_device_up's probe goes out. A UART that cannot be reopened calls
 * sonar_device_up then; a host reopens its socket or port with sonar_device_down's delay.
 */
int64_t sonar_device_reconnect_at(const struct sonar_device *d);

/* The Ping360's firmware version as probed (0.0.0 until then): fw[0] major, fw[1] minor, fw[2] patch. */
void sonar_device_firmware(const struct sonar_device *d, uint8_t fw[3]);

/* A record as the pipeline takes it (samples borrowed from r; a gain outside 0..255 becomes unknown, -1): host and firmware alike. */
struct sonar_beam; /* pipeline.h */
void sonar_device_beam(const struct sonar_record *r, struct sonar_beam *b);

/* The driver's settings as validated at init (read-only; sonar_device_set_gain changes the gain). */
const struct sonar_ping360_config *sonar_device_config(const struct sonar_device *d);

/* Samples per beam the driver asks for (its derived count, not cfg.samples' 0 for automatic). */
uint16_t sonar_device_samples(const struct sonar_device *d);

/* The gain (0 low, 1 normal, 2 high) of the next request. Returns SONAR_OK or SONAR_ERR_ARG. */
SONAR_CHECK int sonar_device_set_gain(struct sonar_device *d, int gain);

/* A scan planner choosing each stepping request's angle (struct sonar_ping360_io's next_angle; NULL: the driver's own sweep). */
void sonar_device_set_planner(struct sonar_device *d, uint16_t (*next_angle)(void *plan_user, int64_t now), void *plan_user);

/* When sonar_device_poll (or a reconnect) is due next (us); INT64_MAX when nothing is pending. */
int64_t sonar_device_deadline(const struct sonar_device *d);

/* Stops the head (motor_off; nothing in passive mode). Returns SONAR_OK or the send error; sonar_device_state says STOPPED when done. */
SONAR_CHECK int sonar_device_stop(struct sonar_device *d, int64_t now);

/* 1 when the device listens only (cfg.passive): another program drives the head. */
int sonar_device_passive(const struct sonar_device *d);

/* Where the driver is: an enum sonar_ping360_state (SONAR_P360_AUTO when the sonar streams by itself). */
int sonar_device_state(const struct sonar_device *d);

#endif
