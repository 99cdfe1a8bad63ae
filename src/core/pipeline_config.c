/* pipeline_config.c -- the pipeline's configuration: its defaults, the study's detector rules, and the check that names a wrong field; O(1), no state. */
#include "sonar/pipeline.h"

#include <string.h>

void sonar_pipeline_defaults(struct sonar_pipeline_config *cfg)
{
    memset(cfg, 0, sizeof(*cfg));
    cfg->median = 5;
    cfg->median2d = 0;
    cfg->max_step = 20;
    cfg->background.mode = SONAR_BACKGROUND_AUTO;
    cfg->background.warmup = 2;
    cfg->background.step = 1;
    cfg->background.margin = 8;
    cfg->detector.threshold_mode = SONAR_DET_CFAR;
    cfg->detector.cfar.across = 1;
    cfg->detector.cfar.cut = 1;
    cfg->detector.cfar.guard = 1;
    cfg->detector.cfar.train = 4;
    cfg->detector.cfar.rank16 = 8;
    cfg->detector.cfar.scale = 2.5f;
    cfg->detector.cfar.floor = 16;
    cfg->detector.threshold_k = 3.0f;
    cfg->detector.min_threshold = 16;
    cfg->detector.max_clusters = 8;
    cfg->detector.iterations = 10;
    cfg->detector.join_beams = 2;
    cfg->detector.min_points = 12;
    /*
     * No echo is smaller than a point target's footprint: the sample's depth times the beam's width at its
     * range, a floor that scales with the range and the setting as the sonar's resolution does (an absolute
     * area dropped a 0.2 m buoy at 0.66 m on a 5 m range, docs/decisions.md).
     */
    cfg->detector.min_area_m2 = 0.0f;
    cfg->detector.min_footprints = 1.0f;
    cfg->detector.join_m = 0.15f;
    cfg->detector.max_extent_m = 3.5f;
    cfg->detector.max_aspect = 2.0f;
    cfg->detector.track_points = 10;
    cfg->detector.angle_offset = 0.0f;
    cfg->track = 1;
    sonar_tracker_defaults(&cfg->tracker);
}

void sonar_pipeline_study_rules(struct sonar_detector_config *d)
{
    d->threshold_mode = SONAR_DET_GLOBAL;
    d->min_points = 20;
    d->max_extent_m = 0.0f;
    d->max_aspect = 0.0f;
    d->min_area_m2 = 0.0f;
    d->min_footprints = 0.0f;
}

const char *sonar_pipeline_config_check(const struct sonar_pipeline_config *cfg)
{
    const char *why;
    if (cfg->median2d != 0 && cfg->median2d != 3 && !(cfg->median2d == 5 && SONAR_MAX_MEDIAN2D >= 5))
        return "median2d: 0, 3 or 5 (up to SONAR_MAX_MEDIAN2D)";
    if (cfg->median2d == 0 && cfg->median != 1 && (cfg->median < 3 || cfg->median > SONAR_MAX_MEDIAN || !(cfg->median & 1u)))
        return "median: 1 (off) or odd 3..SONAR_MAX_MEDIAN";
    if (cfg->max_step < 1 || cfg->max_step > SONAR_PIPE_MAX_STEP_MAX)
        return "max_step: 1..200 gradians";
    if (!(cfg->sweep_gap_s == 0.0f || (cfg->sweep_gap_s >= 0.1f && cfg->sweep_gap_s <= 3600.0f)))
        return "sweep_gap_s: 0 (never) or 0.1..3600 seconds";
    /* The sub-configs' checks name their own fields; the prefix is implied by the field names. */
    if ((why = sonar_background_config_check(&cfg->background)) != NULL)
        return why;
    if (cfg->track > 1)
        return "track: 0 (off) or 1 (on)";
    if (cfg->track && (why = sonar_tracker_config_check(&cfg->tracker)) != NULL)
        return why;
    if (!(cfg->still_alarm_s == 0.0f || (cfg->still_alarm_s >= 1.0f && cfg->still_alarm_s <= SONAR_ACT_STILL_ALARM_MAX)))
        return "still_alarm_s: 0 (never) or 1..86400 seconds";
    if (!(cfg->structure_s == 0.0f || (cfg->structure_s >= 1.0f && cfg->structure_s <= (float)SONAR_STRUCTURE_S_MAX)))
        return "structure_s: 0 (never) or 1.." SONAR_STR(SONAR_STRUCTURE_S_MAX) " seconds";
    return sonar_detector_config_check(&cfg->detector);
}
