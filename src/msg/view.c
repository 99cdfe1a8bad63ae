/* view.c -- the outputs' view of a sweep: each detection placed in the world by the pose at its time, each world track brought to the body frame at its own; O(detections + tracks) pose lookups. */
#include "view.h"

#include <string.h>

void msg_view_of(const struct sonar_pipeline *p, struct msg_view *v)
{
    const struct sonar_detections *d = sonar_pipeline_detections(p);
    const struct sonar_tracker *tk = sonar_pipeline_tracker(p);
    uint8_t i;
    memset(v, 0, sizeof(*v));
    v->world = d->world && tk != NULL && tk->world;
    v->have_pose = (uint8_t)sonar_pipeline_pose_at(p, d->utime, &v->pose);
    for (i = 0; i < d->count; i++) {
        struct sonar_pose q;
        if (sonar_pipeline_pose_at(p, d->det[i].utime, &q)) {
            sonar_pose_to_world(&q, d->det[i].x_m, d->det[i].y_m, &v->det_north[i], &v->det_east[i]);
            v->det_world[i] = 1;
        }
    }
    for (i = 0; tk != NULL && i < tk->n; i++) {
        const struct sonar_track *t = &tk->t[i];
        struct sonar_pose q;
        if (!tk->world) {
            v->trk_x[i] = t->px;
            v->trk_y[i] = t->py;
            v->trk_vx[i] = t->vx;
            v->trk_vy[i] = t->vy;
            continue;
        }
        sonar_pipeline_track_pose(p, t->utime, &q); /* last seen before the poses kept: the latest sweep's */
        sonar_pose_to_body(&q, t->px, t->py, &v->trk_x[i], &v->trk_y[i]);
        sonar_pose_rotate(-q.yaw_deg, t->vx, t->vy, &v->trk_vx[i], &v->trk_vy[i]);
    }
}

void msg_view_keep(struct msg_view *v, const uint8_t *kept, unsigned n)
{
    unsigned i;
    for (i = 0; i < n; i++) {
        v->trk_x[i] = v->trk_x[kept[i]];
        v->trk_y[i] = v->trk_y[kept[i]];
        v->trk_vx[i] = v->trk_vx[kept[i]];
        v->trk_vy[i] = v->trk_vy[kept[i]];
    }
}
