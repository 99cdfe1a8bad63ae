/* options.c -- sonard's option table: every option once, with its field, range, unit, default and help, and its parsing (option values of their own form: options_values.c; the whole config's checks: options_check.c); no heap. */
#include "options.h"
#include "options_internal.h"
#include "version.h"
#include "app.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define F(field) offsetof(struct sonard_options, field)
#define D(field) offsetof(struct sonard_options, pipeline.detector.field)
#define B(field) offsetof(struct sonard_options, pipeline.background.field)
#define V(field) offsetof(struct sonard_options, device.field)
#define P(field) offsetof(struct sonard_options, pipeline.field)
#define T(field) offsetof(struct sonard_options, pipeline.tracker.field)
/* Rows: name, metavariable, type, in files, on SIGHUP, offset, lo, hi, unit, default, help, choices, parser */
#define SECTION(title) {title, NULL, OPT_SECTION, 0, 0, 0, 0, 0, NULL, NULL, NULL, NULL, NULL}


static const struct opt_spec spec[] = {
    SECTION("live"),
    {"sonar", "URL", OPT_CUSTOM, 1, 0, 0, 0, 0, "serial:PATH[:BAUD] | udp:HOST:PORT | tcp:HOST:PORT | blueos[:HOST[:PORT]]", NULL,
     "the Ping360 to drive (Ethernet Ping360: UDP 12345;\nBlueOS serial bridge: UDP 9092; blueos: the one BlueOS's\nping service on HOST:PORT (127.0.0.1:9110) names)", NULL, options_parse_sonar},
    {"baud", "N|auto", OPT_CUSTOM, 1, 0, 0, 0, 0, "bits/s 1200..4000000, or auto", "115200",
     "serial bit rate; auto tries Ping Viewer's list after a line break", NULL, options_parse_baud},
    {"passive", NULL, OPT_FLAG, 1, 0, F(passive), 0, 0, NULL, "off",
     "listen only: use the beams another program (Ping Viewer)\ndraws through a bridge; command nothing", NULL, NULL},
    {"mode", "step|auto", OPT_CHOICE, 1, 0, V(use_auto), 0, 0, "step or auto", "step",
     "step: one transducer request per beam; auto: auto_transmit\nwhen the firmware is newer than 3.3.0, else step",
     "step=0|auto=1", NULL},
    {"sector", "START:STOP", OPT_CUSTOM, 1, 0, 0, 0, 0, "START:STOP gradians 0..399, or full", "full",
     "swept back and forth from START up to STOP (mod 400); full: full turns", NULL, options_parse_sector},
    {"step", "G", OPT_U8, 1, 0, V(step), 1, 50, "gradians", "1", "gradians per beam (at most 10 in auto mode)", NULL, NULL},
    {"gain", "G|auto", OPT_CUSTOM, 1, 0, 0, 0, 0, "0 low, 1 normal, 2 high, or auto", "0",
     "receiver gain; auto: from normal, lowered when a sweep saturates, raised\nwhen its median sits at the bottom of the scale (SONAR_STATUS)", NULL, options_parse_gain},
    {"scan", "sweep|follow", OPT_CHOICE, 1, 0, F(scan.mode), 0, 0, "sweep or follow", "sweep",
     "sweep: the sector in order; follow: passes one way round that look at\nevery tracked target each pass and at the rest in turns (step mode)",
     "sweep=0|follow=1", NULL},
    {"revisit", "S", OPT_F32, 1, 0, F(scan.revisit_s), 0.2, SONAR_SCAN_REVISIT_MAX_S, "seconds", "1.5",
     "follow: the revisit wanted; looks at a target later than this are counted", NULL, NULL},
    {"surveil", "S", OPT_F32, 1, 0, F(scan.surveil_s), 0, SONAR_SCAN_REVISIT_MAX_S, "seconds (0 = twice a plain sweep)", "0",
     "follow: no angle of the sector left unpinged longer than this", NULL, NULL},
    {"frequency", "F", OPT_U16, 1, 0, V(frequency), 500, 1000, "kHz", "750", "transmit frequency", NULL, NULL},
    {"samples", "N", OPT_U16, 1, 0, V(samples), 200, 1200, "samples", "the most the range allows", "samples per beam", NULL, NULL},
    {"transmit-duration", "U|auto", OPT_CUSTOM, 1, 0, 0, 0, 0, "us 5..500, or auto", "auto",
     "transmit pulse length; auto: Ping Viewer's rule, 8000 R / c us, at least\n2.5 sample periods, within 5..500 (geometry.h)", NULL, options_parse_tx},
    {"sweeps", "N", OPT_LONG, 1, 0, F(sweeps), 1, 1e9, "sweeps", "run until SIGINT/SIGTERM", "stop (motor_off) after N sweeps", NULL, NULL},
    {"lcm", "URL", OPT_STR, 1, 0, F(lcm_url), 0, 0, "LCM URL", "LCM's own: $LCM_DEFAULT_URL, else udpm ttl=0",
     "LCM provider; file:///path.lcm?mode=w writes a log; a --replay publishes\nonly when this is given", NULL, NULL},
    {"channel-prefix", "P", OPT_STR, 1, 0, F(channel_prefix), 0, 30, "text", "none",
     "prepended to SONAR_BEAM, SONAR_DETECTIONS, SONAR_STATUS (several sonars)", NULL, NULL},
    {"publish-filtered", NULL, OPT_FLAG, 1, 0, F(publish_filtered), 0, 0, NULL, "off",
     "also publish foreground beams on SONAR_BEAM_FILTERED", NULL, NULL},
    {"obstacles", "on|off", OPT_CHOICE, 1, 0, F(obstacles), 0, 0, "on or off", "on",
     "publish the obstacle map on SONAR_OBSTACLES (the ROS 2 scan); without\n--mavlink it is sonard's own map, about as costly as the rest of sonard", "off=0|on=1", NULL},
    {"control", NULL, OPT_FLAG, 1, 0, F(control), 0, 0, NULL, "off",
     "take commands on SONAR_CONTROL (record the site's survey, cancel it),\nanswered on SONAR_STATUS: anyone on the LCM bus may send them", NULL, NULL},
    {"no-lcm", NULL, OPT_FLAG, 1, 0, F(no_lcm), 0, 0, NULL, "off", "publish nothing (JSON / CSV only)", NULL, NULL},
    {"csv-out", "FILE", OPT_STR, 1, 0, F(csv_out), 0, 0, "file", NULL,
     "record beams in the study's CSV plus metadata columns (live: raw;\nreplay: the --stage)", NULL, NULL},
    {"config", "FILE", OPT_ACTION, 0, 0, 0, 0, 0, "file", NULL,
     "key = value lines, keys as the long options; several apply in order,\nflags override them; re-read on SIGHUP", NULL, NULL},
    SECTION("discovery (Ethernet Ping360s)"),
    {"discover", NULL, OPT_FLAG, 0, 0, F(discover), 0, 0, NULL, "off",
     "list the Ping360s on the network (\"Discovery\" to UDP 30303, as Ping Viewer\ndoes): address, MAC, firmware; then exit", NULL, NULL},
    {"discover-to", "IP:PORT", OPT_STR, 0, 0, F(discover_to), 0, 40, "IPv4:PORT", "255.255.255.255:30303 (broadcast)",
     "where to send the probe (one device, or a test's sonar-feed)", NULL, NULL},
    {"discover-seconds", "S", OPT_F64, 0, 0, F(discover_s), 0.2, 60, "seconds", "2", "how long to listen for replies", NULL, NULL},
    {"discover-data-port", "PORT", OPT_LONG, 0, 0, F(discover_data_port), 1, 65535, "UDP port", "12345",
     "the devices' Ping Protocol port, asked for their firmware", NULL, NULL},
    SECTION("co-processor (docs/coprocessor.md)"),
    {"coprocessor", "URL", OPT_CUSTOM, 1, 0, 0, 0, 0, "serial:PATH[:BAUD] | udp:HOST:PORT | tcp:HOST:PORT", NULL,
     "the co-processor's host link: push these options to its firmware,\nrepublish its detections and status", NULL, options_parse_coprocessor},
    {"coprocessor-beams", "N", OPT_LONG, 1, 0, F(coproc_beams), 0, 1000, "beams (0 = none)", "0",
     "ask the firmware for every Nth raw beam (SONAR_BEAM, --csv-out)", NULL, NULL},
    SECTION("autopilot (MAVLink, docs/mavlink.md)"),
    {"mavlink", "URL", OPT_STR, 1, 0, F(mavlink), 0, 200, "udpin:ADDR:PORT | udpout:HOST:PORT | serial:PATH[:BAUD]", NULL,
     "live: the autopilot's endpoint: ATTITUDE and LOCAL_POSITION_NED in as the\nvehicle's pose; OBSTACLE_DISTANCE, OBSTACLE_DISTANCE_3D, HEARTBEAT out", NULL, NULL},
    {"mavlink-sysid", "N", OPT_LONG, 1, 0, F(mav_sysid), 0, 255, "system id (0 = the autopilot's)", "0",
     "our MAVLink system id: the vehicle's, taken from its autopilot's HEARTBEAT\n(1 until heard)", NULL, NULL},
    {"mavlink-compid", "N", OPT_LONG, 1, 0, F(mav_compid), 1, 255, "component id", "158 (MAV_COMP_ID_PERIPHERAL)",
     "our MAVLink component id", NULL, NULL},
    {"mavlink-autopilot", "N", OPT_LONG, 1, 0, F(mav_autopilot), 0, 255, "system id (0 = the first heard)", "0",
     "the autopilot (component 1) whose pose sonard takes; 0: the first system\nwhose HEARTBEAT says it is an autopilot", NULL, NULL},
    {"mavlink-pose-rate", "HZ", OPT_F32, 1, 0, F(mav_pose_rate), 0, 50, "messages a second (0 = never ask)", "10",
     "ask the autopilot (SET_MESSAGE_INTERVAL) for ATTITUDE and LOCAL_POSITION_NED\nat this rate, every 5 s until they come", NULL, NULL},
    {"mavlink-fail-closed", "on|off", OPT_CHOICE, 1, 0, F(mav_fail_closed), 0, 0, "on or off", "on",
     "no OBSTACLE_DISTANCE while no beam has come for a second, so the autopilot\nmarks the sonar NoData", "off=0|on=1", NULL},
    {"mavlink-3d", "on|off", OPT_CHOICE, 1, 0, F(mav_3d), 0, 0, "on or off", "off",
     "OBSTACLE_DISTANCE_3D for each confirmed track (see docs/mavlink.md first)", "off=0|on=1", NULL},
    {"ignore-deg", "FROM:TO", OPT_CUSTOM, 1, 0, 0, 0, 0, "degrees clockwise from forward", "none",
     "the vehicle's own echoes (hull, thrusters, tether): kept out of the obstacle\nmap and sent unknown; repeatable, up to 8", NULL, options_parse_ignore},
    {"pose-lcm", "URL", OPT_STR, 1, 0, F(pose_lcm), 0, 200, "LCM URL", "sonard's --lcm",
     "live: read the vehicle's pose (sonar.pose_t on SONAR_POSE) from this LCM", NULL, NULL},
    {"mavlink-rate", "HZ", OPT_F32, 1, 0, F(mav_rate), 1, 50, "messages a second", "10",
     "OBSTACLE_DISTANCE rate (ArduPilot drops the sensor after 500 ms without one)", NULL, NULL},
    SECTION("replay"),
    {"replay", "FILE", OPT_STR, 0, 0, F(replay), 0, 0, "file, - for stdin", NULL,
     "process a recording in the study's CSV form instead of a live sonar", NULL, NULL},
    {"pose", "FILE", OPT_STR, 0, 0, F(pose_file), 0, 0, "file", "the rows' north_m= east_m= yaw_deg=",
     "the vehicle's poses for --replay: a CSV with the header\nutime_us,north_m,east_m,yaw_deg (docs/architecture.md, frames)", NULL, NULL},
    {"replay-speed", "X", OPT_F64, 0, 0, F(replay_speed), 0, 1000, "times the recorded pace (0 = at once)", "0",
     "replay at the recording's own pace (1), or faster, e.g. to feed a live\nviewer or a test over LCM", NULL, NULL},
    {"beam-ms", "MS", OPT_F64, 1, 0, F(beam_ms), 0, 60000, "milliseconds (0 = the model)", "0",
     "time between the beams of an untimed recording (brping's angle;samples\nrows); 0: the Ping360 model, 19.4 ms + 6 ms a gradian + 2R/c", NULL, NULL},
    {"stage", "S", OPT_CHOICE, 1, 0, F(stage), 0, 0, "raw, median or foreground", "foreground",
     "replay --csv-out: export after this stage", "raw=0|median=1|foreground=2", NULL},
    SECTION("geometry"),
    {"range", "M", OPT_F64, 1, 0, F(range_m), 1, 60, "metres", "2, or in replay the file's range_m= metadata",
     "range of the sonar", NULL, NULL},
    {"speed-of-sound", "C", OPT_F64, 1, 0, F(speed_of_sound), 1300, 1700, "m/s", "1500",
     "fresh water ~1480, salt ~1520 at 20 C", NULL, NULL},
    {"angle-offset", "G", OPT_F32, 1, 1, D(angle_offset), -SONAR_DET_ANGLE_OFFSET_MAX, SONAR_DET_ANGLE_OFFSET_MAX,
     "gradians", "0", "added to every angle of the output frame (Ping Viewer's forward is 200)", NULL, NULL},
    SECTION("filters"),
    {"median", "W|KxK", OPT_CUSTOM, 1, 1, 0, 0, 0, "1 (off), 3, 5, 7, 9, 3x3 or 5x5", "5",
     "median along range, or K x K over adjacent beams (the study's)", NULL, options_parse_median},
    {"background", "MODE", OPT_CHOICE, 1, 1, B(mode), 0, 0, "auto, per-angle, range or off", "auto",
     "per-angle: each angle learns its own; range: the study's median\nacross the beams of a sweep; auto: per-angle, the across-beam model\nwhile it warms up, and tracked objects never learnt",
     "off=0|per-angle=1|range=2|auto=3", NULL},
    {"bg-warmup", "N", OPT_U8, 1, 1, B(warmup), 1, SONAR_BG_WARMUP_MAX, "observations", "2 per-angle, 8 range",
     "observations averaged to seed the background", NULL, NULL},
    {"bg-step", "N", OPT_U8, 1, 1, B(step), 1, SONAR_BG_STEP_MAX, "grey levels", "1",
     "grey levels the background moves per observation", NULL, NULL},
    {"bg-margin", "N", OPT_U8, 1, 1, B(margin), 0, SONAR_BG_MARGIN_MAX, "sixteenths of the background", "8",
     "a cell must exceed the background b by b*N/16; 0 = the study's\nplain subtraction", NULL, NULL},
    {"background-load", "FILE", OPT_STR, 1, 0, F(bg_load), 0, 0, "file", NULL,
     "start from a recorded background (an empty pool, a harbour at rest):\nper-angle or auto, same range, samples, gain and filters, else\nrefused by name and learnt afresh",
     NULL, NULL},
    {"background-save", "FILE", OPT_STR, 1, 0, F(bg_save), 0, 0, "file", NULL,
     "at exit, write the learnt background there (atomically: the old file\nstays whole if the write fails); not for a moving vehicle", NULL, NULL},
    {"survey", "PATH|N", OPT_CUSTOM, 1, 0, 0, 0, 0, "file, or sweeps 8..255", "none",
     "PATH: the site's survey (the empty site, recorded once), loaded at start when\nit exists: what it holds is never an object; N (command line): record N\nsweeps of the empty site into PATH, then exit (docs/install.md)", NULL, options_parse_survey},
    SECTION("detector (once per sweep)"),
    {"threshold-mode", "MODE", OPT_CHOICE, 1, 1, D(threshold_mode), 0, 0, "cfar or global",
     "cfar; global with --background range (the study's)",
     "cfar: each beam against the noise along it (order-statistic CFAR,\n--cfar-*); global: mean + K std of the previous sweep (the study's)",
     "global=0|cfar=1", NULL},
    {"cfar-scale", "A", OPT_F32, 1, 1, D(cfar.scale), SONAR_CFAR_SCALE_MIN, SONAR_CFAR_SCALE_MAX, "times the noise", "2.5",
     "a window passes when its mean level > A * noise + --cfar-floor", NULL, NULL},
    {"cfar-floor", "T", OPT_U8, 1, 1, D(cfar.floor), 0, 254, "grey levels", "16",
     "added to the CFAR threshold (what passes in silent water)", NULL, NULL},
    {"cfar-beams", "N", OPT_CHOICE, 1, 1, D(cfar.across), 0, 0, "1 or 3", "3",
     "beams in the window: 3 spreads it over each beam's neighbours (a one-beam\nspeck is diluted, an echo two or more beams wide is not; one beam later)",
     "1=0|3=1", NULL},
    {"cfar-window", "N", OPT_U8, 1, 1, D(cfar.cut), 0, SONAR_CFAR_CUT_MAX, "8-sample blocks each side", "1",
     "blocks each side of the block under test averaged with it", NULL, NULL},
    {"cfar-guard", "N", OPT_U8, 1, 1, D(cfar.guard), 0, SONAR_CFAR_GUARD_MAX, "8-sample blocks", "1",
     "blocks left out between the window and the training blocks", NULL, NULL},
    {"cfar-train", "N", OPT_U8, 1, 1, D(cfar.train), 1, SONAR_CFAR_TRAIN_MAX, "8-sample blocks each side", "4",
     "training blocks each side: the noise estimate along the beam", NULL, NULL},
    {"cfar-rank", "Q", OPT_U8, 1, 1, D(cfar.rank16), 1, 16, "sixteenths", "8",
     "the order statistic of the training block means (8: median, 16: largest)", NULL, NULL},
    {"threshold", "K", OPT_F32, 1, 1, D(threshold_k), 0, SONAR_DET_K_MAX, "standard deviations", "3",
     "global: foreground cells > mean + K std of the previous sweep", NULL, NULL},
    {"min-threshold", "T", OPT_U8, 1, 1, D(min_threshold), 0, SONAR_DET_MIN_THRESHOLD_MAX, "grey levels", "16",
     "cells must exceed at least T", NULL, NULL},
    {"clusters", "MAX", OPT_U8, 1, 1, D(max_clusters), 1, SONAR_MAX_CLUSTERS, "clusters", "8", "most detections per sweep", NULL, NULL},
    {"min-points", "N", OPT_U16, 1, 1, D(min_points), 1, 65535, "cells", "12; 20 with --background range", "cells a detection needs", NULL, NULL},
    {"min-footprints", "F", OPT_F32, 1, 1, D(min_footprints), 0, SONAR_DET_FOOTPRINTS_MAX, "point-target footprints (0 = no rule)",
     "1; 0 with --background range",
     "a detection's cells must cover F footprints of a point target at its range\n(range/samples deep, the beam's 2 degrees wide: what the sonar resolves there)", NULL, NULL},
    {"min-area", "M2", OPT_F32, 1, 1, D(min_area_m2), 0, SONAR_DET_AREA_MAX, "square metres (0 = no rule)", "0",
     "square metres a detection's cells must cover (the same at every range and\nsetting; a floor of your own, e.g. for one size of target)", NULL, NULL},
    {"min-beams", "N", OPT_U8, 1, 1, D(min_beams), 0, 255, "beams (0 or 1: any)", "0", "beams a detection must span", NULL, NULL},
    {"max-extent", "M", OPT_F32, 1, 1, D(max_extent_m), 0, SONAR_DET_DISTANCE_MAX, "metres (0 = no limit)", "3.5; 0 with --background range",
     "drop detections wider than M (structure: walls, lane ropes)", NULL, NULL},
    {"split-points", "N", OPT_U16, 1, 1, D(split_points), 0, 65535, "cells (0 = never cut)", "0",
     "cut groups wider than --max-extent with k-means into pieces about\nhalf of it across, keeping pieces of >= N cells", NULL, NULL},
    {"min-range", "M", OPT_F32, 1, 1, D(min_range_m), 0, SONAR_DET_DISTANCE_MAX, "metres", "0",
     "drop detections nearer than M (ring-down, the mount)", NULL, NULL},
    {"max-aspect", "R", OPT_F32, 1, 1, D(max_aspect), 0, SONAR_DET_ASPECT_MAX, "ratio (0 = no limit, else >= 0.1)", "2; 0 with --background range",
     "drop detections R times longer along the beam than across", NULL, NULL},
    {"track-m", "M", OPT_F32, 1, 1, D(track_m), 0, SONAR_DET_TRACK_M_MAX, "metres (0 = off)", "0",
     "a cluster within M of a track's prediction (with --track off: of a\ndetection of the previous sweep) needs only --track-points cells", NULL, NULL},
    {"track-points", "N", OPT_U16, 1, 1, D(track_points), 1, 65535, "cells", "10", "cells a tracked cluster needs", NULL, NULL},
    {"iterations", "N", OPT_U8, 1, 1, D(iterations), 1, SONAR_DET_ITERATIONS_MAX, "rounds", "10", "k-means rounds at most", NULL, NULL},
    {"join-m", "M", OPT_F32, 1, 1, D(join_m), 0, SONAR_DET_JOIN_M_MAX, "metres", "0.15", "range gap still joining one object", NULL, NULL},
    {"join-beams", "N", OPT_U8, 1, 1, D(join_beams), 1, SONAR_DET_JOIN_BEAMS_MAX, "beams", "2", "beams apart still joining one object", NULL, NULL},
    {"max-step", "G", OPT_U16, 1, 1, offsetof(struct sonard_options, pipeline.max_step), 1, SONAR_PIPE_MAX_STEP_MAX,
     "gradians", "20", "an angle move larger than G starts a sweep", NULL, NULL},
    {"sweep-gap", "S", OPT_F32, 1, 1, offsetof(struct sonard_options, pipeline.sweep_gap_s), 0, 3600, "seconds (0: never)",
     "0 (2 with --passive)", "a beam this long after the one before starts a sweep\n(a paused driving program)", NULL, NULL},
    SECTION("tracking (once per sweep, docs/architecture.md)"),
    {"track", "on|off", OPT_CHOICE, 1, 1, P(track), 0, 0, "on or off", "on",
     "Kalman tracks with IDs on SONAR_TRACKS and in --json", "off=0|on=1", NULL},
    {"track-gate", "D2", OPT_F32, 1, 1, T(gate), 1, SONAR_TRK_GATE_MAX, "squared Mahalanobis distance", "9.21",
     "a detection continues a track within this of its prediction\n(chi-square, 2 degrees of freedom: 9.21 = 99%)", NULL, NULL},
    {"track-sigma", "M", OPT_F32, 1, 1, T(meas_m), 0.01, SONAR_TRK_MEAS_MAX, "metres", "0.15",
     "position noise of a detection, per axis", NULL, NULL},
    {"track-accel", "A", OPT_F32, 1, 1, T(accel_mps2), 0.001, SONAR_TRK_ACCEL_MAX, "m/s^2", "0.05",
     "how hard targets manoeuvre (white acceleration noise)", NULL, NULL},
    {"track-manoeuvre", "A", OPT_F32, 1, 1, T(manoeuvre_mps2), 0, SONAR_TRK_ACCEL_MAX, "m/s^2", "0.5",
     "acceleration noise of each track's manoeuvre model (a turn, a start, a stop);\nat or below --track-accel it is the same as the moving model", NULL, NULL},
    {"track-models", "imm|cv", OPT_CHOICE, 1, 1, T(imm), 0, 0, "imm or cv", "imm",
     "imm: each track weighs three models (moving, manoeuvring, resting) and says\nwhich it is in; cv: near constant velocity alone", "cv=0|imm=1", NULL},
    {"track-defer", "on|off", OPT_CHOICE, 1, 1, T(defer), 0, 0, "on or off", "on",
     "on: the likeliest other assignments of a sweep wait for the next look,\nwhich may revise the IDs just published (each revision is said on\nSONAR_TRACKS and in --json); off: each sweep's assignment is final", "off=0|on=1", NULL},
    {"track-speed", "V", OPT_F32, 1, 1, T(speed0_mps), 0.01, SONAR_TRK_SPEED_MAX, "m/s", "1",
     "speed uncertainty of a new track", NULL, NULL},
    {"track-max-speed", "V", OPT_F32, 1, 1, T(max_speed_mps), 0, SONAR_TRK_SPEED_MAX, "m/s (0 = off, else >= 0.1)", "2.5",
     "no track moves faster than this between two looks (people, divers, swimmers)", NULL, NULL},
    {"track-confirm", "M", OPT_U8, 1, 1, T(confirm_m), 1, SONAR_TRK_WINDOW_MAX, "hits", "2",
     "hits in the last --track-window visible sweeps that confirm a track", NULL, NULL},
    {"track-window", "N", OPT_U8, 1, 1, T(confirm_n), 1, SONAR_TRK_WINDOW_MAX, "sweeps", "3",
     "visible sweeps --track-confirm counts over", NULL, NULL},
    {"track-misses", "N", OPT_U8, 1, 1, T(max_misses), 1, 127, "sweeps", "2",
     "visible sweeps in a row without a detection that end a confirmed track\n(twice as many without one, in view or not, also do)", NULL, NULL},
    {"track-life", "hits|existence", OPT_CHOICE, 1, 1, T(existence), 0, 0, "hits or existence", "hits",
     "hits: --track-confirm of --track-window confirm a track, --track-misses end\nit; existence: its probability of existence against the site's clutter map\n(learnt as sonard runs) confirms it at 0.9 and ends it below 0.1. Either way\neach track carries its existence, and alarms need 0.97", "hits=0|existence=1", NULL},
    {"track-walls", "on|off", OPT_CHOICE, 1, 1, T(walls), 0, 0, "on or off", "on",
     "on: where a survey in use holds walls (its lines), a track's prediction that\nwould cross one also turns there (reflected, its speed kept), and each\ndetection is judged against the likelier of the two; off: never", "off=0|on=1", NULL},
    {"structure-s", "S", OPT_F32, 1, 1, P(structure_s), 0, SONAR_STRUCTURE_S_MAX, "seconds (0 = never)", "0",
     "an echo there from the first look (before the background knew the place)\nthat stays within 1 m for S seconds is structure: learnt into the\nbackground, reported as structure, not tracked. A person motionless from\nthe first ping is the same to it: see docs/configuration.md", NULL, NULL},
    {"still-alarm", "S", OPT_F32, 1, 1, P(still_alarm_s), 0, SONAR_ACT_STILL_ALARM_MAX, "seconds (0 = never)", "0",
     "a track not moving and still for S seconds raises a still alarm (a pool\nwatcher's silent case: a body that does not move); with a struggle alarm\n(struggling in 2 of 3 looks, always on) it goes out on SONAR_TRACKS and\n--json and is said once on stderr (docs/activity.md)", NULL, NULL},
    SECTION("output"),
    {"track-late", "on|off", OPT_CHOICE, 1, 0, F(track_late), 0, 0, "on or off", "off",
     "on: each sweep's detections and tracks go out one sweep late, once the next\nlook has revised the IDs it would (--track-defer), with no revisions;\noff: at once, revisions of the sweep before said", "off=0|on=1", NULL},
    {"json", NULL, OPT_FLAG, 1, 0, F(json), 0, 0, NULL, "off", "one JSON line per sweep on stdout", NULL, NULL},
    {"quiet", NULL, OPT_FLAG, 1, 0, F(quiet), 0, 0, NULL, "off", "no per-sweep text (diagnostics: --log-level)", NULL, NULL},
    {"log-level", "LEVEL", OPT_CHOICE, 1, 0, F(log_level), 0, 0, "error, warn, info or debug", "info",
     "diagnostics on stderr (the journal under systemd): error, warn (link lost,\na file refused, ...), info (what happens, the exit summary) or debug",
     "error=0|warn=1|info=2|debug=3", NULL},
    {"help", NULL, OPT_ACTION, 0, 0, 0, 0, 0, NULL, NULL, "this text", NULL, NULL},
    {"version", NULL, OPT_ACTION, 0, 0, 0, 0, 0, NULL, NULL, "the version", NULL, NULL},
};

/* Names that meant two things: --sector is in gradians (the head's), so the arcs in degrees are --ignore-deg; "link" is
   the transport, so runs that touch join (--join-m, --join-beams). */
static const struct opt_rename renamed[] = {{"ignore-sector", "ignore-deg"}, {"link-m", "join-m"}, {"link-beams", "join-beams"}};
static const struct opt_schema schema = {spec, sizeof(spec) / sizeof(spec[0]), "sonard", renamed,
                                         sizeof(renamed) / sizeof(renamed[0])};

SONAR_STATIC_ASSERT(sizeof(spec) / sizeof(spec[0]) <= OPT_GIVEN_ROWS, given_bits_fit);

const struct opt_schema *options_schema(void) { return &schema; }

void options_markdown(FILE *f) { opt_markdown(&schema, f); }

static void defaults(struct sonard_options *o)
{
    memset(o, 0, sizeof(*o));
    sonar_pipeline_defaults(&o->pipeline);
    o->channel_prefix = "";
    o->range_m = -1.0;
    o->speed_of_sound = 1500.0;
    o->discover_s = 2.0;
    o->discover_data_port = 12345;
    o->mav_sysid = 0;
    o->mav_compid = 158;
    o->mav_rate = 10.0f;
    o->log_level = APP_INFO;
    o->mav_pose_rate = 10.0f;
    o->mav_fail_closed = 1;
    o->obstacles = 1;
    o->stage = SONAR_STAGE_FOREGROUND;
    o->device.gain = 0;
    o->scan.revisit_s = 1.5f;
    sonar_gain_defaults(&o->gain_rules);
    o->device.frequency = 750;
    o->device.step = 1;
    o->device.full_circle = 1;
}

static void usage(void)
{
    printf("usage: sonard --sonar URL [options]       live: drive a Ping360, publish over LCM\n"
           "       sonard --coprocessor URL [options] the same, detected on the co-processor\n"
           "       sonard --replay FILE.csv [options] offline: a recording in the study's CSV form\n"
           "       sonard --discover                  list the Ethernet Ping360s on the network\n\n");
    opt_usage(&schema, stdout);
}

int options_given(const struct sonard_options *o, const char *name)
{
    int k = opt_find(&schema, name);
    return k >= 0 && opt_was_given(&o->given, (size_t)k);
}

const char *options_moving(const struct sonard_options *o)
{
    return o->pose_file ? "--pose" : o->mavlink ? "--mavlink" : o->pose_lcm ? "--pose-lcm" : NULL;
}

void options_say_unknown(const struct sonard_options *o, FILE *f)
{
    unsigned i;
    for (i = 0; i < o->given.unknown && i < OPT_UNKNOWN_KEPT; i++)
        fprintf(f, "sonard: warning: %s skipped (a key of a newer or older sonard %s?); the rest of the file applies\n",
                o->given.unknown_said[i], SONARD_VERSION);
    if (o->given.unknown > OPT_UNKNOWN_KEPT)
        fprintf(f, "sonard: warning: %u more unknown keys skipped\n", o->given.unknown - OPT_UNKNOWN_KEPT);
    for (i = 0; i < sizeof(renamed) / sizeof(renamed[0]); i++)
        if (o->given.renamed_used & ((uint32_t)1 << i))
            fprintf(f, "sonard: warning: %s is deprecated: it is now %s (taken as that)\n", renamed[i].old_name,
                    renamed[i].name);
}

int options_parse(int argc, char **argv, struct sonard_options *o, char *err, size_t errlen)
{
    size_t used = 0;
    int i, action, r;
    defaults(o);
    for (i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *path = strncmp(a, "--config=", 9) == 0 ? a + 9 : strcmp(a, "--config") == 0 && i + 1 < argc ? argv[i + 1] : NULL;
        if (path == NULL)
            continue;
        if (o->nconfigs >= OPTIONS_MAX_CONFIGS) {
            snprintf(err, errlen, "--config: more than %d files", OPTIONS_MAX_CONFIGS);
            return HOST_ERR_CONFIG;
        }
        o->configs[o->nconfigs++] = path;
        /* Several files apply in order, each overriding the ones before. */
        if ((r = opt_read_file(&schema, path, o, &o->given, o->pool, sizeof(o->pool), &used, err, errlen)) != HOST_OK)
            return r;
    }
    if (opt_parse_argv(&schema, argc, argv, o, &o->given, &action, err, errlen) != HOST_OK)
        return HOST_ERR_CONFIG;
    if (action >= 0) {
        if (strcmp(spec[action].name, "help") == 0)
            usage();
        else
            printf("sonard %s\n", SONARD_VERSION);
        return 1;
    }
    return options_check_whole(o, err, errlen);
}
