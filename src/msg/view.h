/* view.h -- a sweep's detections and tracks in both frames, the form every output maps (LCM, JSON, MAVLink): computed on the host from the pipeline and its poses, never in the core or the firmware; RAM: struct msg_view ~0.8 KB. */
#ifndef SONAR_MSG_VIEW_H
#define SONAR_MSG_VIEW_H

#include <stdint.h>

#include "sonar/pipeline.h"
#include "sonar/pose.h"

/*
 * A sweep's detections and tracks in both frames, for outputs (filled by msg_view_of; the
 * pipeline itself keeps only the tracks' own frame). RAM: ~0.8 KB.
 */
struct msg_view {
    uint8_t world;                          /* the tracks are in the world frame (north_m .. ve_mps = px .. vy) */
    uint8_t have_pose;                      /* pose holds the vehicle at the sweep's last beam */
    struct sonar_pose pose;
    uint8_t det_world[SONAR_MAX_CLUSTERS];  /* detection i had a pose at its time ... */
    float det_north[SONAR_MAX_CLUSTERS], det_east[SONAR_MAX_CLUSTERS]; /* ... and was there, metres */
    /* Track i in the body frame at its own time: metres, and its velocity over ground in body axes, m/s. */
    float trk_x[SONAR_MAX_TRACKS], trk_y[SONAR_MAX_TRACKS], trk_vx[SONAR_MAX_TRACKS], trk_vy[SONAR_MAX_TRACKS];
};

/*
 * Fills v for the sweep in p->out and the tracks in p->trk (call from on_sweep, or after
 * sonar_pipeline_track). A world track last seen before the oldest pose kept is put in the body
 * frame at the last sweep's pose.
 */
void msg_view_of(const struct sonar_pipeline *p, struct msg_view *v);

/* Keeps tracks kept[0 .. n) of v's (sonar_tracker_relabel's kept), in that order, as its first n. */
void msg_view_keep(struct msg_view *v, const uint8_t *kept, unsigned n);

#endif
