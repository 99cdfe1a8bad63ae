/* ping360.h -- Ping360 driver state machine (probe, configure, sweep, retry, stop) with the clock and the transport injected; RAM: sizeof(struct sonar_ping360) = 168 B. */
#ifndef SONAR_PING360_H
#define SONAR_PING360_H

#include <stddef.h>
#include <stdint.h>

#include "sonar/err.h"
#include "sonar/ping.h"

/* All times are microseconds on a monotonic clock the caller reads; no OS calls are made here. */

#define SONAR_P360_GRAD_US 6000u /* the head's travel, us a gradian (ping.md: Ping Viewer's 2.4 s a turn) */

enum sonar_ping360_state {
    SONAR_P360_DOWN = 0,     /* no link: the host must (re)connect, then call sonar_ping360_connected */
    SONAR_P360_CONNECTING = 1, /* host only: the transport is opening (the driver stays DOWN meanwhile) */
    SONAR_P360_PROBING = 2,  /* waiting for device_information */
    SONAR_P360_SCANNING = 3, /* stepping: one transducer request per beam */
    SONAR_P360_AUTO = 4,     /* the device streams auto_device_data */
    SONAR_P360_STOPPING = 5, /* motor_off sent, waiting for its ack */
    SONAR_P360_STOPPED = 6,
    SONAR_P360_PASSIVE = 7   /* listen-only: another program drives the head; every reply is used */
};

struct sonar_ping360_config {
    float range_m;              /* 1..60 */
    float speed_of_sound;       /* m/s, 1300..1700 */
    uint16_t samples;           /* 200..1200, or 0 for the most the range allows (Ping Viewer's rule) */
    uint16_t transmit_duration; /* us, 5..500, or 0 for the automatic rule (geometry.h) */
    uint8_t gain;               /* 0 low, 1 normal, 2 high */
    uint16_t frequency;         /* kHz, 500..1000 */
    uint16_t start_angle;       /* gradians 0..399 */
    uint16_t stop_angle;        /* gradians 0..399; a sector is start -> stop going up (mod 400) */
    uint8_t step;               /* gradians per beam, 1..50 (1..10 with auto_transmit) */
    uint8_t full_circle;        /* 1: full turns from start_angle (stop ignored); 0: back and forth */
    uint8_t use_auto;           /* 1: auto_transmit when the firmware is newer than 3.3.0 */
    uint32_t baud;              /* serial bit rate, for the transfer time in the timeout; 0 = network */
    uint8_t passive;            /* 1: never command the head; use the replies another program draws */
};

/*
 * The transport, provided by the caller. send returns 0 or < 0; line_break may be NULL.
 * next_angle (may be NULL: the driver steps its sector itself) chooses each stepping request's
 * angle, gradians (taken mod 400), when scanning starts and after each beam, at now (us); a scan
 * planner (scan.h) behind it. It is not asked in auto_transmit mode: the device steps itself.
 */
struct sonar_ping360_io {
    int (*send)(void *user, const uint8_t *buf, size_t len);
    void (*line_break)(void *user);
    void *user;
    uint16_t (*next_angle)(void *plan_user, int64_t now);
    void *plan_user;
};

struct sonar_ping360_counters {
    uint32_t timeouts;   /* replies that did not come in time */
    uint32_t retries;    /* requests sent again */
    uint32_t nacks;      /* NACKs received */
    uint32_t reconnects; /* links declared lost */
    uint32_t beams;      /* beams delivered */
    uint32_t off_angle;  /* replies for another angle than requested (late or duplicate) */
    uint32_t foreign;    /* frames of another device on the link (a Ping1D behind the same bridge), ignored */
    uint32_t hellos;     /* passive: device_information requests sent so a bridge relays to us (none move the head) */
    uint32_t idles;      /* passive: times the beams stopped for SONAR_P360_IDLE_US (the driving program quiet) */
};

#define SONAR_P360_IDLE_US 1500000u  /* passive: no beam for this long is idle (said within 2 s) */
#define SONAR_P360_HELLO_US 1000000u /* passive: a device_information request when nothing came for this long */

enum sonar_ping360_event_kind {
    SONAR_P360_EV_NONE = 0,
    SONAR_P360_EV_READY = 1,     /* probe answered: firmware known, scanning started */
    SONAR_P360_EV_BEAM = 2,      /* ev->data holds a beam (data points into the frame) */
    SONAR_P360_EV_LINK_LOST = 3, /* give up on this link: reconnect after ev->backoff_us */
    SONAR_P360_EV_STOPPED = 4,   /* motor_off acknowledged (or given up on) */
    SONAR_P360_EV_IDLE = 5       /* passive: no beam for SONAR_P360_IDLE_US (the next beam ends it) */
};

struct sonar_ping360_event {
    int kind;
    struct sonar_ping360_data data;
    uint32_t backoff_us;
};

struct sonar_ping360 {
    struct sonar_ping360_config cfg;
    struct sonar_ping360_io io;
    struct sonar_ping360_counters counters;
    struct sonar_ping_device_info info;
    int64_t deadline;      /* when the pending request times out; INT64_MAX when none */
    int64_t sent_at;       /* when the pending request went out */
    int64_t last_rx;       /* last reply of any kind */
    uint32_t expected_us;  /* modelled time of one beam (reply latency) */
    uint32_t observed_us;  /* moving average of measured beam latencies, 0 until the first */
    uint32_t backoff_us;   /* next reconnect delay (doubles to 5 s) */
    uint16_t sample_period; /* ticks */
    uint16_t samples;
    uint16_t tx_us;
    uint16_t angle;        /* requested */
    uint16_t from;         /* the angle of the beam before: the head travels from there */
    uint16_t pos;          /* position in the sector, gradians from start */
    uint16_t span;         /* sector length in gradians */
    int8_t dir;            /* +1 / -1 while bouncing in a sector */
    uint8_t state;
    uint8_t attempts;      /* consecutive timeouts of the pending request */
    uint8_t nack_run;      /* consecutive NACKs */
    uint8_t have_info;
    uint8_t idle;          /* passive: no beam for SONAR_P360_IDLE_US */
    int64_t last_beam;     /* passive: when the last beam came (or the link opened) */
    int64_t last_hello;    /* passive: when the last request went out */
};

/* NULL when cfg is valid, else a static "field: rule" string naming the first bad field. cfg must not be NULL. */
const char *sonar_ping360_config_check(const struct sonar_ping360_config *cfg);

/* The state's name: "down", "connecting", "probing", "scanning", "auto", "stopping", "stopped", "passive"; never NULL. */
const char *sonar_ping360_state_str(int state);

/*
 * Validates cfg (copied) and derives sample period, samples and transmit duration. Returns
 * SONAR_OK, SONAR_ERR_ARG (NULL, or a value outside the ranges above) or SONAR_ERR_RANGE (the
 * range and sample count give a period outside 80..40000 ticks). State: DOWN.
 */
SONAR_CHECK int sonar_ping360_init(struct sonar_ping360 *d, const struct sonar_ping360_config *cfg,
                                   const struct sonar_ping360_io *io);

/*
 * The host opened the link: probe the device. Passive (cfg.passive): state PASSIVE and one
 * device_information request, which a bridge takes as a client's hello; nothing else is ever sent.
 * Returns SONAR_OK or the send error.
 */
SONAR_CHECK int sonar_ping360_connected(struct sonar_ping360 *d, int64_t now);

/* The host lost the link (TCP closed, serial unplugged): state DOWN, one reconnect counted. */
void sonar_ping360_link_lost(struct sonar_ping360 *d, int64_t now);

/*
 * Feeds one received frame. Fills *ev (kind NONE when nothing happened for the caller) and
 * sends the next request when a beam completes. Returns SONAR_OK or a send error.
 */
SONAR_CHECK int sonar_ping360_handle(struct sonar_ping360 *d, const struct sonar_ping_frame *f, int64_t now,
                                     struct sonar_ping360_event *ev);

/*
 * Runs the timers: a request past its deadline is sent again (or the link given up after
 * several). Fills *ev. Returns SONAR_OK or a send error. sonar_ping360_deadline tells when to
 * call it next.
 */
SONAR_CHECK int sonar_ping360_poll(struct sonar_ping360 *d, int64_t now, struct sonar_ping360_event *ev);

/* When the next call to sonar_ping360_poll is due; INT64_MAX when nothing is pending. */
int64_t sonar_ping360_deadline(const struct sonar_ping360 *d);

/* Stops the head: motor_off (after a line break in auto mode), then waits for its ack. */
SONAR_CHECK int sonar_ping360_stop(struct sonar_ping360 *d, int64_t now);

/*
 * The device's timing model (ping.md, section 3), in us: 19.4 ms + 6 ms per gradian stepped (step
 * 0 counts as 1) + 2R/c (range_m metres, speed_of_sound m/s, > 0) + the serial transfer of request
 * and reply at baud bits/s (0: no transfer counted, e.g. UDP or a recording whose transport is unknown).
 */
uint32_t sonar_ping360_model_us(unsigned step, float range_m, float speed_of_sound, uint32_t baud, uint16_t samples);

/* Modelled beam time in us of d's settings: sonar_ping360_model_us at its step, range, c, baud and samples. */
uint32_t sonar_ping360_beam_time_us(const struct sonar_ping360 *d);

#endif
