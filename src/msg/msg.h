/* msg.h -- core structs to LCM messages, once, for the host's LCM sink and the co-processor firmware; no heap (the messages point into the caller's structs). */
#ifndef SONAR_MSG_H
#define SONAR_MSG_H

#include "sonar/detector.h"
#include "sonar/pipeline.h"
#include "sonar/tracker.h"
#include "sonar_detections_t.h"
#include "sonar_tracks_t.h"

/*
 * Fills *m from d; det (SONAR_MAX_CLUSTERS entries) holds the detections, whose hulls point into d.
 * v: the world positions and the vehicle's pose (sonar_pipeline_view), or NULL (none: all 0).
 */
void msg_detections(const struct sonar_detections *d, const struct sonar_view *v, sonar_detection_t *det,
                    sonar_detections_t *m);

/* The reverse, for a host republishing a co-processor's detections; counts beyond the limits are cut. */
void msg_detections_in(const sonar_detections_t *m, struct sonar_detections *d);

/*
 * Fills *m from the tracker after sweep d; t (SONAR_MAX_TRACKS entries) holds the tracks. v: their
 * body-frame states when they are tracked in the world (sonar_pipeline_view), or NULL (a body-frame
 * tracker: its own state).
 */
void msg_tracks(const struct sonar_tracker *tk, const struct sonar_detections *d, const struct sonar_view *v,
                sonar_track_t *t, sonar_tracks_t *m);

#endif
