/* msg.h -- core structs <-> LCM messages, once: the only code that assigns message fields, for the host's sinks and sources and the co-processor firmware; no heap (messages point into the caller's structs). */
#ifndef SONAR_MSG_H
#define SONAR_MSG_H

#include "sonar/detector.h"
#include "sonar/device.h"
#include "sonar/obstacle.h"
#include "sonar/ping360.h"
#include "sonar/pose.h"
#include "sonar/pipeline.h"
#include "sonar/status.h"
#include "sonar/tracker.h"
#include "view.h"
#include "sonar_beam_t.h"
#include "sonar_clutter_t.h"
#include "sonar_config_t.h"
#include "sonar_detections_t.h"
#include "sonar_obstacles_t.h"
#include "sonar_pose_t.h"
#include "sonar_status_t.h"
#include "sonar_survey_t.h"
#include "sonar_tracks_t.h"

/*
 * Fills *m from d; det (SONAR_MAX_CLUSTERS entries) holds the detections, whose hulls point into d.
 * v: the world positions and the vehicle's pose (msg_view_of), or NULL (none: all 0).
 */
void msg_detections(const struct sonar_detections *d, const struct msg_view *v, sonar_detection_t *det,
                    sonar_detections_t *m);

/* The reverse, for a host republishing a co-processor's detections; counts beyond the limits are cut. */
void msg_detections_in(const sonar_detections_t *m, struct sonar_detections *d);

/* Room for the revisions a SONAR_TRACKS message carries (sonar_tracker_revisions: at most 2). */
struct msg_revisions {
    int32_t from[2], to[2];
};

/*
 * Fills *m from the tracker after sweep d; t (SONAR_MAX_TRACKS entries) holds the tracks, rv the
 * revisions of the last sweep's IDs. v: their body-frame states when they are tracked in the
 * world (msg_view_of), or NULL (a body-frame tracker: its own state).
 */
void msg_tracks(const struct sonar_tracker *tk, const struct sonar_detections *d, const struct msg_view *v,
                sonar_track_t *t, struct msg_revisions *rv, sonar_tracks_t *m);

/* A beam record <-> sonar.beam_t; the samples are borrowed both ways (m->samples points at b's, b->samples at m's). */
void msg_beam(const struct sonar_record *b, sonar_beam_t *m);
void msg_beam_in(const sonar_beam_t *m, struct sonar_record *b);

/*
 * A status record <-> sonar.status_t; the link string is borrowed both ways. Counters beyond
 * the record's 32 bits are held at 2^32 - 1 on the way in, negative ones at 0.
 */
void msg_status(const struct sonar_status *s, sonar_status_t *m);
void msg_status_in(const sonar_status_t *m, struct sonar_status *s);

/*
 * The survey's part of a status record -> sonar.survey_t (SONAR_SURVEY): its state and its structure; det
 * (SONAR_MAX_CLUSTERS entries) holds the places, whose hulls point into the survey's.
 */
void msg_survey(const struct sonar_status *s, sonar_detection_t *det, sonar_survey_t *m);

/*
 * The clutter map of a status record -> sonar.clutter_t (SONAR_CLUTTER); density (SONAR_CLUTTER_BANDS x
 * SONAR_CLUTTER_SECTORS entries, the caller's) holds the cells. Returns 0 when the record has no map (nothing to send).
 */
int msg_clutter(const struct sonar_status *s, float *density, sonar_clutter_t *m);

/*
 * The obstacle map read at utime (us since the epoch) -> sonar.obstacles_t (SONAR_OBSTACLES): dist_cm
 * (SONAR_OBS_SECTORS entries, sector k centred on k * SONAR_OBS_SECTOR_DEG degrees clockwise from ahead,
 * cm) as obstacle.h gives them; cells (SONAR_OBS_SECTORS entries, the caller's) holds the message's copy.
 */
void msg_obstacles(int64_t utime, const uint16_t *dist_cm, uint16_t min_cm, uint16_t max_cm, int32_t *cells,
                   sonar_obstacles_t *m);

/* A pose <-> sonar.pose_t (SONAR_POSE). */
void msg_pose(const struct sonar_pose *p, sonar_pose_t *m);
void msg_pose_in(const sonar_pose_t *m, struct sonar_pose *p);

/*
 * The co-processor's configuration: acquisition d, pipeline p and every Nth beam forwarded
 * (0 = none) <-> sonar.config_t. The way in fills every field of *d (baud: the firmware's own
 * serial rate to the sonar, which the host does not set) and every field of *p the message
 * carries (callbacks and user stay as they were); a value that does not fit its field becomes
 * one the core's checks refuse by name. Nothing is checked here.
 */
void msg_config(const struct sonar_ping360_config *d, const struct sonar_pipeline_config *p, uint16_t beam_every,
                sonar_config_t *c);
void msg_config_in(const sonar_config_t *c, uint32_t baud, struct sonar_ping360_config *d,
                   struct sonar_pipeline_config *p, uint16_t *beam_every);

#endif
