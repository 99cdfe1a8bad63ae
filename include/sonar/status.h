/* status.h -- the health record both ends report (SONAR_STATUS): counters of the device, the pipeline, the tracker, the pose and the co-processor link, one meaning each; RAM: struct sonar_status (docs/sizes.md). */
#ifndef SONAR_STATUS_H
#define SONAR_STATUS_H

#include <stdint.h>

#include "sonar/device.h"
#include "sonar/pipeline.h"

enum sonar_pose_state { SONAR_POSE_NONE = 0, SONAR_POSE_OK = 1, SONAR_POSE_STALE = 2 };

struct sonar_status {
    int64_t utime;
    int link_state;                        /* enum sonar_ping360_state (SONAR_P360_CONNECTING included) */
    const char *link;                      /* "tcp:127.0.0.1:5000", "replay:FILE", "coprocessor:uart0"; borrowed */
    uint8_t fw[3];                         /* the Ping360's firmware version, 0.0.0 until probed */
    struct sonar_ping_counters parser;     /* every parser counter */
    struct sonar_ping360_counters driver;  /* every driver counter */
    uint32_t sweeps;
    uint32_t beams_rejected;               /* beams the pipeline refused (bad geometry) */
    uint32_t blank_beams;                  /* beams skipped: every sample 0 or every one 255 (pipeline.h) */
    uint32_t interference_beams;           /* beams judged interference streaks (streak.h) */
    uint32_t rows_bad;                     /* replay: malformed rows skipped */
    uint32_t sink_errors;                  /* host sink calls that failed, all sinks */
    float last_sweep_s;                    /* seconds the last sweep took */
    float beam_us_p50, beam_us_p99;        /* per-beam processing time */
    uint32_t stack_used;                   /* co-processor: stack high-water mark, bytes; 0 on the host */
    struct {
        uint32_t live, ended, bad_detections, clock_back, overflow;
        uint32_t dropped, out_of_order;    /* detections past SONAR_MAX_CLUSTERS a sweep; older than the last sweep */
        uint32_t revisions, hyp_overflow;  /* IDs a later look revised; alternatives that did not fit (final at once) */
        uint32_t activity_unplaced;        /* track-looks that found every activity slot taken (their activity unknown) */
        struct sonar_clutter_summary clutter; /* the site's clutter map at a glance (clutter.h); zeros without one */
        const struct sonar_clutter *map;   /* ... and the map itself (the pipeline's), NULL: none or no look yet */
    } tracker;                             /* all 0 with tracking off */
    struct {
        int state;                         /* enum sonar_pose_state, at the latest beam */
        uint32_t accepted, out_of_order, jumps, bad, thinned; /* the ring's counters */
        uint32_t stale;                    /* times the pose went stale (none within 1 s of a beam) */
        uint32_t world_sweeps, body_sweeps; /* sweeps tracked in each frame */
    } pose;
    struct {
        uint32_t rx_crc_errors;            /* host frames the firmware dropped for their CRC */
        uint32_t tx_dropped;               /* frames the firmware's host link could not take */
        uint32_t config_refused;           /* configurations the firmware refused */
        uint32_t frames_bad;               /* firmware frames the host dropped (CRC or undecodable) */
    } coproc;                              /* all 0 without a co-processor */
    struct {
        uint32_t sysid;                    /* the autopilot's system id, 0 until its HEARTBEAT is heard */
        float pose_hz;                     /* ATTITUDE messages a second from it, over the last 2 s */
        uint32_t interval_requests;        /* MAV_CMD_SET_MESSAGE_INTERVAL sent (ATTITUDE, LOCAL_POSITION_NED) */
        uint32_t interval_refused;         /* ... answered with a COMMAND_ACK other than accepted */
        uint32_t acks_other;               /* COMMAND_ACKs for commands we did not send */
        uint32_t pose_held;                /* 1: the obstacle map uses the last pose, the pose being stale */
        uint32_t od_sent;                  /* OBSTACLE_DISTANCE sent */
        uint32_t od_withheld;              /* ... not sent: no beam for a second (fail closed) */
        uint32_t rx_other;                 /* messages from other systems and components, ignored */
    } autopilot;                           /* all 0 without --mavlink */
    struct {
        int gain;                          /* the gain asked: 0 low, 1 normal, 2 high */
        int gain_auto;                     /* 1 while --gain auto chooses it */
        uint32_t gain_changes;             /* changes made by auto gain */
        uint32_t gain_refused;             /* changes the sonar did not take (auto gain then off) */
        uint32_t background_restarts;      /* backgrounds restarted at every angle: the beams' gain changed */
    } acq;
    struct {
        int mode;                          /* enum sonar_scan_mode */
        uint32_t interleave;               /* follow: a grid angle every this many passes */
        uint32_t target_pings, surveil_pings, late_looks, targets_dropped; /* struct sonar_scan_counters */
    } scan;                                /* all 0 in sweep mode */
    struct {
        uint32_t places, learnt;           /* places seen now (structure.h) and those learnt as structure */
        uint32_t promoted, detections, restarts; /* its counters since the start */
    } structure;                           /* all 0 with --structure-s 0 */
    struct {
        int state;                         /* enum sonar_survey_state: none (learning), in use, unfit (learning) */
        int why;                           /* enum sonar_survey_why, while unfit */
        int fixed;                         /* 1: a recorded survey; 0: a learnt model learnt on from */
        int64_t utime;                     /* when it was recorded (its last beam), us since the epoch */
        uint32_t sweeps;                   /* sweeps it was recorded over */
        int turn_grad;                     /* unfit for a turn: the turn estimated, gradians */
        uint32_t unfits;                   /* times it was given up since the start */
        uint32_t agree16, standout1000;    /* the last sweep's agreement (16ths) and stand-out (thousandths) */
        uint32_t nplaces;                  /* its structure places ... */
        const struct sonar_detection *places; /* ... borrowed from the survey, NULL with none */
    } survey;                              /* state 0 and the rest 0 with no survey */
    struct {
        int on;                            /* 1: listen-only (--passive): another program drives the head */
        int idle;                          /* 1: no beam for SONAR_P360_IDLE_US */
        int samples;                       /* the driving program's settings, from its latest beam ... */
        float range_m;                     /* ... (the gain is acq.gain) */
        uint32_t changes;                  /* its changes of range, samples or gain, said and counted */
    } passive;                             /* all 0 when sonard drives the head */
    struct {
        int on;                            /* 1: commands are taken (sonard --control) */
        uint32_t seq;                      /* the last command handled (its seq), 0 none yet */
        int result;                        /* enum sonar_control_result of that command */
        const char *said;                  /* why it was refused, or what it did; borrowed, "" none */
        int rec;                           /* enum sonar_control_rec: a survey recorded while running */
        uint32_t rec_sweeps, rec_of;       /* its sweeps so far, of those asked for */
        const char *rec_said;              /* its end: where written, or why refused; borrowed, "" none */
    } control;                             /* all 0 without --control (the host's: a co-processor has none) */
};

enum sonar_control_result { SONAR_CONTROL_NONE = 0, SONAR_CONTROL_TAKEN = 1, SONAR_CONTROL_REFUSED = 2 };
enum sonar_control_rec {
    SONAR_CONTROL_REC_NONE = 0,      /* none asked for since the start */
    SONAR_CONTROL_REC_RECORDING = 1, /* recording: rec_sweeps of rec_of */
    SONAR_CONTROL_REC_WRITTEN = 2,   /* written and in use (rec_said: where) */
    SONAR_CONTROL_REC_REFUSED = 3,   /* refused, nothing written (rec_said: why) */
    SONAR_CONTROL_REC_CANCELLED = 4, /* cancelled by a command, nothing written */
    SONAR_CONTROL_REC_FAILED = 5     /* kept, but the write or the load failed (rec_said: why; the old file whole) */
};

/*
 * Fills the device's and the pipeline's part of *s: fw, parser, driver (from dev, or left as they
 * are when dev is NULL), the tracker's counters, the sweeps per frame, the beams' gain and the
 * backgrounds a change of it restarted (from p, initialised, or NULL for the device's part alone).
 * Other fields are left as they are.
 */
void sonar_status_fill(struct sonar_status *s, const struct sonar_device *dev, const struct sonar_pipeline *p);

/* The survey's part (s->survey) from sv: left as it is with none (NULL, or no survey). */
void sonar_status_survey(struct sonar_status *s, const struct sonar_survey *sv);

/* The pose ring's counters (accepted, out of order, jumps, bad, thinned) into s->pose; the rest of s->pose is left. */
struct sonar_pose_ring; /* pose.h */
void sonar_status_poses(struct sonar_status *s, const struct sonar_pose_ring *r);

/* The tracker's counters (when p tracks) and the sweeps tracked per frame, from p: the part of sonar_status_fill that follows
   the tracker, for a host whose tracks come from its own pipeline while the rest of the record comes from a co-processor. */
void sonar_status_tracking(struct sonar_status *s, const struct sonar_pipeline *p);

#endif
