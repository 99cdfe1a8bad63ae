/* msg.c -- struct sonar_detections <-> sonar_detections_t and the tracker -> sonar_tracks_t, field by field; O(detections x hull + tracks) per call, no heap. */
#include "msg.h"

#include <math.h>
#include <string.h>

void msg_detections(const struct sonar_detections *d, const struct msg_view *v, sonar_detection_t *det,
                    sonar_detections_t *m)
{
    unsigned i;
    for (i = 0; i < d->count; i++) {
        const struct sonar_detection *o = &d->det[i];
        det[i].utime = o->utime;
        det[i].x_m = o->x_m;
        det[i].y_m = o->y_m;
        det[i].range_m = o->range_m;
        det[i].bearing_deg = o->bearing_deg;
        det[i].area_m2 = o->area_m2;
        det[i].points = (int32_t)o->points;
        det[i].mean_intensity = o->mean_intensity;
        det[i].world = (int8_t)(v != NULL && v->det_world[i]);
        det[i].north_m = det[i].world ? v->det_north[i] : 0.0f;
        det[i].east_m = det[i].world ? v->det_east[i] : 0.0f;
        det[i].kind = (int8_t)o->kind;
        det[i].hull_count = o->hull_count;
        det[i].hull_x = (float *)(uintptr_t)o->hull_x; /* encode only reads them */
        det[i].hull_y = (float *)(uintptr_t)o->hull_y;
    }
    m->utime = d->utime;
    m->sweep = (int32_t)d->sweep;
    m->beams = (int16_t)d->beams;
    m->threshold = d->threshold;
    m->runs = (int16_t)d->runs;
    m->groups = (int16_t)d->groups;
    m->count = d->count;
    m->world = (int8_t)(v != NULL && v->world);
    m->north_m = v != NULL && v->have_pose ? v->pose.north_m : 0.0f;
    m->east_m = v != NULL && v->have_pose ? v->pose.east_m : 0.0f;
    m->yaw_deg = v != NULL && v->have_pose ? v->pose.yaw_deg : 0.0f;
    m->detections = det;
}

void msg_detections_in(const sonar_detections_t *m, struct sonar_detections *d)
{
    int i, v;
    memset(d, 0, sizeof(*d));
    d->utime = m->utime;
    d->sweep = (uint32_t)m->sweep;
    d->beams = (uint16_t)m->beams;
    d->threshold = (uint8_t)(m->threshold < 0 ? 0 : m->threshold > 255 ? 255 : m->threshold);
    d->runs = (uint16_t)(m->runs < 0 ? 0 : m->runs);
    d->groups = (uint16_t)(m->groups < 0 ? 0 : m->groups);
    d->count = (uint8_t)(m->count < 0 ? 0 : m->count > SONAR_MAX_CLUSTERS ? SONAR_MAX_CLUSTERS : m->count);
    /* The sweep's frame and pose are the receiver's to decide (sonar_pipeline_track locates again). */
    for (i = 0; i < d->count; i++) {
        const sonar_detection_t *o = &m->detections[i];
        struct sonar_detection *t = &d->det[i];
        t->utime = o->utime;
        t->x_m = o->x_m;
        t->y_m = o->y_m;
        t->range_m = o->range_m;
        t->bearing_deg = o->bearing_deg;
        t->area_m2 = o->area_m2;
        t->points = o->points < 0 ? 0u : (uint32_t)o->points;
        t->mean_intensity = o->mean_intensity;
        t->kind = o->kind >= 0 && o->kind <= SONAR_DET_WALL_ECHO ? (uint8_t)o->kind : SONAR_DET_OBJECT;
        t->hull_count = (uint8_t)(o->hull_count < 0 ? 0 : o->hull_count > SONAR_MAX_HULL ? SONAR_MAX_HULL : o->hull_count);
        for (v = 0; v < t->hull_count; v++) {
            t->hull_x[v] = o->hull_x[v];
            t->hull_y[v] = o->hull_y[v];
        }
    }
}

static int16_t to_i16(uint16_t v)
{
    return (int16_t)(v > 32767u ? 32767u : v);
}

/* An ID on the wire: int32 (IDs past 2^31 - 1, after billions of births, are held there). */
static int32_t id32(uint32_t id)
{
    return (int32_t)(id > 2147483647u ? 2147483647u : id);
}

void msg_tracks(const struct sonar_tracker *tk, const struct sonar_detections *d, const struct msg_view *v,
                sonar_track_t *t, struct msg_revisions *rv, sonar_tracks_t *m)
{
    const struct sonar_track_revision *r;
    unsigned i, nr;
    for (i = 0; i < tk->n; i++) {
        const struct sonar_track *s = &tk->t[i];
        t[i].id = id32(s->id);
        t[i].state = (int8_t)s->state;
        t[i].utime = s->utime;
        t[i].world = (int8_t)(v != NULL && v->world);
        t[i].x_m = t[i].world ? v->trk_x[i] : s->px;
        t[i].y_m = t[i].world ? v->trk_y[i] : s->py;
        t[i].vx_mps = t[i].world ? v->trk_vx[i] : s->vx;
        t[i].vy_mps = t[i].world ? v->trk_vy[i] : s->vy;
        t[i].north_m = t[i].world ? s->px : 0.0f;
        t[i].east_m = t[i].world ? s->py : 0.0f;
        t[i].vn_mps = t[i].world ? s->vx : 0.0f;
        t[i].ve_mps = t[i].world ? s->vy : 0.0f;
        /* Both axes share one covariance (tracker.h): the 2 x 2 position block is pa I. */
        t[i].cov_xx = s->pa;
        t[i].cov_xy = 0.0f;
        t[i].cov_yy = s->pa;
        t[i].age = to_i16(s->age);
        t[i].hits = to_i16(s->hits);
        t[i].misses = to_i16(s->misses);
        t[i].detection = s->det;
        t[i].still_s = sonar_track_still_s(s, d->utime);
        t[i].mode = (int8_t)s->mode;
        t[i].p_moving = (float)s->mu[SONAR_TRK_CV] / 255.0f;
        t[i].p_manoeuvre = (float)s->mu[SONAR_TRK_MANOEUVRE] / 255.0f;
        t[i].p_rest = (float)s->mu[SONAR_TRK_REST] / 255.0f;
        t[i].kind = (int8_t)s->kind;
        t[i].activity = (int8_t)s->activity;
        t[i].echo_corr = s->echo_corr == SONAR_ACT_NO_CORR ? NAN : (float)s->echo_corr / 100.0f;
        t[i].alarms = (int8_t)s->alarms;
        t[i].existence = s->existence;
    }
    m->utime = d->utime;
    m->sweep = (int32_t)d->sweep;
    m->count = (int16_t)tk->n;
    m->tracks = t;
    r = sonar_tracker_revisions(tk, &nr);
    for (i = 0; i < nr && i < 2; i++) {
        rv->from[i] = id32(r[i].from);
        rv->to[i] = id32(r[i].to);
    }
    m->revisions = (int16_t)i;
    m->revised_from = rv->from;
    m->revised_to = rv->to;
}
