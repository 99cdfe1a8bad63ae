/* options.h -- sonard's options: one schema table (options.c) gives the command line, the config-file keys, --help and docs/configuration.md; sizeof(struct sonard_options) = 12 560 B, most of it the string pool. */
#ifndef SONARD_OPTIONS_H
#define SONARD_OPTIONS_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "herr.h"
#include "optschema.h"
#include "sonar/ping360.h"
#include "sonar/gain.h"
#include "sonar/pipeline.h"

#define OPTIONS_MAX_CONFIGS 8

#define SONARD_MAX_IGNORE 8 /* --ignore-deg arcs (obsmap.h OBSMAP_MAX_IGNORE) */

struct sonard_options {
    const char *replay;         /* CSV file, "-" for stdin */
    const char *pose_file;      /* replay: the vehicle's poses, utime_us,north_m,east_m,yaw_deg */
    const char *pose_lcm;       /* live: SONAR_POSE on an LCM of its own (else sonard's --lcm) */
    const char *sonar;          /* live: serial:PATH[:BAUD] | udp:HOST:PORT | tcp:HOST:PORT */
    const char *coprocessor;    /* the firmware's host link, same URL forms */
    long coproc_beams;          /* ask the firmware for every Nth raw beam; 0 = none */
    const char *mavlink;        /* the autopilot: udpin:ADDR:PORT | udpout:HOST:PORT | serial:PATH[:BAUD] */
    long mav_sysid, mav_compid, mav_autopilot; /* sysid 0: the autopilot's; autopilot 0: the first heard */
    float mav_rate;             /* OBSTACLE_DISTANCE messages a second */
    float mav_pose_rate;        /* ATTITUDE and LOCAL_POSITION_NED asked of the autopilot; 0: never ask */
    uint8_t mav_fail_closed;    /* no OBSTACLE_DISTANCE without a beam for a second */
    uint8_t mav_3d;             /* OBSTACLE_DISTANCE_3D per confirmed track */
    uint8_t track_late;         /* the sinks get each sweep one sweep late, revised (app_set_track_late) */
    uint8_t n_ignore;           /* --ignore-deg arcs, degrees clockwise from forward: from, to */
    float ignore[SONARD_MAX_IGNORE][2];
    int discover;               /* list the network's Ping360s and exit */
    const char *discover_to;    /* NULL: broadcast 255.255.255.255:30303 */
    double discover_s;
    long discover_data_port;
    const char *csv_out;        /* export / recording file */
    const char *bg_load;        /* a recorded background to start from (bgstore.h) */
    const char *bg_save;        /* where the learnt background is written at exit */
    const char *survey;         /* the site's survey file (survey = PATH): loaded at start when it exists */
    long survey_sweeps;         /* --survey N: record N sweeps of the empty site into it, then exit; 0 = no */
    const char *lcm_url;        /* NULL: LCM's default ($LCM_DEFAULT_URL, else udpm ttl=0) */
    const char *channel_prefix; /* prepended to every channel; "" by default */
    uint8_t stage;              /* enum sonar_stage exported to csv_out (replay) */
    double replay_speed;        /* replay: 0 at once, else this multiple of the recorded pace */
    double beam_ms;             /* replay: time between untimed rows; 0 = the device model */
    double range_m;             /* < 0: replay takes it from the CSV metadata, else 2 m */
    double speed_of_sound;      /* m/s */
    long baud;                  /* serial: bits/s; 0 = from the URL or 115200; -1 = auto */
    long sweeps;                /* stop after this many sweeps; 0 = run until signalled */
    int json;
    int quiet;                  /* no per-sweep text report */
    int passive;                /* --passive: copied into device.passive by the whole-options check */
    uint8_t log_level;          /* enum app_level: diagnostics at or below it go to stderr */
    int publish_filtered;
    uint8_t obstacles;          /* SONAR_OBSTACLES on LCM */
    int no_lcm;
    int control;                /* --control: SONAR_CONTROL commands taken (control.h) */
    struct sonar_ping360_config device;
    struct sonar_pipeline_config pipeline;
    struct sonar_scan_config scan; /* mode, revisit_s, surveil_s; the sector and timing come from device */
    int gain_auto;              /* --gain auto: device.gain is where it starts */
    struct sonar_gain_config gain_rules; /* --gain auto's thresholds (sonar_gain_defaults) */
    struct opt_given given;     /* one bit per schema row applied (file or command line) */
    const char *configs[OPTIONS_MAX_CONFIGS]; /* --config files in order, re-read on SIGHUP */
    int nconfigs;
    char pool[8192];            /* values read from config files; string fields may point into it */
};

/* The schema: sonard's option table. */
const struct opt_schema *options_schema(void);

/*
 * Fills defaults, reads every --config FILE in order (key = value lines, keys being long option
 * names), then argv, which overrides the files, then checks the result as a whole (each core
 * config's check names the failing field). Returns 0 to run, 1 when --help/--version was handled
 * (printed to stdout), or HOST_ERR_CONFIG / HOST_ERR_IO with err naming the option or file:line.
 */
/* Names on f each config-file key options_parse skipped (a newer or older version's, or a slip), once each. */
void options_say_unknown(const struct sonard_options *o, FILE *f);

HOST_CHECK int options_parse(int argc, char **argv, struct sonard_options *o, char *err, size_t errlen);

/* Whether the option named (its long name) was given, on the command line or in a --config file. */
int options_given(const struct sonard_options *o, const char *name);

/* The option that gives the vehicle's pose, so that the sonar moves (the world frame): "--pose", "--mavlink",
   "--pose-lcm", or NULL when none does (a fixed site). */
const char *options_moving(const struct sonard_options *o);

/* The Markdown option reference (docs/configuration.md is generated from it). */
void options_markdown(FILE *f);

#endif
