/* report.c -- JSON and text renderings of a sweep's detections and tracks; a few hundred bytes of stdio per sweep. */
#include "report.h"

#include <inttypes.h>

/* Track i's body-frame x, y, vx, vy (k = 0..3): the view's, or its own state without one. */
static float body(const struct msg_view *v, const struct sonar_track *t, unsigned i, int k)
{
    if (v == NULL) {
        const float own[4] = {t->px, t->py, t->vx, t->vy};
        return own[k];
    }
    return k == 0 ? v->trk_x[i] : k == 1 ? v->trk_y[i] : k == 2 ? v->trk_vx[i] : v->trk_vy[i];
}

/* A track's activity, its echo's correlation (null: none yet) and its alarms, as JSON members. */
static void activity_json(FILE *f, const struct sonar_track *t)
{
    fprintf(f, ",\"activity\":\"%s\"", sonar_activity_str(t->activity));
    if (t->echo_corr == SONAR_ACT_NO_CORR)
        fputs(",\"echo_corr\":null", f);
    else
        fprintf(f, ",\"echo_corr\":%.2f", (double)t->echo_corr / 100.0);
    fprintf(f, ",\"alarms\":[%s%s%s]", t->alarms & SONAR_ALARM_STRUGGLE ? "\"struggle\"" : "",
            (t->alarms & SONAR_ALARM_STRUGGLE) && (t->alarms & SONAR_ALARM_STILL) ? "," : "",
            t->alarms & SONAR_ALARM_STILL ? "\"still\"" : "");
}

int report_json(FILE *f, const struct sonar_detections *d, const struct sonar_tracker *tk, const struct msg_view *v)
{
    unsigned i, h;
    fprintf(f, "{\"sweep\":%" PRIu32 ",\"utime\":%" PRId64 ",\"beams\":%u,\"threshold\":%u,\"runs\":%u,\"groups\":%u,\"detections\":[",
            d->sweep, d->utime, (unsigned)d->beams, (unsigned)d->threshold, (unsigned)d->runs, (unsigned)d->groups);
    for (i = 0; i < d->count; i++) {
        const struct sonar_detection *o = &d->det[i];
        fprintf(f, "%s{\"utime\":%" PRId64 ",\"x_m\":%.3f,\"y_m\":%.3f,\"range_m\":%.3f,\"bearing_deg\":%.2f,\"area_m2\":%.4f,\"points\":%" PRIu32
                   ",\"mean_intensity\":%.1f,\"hull\":[",
                i ? "," : "", o->utime, (double)o->x_m, (double)o->y_m, (double)o->range_m, (double)o->bearing_deg,
                (double)o->area_m2, o->points, (double)o->mean_intensity);
        for (h = 0; h < o->hull_count; h++)
            fprintf(f, "%s[%.3f,%.3f]", h ? "," : "", (double)o->hull_x[h], (double)o->hull_y[h]);
        fputs("]", f);
        if (v != NULL && v->det_world[i])
            fprintf(f, ",\"north_m\":%.3f,\"east_m\":%.3f", (double)v->det_north[i], (double)v->det_east[i]);
        /* Plain objects carry no kind: their lines are as they always were. */
        if (o->kind != SONAR_DET_OBJECT)
            fprintf(f, ",\"kind\":\"%s\"", sonar_det_kind_str(o->kind));
        fputs("}", f);
    }
    fputs("]", f);
    /* The frame the tracks are in, and where the vehicle was at the sweep's end. */
    fprintf(f, ",\"frame\":\"%s\"", v != NULL && v->world ? "world" : "body");
    if (v != NULL && v->have_pose)
        fprintf(f, ",\"pose\":{\"north_m\":%.3f,\"east_m\":%.3f,\"yaw_deg\":%.2f}", (double)v->pose.north_m,
                (double)v->pose.east_m, (double)v->pose.yaw_deg);
    if (tk != NULL) {
        fputs(",\"tracks\":[", f);
        for (i = 0; i < sonar_tracker_count(tk); i++) {
            const struct sonar_track *t = sonar_tracker_track(tk, i);
            fprintf(f, "%s{\"id\":%" PRIu32 ",\"state\":\"%s\",\"utime\":%" PRId64 ",\"x_m\":%.3f,\"y_m\":%.3f,\"vx_mps\":%.3f,"
                       "\"vy_mps\":%.3f,\"age\":%u,\"hits\":%u,\"detection\":%d,\"still_s\":%.1f",
                    i ? "," : "", t->id, sonar_track_state_str(t->state), t->utime, (double)body(v, t, i, 0),
                    (double)body(v, t, i, 1), (double)body(v, t, i, 2), (double)body(v, t, i, 3), (unsigned)t->age,
                    (unsigned)t->hits, (int)t->det, (double)sonar_track_still_s(t, d->utime));
            fprintf(f, ",\"existence\":%.3f,\"mode\":\"%s\",\"kind\":\"%s\"", (double)t->existence,
                    sonar_track_mode_str(t->mode), sonar_track_kind_str(t->kind));
            activity_json(f, t);
            if (v != NULL && v->world)
                fprintf(f, ",\"north_m\":%.3f,\"east_m\":%.3f,\"vn_mps\":%.3f,\"ve_mps\":%.3f", (double)t->px,
                        (double)t->py, (double)t->vx, (double)t->vy);
            fputs("}", f);
        }
        fputs("]", f);
        {
            /* IDs the last sweep published that this look revised: the track published as id is now. */
            unsigned nr, r;
            const struct sonar_track_revision *rv = sonar_tracker_revisions(tk, &nr);
            if (nr > 0) {
                fputs(",\"revisions\":[", f);
                for (r = 0; r < nr; r++)
                    fprintf(f, "%s{\"id\":%" PRIu32 ",\"now\":%" PRIu32 "}", r ? "," : "", rv[r].from, rv[r].to);
                fputs("]", f);
            }
        }
    }
    fputs("}\n", f);
    return ferror(f) ? -1 : 0;
}

int report_text(FILE *f, const struct sonar_detections *d, const struct sonar_tracker *tk, const struct msg_view *v)
{
    unsigned i;
    fprintf(f, "sweep %" PRIu32 ": %u beams, threshold %u, %u detection%s\n", d->sweep, (unsigned)d->beams,
            (unsigned)d->threshold, (unsigned)d->count, d->count == 1 ? "" : "s");
    if (v != NULL && v->have_pose)
        fprintf(f, "  vehicle  north %8.2f m  east %8.2f m  yaw %6.1f deg (tracks in the %s frame)\n",
                (double)v->pose.north_m, (double)v->pose.east_m, (double)v->pose.yaw_deg, v->world ? "world" : "body");
    for (i = 0; i < d->count; i++) {
        const struct sonar_detection *o = &d->det[i];
        fprintf(f, "  #%u  x %7.2f m  y %7.2f m  range %6.2f m  bearing %6.1f deg  area %6.3f m2  %5" PRIu32 " cells  mean %5.1f%s%s\n",
                i + 1, (double)o->x_m, (double)o->y_m, (double)o->range_m, (double)o->bearing_deg, (double)o->area_m2,
                o->points, (double)o->mean_intensity, o->kind == SONAR_DET_OBJECT ? "" : "  ", o->kind == SONAR_DET_OBJECT ? "" : sonar_det_kind_str(o->kind));
    }
    for (i = 0; tk != NULL && i < sonar_tracker_count(tk); i++) {
        const struct sonar_track *t = sonar_tracker_track(tk, i);
        fprintf(f, "  track %-5" PRIu32 " %-9s x %7.2f m  y %7.2f m  vx %6.2f  vy %6.2f m/s  age %u  hits %u  still %.0f s",
                t->id, sonar_track_state_str(t->state), (double)body(v, t, i, 0), (double)body(v, t, i, 1),
                (double)body(v, t, i, 2), (double)body(v, t, i, 3), (unsigned)t->age, (unsigned)t->hits,
                (double)sonar_track_still_s(t, d->utime));
        if (v != NULL && v->world)
            fprintf(f, "  N %8.2f E %8.2f m  vN %6.2f vE %6.2f m/s", (double)t->px, (double)t->py, (double)t->vx,
                    (double)t->vy);
        if (t->activity != SONAR_ACT_UNKNOWN)
            fprintf(f, "  %s", sonar_activity_str(t->activity));
        if (t->alarms & SONAR_ALARM_STRUGGLE)
            fputs("  STRUGGLE ALARM", f);
        if (t->alarms & SONAR_ALARM_STILL)
            fputs("  STILL ALARM", f);
        fputs(t->det >= 0 ? "\n" : "  (no detection)\n", f);
    }
    return ferror(f) ? -1 : 0;
}
