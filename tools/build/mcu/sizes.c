/* sizes.c -- not run: compiled for each target, its arrays' sizes (read back with nm -S by tools/build/sizes.sh) are the core's state structs' sizeof, for docs/sizes.md; no code. */
#include "sonar/activity.h"
#include "sonar/background.h"
#include "sonar/clutter.h"
#include "sonar/cpframe.h"
#include "sonar/detector.h"
#include "sonar/device.h"
#include "sonar/median.h"
#include "sonar/obstacle.h"
#include "sonar/ping.h"
#include "sonar/ping360.h"
#include "sonar/pipeline.h"
#include "sonar/pose.h"
#include "sonar/status.h"
#include "sonar/gain.h"
#include "sonar/scan.h"
#include "sonar/sweep.h"
#include "sonar/structure.h"
#include "sonar/survey.h"
#include "sonar/tracker.h"

/* One array per struct: sizeof_<header>__<struct>. */
#define SIZE(h, s) unsigned char sizeof_##h##__##s[sizeof(struct s)];
SIZE(pipeline, sonar_pipeline)
SIZE(background, sonar_background)
SIZE(detector, sonar_detector)
SIZE(detector, sonar_detections)
SIZE(tracker, sonar_tracker)
SIZE(tracker, sonar_track)
SIZE(tracker, sonar_trk_alt)
SIZE(clutter, sonar_clutter)
SIZE(activity, sonar_activity)
SIZE(activity, sonar_act_slot)
SIZE(median, sonar_median2d)
SIZE(obstacle, sonar_obstacle)
SIZE(pose, sonar_pose_ring)
SIZE(gain, sonar_gain)
SIZE(scan, sonar_scan)
SIZE(sweep, sonar_sweep)
SIZE(ping, sonar_ping_parser)
SIZE(ping360, sonar_ping360)
SIZE(device, sonar_device)
SIZE(status, sonar_status)
SIZE(cpframe, sonar_cpf_parser)
SIZE(survey, sonar_survey)
SIZE(survey, sonar_survey_rec)
SIZE(survey, sonar_survey_spread)
SIZE(pipeline, sonar_pipeline_config)
/* What the limits in config.h multiply: a run, a detection, a place, a track, a pose, an echo. */
SIZE(kmeans, sonar_point)
SIZE(frame, sonar_xy)
SIZE(detector, sonar_detector_run)
SIZE(detector, sonar_detection)
SIZE(structure, sonar_place)
SIZE(structure, sonar_structure)
SIZE(pose, sonar_pose)
SIZE(obstacle, sonar_obstacle_echo)
SIZE(obstacle, sonar_obstacle_sector)
