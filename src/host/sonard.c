/* sonard.c -- the sonard front end: options, the app core with its sinks, then a source: --sonar (live.c's loop) or --replay; SIGHUP re-reads --config. */
#include <errno.h>
#include <inttypes.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "app.h"
#include "bgstore.h"
#include "blueos.h"
#include "control.h"
#include "discover.h"
#include "live.h"
#include "options.h"
#include "sinks.h"
#include "source_coproc.h"
#include "source_link.h"
#include "mav.h"
#include "source_pose_lcm.h"
#include "source_replay.h"
#include "survey_run.h"

/* Everything sonard holds (~7 MB: the pipeline, a survey's spread, the CSV reader, --survey's recording; pages never used cost nothing): static in main, never global. */
/* --ignore-deg's arcs are copied whole from the options into the endpoint's config. */
SONAR_STATIC_ASSERT(SONARD_MAX_IGNORE == MAV_MAX_IGNORE, ignore_arcs_match);

struct sonard {
    struct sonard_options opt, reload; /* running options, and the scratch a SIGHUP parses into */
    int argc;
    char **argv;
    struct app_storage app_mem;
    struct app *app;
    struct sink_lcm lcm;
    struct sink_csv csv;
    struct sink_report report;
    struct source_link link;
    struct source_coproc coproc;
    struct source_replay replay;
    struct posefile pose;
    struct mav mav;
    struct obsmap obs;        /* the obstacle map for SONAR_OBSTACLES without --mavlink (with it, the endpoint's) */
    struct source_pose_lcm plcm;
    struct live_aux aux[2];
    unsigned naux;
    int have_mav, have_plcm, have_obs;
    FILE *csv_out;
    int have_lcm;
    char sonar_url[160]; /* --sonar blueos...: the URL the ping service named (or its fallback) */
    struct survey_run survey; /* --survey N's or --control's recording (4.3 MB, untouched otherwise) */
    struct control control;   /* --control: commands on SONAR_CONTROL */
    int have_control;
};

static int64_t mono_ns(void *user)
{
    struct timespec t;
    (void)user;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (int64_t)t.tv_sec * 1000000000 + t.tv_nsec;
}

static int64_t wall_us(void *user)
{
    struct timespec t;
    (void)user;
    clock_gettime(CLOCK_REALTIME, &t);
    return (int64_t)t.tv_sec * 1000000 + t.tv_nsec / 1000;
}

/* Diagnostics at or below --log-level (--quiet is the per-sweep report's, not theirs: the journal keeps them). */
static int shows(const struct sonard *s, int level)
{
    return level <= (int)s->opt.log_level;
}

/* --sonar as given, or for blueos[:HOST[:PORT]] the Ping360 BlueOS's ping service names (bounded: 3 asks of 2 s). */
static const char *sonar_url(struct sonard *s, char *err, size_t errlen)
{
    char host[128];
    int port, rc = blueos_spec(s->opt.sonar, host, sizeof host, &port, err, errlen);
    if (rc <= 0)
        return rc == 0 ? s->opt.sonar : NULL;
    if (blueos_resolve(host, port, 2000, 1000, s->sonar_url, sizeof s->sonar_url, shows(s, APP_WARN) ? stderr : NULL) &&
        shows(s, APP_INFO))
        fprintf(stderr, "sonard: the ping service at %s:%d names the Ping360 at %s\n", host, port, s->sonar_url);
    return s->sonar_url;
}

static void log_stderr(void *user, int level, const char *fmt, va_list ap)
{
    const struct sonard *s = user;
    if (!shows(s, level))
        return;
    fputs(level == APP_WARN ? "sonard: warning: " : "sonard: ", stderr);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
}

/* What the firmware is configured with: the running acquisition (a restart changes it) and these filters and detector. */
static struct source_coproc_config coproc_config(const struct sonard *s, const struct sonar_pipeline_config *pipeline)
{
    struct source_coproc_config cc;
    cc.baud = s->opt.baud;
    cc.device = &s->opt.device;
    cc.pipeline = pipeline;
    cc.beam_every = (uint16_t)s->opt.coproc_beams;
    return cc;
}

/* SIGHUP: the --config files and argv again; filter and detector settings apply from the next sweep. */
static int reload(void *user)
{
    struct sonard *s = user;
    char err[256];
    int r = options_parse(s->argc, s->argv, &s->reload, err, sizeof(err));
    /* The files' unknown keys first, so that an error they lead to comes after them. */
    if (shows(s, APP_WARN))
        options_say_unknown(&s->reload, stderr);
    if (r != 0) {
        fprintf(stderr, "sonard: SIGHUP: %s; the running settings stay\n", r < 0 ? err : "no reload from --help");
        return HOST_ERR_CONFIG;
    }
    /* The obstacle map takes angle-offset and min-range from the pipeline beam by beam (app_frame), so both turn
       together with the sweep the new settings take over at; a min range the map cannot take refuses the reload. */
    if ((s->have_mav || s->have_obs) &&
        obsmap_check_min_range(s->reload.pipeline.detector.min_range_m, err, sizeof(err)) != HOST_OK) {
        fprintf(stderr, "sonard: SIGHUP: %s; the running settings stay\n", err);
        return HOST_ERR_CONFIG;
    }
    if (app_reconfigure(s->app, &s->reload.pipeline, err, sizeof(err)) != HOST_OK) {
        fprintf(stderr, "sonard: SIGHUP: %s; the running settings stay\n", err);
        return HOST_ERR_CONFIG;
    }
    {
        char names[200];
        const struct opt_schema *sc = options_schema();
        unsigned n = opt_restart_needed(sc->spec, sc->count, &s->opt.given, &s->reload.given, names, sizeof(names));
        if (n > 0)
            fprintf(stderr, "sonard: SIGHUP: %s changed: %s after a restart; the running value%s stay%s\n", names,
                    n == 1 ? "applies" : "apply", n == 1 ? "" : "s", n == 1 ? "s" : "");
    }
    if (s->opt.coprocessor != NULL) {
        /* The firmware runs the filters and the detector: it gets them too (with the acquisition it runs). */
        struct source_coproc_config cc = coproc_config(s, &s->reload.pipeline);
        if (source_coproc_reconfigure(&s->coproc, &cc, app_mono_us(s->app), err, sizeof(err)) != HOST_OK)
            fprintf(stderr, "sonard: SIGHUP: %s; the co-processor keeps its settings\n", err);
    }
    if (shows(s, APP_INFO))
        fprintf(stderr, "sonard: SIGHUP: %d config file%s re-read; filter and detector settings apply from the next sweep\n",
                s->reload.nconfigs, s->reload.nconfigs == 1 ? "" : "s");
    /* The pipeline copied what it needs: the scratch can be parsed into again. */
    return HOST_OK;
}

static int open_sinks(struct sonard *s, char *err, size_t errlen)
{
    const struct sonard_options *o = &s->opt;
    int live = o->replay == NULL, r;
    /* A replay publishes only when asked (--lcm URL): the same messages as live, e.g. into a log for lcm2mcap. */
    if ((live && !o->no_lcm) || (!live && o->lcm_url != NULL && !o->no_lcm)) {
        if ((r = sink_lcm_open(&s->lcm, o->lcm_url, o->channel_prefix, o->publish_filtered, err, errlen)) != HOST_OK)
            return r;
        s->have_lcm = 1;
        if (app_add_sink(s->app, &s->lcm.sink) != HOST_OK)
            return HOST_ERR_CONFIG;
    }
    if (o->csv_out != NULL) {
        if ((s->csv_out = fopen(o->csv_out, "w")) == NULL) {
            snprintf(err, errlen, "--csv-out %s: %s", o->csv_out, strerror(errno));
            return HOST_ERR_IO;
        }
        sink_csv_init(&s->csv, s->csv_out, live ? SONAR_STAGE_RAW : o->stage);
        if (app_add_sink(s->app, &s->csv.sink) != HOST_OK)
            return HOST_ERR_CONFIG;
    }
    if (o->json || !o->quiet) {
        sink_report_init(&s->report, stdout, o->json);
        if (app_add_sink(s->app, &s->report.sink) != HOST_OK)
            return HOST_ERR_CONFIG;
    }
    return HOST_OK;
}

/* Exit summary of the live run: every counter SONAR_STATUS carries. */
static void summary(const struct sonar_status *st)
{
    fprintf(stderr,
            "sonard: status frames %" PRIu32 " checksum_errors %" PRIu32 " resyncs %" PRIu32 " oversize %" PRIu32
            " bytes_dropped %" PRIu32 " timeouts %" PRIu32 " retries %" PRIu32 " nacks %" PRIu32 " reconnects %" PRIu32
            " off_angle %" PRIu32 " foreign %" PRIu32 " beams %" PRIu32 " sweeps %" PRIu32 " beams_rejected %" PRIu32 " sink_errors %" PRIu32 "\n",
            st->parser.frames, st->parser.checksum_errors, st->parser.resyncs, st->parser.oversize,
            st->parser.bytes_dropped, st->driver.timeouts, st->driver.retries, st->driver.nacks, st->driver.reconnects,
            st->driver.off_angle, st->driver.foreign, st->driver.beams, st->sweeps, st->beams_rejected, st->sink_errors);
}

/* What each sink delivered: "sonard: sink lcm: beams B detections D status S errors E". */
static void sink_summary(const struct app *a)
{
    unsigned i;
    const struct app_sink *k;
    for (i = 0; (k = app_sink_at(a, i)) != NULL; i++)
        if (k->beam != NULL || k->detections != NULL || k->status != NULL) /* not --control's, which only adds to status */
            fprintf(stderr, "sonard: sink %s: beams %lu detections %lu status %lu errors %lu\n", k->name, k->n_beams,
                k->n_detections, k->n_statuses, k->errors);
}

/*
 * The site's background at start: --survey N records one (nothing loaded: the recording is the site as it is now);
 * else the survey's file when it exists, or --background-load's. A file that cannot be used is said, and the
 * background learns from scratch: nothing else changes.
 */
static void site_background(struct sonard *s)
{
    char err[320];
    if (s->opt.survey_sweeps > 0) {
        survey_run_start(&s->survey, s->app, 1);
        if (shows(s, APP_INFO))
            fprintf(stderr, "sonard: survey: recording %ld sweeps of the site into %s (the site must be empty and still; the "
                            "file there now is replaced only if this one is kept)\n", s->opt.survey_sweeps, s->opt.survey);
    } else if (s->opt.survey != NULL && access(s->opt.survey, F_OK) != 0 && errno == ENOENT) {
        /* The package's configuration names a survey's file for every installation: a vehicle's or a co-processor's
           has none to be told about. */
        if (options_moving(&s->opt) == NULL && s->opt.coprocessor == NULL && shows(s, APP_INFO))
            fprintf(stderr, "sonard: survey: none at %s yet (record one with --survey N when the site is empty): no "
                            "survey: learning, and nothing present at the start is learnt\n", s->opt.survey);
    } else if (s->opt.survey != NULL && s->opt.coprocessor != NULL) {
        if (shows(s, APP_WARN))
            fprintf(stderr, "sonard: warning: survey %s: not used with --coprocessor (the firmware's background is its "
                            "own)\n", s->opt.survey);
    } else if (s->opt.survey != NULL && bgstore_load(s->app, "survey", s->opt.survey, err, sizeof(err)) != HOST_OK) {
        fprintf(stderr, "sonard: %s; no survey: the background learns afresh\n", err);
    } else if (s->opt.bg_load != NULL && bgstore_load(s->app, "--background-load", s->opt.bg_load, err, sizeof(err)) !=
                                             HOST_OK) {
        fprintf(stderr, "sonard: %s; the background learns afresh\n", err);
    }
}

/* The host's stalls over a live run: "sonard: loop: host stalls N, longest L ms, T ms in all". */
static void stall_summary(const struct live_stalls *st)
{
    fprintf(stderr, "sonard: loop: host stalls %" PRIu32 ", longest %.0f ms, %.0f ms in all (sonard kept from running: "
                    "the sonar's timeouts waited them out)\n", st->n, (double)st->longest_us * 1e-3,
            (double)st->total_us * 1e-3);
}

static int run_live(struct sonard *s)
{
    struct sonar_status st;
    struct live_source ls;
    struct live_stalls stalls;
    source_link_live(&s->link, &ls);
    if (live_run(s->app, &ls, s->aux, s->naux, reload, s, &stalls) != HOST_OK)
        return 2;
    if (shows(s, APP_INFO)) {
        stall_summary(&stalls);
        app_report_status(s->app, SONAR_P360_STOPPED, &st); /* the final counters (also one more SONAR_STATUS) */
        summary(&st);
        sink_summary(s->app);
        if (s->have_mav) {
            char line[512];
            mav_summary(&s->mav, line, sizeof(line));
            fprintf(stderr, "sonard: %s\n", line);
        }
        if (s->have_plcm && s->plcm.received > 0)
            fprintf(stderr, "sonard: %s: %u poses, %u did not decode, %u refused\n", s->plcm.channel, s->plcm.received,
                    s->plcm.bad, s->plcm.refused);
    }
    return 0;
}

static int run_coproc(struct sonard *s)
{
    struct live_source ls;
    struct live_stalls stalls;
    source_coproc_live(&s->coproc, &ls);
    if (live_run(s->app, &ls, s->aux, s->naux, reload, s, &stalls) != HOST_OK)
        return 2;
    if (shows(s, APP_INFO)) {
        stall_summary(&stalls);
        fprintf(stderr, "sonard: co-processor link: frames %u crc_errors %u oversize %u bytes_dropped %u decode_errors %u"
                        " before_config %u\n",
                s->coproc.parser.counters.frames, s->coproc.parser.counters.crc_errors, s->coproc.parser.counters.oversize,
                s->coproc.parser.counters.bytes_dropped, s->coproc.decode_errors, s->coproc.dropped_before_config);
        sink_summary(s->app);
    }
    return s->coproc.refused ? 2 : 0;
}

static int run_replay(struct sonard *s)
{
    struct timespec t0, t1;
    double ms;
    unsigned long good, used;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    good = source_replay_run(&s->replay, s->app, stderr);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    ms = (double)(t1.tv_sec - t0.tv_sec) * 1e3 + (double)(t1.tv_nsec - t0.tv_nsec) * 1e-6;
    used = good - app_beams_rejected(s->app);
    fflush(stdout);
    if (shows(s, APP_INFO))
        fprintf(stderr, "sonard: %s: %lu rows used, %lu skipped, %" PRIu32 " sweeps, %.1f ms (%.2f us/beam)\n",
                s->opt.replay, used, (unsigned long)app_rows_bad(s->app), app_sweeps(s->app), ms, used ? ms * 1e3 / (double)used : 0.0);
    else if (app_rows_bad(s->app) && shows(s, APP_WARN))
        fprintf(stderr, "sonard: %s: %lu rows skipped\n", s->opt.replay, (unsigned long)app_rows_bad(s->app));
    if ((app_blank_beams(s->app) || app_interference_beams(s->app)) && shows(s, APP_INFO))
        fprintf(stderr, "sonard: %s: %" PRIu32 " blank beams skipped, %" PRIu32 " beams left out as interference\n",
                s->opt.replay, app_blank_beams(s->app), app_interference_beams(s->app));
    source_replay_close(&s->replay);
    if (s->replay.pose != NULL) {
        if (s->pose.bad)
            fprintf(stderr, "sonard: --pose %s: %lu rows skipped\n", s->opt.pose_file, s->pose.bad);
        posefile_close(&s->pose);
    }
    return used == 0 ? 1 : 0;
}

/* Long: the order of setting up (options, source, app, sinks, pose, MAVLink, background) and tearing down is the program's
   whole story, told once here; each step is a call, and the error paths must unwind what came before. */
int main(int argc, char **argv)
{
    static struct sonard s;
    struct app_clock clock = {mono_ns, wall_us, NULL};
    struct sonar_ping360_io io;
    char err[320];
    int rc;
    memset(&io, 0, sizeof(io));
    /* A file grown past a size limit fails its write (said, the old file kept) instead of killing sonard. */
    signal(SIGXFSZ, SIG_IGN);
    s.argc = argc;
    s.argv = argv;
    rc = options_parse(argc, argv, &s.opt, err, sizeof(err));
    /* The files' unknown keys first: a key misspelt in a file is often why the error after them happened. */
    if (rc < 0 || shows(&s, APP_WARN))
        options_say_unknown(&s.opt, stderr);
    if (rc != 0) {
        if (rc < 0)
            fprintf(stderr, "sonard: %s\n", err);
        return rc < 0 ? 2 : 0;
    }
    if (s.opt.discover) {
        struct discover_config dc;
        dc.to = s.opt.discover_to;
        dc.seconds = s.opt.discover_s;
        dc.data_port = (int)s.opt.discover_data_port;
        rc = discover_run(&dc, stdout, stderr);
        return rc > 0 ? 0 : rc == 0 ? 1 : 2;
    }
    if (s.opt.sonar != NULL) {
        const char *url = sonar_url(&s, err, sizeof(err));
        if (url == NULL || source_link_parse(&s.link, url, s.opt.baud, err, sizeof(err)) != HOST_OK) {
            fprintf(stderr, "sonard: %s\n", err);
            return 2;
        }
        s.opt.device.baud = source_link_baud(&s.link);
        io.send = source_link_send;
        io.line_break = source_link_break;
        io.user = &s.link;
    } else if (s.opt.coprocessor != NULL) {
        struct source_coproc_config cc = coproc_config(&s, &s.opt.pipeline);
        if (source_coproc_parse(&s.coproc, s.opt.coprocessor, &cc, err, sizeof(err)) != HOST_OK) {
            fprintf(stderr, "sonard: %s\n", err);
            return 2;
        }
    } else if (source_replay_open(&s.replay, s.opt.replay, s.opt.range_m, s.opt.speed_of_sound, err, sizeof(err)) !=
               HOST_OK) {
        fprintf(stderr, "sonard: %s\n", err);
        return 2;
    } else {
        s.replay.beam_ms = s.opt.beam_ms;
        s.replay.speed = s.opt.replay_speed;
        s.replay.quiet = !shows(&s, APP_INFO); /* which form the file is in */
        /* a progress line is for a person watching, not for a log */
        s.replay.progress = !s.opt.quiet && isatty(fileno(stderr));
        if (s.opt.pose_file != NULL) {
            if (posefile_open(&s.pose, s.opt.pose_file, err, sizeof(err)) != HOST_OK) {
                fprintf(stderr, "sonard: --pose %s\n", err);
                return 2;
            }
            s.replay.pose = &s.pose;
        }
    }
    if (app_init(&s.app, &s.app_mem, &s.opt.pipeline, s.opt.sonar ? &s.opt.device : NULL, &io, &clock,
                 s.opt.sweeps, err, sizeof(err)) != HOST_OK ||
        (s.opt.sonar != NULL && app_set_scan(s.app, &s.opt.scan, err, sizeof(err)) != HOST_OK) ||
        (s.opt.sonar != NULL && s.opt.gain_auto && app_set_gain_auto(s.app, &s.opt.gain_rules, err, sizeof(err)) != HOST_OK) ||
        open_sinks(&s, err, sizeof(err)) != HOST_OK) {
        fprintf(stderr, "sonard: %s\n", err);
        return 2;
    }
    app_set_log(s.app, log_stderr, &s);
    app_set_track_late(s.app, s.opt.track_late);
    site_background(&s);
    if (s.opt.mavlink != NULL) {
        struct mav_config mc;
        mc.url = s.opt.mavlink;
        mc.sysid = (uint8_t)s.opt.mav_sysid;
        mc.compid = (uint8_t)s.opt.mav_compid;
        mc.autopilot = (uint8_t)s.opt.mav_autopilot;
        mc.rate_hz = s.opt.mav_rate;
        mc.pose_rate_hz = s.opt.mav_pose_rate;
        mc.fail_closed = s.opt.mav_fail_closed;
        mc.send_3d = s.opt.mav_3d;
        mc.n_ignore = s.opt.n_ignore;
        memcpy(mc.ignore, s.opt.ignore, sizeof(mc.ignore));
        if (obsmap_check_min_range(s.opt.pipeline.detector.min_range_m, err, sizeof(err)) != HOST_OK ||
            mav_init(&s.mav, &mc, err, sizeof(err)) != HOST_OK || mav_attach(&s.mav, s.app) != HOST_OK) {
            fprintf(stderr, "sonard: %s\n", err);
            return 2;
        }
        mav_live(&s.mav, &s.aux[s.naux++]);
        s.have_mav = 1;
    }
    /* SONAR_OBSTACLES: the autopilot's map when there is one (the same figures), else a map of its own. */
    if (s.have_lcm && s.opt.obstacles) {
        if (!s.have_mav && (obsmap_check_min_range(s.opt.pipeline.detector.min_range_m, err, sizeof(err)) != HOST_OK ||
                            obsmap_init(&s.obs, (const float (*)[2])s.opt.ignore, s.opt.n_ignore, err, sizeof(err)) != HOST_OK ||
                            obsmap_attach(&s.obs, s.app) != HOST_OK)) {
            fprintf(stderr, "sonard: %s\n", err);
            return 2;
        }
        s.have_obs = !s.have_mav;
        obsmap_on_read(s.have_mav ? &s.mav.map : &s.obs, sink_lcm_obstacles, &s.lcm);
    }
    /* Poses over LCM (SONAR_POSE): on sonard's own LCM, or on --pose-lcm URL. */
    if (s.opt.replay == NULL && (s.have_lcm || s.opt.pose_lcm != NULL)) {
        if (source_pose_lcm_open(&s.plcm, s.have_lcm ? s.lcm.lcm : NULL, s.opt.pose_lcm, s.opt.channel_prefix, s.app, err,
                                 sizeof(err)) != HOST_OK) {
            fprintf(stderr, "sonard: %s\n", err);
            return 2;
        }
        source_pose_lcm_live(&s.plcm, &s.aux[s.naux++]);
        s.have_plcm = 1;
    }
    if (s.opt.control) {
        if (control_open(&s.control, s.lcm.lcm, s.opt.channel_prefix, s.app, &s.opt, &s.survey, err, sizeof(err)) !=
            HOST_OK) {
            fprintf(stderr, "sonard: %s\n", err);
            return 2;
        }
        control_live(&s.control, &s.aux[s.naux++]);
        s.have_control = 1;
        if (shows(&s, APP_WARN))
            fprintf(stderr, "sonard: control: on: commands on %s (record the site's survey into %s, cancel it) are taken "
                            "from anyone on the LCM bus, one a second, and answered on SONAR_STATUS\n",
                    s.control.channel, s.opt.survey != NULL ? s.opt.survey : "(no survey file: refused)");
    }
    if (s.opt.replay != NULL)
        app_set_link(s.app, s.opt.replay);
    rc = s.opt.sonar != NULL ? run_live(&s) : s.opt.coprocessor != NULL ? run_coproc(&s) : run_replay(&s);
    if (s.opt.survey_sweeps > 0 && survey_run_finish(&s.survey, s.app, &s.opt, s.opt.survey_sweeps, stderr, err, sizeof(err)) != HOST_OK) {
        fprintf(stderr, "sonard: %s\n", err);
        rc = rc != 0 ? rc : 1;
    }
    if (s.opt.bg_save != NULL) {
        if (bgstore_save(s.app, s.opt.bg_save, err, sizeof(err)) != HOST_OK) {
            fprintf(stderr, "sonard: %s\n", err);
            rc = rc != 0 ? rc : 1;
        } else if (shows(&s, APP_INFO)) {
            fprintf(stderr, "sonard: background saved to %s\n", s.opt.bg_save);
        }
    }
    if (s.csv_out != NULL && fclose(s.csv_out) != 0)
        s.csv.sink.errors++;
    if (s.csv.sink.errors)
        fprintf(stderr, "sonard: --csv-out %s: %lu rows could not be written\n", s.opt.csv_out, s.csv.sink.errors);
    if (s.have_lcm) {
        if (s.lcm.sink.errors)
            fprintf(stderr, "sonard: %lu LCM messages could not be published\n", s.lcm.sink.errors);
        sink_lcm_close(&s.lcm);
    }
    return rc != 0 ? rc : (s.csv.sink.errors ? 1 : 0);
}
