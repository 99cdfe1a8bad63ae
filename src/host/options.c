/* options.c -- sonard option parsing; every value is range-checked and a bad one is named with its unit. */
#include "options.h"

#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sonar/pipeline.h"

enum {
    OPT_REPLAY = 256, OPT_RANGE, OPT_SOS, OPT_OFFSET, OPT_MEDIAN, OPT_BACKGROUND, OPT_BG_WARMUP, OPT_BG_STEP, OPT_BG_MARGIN,
    OPT_THRESHOLD, OPT_MIN_THRESHOLD, OPT_CLUSTERS, OPT_MIN_POINTS, OPT_ITERATIONS, OPT_LINK_M, OPT_LINK_BEAMS,
    OPT_MAX_STEP, OPT_JSON, OPT_CSV_OUT, OPT_STAGE, OPT_QUIET, OPT_HELP, OPT_VERSION
};

void options_usage(const char *prog)
{
    printf("usage: %s --replay FILE.csv [options]\n"
           "Runs the sonar pipeline (median, background, detector) over a recording in the study's CSV form.\n\n"
           "input\n"
           "  --replay FILE          CSV rows: sec,nsec,angle,samples ('-' = stdin)\n"
           "  --range M              metres covered by each beam's samples, 1..60 (default: the file's\n"
           "                         range_m= metadata, else 2, Ping Viewer's default)\n"
           "  --speed-of-sound C     m/s, 1300..1700, used with sample_period metadata (default 1500)\n"
           "  --angle-offset G       gradians added to every angle of the output frame, -400..400 (default 0)\n"
           "filters\n"
           "  --median W|KxK         1 (off), 3, 5, 7 or 9 samples along range, or 3x3 / 5x5 over adjacent\n"
           "                         beams (the study's median_filter) (default 5)\n"
           "  --background MODE      per-angle | range | off (default per-angle; range = the study's median\n"
           "                         across the beams of a sweep)\n"
           "  --bg-warmup N          observations averaged to seed the background, 1..64 (default 2 sweeps\n"
           "                         per-angle, 8 beams range)\n"
           "  --bg-step N            grey levels the background moves per observation, 1..64 (default 1)\n"
           "  --bg-margin N          contrast margin: a cell must exceed the background b by b*N/16\n"
           "                         before it counts, 0..64; 0 = the study's plain subtraction (default 8)\n"
           "detector (once per sweep)\n"
           "  --threshold K          foreground cells > mean + K std of the previous sweep, 0..20 (default 3)\n"
           "  --min-threshold T      cells must exceed at least T grey levels, 0..254 (default 16)\n"
           "  --clusters MAX         most detections per sweep, 1..%d (default 8)\n"
           "  --min-points N         cells a detection needs, 1..65535 (default 20)\n"
           "  --iterations N         k-means rounds at most, 1..100 (default 10)\n"
           "  --link-m M             range gap in metres still joining one object, 0..10 (default 0.15)\n"
           "  --link-beams N         beams apart still joining one object, 1..8 (default 2)\n"
           "  --max-step G           an angle move larger than G gradians starts a sweep, 1..200 (default 20)\n"
           "output\n"
           "  --json                 one JSON line per sweep on stdout\n"
           "  --csv-out FILE         export beams in the study's CSV form ...\n"
           "  --stage S              ... after stage raw | median | foreground (default foreground)\n"
           "  --quiet                no per-sweep text and no summary\n"
           "  --help, --version\n",
           prog, SONAR_MAX_CLUSTERS);
}

static int num(const char *name, const char *s, double lo, double hi, const char *unit, double *v, char *err, size_t n)
{
    char *end;
    double x = strtod(s, &end);
    if (*s == '\0' || *end != '\0' || !(x >= lo && x <= hi)) {
        snprintf(err, n, "%s: '%s' is not a number in %g..%g %s", name, s, lo, hi, unit);
        return -1;
    }
    *v = x;
    return 0;
}

static int whole(const char *name, const char *s, long lo, long hi, const char *unit, long *v, char *err, size_t n)
{
    char *end;
    long x = strtol(s, &end, 10);
    if (*s == '\0' || *end != '\0' || x < lo || x > hi) {
        snprintf(err, n, "%s: '%s' is not a whole number in %ld..%ld %s", name, s, lo, hi, unit);
        return -1;
    }
    *v = x;
    return 0;
}

int options_parse(int argc, char **argv, struct sonard_options *o, char *err, size_t errlen)
{
    static const struct option longs[] = {
        {"replay", required_argument, NULL, OPT_REPLAY},
        {"range", required_argument, NULL, OPT_RANGE},
        {"speed-of-sound", required_argument, NULL, OPT_SOS},
        {"angle-offset", required_argument, NULL, OPT_OFFSET},
        {"median", required_argument, NULL, OPT_MEDIAN},
        {"background", required_argument, NULL, OPT_BACKGROUND},
        {"bg-warmup", required_argument, NULL, OPT_BG_WARMUP},
        {"bg-step", required_argument, NULL, OPT_BG_STEP},
        {"bg-margin", required_argument, NULL, OPT_BG_MARGIN},
        {"threshold", required_argument, NULL, OPT_THRESHOLD},
        {"min-threshold", required_argument, NULL, OPT_MIN_THRESHOLD},
        {"clusters", required_argument, NULL, OPT_CLUSTERS},
        {"min-points", required_argument, NULL, OPT_MIN_POINTS},
        {"iterations", required_argument, NULL, OPT_ITERATIONS},
        {"link-m", required_argument, NULL, OPT_LINK_M},
        {"link-beams", required_argument, NULL, OPT_LINK_BEAMS},
        {"max-step", required_argument, NULL, OPT_MAX_STEP},
        {"json", no_argument, NULL, OPT_JSON},
        {"csv-out", required_argument, NULL, OPT_CSV_OUT},
        {"stage", required_argument, NULL, OPT_STAGE},
        {"quiet", no_argument, NULL, OPT_QUIET},
        {"help", no_argument, NULL, OPT_HELP},
        {"version", no_argument, NULL, OPT_VERSION},
        {NULL, 0, NULL, 0}};
    struct sonar_pipeline_config *p = &o->pipeline;
    int c, warmup_set = 0;
    double d;
    long l;
    memset(o, 0, sizeof(*o));
    sonar_pipeline_defaults(p);
    o->range_m = -1.0;
    o->speed_of_sound = 1500.0;
    o->stage = SONAR_STAGE_FOREGROUND;
    opterr = 0;
    optind = 1;
    while ((c = getopt_long(argc, argv, ":", longs, NULL)) != -1) {
        const char *a = optarg;
        switch (c) {
        case OPT_REPLAY: o->replay = a; break;
        case OPT_RANGE: if (num("--range", a, 1, 60, "metres", &o->range_m, err, errlen)) return -1; break;
        case OPT_SOS: if (num("--speed-of-sound", a, 1300, 1700, "m/s", &o->speed_of_sound, err, errlen)) return -1; break;
        case OPT_OFFSET:
            if (num("--angle-offset", a, -400, 400, "gradians", &d, err, errlen)) return -1;
            p->detector.angle_offset = (float)d;
            break;
        case OPT_MEDIAN:
            if (strcmp(a, "3x3") == 0 || strcmp(a, "5x5") == 0) {
                p->median2d = (uint8_t)(a[0] - '0');
            } else {
                if (whole("--median", a, 1, SONAR_MAX_MEDIAN, "samples (odd), or 3x3 / 5x5", &l, err, errlen)) return -1;
                if (l % 2 == 0) {
                    snprintf(err, errlen, "--median: '%s' is even; use 1 (off), 3, 5, 7, 9, 3x3 or 5x5", a);
                    return -1;
                }
                p->median = (uint8_t)l;
                p->median2d = 0;
            }
            break;
        case OPT_BACKGROUND:
            if (strcmp(a, "per-angle") == 0) p->background.mode = SONAR_BACKGROUND_PER_ANGLE;
            else if (strcmp(a, "range") == 0) p->background.mode = SONAR_BACKGROUND_RANGE;
            else if (strcmp(a, "off") == 0) p->background.mode = SONAR_BACKGROUND_OFF;
            else {
                snprintf(err, errlen, "--background: '%s' is not per-angle, range or off", a);
                return -1;
            }
            break;
        case OPT_BG_WARMUP: if (whole("--bg-warmup", a, 1, 64, "observations", &l, err, errlen)) return -1; p->background.warmup = (uint8_t)l; warmup_set = 1; break;
        case OPT_BG_STEP: if (whole("--bg-step", a, 1, 64, "grey levels", &l, err, errlen)) return -1; p->background.step = (uint8_t)l; break;
        case OPT_BG_MARGIN: if (whole("--bg-margin", a, 0, 64, "sixteenths of the background", &l, err, errlen)) return -1; p->background.margin = (uint8_t)l; break;
        case OPT_THRESHOLD: if (num("--threshold", a, 0, 20, "standard deviations", &d, err, errlen)) return -1; p->detector.threshold_k = (float)d; break;
        case OPT_MIN_THRESHOLD: if (whole("--min-threshold", a, 0, 254, "grey levels", &l, err, errlen)) return -1; p->detector.min_threshold = (uint8_t)l; break;
        case OPT_CLUSTERS: if (whole("--clusters", a, 1, SONAR_MAX_CLUSTERS, "clusters", &l, err, errlen)) return -1; p->detector.max_clusters = (uint8_t)l; break;
        case OPT_MIN_POINTS: if (whole("--min-points", a, 1, 65535, "cells", &l, err, errlen)) return -1; p->detector.min_points = (uint16_t)l; break;
        case OPT_ITERATIONS: if (whole("--iterations", a, 1, 100, "rounds", &l, err, errlen)) return -1; p->detector.iterations = (uint8_t)l; break;
        case OPT_LINK_M: if (num("--link-m", a, 0, 10, "metres", &d, err, errlen)) return -1; p->detector.link_m = (float)d; break;
        case OPT_LINK_BEAMS: if (whole("--link-beams", a, 1, 8, "beams", &l, err, errlen)) return -1; p->detector.link_beams = (uint8_t)l; break;
        case OPT_MAX_STEP: if (whole("--max-step", a, 1, 200, "gradians", &l, err, errlen)) return -1; p->max_step = (uint16_t)l; break;
        case OPT_JSON: o->json = 1; break;
        case OPT_CSV_OUT: o->csv_out = a; break;
        case OPT_STAGE:
            if (strcmp(a, "raw") == 0) o->stage = SONAR_STAGE_RAW;
            else if (strcmp(a, "median") == 0) o->stage = SONAR_STAGE_MEDIAN;
            else if (strcmp(a, "foreground") == 0) o->stage = SONAR_STAGE_FOREGROUND;
            else {
                snprintf(err, errlen, "--stage: '%s' is not raw, median or foreground", a);
                return -1;
            }
            break;
        case OPT_QUIET: o->quiet = 1; break;
        case OPT_HELP: options_usage(argv[0]); return 1;
        case OPT_VERSION: printf("sonard 0.1.0\n"); return 1;
        case ':':
            snprintf(err, errlen, "%s: needs a value", argv[optind - 1]);
            return -1;
        default:
            snprintf(err, errlen, "%s: unknown option (see --help)", argv[optind - 1]);
            return -1;
        }
    }
    if (optind < argc) {
        snprintf(err, errlen, "%s: unexpected argument (see --help)", argv[optind]);
        return -1;
    }
    /* Warm-up counts observations: a sweep per cell in per-angle mode, a beam per bin in range mode. */
    if (!warmup_set)
        p->background.warmup = p->background.mode == SONAR_BACKGROUND_RANGE ? 8 : 2;
    if (o->replay == NULL) {
        snprintf(err, errlen, "--replay: a CSV file is required (see --help)");
        return -1;
    }
    return 0;
}
