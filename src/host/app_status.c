/* app_status.c -- the app's health: counters collected into a status record, the per-beam time percentiles, the accessors sources and sinks read; O(APP_PROC_RING log APP_PROC_RING) a report. */
#include "app_internal.h"

#include <stdlib.h>
#include <string.h>

static int cmpf(const void *x, const void *y)
{
    float p = *(const float *)x, q = *(const float *)y;
    return p < q ? -1 : p > q;
}

unsigned long app_sink_errors(const struct app *a)
{
    unsigned long e = 0;
    unsigned i;
    for (i = 0; i < a->nsinks; i++)
        e += a->sinks[i]->errors;
    return e;
}

/* What only this process knows, whoever made the rest of the record: its sinks' errors, its poses, its sinks'
   own counters (the autopilot's), and its tracker's (SONAR_TRACKS come from it, with or without a co-processor). */
void app_host_status(const struct app *a, struct sonar_status *s)
{
    unsigned i;
    s->sink_errors = (uint32_t)app_sink_errors(a);
    s->pose.state = a->pose_state;
    sonar_status_poses(s, &a->poses);
    s->pose.stale = a->pose_stale;
    sonar_status_tracking(s, &a->pipe);
    for (i = 0; i < a->nsinks; i++)
        if (a->sinks[i]->fill != NULL)
            a->sinks[i]->fill(a->sinks[i]->self, s);
}

void app_report_status(struct app *a, int link_state, struct sonar_status *s)
{
    unsigned n = (unsigned)(a->nproc < APP_PROC_RING ? a->nproc : APP_PROC_RING);
    memcpy(a->sorted, a->proc_us, n * sizeof(float));
    qsort(a->sorted, n, sizeof(float), cmpf);
    memset(s, 0, sizeof(*s));
    s->utime = app_wall_us(a);
    s->link_state = link_state;
    s->link = a->link;
    sonar_status_fill(s, a->have_dev ? &a->dev : NULL, &a->pipe);
    s->sweeps = a->sweeps;
    s->beams_rejected = a->beams_rejected;
    s->rows_bad = a->rows_bad;
    s->last_sweep_s = a->last_sweep_s;
    s->beam_us_p50 = n ? a->sorted[n / 2] : 0.0f;
    s->beam_us_p99 = n ? a->sorted[(n * 99) / 100] : 0.0f;
    s->acq.gain = a->have_dev && !sonar_device_passive(&a->dev) ? (int)sonar_device_config(&a->dev)->gain : (int)a->last_gain;
    if (a->have_dev && sonar_device_passive(&a->dev)) {
        s->passive.on = 1;
        s->passive.idle = a->passive_idle;
        s->passive.samples = a->passive_last.n;
        s->passive.range_m = a->passive_last.range_m;
        s->passive.changes = a->passive_changes;
    }
    s->acq.gain_auto = a->have_gain_auto && !a->gain_off;
    s->acq.gain_changes = a->have_gain_auto ? a->gain.changes : 0u;
    s->acq.gain_refused = a->gain_refused;
    s->acq.background_restarts = a->bg_restarts;
    if (a->have_scan) {
        s->scan.mode = a->scan.cfg.mode;
        s->scan.interleave = a->scan.k;
        s->scan.target_pings = a->scan.counters.target_pings;
        s->scan.surveil_pings = a->scan.counters.surveil_pings;
        s->scan.late_looks = a->scan.counters.late_looks;
        s->scan.targets_dropped = a->scan.counters.targets_dropped;
    }
    app_host_status(a, s);
    app_send_status(a, s);
}

int64_t app_mono_us(const struct app *a)
{
    return a->clock.mono_ns(a->clock.user) / 1000;
}

int64_t app_wall_us(const struct app *a)
{
    return a->clock.wall_us(a->clock.user);
}

uint32_t app_sweeps(const struct app *a) { return a->sweeps; }
int app_done(const struct app *a) { return a->sweeps_done; }
uint32_t app_beams_rejected(const struct app *a) { return a->beams_rejected; }
uint32_t app_blank_beams(const struct app *a) { return sonar_pipeline_blank_beams(&a->pipe); }
uint32_t app_interference_beams(const struct app *a) { return sonar_pipeline_interference_beams(&a->pipe); }
uint32_t app_rows_bad(const struct app *a) { return a->rows_bad; }
float app_last_sweep_s(const struct app *a) { return a->last_sweep_s; }
const struct sonar_pipeline *app_pipeline(const struct app *a) { return &a->pipe; }

void app_row_bad(struct app *a)
{
    a->rows_bad++;
}

const struct app_sink *app_sink_at(const struct app *a, unsigned i)
{
    return i < a->nsinks ? a->sinks[i] : NULL;
}

void app_set_link(struct app *a, const char *desc)
{
    a->link = desc;
}
