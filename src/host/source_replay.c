/* source_replay.c -- CSV rows -> beam records: the range from --range, the row's metadata or 2 m; O(row) per row. */
#include "source_replay.h"

#include <errno.h>
#include <string.h>

#include "sonar/geometry.h"

int source_replay_open(struct source_replay *r, const char *path, double range_m, double speed_of_sound, char *err,
                       size_t errlen)
{
    if (csv_open(&r->csv, path) != 0) {
        snprintf(err, errlen, "%s: %s", path, strerror(errno));
        return HOST_ERR_IO;
    }
    r->range_m = range_m;
    r->speed_of_sound = speed_of_sound;
    r->pose = NULL;
    return HOST_OK;
}

void source_replay_stream(struct source_replay *r, FILE *f, const char *name, double range_m, double speed_of_sound)
{
    csv_open_stream(&r->csv, f, name);
    r->range_m = range_m;
    r->speed_of_sound = speed_of_sound;
    r->pose = NULL;
}

/* Range of a row: --range, else the row's range_m or sample_period metadata, else 2 m. */
static float row_range(const struct source_replay *r, double c)
{
    const struct csv_row *w = &r->row;
    if (r->range_m > 0.0)
        return (float)r->range_m;
    if (w->range_m > 0.0)
        return (float)w->range_m;
    if (w->sample_period > 0.0)
        return (float)sonar_geometry_range_m((uint16_t)w->sample_period, w->n, c);
    return 2.0f;
}

static int32_t meta_int(double v)
{
    return v >= 0.0 ? (int32_t)(v + 0.5) : -1; /* the reader bounds every value to 0..65535 */
}

unsigned long source_replay_run(struct source_replay *r, struct app *a, FILE *errf)
{
    char err[256];
    int got;
    while ((got = csv_next(&r->csv, &r->row, err, sizeof(err))) != 0) {
        const struct csv_row *w = &r->row;
        struct app_beam b;
        double c = w->speed_of_sound > 0.0 ? w->speed_of_sound : r->speed_of_sound;
        int pr;
        if (got < 0) {
            a->rows_bad++;
            if (errf != NULL)
                fprintf(errf, "%s:%lu: %s; row skipped\n", r->csv.path, r->csv.line, err);
            continue;
        }
        b.utime = w->sec * 1000000 + (int64_t)(w->nsec / 1000u); /* the reader bounds sec to fit */
        b.angle = w->angle;
        b.n = w->n;
        b.gain = meta_int(w->gain);
        b.sample_period = meta_int(w->sample_period);
        b.transmit_duration = meta_int(w->transmit_duration);
        b.transmit_frequency = meta_int(w->transmit_frequency);
        b.speed_of_sound = (float)c;
        b.range_m = row_range(r, c);
        b.stage = SONAR_STAGE_RAW;
        /* A pose file, when given, says where the vehicle was; else the row's own pose, if any. */
        b.has_pose = (uint8_t)(r->pose == NULL && w->has_pose);
        b.north_m = (float)w->north_m;
        b.east_m = (float)w->east_m;
        b.yaw_deg = (float)w->yaw_deg;
        b.samples = w->samples;
        if (r->pose != NULL)
            posefile_feed(r->pose, a, b.utime + SONAR_POSE_STALE_US, errf);
        if ((pr = app_push(a, &b)) != HOST_OK) {
            a->rows_bad++;
            if (errf != NULL)
                fprintf(errf, "%s:%lu: %s; row skipped\n", r->csv.path, r->csv.line, host_err_str(pr));
        }
    }
    if (app_finish(a) != SONAR_OK && errf != NULL)
        fprintf(errf, "sonard: finishing the last sweep failed\n");
    return r->csv.good;
}

void source_replay_close(struct source_replay *r)
{
    csv_close(&r->csv);
}
