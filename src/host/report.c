/* report.c -- JSON and text renderings of a sweep's detections and tracks; a few hundred bytes of stdio per sweep. */
#include "report.h"

#include <inttypes.h>

int report_json(FILE *f, const struct sonar_detections *d, const struct sonar_tracker *tk)
{
    unsigned i, v;
    fprintf(f, "{\"sweep\":%" PRIu32 ",\"utime\":%" PRId64 ",\"beams\":%u,\"threshold\":%u,\"runs\":%u,\"groups\":%u,\"detections\":[",
            d->sweep, d->utime, (unsigned)d->beams, (unsigned)d->threshold, (unsigned)d->runs, (unsigned)d->groups);
    for (i = 0; i < d->count; i++) {
        const struct sonar_detection *o = &d->det[i];
        fprintf(f, "%s{\"utime\":%" PRId64 ",\"x_m\":%.3f,\"y_m\":%.3f,\"range_m\":%.3f,\"bearing_deg\":%.2f,\"area_m2\":%.4f,\"points\":%" PRIu32
                   ",\"mean_intensity\":%.1f,\"hull\":[",
                i ? "," : "", o->utime, (double)o->x_m, (double)o->y_m, (double)o->range_m, (double)o->bearing_deg,
                (double)o->area_m2, o->points, (double)o->mean_intensity);
        for (v = 0; v < o->hull_count; v++)
            fprintf(f, "%s[%.3f,%.3f]", v ? "," : "", (double)o->hull_x[v], (double)o->hull_y[v]);
        fputs("]}", f);
    }
    fputs("]", f);
    if (tk != NULL) {
        fputs(",\"tracks\":[", f);
        for (i = 0; i < tk->n; i++) {
            const struct sonar_track *t = &tk->t[i];
            fprintf(f, "%s{\"id\":%" PRIu32 ",\"state\":\"%s\",\"utime\":%" PRId64 ",\"x_m\":%.3f,\"y_m\":%.3f,\"vx_mps\":%.3f,"
                       "\"vy_mps\":%.3f,\"age\":%u,\"hits\":%u,\"detection\":%d}",
                    i ? "," : "", t->id, sonar_track_state_str(t->state), t->utime, (double)t->px, (double)t->py,
                    (double)t->vx, (double)t->vy, (unsigned)t->age, (unsigned)t->hits, (int)t->det);
        }
        fputs("]", f);
    }
    fputs("}\n", f);
    return ferror(f) ? -1 : 0;
}

int report_text(FILE *f, const struct sonar_detections *d, const struct sonar_tracker *tk)
{
    unsigned i;
    fprintf(f, "sweep %" PRIu32 ": %u beams, threshold %u, %u detection%s\n", d->sweep, (unsigned)d->beams,
            (unsigned)d->threshold, (unsigned)d->count, d->count == 1 ? "" : "s");
    for (i = 0; i < d->count; i++) {
        const struct sonar_detection *o = &d->det[i];
        fprintf(f, "  #%u  x %7.2f m  y %7.2f m  range %6.2f m  bearing %6.1f deg  area %6.3f m2  %5" PRIu32 " cells  mean %5.1f\n",
                i + 1, (double)o->x_m, (double)o->y_m, (double)o->range_m, (double)o->bearing_deg, (double)o->area_m2,
                o->points, (double)o->mean_intensity);
    }
    for (i = 0; tk != NULL && i < tk->n; i++) {
        const struct sonar_track *t = &tk->t[i];
        fprintf(f, "  track %-5" PRIu32 " %-9s x %7.2f m  y %7.2f m  vx %6.2f  vy %6.2f m/s  age %u  hits %u%s\n", t->id,
                sonar_track_state_str(t->state), (double)t->px, (double)t->py, (double)t->vx, (double)t->vy,
                (unsigned)t->age, (unsigned)t->hits, t->det >= 0 ? "" : "  (no detection)");
    }
    return ferror(f) ? -1 : 0;
}
