/* options.c -- sonard option parsing from the command line and a key = value file; every value is range-checked and a bad one is named with its unit. */
#include "options.h"

#include <errno.h>
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum {
    OPT_REPLAY = 256, OPT_SONAR, OPT_BAUD, OPT_LCM, OPT_PREFIX, OPT_FILTERED, OPT_NO_LCM, OPT_SWEEPS, OPT_MODE,
    OPT_SECTOR, OPT_STEP, OPT_GAIN, OPT_FREQUENCY, OPT_SAMPLES, OPT_TX, OPT_CONFIG, OPT_RANGE, OPT_SOS, OPT_OFFSET,
    OPT_MEDIAN, OPT_BACKGROUND, OPT_BG_WARMUP, OPT_BG_STEP, OPT_BG_MARGIN, OPT_THRESHOLD, OPT_MIN_THRESHOLD,
    OPT_CLUSTERS, OPT_MIN_POINTS, OPT_MIN_BEAMS, OPT_MAX_EXTENT, OPT_SPLIT_POINTS, OPT_MIN_RANGE, OPT_MAX_ASPECT, OPT_TRACK_M, OPT_TRACK_POINTS, OPT_ITERATIONS, OPT_LINK_M, OPT_LINK_BEAMS, OPT_MAX_STEP, OPT_JSON, OPT_CSV_OUT,
    OPT_STAGE, OPT_QUIET, OPT_HELP, OPT_VERSION
};

static const struct option longs[] = {
    {"replay", required_argument, NULL, OPT_REPLAY},
    {"sonar", required_argument, NULL, OPT_SONAR},
    {"baud", required_argument, NULL, OPT_BAUD},
    {"lcm", required_argument, NULL, OPT_LCM},
    {"channel-prefix", required_argument, NULL, OPT_PREFIX},
    {"publish-filtered", no_argument, NULL, OPT_FILTERED},
    {"no-lcm", no_argument, NULL, OPT_NO_LCM},
    {"sweeps", required_argument, NULL, OPT_SWEEPS},
    {"mode", required_argument, NULL, OPT_MODE},
    {"sector", required_argument, NULL, OPT_SECTOR},
    {"step", required_argument, NULL, OPT_STEP},
    {"gain", required_argument, NULL, OPT_GAIN},
    {"frequency", required_argument, NULL, OPT_FREQUENCY},
    {"samples", required_argument, NULL, OPT_SAMPLES},
    {"transmit-duration", required_argument, NULL, OPT_TX},
    {"config", required_argument, NULL, OPT_CONFIG},
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
    {"min-beams", required_argument, NULL, OPT_MIN_BEAMS},
    {"max-extent", required_argument, NULL, OPT_MAX_EXTENT},
    {"split-points", required_argument, NULL, OPT_SPLIT_POINTS},
    {"min-range", required_argument, NULL, OPT_MIN_RANGE},
    {"max-aspect", required_argument, NULL, OPT_MAX_ASPECT},
    {"track-m", required_argument, NULL, OPT_TRACK_M},
    {"track-points", required_argument, NULL, OPT_TRACK_POINTS},
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

void options_usage(const char *prog)
{
    printf("usage: %s --sonar URL [options]      live: drive a Ping360, publish over LCM\n"
           "       %s --replay FILE.csv [options] offline: a recording in the study's CSV form\n\n"
           "live\n"
           "  --sonar URL            serial:/dev/ttyUSB0[:BAUD] | udp:HOST:PORT (Ethernet Ping360: 12345,\n"
           "                         BlueOS bridge: 9092) | tcp:HOST:PORT\n"
           "  --baud N|auto          serial bit rate (default 115200; auto tries Ping Viewer's list)\n"
           "  --mode step|auto       step: one transducer request per beam; auto: auto_transmit when the\n"
           "                         firmware is newer than 3.3.0, else step (default step)\n"
           "  --sector START:STOP    gradians 0..399, swept back and forth; 'full' for full turns (default full)\n"
           "  --step G               gradians per beam, 1..50 (1..10 in auto mode) (default 1)\n"
           "  --gain G               0 low, 1 normal, 2 high (default 0)\n"
           "  --frequency F          transmit frequency, kHz 500..1000 (default 750)\n"
           "  --samples N            samples per beam, 200..1200 (default: the most the range allows)\n"
           "  --transmit-duration U  us 5..500 (default: automatic, 8000 R / c floored at 2.5 samples)\n"
           "  --sweeps N             stop after N sweeps (default: run until SIGINT/SIGTERM)\n"
           "  --lcm URL              LCM provider (default LCM's own: $LCM_DEFAULT_URL, else udpm ttl=0)\n"
           "  --channel-prefix P     channels P + SONAR_BEAM, SONAR_DETECTIONS, SONAR_STATUS (default none)\n"
           "  --publish-filtered     also publish foreground beams on SONAR_BEAM_FILTERED\n"
           "  --no-lcm               publish nothing (JSON / CSV only)\n"
           "  --csv-out FILE         record raw beams in the study's CSV, plus metadata columns\n"
           "  --config FILE          key = value lines, keys as the long options; several apply in order;\n"
           "                         flags override them\n"
           "geometry\n"
           "  --range M              metres, 1..60 (default 2, Ping Viewer's; in replay: the file's range_m=\n"
           "                         metadata when present)\n"
           "  --speed-of-sound C     m/s, 1300..1700 (default 1500)\n"
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
           "                         before it counts, 0..64; 0 = the study's plain subtraction (default 8)\n",
           prog, prog);
    printf("detector (once per sweep)\n"
           "  --threshold K          foreground cells > mean + K std of the previous sweep, 0..20 (default 3)\n"
           "  --min-threshold T      cells must exceed at least T grey levels, 0..254 (default 16)\n"
           "  --clusters MAX         most detections per sweep, 1..%d (default 8)\n"
           "  --min-points N         cells a detection needs, 1..65535 (default 20)\n"
           "  --min-beams N          beams a detection must span, 0..255 (default 1)\n"
           "  --max-extent M         drop detections wider than M metres (structure), 0 = no limit (default 0)\n"
           "  --split-points N       cut groups wider than --max-extent with k-means into pieces about half\n"
           "                         of it across, keeping pieces of >= N cells; 0 = drop them whole (default 0)\n"
           "  --min-range M          drop detections nearer than M metres (ring-down, the mount), 0..1000 (default 0)\n"
           "  --max-aspect R         drop detections R times longer along the beam than across (radial\n"
           "                         streaks), 0.1..100, 0 = no limit (default 0)\n"
           "  --track-m M            a cluster within M metres of a detection of the previous sweep needs\n"
           "                         only --track-points cells, 0..100, 0 = off (default 0)\n"
           "  --track-points N       cells a tracked cluster needs, 1..65535 (default 10)\n"
           "  --iterations N         k-means rounds at most, 1..100 (default 10)\n"
           "  --link-m M             range gap in metres still joining one object, 0..10 (default 0.15)\n"
           "  --link-beams N         beams apart still joining one object, 1..8 (default 2)\n"
           "  --max-step G           an angle move larger than G gradians starts a sweep, 1..200 (default 20)\n"
           "output\n"
           "  --json                 one JSON line per sweep on stdout\n"
           "  --stage S              replay --csv-out: export after raw | median | foreground (default foreground)\n"
           "  --quiet                no per-sweep text and no summary\n"
           "  --help, --version\n",
           SONAR_MAX_CLUSTERS);
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

struct parse_state {
    int warmup_set;
};

/* Applies one option; returns 0, 1 (help/version shown) or -1 with err set. */
static int apply(struct sonard_options *o, int c, const char *a, const char *prog, struct parse_state *ps, char *err,
                 size_t errlen)
{
    struct sonar_pipeline_config *p = &o->pipeline;
    struct sonar_ping360_config *d = &o->device;
    double v;
    long l;
    switch (c) {
    case OPT_REPLAY: o->replay = a; break;
    case OPT_SONAR:
        if (strncmp(a, "serial:", 7) != 0 && strncmp(a, "udp:", 4) != 0 && strncmp(a, "tcp:", 4) != 0) {
            snprintf(err, errlen, "--sonar: '%s' is not serial:PATH[:BAUD], udp:HOST:PORT or tcp:HOST:PORT", a);
            return -1;
        }
        o->sonar = a;
        break;
    case OPT_BAUD:
        if (strcmp(a, "auto") == 0)
            o->baud = -1;
        else if (whole("--baud", a, 1200, 4000000, "bits/s (or auto)", &o->baud, err, errlen))
            return -1;
        break;
    case OPT_LCM: o->lcm_url = a; break;
    case OPT_PREFIX:
        if (strlen(a) >= sizeof(o->channel_prefix) - 1) {
            snprintf(err, errlen, "--channel-prefix: '%s' is longer than %d characters", a, (int)sizeof(o->channel_prefix) - 2);
            return -1;
        }
        strcpy(o->channel_prefix, a);
        break;
    case OPT_FILTERED: o->publish_filtered = 1; break;
    case OPT_NO_LCM: o->no_lcm = 1; break;
    case OPT_SWEEPS: if (whole("--sweeps", a, 1, 1000000000L, "sweeps", &o->sweeps, err, errlen)) return -1; break;
    case OPT_MODE:
        if (strcmp(a, "auto") == 0) d->use_auto = 1;
        else if (strcmp(a, "step") == 0) d->use_auto = 0;
        else {
            snprintf(err, errlen, "--mode: '%s' is not step or auto", a);
            return -1;
        }
        break;
    case OPT_SECTOR: {
        unsigned s0, s1;
        char tail;
        if (strcmp(a, "full") == 0) {
            d->full_circle = 1;
            d->start_angle = 0;
            break;
        }
        if (sscanf(a, "%u:%u%c", &s0, &s1, &tail) != 2 || s0 > 399 || s1 > 399 || s0 == s1) {
            snprintf(err, errlen, "--sector: '%s' is not START:STOP in gradians 0..399 (START != STOP), or full", a);
            return -1;
        }
        d->full_circle = 0;
        d->start_angle = (uint16_t)s0;
        d->stop_angle = (uint16_t)s1;
        break;
    }
    case OPT_STEP: if (whole("--step", a, 1, 50, "gradians", &l, err, errlen)) return -1; d->step = (uint8_t)l; break;
    case OPT_GAIN: if (whole("--gain", a, 0, 2, "(0 low, 1 normal, 2 high)", &l, err, errlen)) return -1; d->gain = (uint8_t)l; break;
    case OPT_FREQUENCY: if (whole("--frequency", a, 500, 1000, "kHz", &l, err, errlen)) return -1; d->frequency = (uint16_t)l; break;
    case OPT_SAMPLES: if (whole("--samples", a, 200, 1200, "samples", &l, err, errlen)) return -1; d->samples = (uint16_t)l; break;
    case OPT_TX: if (whole("--transmit-duration", a, 5, 500, "us", &l, err, errlen)) return -1; d->transmit_duration = (uint16_t)l; break;
    case OPT_CONFIG: break; /* read before the command line */
    case OPT_RANGE: if (num("--range", a, 1, 60, "metres", &o->range_m, err, errlen)) return -1; break;
    case OPT_SOS: if (num("--speed-of-sound", a, 1300, 1700, "m/s", &o->speed_of_sound, err, errlen)) return -1; break;
    case OPT_OFFSET:
        if (num("--angle-offset", a, -400, 400, "gradians", &v, err, errlen)) return -1;
        p->detector.angle_offset = (float)v;
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
    case OPT_BG_WARMUP:
        if (whole("--bg-warmup", a, 1, 64, "observations", &l, err, errlen)) return -1;
        p->background.warmup = (uint8_t)l;
        ps->warmup_set = 1;
        break;
    case OPT_BG_STEP: if (whole("--bg-step", a, 1, 64, "grey levels", &l, err, errlen)) return -1; p->background.step = (uint8_t)l; break;
    case OPT_BG_MARGIN: if (whole("--bg-margin", a, 0, 64, "sixteenths of the background", &l, err, errlen)) return -1; p->background.margin = (uint8_t)l; break;
    case OPT_THRESHOLD: if (num("--threshold", a, 0, 20, "standard deviations", &v, err, errlen)) return -1; p->detector.threshold_k = (float)v; break;
    case OPT_MIN_THRESHOLD: if (whole("--min-threshold", a, 0, 254, "grey levels", &l, err, errlen)) return -1; p->detector.min_threshold = (uint8_t)l; break;
    case OPT_CLUSTERS: if (whole("--clusters", a, 1, SONAR_MAX_CLUSTERS, "clusters", &l, err, errlen)) return -1; p->detector.max_clusters = (uint8_t)l; break;
    case OPT_MIN_POINTS: if (whole("--min-points", a, 1, 65535, "cells", &l, err, errlen)) return -1; p->detector.min_points = (uint16_t)l; break;
    case OPT_MIN_BEAMS: if (whole("--min-beams", a, 0, 255, "beams", &l, err, errlen)) return -1; p->detector.min_beams = (uint8_t)l; break;
    case OPT_MAX_EXTENT: if (num("--max-extent", a, 0, 1000, "metres (0 = no limit)", &v, err, errlen)) return -1; p->detector.max_extent_m = (float)v; break;
    case OPT_SPLIT_POINTS: if (whole("--split-points", a, 0, 65535, "cells (0 = never cut)", &l, err, errlen)) return -1; p->detector.split_points = (uint16_t)l; break;
    case OPT_MIN_RANGE: if (num("--min-range", a, 0, 1000, "metres", &v, err, errlen)) return -1; p->detector.min_range_m = (float)v; break;
    case OPT_MAX_ASPECT:
        if (num("--max-aspect", a, 0, 100, "ratio (0 = no limit)", &v, err, errlen)) return -1;
        if (v > 0.0 && v < 0.1) {
            snprintf(err, errlen, "--max-aspect: '%s' is below 0.1 (0 = no limit)", a);
            return -1;
        }
        p->detector.max_aspect = (float)v;
        break;
    case OPT_TRACK_M: if (num("--track-m", a, 0, 100, "metres (0 = off)", &v, err, errlen)) return -1; p->detector.track_m = (float)v; break;
    case OPT_TRACK_POINTS: if (whole("--track-points", a, 1, 65535, "cells", &l, err, errlen)) return -1; p->detector.track_points = (uint16_t)l; break;
    case OPT_ITERATIONS: if (whole("--iterations", a, 1, 100, "rounds", &l, err, errlen)) return -1; p->detector.iterations = (uint8_t)l; break;
    case OPT_LINK_M: if (num("--link-m", a, 0, 10, "metres", &v, err, errlen)) return -1; p->detector.link_m = (float)v; break;
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
    case OPT_HELP: options_usage(prog); return 1;
    case OPT_VERSION: printf("sonard 0.2.0\n"); return 1;
    default:
        snprintf(err, errlen, "unknown option");
        return -1;
    }
    return 0;
}

/* Values from a config file outlive parsing: they are kept in the options' own string pool. */
static char *keep(char *pool, size_t cap, size_t *used, const char *s)
{
    size_t n = strlen(s) + 1;
    char *r;
    if (*used + n > cap)
        return NULL;
    r = pool + *used;
    memcpy(r, s, n);
    *used += n;
    return r;
}

/* One --config file; *used carries the string pool's fill across several files. */
static int read_config(struct sonard_options *o, const char *path, const char *prog, struct parse_state *ps,
                       char *pool, size_t cap, size_t *used, char *err, size_t errlen)
{
    char line[512], msg[256];
    unsigned long ln = 0;
    FILE *f = fopen(path, "r");
    if (f == NULL) {
        snprintf(err, errlen, "--config %s: %s", path, strerror(errno));
        return -1;
    }
    while (fgets(line, sizeof(line), f) != NULL) {
        char *k = line, *eq, *v, *e;
        const struct option *opt;
        ln++;
        while (*k == ' ' || *k == '\t')
            k++;
        if (*k == '#' || *k == '\n' || *k == '\r' || *k == '\0')
            continue;
        eq = strchr(k, '=');
        if (eq == NULL) {
            snprintf(err, errlen, "%s:%lu: expected key = value", path, ln);
            fclose(f);
            return -1;
        }
        for (e = eq; e > k && (e[-1] == ' ' || e[-1] == '\t'); e--)
            ;
        *e = '\0';
        for (v = eq + 1; *v == ' ' || *v == '\t'; v++)
            ;
        for (e = v + strlen(v); e > v && (e[-1] == '\n' || e[-1] == '\r' || e[-1] == ' ' || e[-1] == '\t'); e--)
            ;
        *e = '\0';
        for (opt = longs; opt->name != NULL && strcmp(opt->name, k) != 0; opt++)
            ;
        if (opt->name == NULL || opt->val == OPT_CONFIG || opt->val == OPT_HELP || opt->val == OPT_VERSION) {
            snprintf(err, errlen, "%s:%lu: unknown key '%s'", path, ln, k);
            fclose(f);
            return -1;
        }
        if (opt->has_arg == no_argument) {
            if (strcmp(v, "true") != 0 && strcmp(v, "yes") != 0 && strcmp(v, "1") != 0 && strcmp(v, "false") != 0 &&
                strcmp(v, "no") != 0 && strcmp(v, "0") != 0) {
                snprintf(err, errlen, "%s:%lu: %s: '%s' is not true or false", path, ln, k, v);
                fclose(f);
                return -1;
            }
            if (v[0] == 'f' || v[0] == 'n' || v[0] == '0')
                continue;
        }
        if ((v = keep(pool, cap, used, v)) == NULL) {
            snprintf(err, errlen, "%s:%lu: the file's values exceed %zu bytes", path, ln, cap);
            fclose(f);
            return -1;
        }
        if (apply(o, opt->val, v, prog, ps, msg, sizeof(msg)) != 0) {
            snprintf(err, errlen, "%s:%lu: %s", path, ln, msg);
            fclose(f);
            return -1;
        }
    }
    fclose(f);
    return 0;
}

int options_parse(int argc, char **argv, struct sonard_options *o, char *err, size_t errlen)
{
    struct parse_state ps = {0};
    size_t used = 0;
    int c, i, r;
    memset(o, 0, sizeof(*o));
    sonar_pipeline_defaults(&o->pipeline);
    o->range_m = -1.0;
    o->speed_of_sound = 1500.0;
    o->stage = SONAR_STAGE_FOREGROUND;
    o->device.gain = 0;
    o->device.frequency = 750;
    o->device.step = 1;
    o->device.full_circle = 1;
    for (i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *path = strncmp(a, "--config=", 9) == 0 ? a + 9 : strcmp(a, "--config") == 0 && i + 1 < argc ? argv[i + 1] : NULL;
        if (path != NULL) {
            snprintf(o->config_path, sizeof(o->config_path), "%s", path);
            /* Several files apply in order, each overriding the ones before. */
            if (read_config(o, path, argv[0], &ps, o->pool, sizeof(o->pool), &used, err, errlen) != 0)
                return -1;
        }
    }
    opterr = 0;
    optind = 1;
    while ((c = getopt_long(argc, argv, ":", longs, NULL)) != -1) {
        if (c == ':') {
            snprintf(err, errlen, "%s: needs a value", argv[optind - 1]);
            return -1;
        }
        if (c == '?') {
            snprintf(err, errlen, "%s: unknown option (see --help)", argv[optind - 1]);
            return -1;
        }
        if ((r = apply(o, c, optarg, argv[0], &ps, err, errlen)) != 0)
            return r;
    }
    if (optind < argc) {
        snprintf(err, errlen, "%s: unexpected argument (see --help)", argv[optind]);
        return -1;
    }
    /* Warm-up counts observations: a sweep per cell in per-angle mode, a beam per bin in range mode. */
    if (!ps.warmup_set)
        o->pipeline.background.warmup = o->pipeline.background.mode == SONAR_BACKGROUND_RANGE ? 8 : 2;
    if ((o->replay == NULL) == (o->sonar == NULL)) {
        snprintf(err, errlen, "give either --sonar URL (live) or --replay FILE.csv (see --help)");
        return -1;
    }
    if (o->device.use_auto && o->device.step > 10) {
        snprintf(err, errlen, "--step: %u gradians is more than auto_transmit's 10", o->device.step);
        return -1;
    }
    o->device.range_m = (float)(o->range_m > 0 ? o->range_m : 2.0);
    o->device.speed_of_sound = (float)o->speed_of_sound;
    return 0;
}
