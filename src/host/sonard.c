/* sonard.c -- the sonard front end: --sonar (live, live.c) or --replay of a CSV recording through the core pipeline. */
#include <errno.h>
#include <inttypes.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "csv.h"
#include "live.h"
#include "options.h"
#include "report.h"
#include "sonar/geometry.h"
#include "sonar/pipeline.h"

struct replay {
    struct sonard_options opt;
    struct sonar_pipeline pipe;
    struct csv_reader csv;
    struct csv_row row;
    FILE *csv_out;
    unsigned long sweeps, detections, write_errors;
};

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + (double)t.tv_nsec * 1e-9;
}

static void on_beam(void *user, int stage, const struct sonar_beam *b)
{
    struct replay *r = user;
    struct csv_meta m = csv_meta_none();
    if (r->csv_out == NULL || stage != r->opt.stage)
        return;
    m.range_m = (double)b->range_m;
    if (csv_write(r->csv_out, b->utime / 1000000, (uint32_t)(b->utime % 1000000) * 1000u, b->angle, b->samples, b->n,
                  &m) != 0)
        r->write_errors++;
}

static void on_sweep(void *user, const struct sonar_detections *d)
{
    struct replay *r = user;
    r->sweeps++;
    r->detections += d->count;
    if (r->opt.json)
        report_json(stdout, d);
    else if (!r->opt.quiet)
        report_text(stdout, d);
}

/* Range of a row: --range, else the row's range_m or sample_period metadata, else 2 m. */
static float row_range(const struct replay *r)
{
    const struct csv_row *w = &r->row;
    if (r->opt.range_m > 0.0)
        return (float)r->opt.range_m;
    if (w->range_m > 0.0)
        return (float)w->range_m;
    if (w->sample_period > 0.0) {
        double c = w->speed_of_sound > 0.0 ? w->speed_of_sound : r->opt.speed_of_sound;
        return (float)sonar_geometry_range_m((uint16_t)w->sample_period, w->n, c);
    }
    return 2.0f;
}

int main(int argc, char **argv)
{
    static struct replay r; /* ~600 KB: too big for the stack, and main's own, so not a shared global */
    char err[256];
    double t0, t1;
    int rc, got;

    rc = options_parse(argc, argv, &r.opt, err, sizeof(err));
    if (rc != 0) {
        if (rc < 0)
            fprintf(stderr, "sonard: %s\n", err);
        return rc < 0 ? 2 : 0;
    }
    if (r.opt.sonar != NULL)
        return live_run(&r.opt);
    r.opt.pipeline.on_beam = on_beam;
    r.opt.pipeline.on_sweep = on_sweep;
    r.opt.pipeline.user = &r;
    if (sonar_pipeline_init(&r.pipe, &r.opt.pipeline) != SONAR_OK) {
        fprintf(stderr, "sonard: the pipeline configuration is invalid\n");
        return 2;
    }
    if (csv_open(&r.csv, r.opt.replay) != 0) {
        fprintf(stderr, "sonard: %s: %s\n", r.opt.replay, strerror(errno));
        return 2;
    }
    if (r.opt.csv_out != NULL && (r.csv_out = fopen(r.opt.csv_out, "w")) == NULL) {
        fprintf(stderr, "sonard: --csv-out %s: %s\n", r.opt.csv_out, strerror(errno));
        csv_close(&r.csv);
        return 2;
    }
    t0 = now_s();
    while ((got = csv_next(&r.csv, &r.row, err, sizeof(err))) != 0) {
        struct sonar_beam b;
        int pr;
        if (got < 0) {
            fprintf(stderr, "%s:%lu: %s; row skipped\n", r.opt.replay, r.csv.line, err);
            continue;
        }
        b.utime = r.row.sec * 1000000 + (int64_t)(r.row.nsec / 1000u);
        b.angle = r.row.angle;
        b.n = r.row.n;
        b.range_m = row_range(&r);
        b.samples = r.row.samples;
        if ((pr = sonar_pipeline_push(&r.pipe, &b)) != SONAR_OK)
            fprintf(stderr, "%s:%lu: %s; row skipped\n", r.opt.replay, r.csv.line, sonar_err_str(pr));
    }
    if (sonar_pipeline_finish(&r.pipe) != SONAR_OK)
        fprintf(stderr, "sonard: finishing the last sweep failed\n");
    t1 = now_s();
    fflush(stdout);
    if (r.csv_out != NULL && fclose(r.csv_out) != 0)
        r.write_errors++;
    if (r.write_errors)
        fprintf(stderr, "sonard: --csv-out %s: %lu rows could not be written\n", r.opt.csv_out, r.write_errors);
    if (!r.opt.quiet)
        fprintf(stderr, "sonard: %s: %lu rows used, %lu skipped, %lu sweeps, %lu detections, %.1f ms (%.2f us/beam)\n",
                r.opt.replay, r.csv.good, r.csv.bad, r.sweeps, r.detections, (t1 - t0) * 1e3,
                r.csv.good ? (t1 - t0) * 1e6 / (double)r.csv.good : 0.0);
    else if (r.csv.bad)
        fprintf(stderr, "sonard: %s: %lu rows skipped\n", r.opt.replay, r.csv.bad);
    csv_close(&r.csv);
    return r.csv.good == 0 ? 1 : (r.write_errors ? 1 : 0);
}
