/* msg_config.c -- the host's acquisition and pipeline settings <-> sonar.config_t (the co-processor's configuration), field by field both ways; O(fields), no heap. */
#include "msg.h"

#include <string.h>

/* The CFAR rules, both ways: one struct of the detector's, mapped in one place each way. */
static void cfar_out(const struct sonar_cfar_config *f, sonar_config_t *c)
{
    c->cfar_across = (int8_t)f->across;
    c->cfar_cut = (int8_t)f->cut;
    c->cfar_guard = (int8_t)f->guard;
    c->cfar_train = (int8_t)f->train;
    c->cfar_rank16 = (int8_t)f->rank16;
    c->cfar_scale = f->scale;
    c->cfar_floor = f->floor;
}


void msg_config(const struct sonar_ping360_config *d, const struct sonar_pipeline_config *p, uint16_t beam_every,
                sonar_config_t *c)
{
    memset(c, 0, sizeof(*c));
    c->range_m = d->range_m;
    c->speed_of_sound = d->speed_of_sound;
    c->samples = (int16_t)d->samples;
    c->transmit_duration = (int16_t)d->transmit_duration;
    c->gain = (int8_t)d->gain;
    c->frequency = (int16_t)d->frequency;
    c->start_angle = (int16_t)d->start_angle;
    c->stop_angle = (int16_t)d->stop_angle;
    c->step = (int8_t)d->step;
    c->full_circle = (int8_t)(d->full_circle != 0);
    c->use_auto = (int8_t)(d->use_auto != 0);
    c->median = (int8_t)p->median;
    c->median2d = (int8_t)p->median2d;
    c->max_step = (int16_t)p->max_step;
    c->bg_mode = (int8_t)p->background.mode;
    c->bg_warmup = (int8_t)p->background.warmup;
    c->bg_step = (int8_t)p->background.step;
    c->bg_margin = (int8_t)p->background.margin;
    c->threshold_mode = (int8_t)p->detector.threshold_mode;
    cfar_out(&p->detector.cfar, c);
    c->threshold_k = p->detector.threshold_k;
    c->min_threshold = p->detector.min_threshold;
    c->max_clusters = p->detector.max_clusters;
    c->iterations = p->detector.iterations;
    c->join_beams = p->detector.join_beams;
    c->min_points = p->detector.min_points;
    c->join_m = p->detector.join_m;
    c->angle_offset = p->detector.angle_offset;
    c->min_beams = p->detector.min_beams;
    c->max_extent_m = p->detector.max_extent_m;
    c->split_points = p->detector.split_points;
    c->min_range_m = p->detector.min_range_m;
    c->max_aspect = p->detector.max_aspect;
    c->track_m = p->detector.track_m;
    c->track_points = p->detector.track_points;
    c->track = (int8_t)(p->track != 0);
    c->track_accel_mps2 = p->tracker.accel_mps2;
    c->track_manoeuvre_mps2 = p->tracker.manoeuvre_mps2;
    c->track_meas_m = p->tracker.meas_m;
    c->track_speed0_mps = p->tracker.speed0_mps;
    c->track_max_speed_mps = p->tracker.max_speed_mps;
    c->track_gate = p->tracker.gate;
    c->track_confirm_m = (int8_t)p->tracker.confirm_m;
    c->track_confirm_n = (int8_t)p->tracker.confirm_n;
    c->track_max_misses = (int16_t)p->tracker.max_misses;
    c->track_max_dt_s = p->tracker.max_dt_s;
    c->beam_every = (int16_t)(beam_every > 32767u ? 32767u : beam_every);
    c->min_area_m2 = p->detector.min_area_m2;
    c->min_footprints = p->detector.min_footprints;
    c->structure_s = p->structure_s;
    c->track_imm = (int8_t)p->tracker.imm;
    c->track_defer = (int8_t)p->tracker.defer;
    c->track_existence = (int8_t)p->tracker.existence;
    c->track_walls = (int8_t)p->tracker.walls;
}

/* A wire integer into a narrower field; one that does not fit becomes `bad`, which the core's checks refuse by name. */
static uint8_t to_u8(int32_t v, uint8_t bad)
{
    return v < 0 || v > 255 ? bad : (uint8_t)v;
}

static void cfar_in(const sonar_config_t *c, struct sonar_cfar_config *f)
{
    f->across = to_u8(c->cfar_across, 255);
    f->cut = to_u8(c->cfar_cut, 255);
    f->guard = to_u8(c->cfar_guard, 255);
    f->train = to_u8(c->cfar_train, 0);
    f->rank16 = to_u8(c->cfar_rank16, 255);
    f->scale = c->cfar_scale;
    f->floor = to_u8(c->cfar_floor, 255);
}

static uint16_t to_u16(int32_t v, uint16_t bad)
{
    return v < 0 || v > 65535 ? bad : (uint16_t)v;
}

void msg_config_in(const sonar_config_t *c, uint32_t baud, struct sonar_ping360_config *d,
                   struct sonar_pipeline_config *p, uint16_t *beam_every)
{
    memset(d, 0, sizeof(*d));
    d->range_m = c->range_m;
    d->speed_of_sound = c->speed_of_sound;
    d->samples = to_u16(c->samples, 1);
    d->transmit_duration = to_u16(c->transmit_duration, 1);
    d->gain = to_u8(c->gain, 255);
    d->frequency = to_u16(c->frequency, 0);
    d->start_angle = to_u16(c->start_angle, 65535);
    d->stop_angle = to_u16(c->stop_angle, 65535);
    d->step = to_u8(c->step, 0);
    d->full_circle = (uint8_t)(c->full_circle != 0);
    d->use_auto = (uint8_t)(c->use_auto != 0);
    d->baud = baud;
    p->median = to_u8(c->median, 255);
    p->median2d = to_u8(c->median2d, 255);
    p->max_step = to_u16(c->max_step, 65535);
    p->background.mode = to_u8(c->bg_mode, 255);
    p->background.warmup = to_u8(c->bg_warmup, 0);
    p->background.step = to_u8(c->bg_step, 0);
    p->background.margin = to_u8(c->bg_margin, 255);
    p->detector.threshold_mode = to_u8(c->threshold_mode, 255);
    cfar_in(c, &p->detector.cfar);
    p->detector.threshold_k = c->threshold_k;
    p->detector.min_threshold = to_u8(c->min_threshold, 255);
    p->detector.max_clusters = to_u8(c->max_clusters, 0);
    p->detector.iterations = to_u8(c->iterations, 0);
    p->detector.join_beams = to_u8(c->join_beams, 0);
    p->detector.min_points = to_u16(c->min_points, 0);
    p->detector.join_m = c->join_m;
    p->detector.angle_offset = c->angle_offset;
    p->detector.min_beams = to_u8(c->min_beams, 255);
    p->detector.max_extent_m = c->max_extent_m;
    p->detector.split_points = to_u16(c->split_points, 65535);
    p->detector.min_range_m = c->min_range_m;
    p->detector.max_aspect = c->max_aspect;
    p->detector.track_m = c->track_m;
    p->detector.track_points = to_u16(c->track_points, 0);
    p->track = c->track ? 1u : 0u;
    p->tracker.accel_mps2 = c->track_accel_mps2;
    p->tracker.manoeuvre_mps2 = c->track_manoeuvre_mps2;
    p->tracker.meas_m = c->track_meas_m;
    p->tracker.speed0_mps = c->track_speed0_mps;
    p->tracker.max_speed_mps = c->track_max_speed_mps;
    p->tracker.gate = c->track_gate;
    p->tracker.confirm_m = to_u8(c->track_confirm_m, 0);
    p->tracker.confirm_n = to_u8(c->track_confirm_n, 0);
    p->tracker.max_misses = to_u8(c->track_max_misses, 0);
    p->tracker.max_dt_s = c->track_max_dt_s;
    *beam_every = (uint16_t)(c->beam_every < 0 ? 0 : c->beam_every);
    p->detector.min_area_m2 = c->min_area_m2;
    p->detector.min_footprints = c->min_footprints;
    p->structure_s = c->structure_s;
    p->tracker.imm = to_u8(c->track_imm, 255);
    p->tracker.defer = to_u8(c->track_defer, 255);
    p->tracker.existence = to_u8(c->track_existence, 255);
    p->tracker.walls = to_u8(c->track_walls, 255);
}
