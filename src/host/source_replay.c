/* source_replay.c -- CSV rows -> beam records: the range from --range, the row's metadata or 2 m; O(row) per row. */
#include "source_replay.h"

#include <errno.h>
#include <inttypes.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "sonar/geometry.h"
#include "sonar/ping360.h"

/* Everything but the reader: the caller's range and c, no pose file, no pacing, the untimed clock at 0. */
static void reset(struct source_replay *r, double range_m, double speed_of_sound)
{
    r->range_m = range_m;
    r->speed_of_sound = speed_of_sound;
    r->pose = NULL;
    r->beam_ms = 0.0;
    r->speed = 0.0;
    r->progress = r->quiet = 0;
    r->clock_us = 0;
    r->prev_angle = -1;
}

int source_replay_open(struct source_replay *r, const char *path, double range_m, double speed_of_sound, char *err,
                       size_t errlen)
{
    if (csv_open(&r->csv, path) != 0) {
        snprintf(err, errlen, "%s: %s", path, strerror(errno));
        return HOST_ERR_IO;
    }
    reset(r, range_m, speed_of_sound);
    return HOST_OK;
}

void source_replay_stream(struct source_replay *r, FILE *f, const char *name, double range_m, double speed_of_sound)
{
    csv_open_stream(&r->csv, f, name);
    reset(r, range_m, speed_of_sound);
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

/* Untimed rows: each one a modelled beam (or --beam-ms) after the previous, from 0. */
static int64_t untimed_utime(struct source_replay *r, float range_m, double c)
{
    if (r->prev_angle >= 0) {
        unsigned d = (unsigned)(r->row.angle > r->prev_angle ? r->row.angle - r->prev_angle : r->prev_angle - r->row.angle);
        unsigned step = d > 200u ? 400u - d : d; /* the short way round */
        r->clock_us += r->beam_ms > 0.0 ? (int64_t)(r->beam_ms * 1000.0 + 0.5)
                                        : (int64_t)sonar_ping360_model_us(step, range_m, (float)c, 0, r->row.n);
    }
    r->prev_angle = r->row.angle;
    return r->clock_us;
}

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + (double)t.tv_nsec * 1e-9;
}

#define PACE_LATE_S 0.1 /* a row this late: the host stalled; the replay goes on at its pace, not in a burst */

/*
 * --replay-speed: waits until the row's recorded time, scaled, has come; a clock that jumps back does not wait. A
 * row over PACE_LATE_S late moves the pace on by its lateness, as a sonar paused with its host would. Returns the
 * wall time the recording's utime0 is now paced from.
 */
static double pace(const struct source_replay *r, int64_t utime, int64_t utime0, double wall0)
{
    double due = wall0 + (double)(utime - utime0) * 1e-6 / r->speed, wait = due - now_s();
    if (wait < -PACE_LATE_S)
        return wall0 - wait;
    if (wait > 0.0) {
        struct timespec ts;
        if (wait > 10.0)
            wait = 10.0; /* a gap in the recording is not waited out in full */
        ts.tv_sec = (time_t)wait;
        ts.tv_nsec = (long)((wait - (double)ts.tv_sec) * 1e9);
        nanosleep(&ts, NULL);
    }
    return wall0;
}

/* "beams 12000  sweeps 30  41000 beams/s  37 %  ETA 3 s", over itself with \r. */
static void show_progress(struct source_replay *r, const struct app *a, FILE *errf, double t0, long size, int last)
{
    double dt = now_s() - t0;
    long at = ftell(r->csv.f);
    double rate = dt > 0.0 ? (double)r->csv.good / dt : 0.0;
    fprintf(errf, "\r%s: beams %lu  sweeps %" PRIu32 "  %.0f beams/s", r->csv.path, r->csv.good, app_sweeps(a), rate);
    if (size > 0 && at >= 0) {
        double frac = (double)at / (double)size;
        fprintf(errf, "  %3.0f %%", 100.0 * frac);
        if (frac > 0.0 && !last)
            fprintf(errf, "  ETA %.0f s ", dt * (1.0 - frac) / frac);
        else
            fprintf(errf, "           ");
    }
    if (last)
        fputc('\n', errf);
    fflush(errf);
}

unsigned long source_replay_run(struct source_replay *r, struct app *a, FILE *errf)
{
    char err[256];
    int got, said = 0;
    double t0 = now_s(), next_show = t0 + 0.25, wall0 = 0.0;
    int64_t utime0 = 0;
    int paced = 0;
    long size = -1;
    struct stat st;
    if (r->progress && errf != NULL && fstat(fileno(r->csv.f), &st) == 0 && S_ISREG(st.st_mode))
        size = (long)st.st_size;
    while ((got = csv_next(&r->csv, &r->row, err, sizeof(err))) != 0) {
        if (!said && r->csv.format != CSV_FORMAT_UNKNOWN) {
            said = 1;
            if (errf != NULL && !r->quiet && r->csv.format == CSV_FORMAT_UNTIMED)
                fprintf(errf, "sonard: %s: %s: beams timed %s\n", r->csv.path, csv_format_name(&r->csv),
                        r->beam_ms > 0.0 ? "--beam-ms apart" : "by the Ping360 model (19.4 ms + 6 ms a gradian + 2R/c)");
            else if (errf != NULL && !r->quiet)
                fprintf(errf, "sonard: %s: %s\n", r->csv.path, csv_format_name(&r->csv));
        }
        if (r->progress && errf != NULL && (r->csv.good & 255u) == 0 && now_s() >= next_show) {
            show_progress(r, a, errf, t0, size, 0);
            next_show = now_s() + 0.25;
        }
        const struct csv_row *w = &r->row;
        struct sonar_record b;
        double c = w->speed_of_sound > 0.0 ? w->speed_of_sound : r->speed_of_sound;
        int pr;
        if (got < 0) {
            app_row_bad(a);
            if (errf != NULL)
                fprintf(errf, "%s:%lu: %s; row skipped\n", r->csv.path, r->csv.line, err);
            continue;
        }
        b.angle = w->angle;
        b.n = w->n;
        b.gain = meta_int(w->gain);
        b.sample_period = meta_int(w->sample_period);
        b.transmit_duration = meta_int(w->transmit_duration);
        b.transmit_frequency = meta_int(w->transmit_frequency);
        b.speed_of_sound = (float)c;
        b.range_m = row_range(r, c);
        b.utime = w->timed ? w->sec * 1000000 + (int64_t)(w->nsec / 1000u) /* the reader bounds sec to fit */
                           : untimed_utime(r, b.range_m, c);
        b.stage = SONAR_STAGE_RAW;
        /* A pose file, when given, says where the vehicle was; else the row's own pose, if any. */
        b.has_pose = (uint8_t)(r->pose == NULL && w->has_pose);
        b.north_m = (float)w->north_m;
        b.east_m = (float)w->east_m;
        b.yaw_deg = (float)w->yaw_deg;
        b.samples = w->samples;
        if (r->speed > 0.0) {
            if (!paced || b.utime < utime0) {
                paced = 1;
                utime0 = b.utime;
                wall0 = now_s();
            }
            wall0 = pace(r, b.utime, utime0, wall0);
        }
        if (r->pose != NULL)
            posefile_feed(r->pose, a, b.utime + SONAR_POSE_STALE_US, errf);
        if ((pr = app_push(a, &b)) != HOST_OK) {
            app_row_bad(a);
            if (errf != NULL)
                fprintf(errf, "%s:%lu: %s; row skipped\n", r->csv.path, r->csv.line, host_err_str(pr));
        }
    }
    if (app_finish(a) != HOST_OK && errf != NULL)
        fprintf(errf, "sonard: finishing the last sweep failed\n");
    if (r->progress && errf != NULL)
        show_progress(r, a, errf, t0, size, 1);
    return r->csv.good;
}

void source_replay_close(struct source_replay *r)
{
    csv_close(&r->csv);
}
