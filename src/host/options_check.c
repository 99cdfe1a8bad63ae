/* options_check.c -- the whole configuration's checks after parsing (--background's own defaults, passive mode, a survey's needs, options that exclude one another), each refusal naming the option and its --config file and line; no heap. */
#include "options.h"
#include "options_internal.h"
#include "app.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

/* The settings that follow --background unless given: the warm-up, and the study's detector rules with its median background. */
static void mode_defaults(struct sonard_options *o)
{
    /* Warm-up counts observations: a sweep per cell in per-angle mode, a beam per bin in range mode. */
    if (!options_given(o, "bg-warmup"))
        o->pipeline.background.warmup = o->pipeline.background.mode == SONAR_BACKGROUND_RANGE ? 8 : 2;
    /* The study's median background goes with its rules, unless they are given: its configuration replays as it always has. */
    {
        struct sonar_pipeline_config d;
        sonar_pipeline_defaults(&d);
        if (o->pipeline.background.mode == SONAR_BACKGROUND_RANGE)
            sonar_pipeline_study_rules(&d.detector);
        if (!options_given(o, "threshold-mode"))
            o->pipeline.detector.threshold_mode = d.detector.threshold_mode;
        if (!options_given(o, "min-points"))
            o->pipeline.detector.min_points = d.detector.min_points;
        if (!options_given(o, "max-extent"))
            o->pipeline.detector.max_extent_m = d.detector.max_extent_m;
        if (!options_given(o, "max-aspect"))
            o->pipeline.detector.max_aspect = d.detector.max_aspect;
        if (!options_given(o, "min-area"))
            o->pipeline.detector.min_area_m2 = d.detector.min_area_m2;
        if (!options_given(o, "min-footprints"))
            o->pipeline.detector.min_footprints = d.detector.min_footprints;
    }
}

/* Whether the option named came from a --config file. */
static int from_file(const struct sonard_options *o, const char *key)
{
    char where[8];
    int k = opt_find(options_schema(), key);
    return k >= 0 && *opt_where(&o->given, (size_t)k, where, sizeof(where)) != '\0';
}

/*
 * Refuses the options with err: the message from fmt, after "FILE:LINE: " when the option named key (its long name,
 * the one at fault) came from a --config file. Returns HOST_ERR_CONFIG.
 */
static int refuse(const struct sonard_options *o, const char *key, char *err, size_t errlen, const char *fmt, ...)
{
    char where[300];
    int k = opt_find(options_schema(), key), n;
    va_list ap;
    n = snprintf(err, errlen, "%s", k >= 0 ? opt_where(&o->given, (size_t)k, where, sizeof(where)) : "");
    if (n < 0 || (size_t)n >= errlen)
        return HOST_ERR_CONFIG;
    va_start(ap, fmt);
    vsnprintf(err + n, errlen - (size_t)n, fmt, ap);
    va_end(ap);
    return HOST_ERR_CONFIG;
}

/* --passive: a live sonar, and none of the options that command the head (whoever drives it chooses them). */
static int check_passive(struct sonard_options *o, char *err, size_t errlen)
{
    /* Whoever drives the head chooses these; sonard takes them from each reply. */
    static const char *const head[] = {"mode", "sector", "step", "gain", "scan", "frequency", "samples",
                                       "transmit-duration", "range"};
    size_t i;
    o->device.passive = (uint8_t)(o->passive != 0);
    if (!o->device.passive)
        return HOST_OK;
    if (o->sonar == NULL)
        return refuse(o, "passive", err, errlen, "--passive listens to a live sonar: it goes with --sonar");
    for (i = 0; i < sizeof head / sizeof head[0]; i++)
        if (options_given(o, head[i]))
            return refuse(o, head[i], err, errlen,
                          "--%s commands the head: with --passive the program driving it chooses that", head[i]);
    if (!options_given(o, "sweep-gap"))
        o->pipeline.sweep_gap_s = 2.0f;
    return HOST_OK;
}

/* --survey N records a fixed, empty site into the survey's file with sonard's own per-angle background, then stops. */
static int check_survey(struct sonard_options *o, char *err, size_t errlen)
{
    const char *moving = options_moving(o);
    if (o->survey != NULL && o->bg_load != NULL)
        return refuse(o, "background-load", err, errlen,
                      "survey %s and --background-load %s name two files for one thing: give one", o->survey, o->bg_load);
    if (o->survey_sweeps == 0)
        return HOST_OK;
    if (o->survey == NULL)
        return refuse(o, "survey", err, errlen, "--survey %ld writes the site's survey: give its file too (survey = PATH "
                                                "in the --config file, or --survey PATH)", o->survey_sweeps);
    if (moving != NULL)
        return refuse(o, moving + 2, err, errlen, "--survey records a fixed site; with %s the sonar moves (the world "
                                                  "frame): a survey is of a site, not of where a vehicle was", moving);
    if (o->coprocessor != NULL || o->bg_save != NULL || options_given(o, "sweeps"))
        return refuse(o, o->coprocessor != NULL ? "coprocessor" : o->bg_save != NULL ? "background-save" : "sweeps", err,
                      errlen, "--survey %ld records the survey from sonard's own beams for that many sweeps: it takes no %s",
                      o->survey_sweeps, o->coprocessor != NULL ? "--coprocessor (the firmware keeps its beams)"
                                        : o->bg_save != NULL ? "--background-save (the survey is the file written)" : "--sweeps");
    if (o->pipeline.background.mode != SONAR_BACKGROUND_PER_ANGLE && o->pipeline.background.mode != SONAR_BACKGROUND_AUTO)
        return refuse(o, "background", err, errlen,
                      "--survey keeps a per-angle model: it goes with --background auto or per-angle");
    /* Nothing held out of the background while the site is recorded: all that stands still is learnt (what stood
       there from the first ping included, as it must be), and what moves stands out, is tracked and refuses it. */
    o->pipeline.background.mode = SONAR_BACKGROUND_PER_ANGLE;
    o->sweeps = o->survey_sweeps;
    /* A run that records and exits takes no commands (a configuration with control = yes records as well). */
    o->control = 0;
    return HOST_OK;
}

/* Checks what no single option can: combinations, and each core config as a whole. */
int options_check_whole(struct sonard_options *o, char *err, size_t errlen)
{
    const char *why;
    mode_defaults(o);
    if (check_passive(o, err, errlen) != HOST_OK)
        return HOST_ERR_CONFIG;
    if (o->pose_lcm != NULL && o->replay != NULL)
        return refuse(o, "pose-lcm", err, errlen, "--pose-lcm URL is for a live sonar; a replay takes --pose FILE.csv");
    if (o->mavlink != NULL && o->sonar == NULL)
        return refuse(o, "mavlink", err, errlen,
                      "--mavlink URL goes with --sonar: the obstacle map is made from a live sonar's beams");
    if (o->pipeline.structure_s > 0.0f && o->pipeline.structure_s < 1.0f)
        return refuse(o, "structure-s", err, errlen,
                      "--structure-s: '%g' is not 0 (never) or 1.." SONAR_STR(SONAR_STRUCTURE_S_MAX) " seconds",
                      (double)o->pipeline.structure_s);
    if (o->pipeline.still_alarm_s > 0.0f && o->pipeline.still_alarm_s < 1.0f)
        return refuse(o, "still-alarm", err, errlen, "--still-alarm: '%g' is not 0 (never) or 1..86400 seconds",
                      (double)o->pipeline.still_alarm_s);
    if (check_survey(o, err, errlen) != HOST_OK)
        return HOST_ERR_CONFIG;
    if ((o->bg_load != NULL || o->bg_save != NULL) && o->coprocessor != NULL)
        return refuse(o, o->bg_load != NULL ? "background-load" : "background-save", err, errlen,
                      "--background-load and --background-save are for sonard's own pipeline: with --coprocessor the "
                      "background is the firmware's");
    if ((o->bg_load != NULL || o->bg_save != NULL) && o->pipeline.background.mode != SONAR_BACKGROUND_PER_ANGLE &&
        o->pipeline.background.mode != SONAR_BACKGROUND_AUTO)
        return refuse(o, "background", err, errlen, "--background-load and --background-save keep a per-angle model: they "
                                                    "go with --background auto or per-angle");
    if (o->pose_file != NULL && o->replay == NULL)
        return refuse(o, "pose", err, errlen,
                      "--pose FILE.csv goes with --replay: a live vehicle's pose comes from its autopilot");
    if (o->discover) {
        if (o->replay != NULL || o->sonar != NULL || o->coprocessor != NULL) {
            snprintf(err, errlen, "--discover lists the sonars and exits: it takes no --sonar, --coprocessor or --replay");
            return HOST_ERR_CONFIG;
        }
        return HOST_OK;
    }
    if ((o->replay != NULL) + (o->sonar != NULL) + (o->coprocessor != NULL) != 1)
        return refuse(o, from_file(o, "replay") ? "replay" : from_file(o, "sonar") ? "sonar" : "coprocessor", err, errlen,
                      "give one of --sonar URL (live), --coprocessor URL or --replay FILE.csv (see --help)");
    if (o->control && (o->sonar == NULL || o->no_lcm))
        return refuse(o, "control", err, errlen, "--control takes commands for a live sonar over LCM: it goes with --sonar "
                                                 "and without --no-lcm");
    if (o->gain_auto && o->sonar == NULL)
        return refuse(o, "gain", err, errlen, "--gain auto sets a live sonar's gain: it goes with --sonar URL");
    if (o->scan.mode == SONAR_SCAN_FOLLOW && o->sonar == NULL)
        return refuse(o, "scan", err, errlen, "--scan follow steers a live sonar: it goes with --sonar URL");
    if (o->device.use_auto && o->device.step > 10)
        return refuse(o, "step", err, errlen, "--step: %u gradians is more than auto_transmit's 10", o->device.step);
    o->device.range_m = (float)(o->range_m > 0 ? o->range_m : 2.0);
    o->device.speed_of_sound = (float)o->speed_of_sound;
    if (o->pipeline.tracker.confirm_m > o->pipeline.tracker.confirm_n)
        return refuse(o, "track-confirm", err, errlen,
                      "--track-confirm %u exceeds --track-window %u: a track needs M hits in the last N sweeps, M <= N",
                      (unsigned)o->pipeline.tracker.confirm_m, (unsigned)o->pipeline.tracker.confirm_n);
    if ((why = sonar_pipeline_config_check(&o->pipeline)) != NULL ||
        (o->replay == NULL && (why = sonar_ping360_config_check(&o->device)) != NULL)) {
        snprintf(err, errlen, "configuration: %s", why);
        return HOST_ERR_CONFIG;
    }
    return HOST_OK;
}

