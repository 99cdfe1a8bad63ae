/* feed.h -- sonar-feed, a simulated Ping360, split by job: the device (feed_device.c), its faults (feed_faults.c), its transports (feed_transport.c), the vehicle's autopilot (feed_autopilot.c), discovery (feed_discovery.c) and the options and loop (feed_main.c); one struct feed. */
#ifndef SONAR_FEED_H
#define SONAR_FEED_H

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>
#include <arpa/inet.h>

#include "csv.h"
#include "discover.h"
#include "optschema.h"
#include "ardupilotmega/mavlink.h"
#include "scene.h"
#include "sonar/frame.h"
#include "sonar/geometry.h"
#include "sonar/ping.h"
#include "sonar/sweep.h"

enum { T_TCP, T_UDP, T_PTY };

struct recording {
    uint8_t (*rows)[SONAR_MAX_SAMPLES];
    uint16_t *angle;
    uint32_t *sweep_start; /* first row of each sweep */
    uint32_t rows_n, sweeps;
    uint16_t n;
    double range_m;
};

struct feed {
    /* options */
    int transport;
    char host[64];
    int port;
    const char *pty_link;
    const char *log_path;
    int device_pace;
    double pace_speedup; /* --pace xN: the device's timing N times faster (1: as the device) */
    double drop, corrupt, garbage;
    double ping1d;  /* probability that a Ping1D's frame (a bridge's other device) precedes a reply */
    long disconnect_after, stall_at, drop_at;
    long disconnect_every, stall_every, max_beams; /* soak: faults every N replies; exit after N intact beams */
    double stall_s, max_s;
    const char *scene_name, *csv_path;
    double csv_range;
    int exit_after_motor_off;
    uint8_t fw[3];
    struct scene scene;
    int use_scene;
    struct recording rec;
    /* state */
    int lfd, cfd; /* listening socket (TCP), connection / UDP socket / pty master */
    struct sockaddr_in peer;
    int have_peer;
    struct sonar_ping_parser parser;
    struct sonar_sweep sweep;
    struct scene_rng rng, fault_rng;
    /* device settings, as the last command set them */
    uint8_t gain;
    uint16_t angle, tx, sp, freq, n;
    double c;
    /* a pending reply */
    uint8_t out[2 * 1300];
    size_t out_len;
    double due;
    /* auto-transmit */
    int streaming;
    uint16_t a_start, a_stop, a_step;
    int a_dir;
    /* counters */
    long ping1d_frames;
    long replies, dropped, corrupted, garbage_runs, disconnects, stalls, motor_offs, requests, nacks_sent, beams;
    int stop_after;
    double stop_at;
    int out_is_beam;   /* the pending reply is device_data / auto_device_data */
    long beams_intact; /* beam replies sent whole and uncorrupted */
    long last_fault;   /* reply number of the last periodic stall (it is not counted twice) */
    FILE *log;
    /* the vehicle's autopilot (--mavlink udpout:HOST:PORT): a pose every 50 ms */
    const char *mavlink;
    int mfd;
    mavlink_status_t mstatus;
    double scene_t0;    /* when the first beam was served: the scene's clock starts then (a vehicle's path is timed) */
    long gain_ref;      /* --gain-model G: the setting the scene is drawn at; each step up doubles the echoes (saturating at 255), each down halves them; -1: off */
    int gain_fixed;     /* --gain-fixed: keep the first gain asked, whatever later requests say (a refusal) */
    int empty;          /* --empty: the scene with nobody in it (walls, ropes, structure): a site to survey */
    int as_recorded;    /* --samples-as-recorded: a recording's rows as they are, whatever is asked */
    int arrive;         /* --arrive-at-motor-off: empty until the first motor_off, then `full` from sweep 0 */
    struct scene full;  /* the scene as made, held while --arrive-at-motor-off keeps it empty */
    int gain_set;
    uint8_t wall_clock; /* --scene-clock wall: timed objects move on the wall clock, whatever the order of requests */
    const char *truth_path; /* --truth: the scene's objects every 0.1 s and each beam served, JSON lines */
    FILE *truth;
    double truth_next;  /* scene seconds of the next objects line */
    double next_pose;   /* the earliest of the three below */
    long poses_sent;
    double next_hb, next_att, next_pos; /* HEARTBEAT each second; ATTITUDE, LOCAL_POSITION_NED at their intervals */
    double att_s, pos_s;                /* the intervals, seconds (--mavlink-rate, then SET_MESSAGE_INTERVAL); 0: off */
    double mav_rate0;                   /* --mavlink-rate: the streams' rate at the start, Hz */
    int mav_refuse;                     /* --mavlink-refuse: answer SET_MESSAGE_INTERVAL with MAV_RESULT_DENIED */
    long intervals_set, intervals_refused, acks_sent;
    mavlink_message_t mrx_buf, mrx_msg;
    mavlink_status_t mrx_status, mrx_rstatus;
    /* discovery (--discovery udp:127.x.x.x:PORT): answers "Discovery" as the device does */
    char disc_host[64];
    int disc_port, dfd;
    uint8_t mac[6];
    const char *claim_ip;  /* the address the reply claims; the --listen host by default */
    long discoveries;
};

/* feed_transport.c: the clock, the event log, the link to sonard (TCP, UDP, a pty). */
double feed_now(void);
void feed_log(struct feed *f, const char *fmt, const char *what, long v);
int feed_setup(struct feed *f);
int feed_send_bytes(struct feed *f, const uint8_t *b, size_t n);
void feed_close_client(struct feed *f);
int feed_open_pty(struct feed *f);

/* feed_device.c: the Ping360 -- a recording or a scene rendered per beam, the protocol answered at the device's pace. */
int feed_load_csv(struct recording *r, const char *path, double range_m);
void feed_render(struct feed *f, uint16_t a, uint8_t *out, uint16_t *n, uint16_t *sp);
void feed_queue(struct feed *f, uint16_t id, const uint8_t *payload, uint16_t len, double delay);
double feed_beam_time(const struct feed *f, uint16_t from, uint16_t to);
void feed_queue_beam(struct feed *f, uint16_t a, int is_auto, double delay);
void feed_auto_next(struct feed *f, double delay);
void feed_handle_frame(struct feed *f, const struct sonar_ping_frame *fr);

/* feed_faults.c: the pending reply sent through the fault injector (stalls, disconnects, drops, garbage, corruption). */
void feed_flush_reply(struct feed *f);

/* feed_autopilot.c: the scene's vehicle as its autopilot reports it over MAVLink; it honours SET_MESSAGE_INTERVAL. */
int feed_open_mavlink(struct feed *f);
void feed_autopilot(struct feed *f, double now);

/* feed_discovery.c: Ping Viewer's UDP discovery answered as the device does. */
void feed_answer_discovery(struct feed *f);

#endif
