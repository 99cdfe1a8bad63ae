/* pipeline.c -- glue of the per-beam stages and the per-sweep detector; adds O(1) work per beam, no heap. */
#include "sonar/pipeline.h"

#include <string.h>

#include "sonar/frame.h"

void sonar_pipeline_defaults(struct sonar_pipeline_config *cfg)
{
    memset(cfg, 0, sizeof(*cfg));
    cfg->median = 5;
    cfg->median2d = 0;
    cfg->max_step = 20;
    cfg->background.mode = SONAR_BACKGROUND_PER_ANGLE;
    cfg->background.warmup = 2;
    cfg->background.step = 1;
    cfg->background.margin = 8;
    cfg->detector.threshold_k = 3.0f;
    cfg->detector.min_threshold = 16;
    cfg->detector.max_clusters = 8;
    cfg->detector.iterations = 10;
    cfg->detector.link_beams = 2;
    cfg->detector.min_points = 20;
    cfg->detector.link_m = 0.15f;
    cfg->detector.track_points = 10;
    cfg->detector.angle_offset = 0.0f;
    cfg->track = 1;
    sonar_tracker_defaults(&cfg->tracker);
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
    /* The sub-configs' checks name their own fields; the prefix is implied by the field names. */
    if ((why = sonar_background_config_check(&cfg->background)) != NULL)
        return why;
    if (cfg->track > 1)
        return "track: 0 (off) or 1 (on)";
    if (cfg->track && (why = sonar_tracker_config_check(&cfg->tracker)) != NULL)
        return why;
    return sonar_detector_config_check(&cfg->detector);
}

int sonar_pipeline_init(struct sonar_pipeline *p, const struct sonar_pipeline_config *cfg)
{
    int r;
    if (p == NULL || cfg == NULL || sonar_pipeline_config_check(cfg) != NULL)
        return SONAR_ERR_ARG;
    memset(p, 0, sizeof(*p));
    p->cfg = cfg;
    if ((r = sonar_sweep_init(&p->sweep, cfg->max_step, SONAR_MAX_SWEEP_BEAMS)) != SONAR_OK)
        return r;
    if (cfg->median2d != 0 && (r = sonar_median2d_init(&p->m2d, cfg->median2d)) != SONAR_OK)
        return r;
    if ((r = sonar_background_init(&p->bg, &cfg->background)) != SONAR_OK)
        return r;
    if (cfg->track && (r = sonar_tracker_init(&p->trk, &cfg->tracker)) != SONAR_OK)
        return r;
    return sonar_detector_init(&p->det, &cfg->detector);
}

static void emit(const struct sonar_pipeline *p, int stage, int64_t utime, uint16_t angle, const uint8_t *s)
{
    struct sonar_beam b;
    if (p->cfg->on_beam == NULL)
        return;
    b.utime = utime;
    b.angle = angle;
    b.n = p->n;
    b.range_m = p->range_m;
    b.samples = s;
    p->cfg->on_beam(p->cfg->user, stage, &b);
}

/* Median output -> background -> detector. */
static int after_median(struct sonar_pipeline *p, int64_t utime, uint16_t angle)
{
    int r;
    emit(p, SONAR_STAGE_MEDIAN, utime, angle, p->filt);
    if ((r = sonar_background_apply(&p->bg, angle, p->filt, p->fg, p->n)) != SONAR_OK)
        return r;
    emit(p, SONAR_STAGE_FOREGROUND, utime, angle, p->fg);
    r = sonar_detector_add(&p->det, angle, p->fg, p->n, p->range_m, utime);
    /* The sweep tracker cuts at SONAR_MAX_SWEEP_BEAMS, so FULL cannot happen here. */
    return r == SONAR_ERR_FULL ? SONAR_OK : r;
}

/* Moves to p->next at a sweep boundary (no sweep open). */
static int switch_config(struct sonar_pipeline *p)
{
    const struct sonar_pipeline_config *old = p->cfg, *c = p->next;
    int r, fresh;
    p->next = NULL;
    fresh = c->median != old->median || c->median2d != old->median2d || c->max_step != old->max_step ||
            c->background.mode != old->background.mode || c->background.warmup != old->background.warmup;
    p->cfg = c;
    if ((r = sonar_detector_set_config(&p->det, &c->detector)) != SONAR_OK)
        return r;
    /* Tracks survive a reload; turning tracking on starts a fresh tracker (IDs from 1). */
    if (c->track && (r = old->track ? sonar_tracker_tune(&p->trk, &c->tracker)
                                    : sonar_tracker_init(&p->trk, &c->tracker)) != SONAR_OK)
        return r;
    if (!fresh)
        return sonar_background_tune(&p->bg, &c->background);
    /* The filtered values the model learned no longer match: relearn from the next beam. */
    if ((r = sonar_sweep_init(&p->sweep, c->max_step, SONAR_MAX_SWEEP_BEAMS)) != SONAR_OK)
        return r;
    if (c->median2d != 0 && (r = sonar_median2d_init(&p->m2d, c->median2d)) != SONAR_OK)
        return r;
    return sonar_background_init(&p->bg, &c->background);
}

int sonar_pipeline_reconfigure(struct sonar_pipeline *p, const struct sonar_pipeline_config *cfg)
{
    if (p == NULL || p->cfg == NULL || cfg == NULL || sonar_pipeline_config_check(cfg) != NULL)
        return SONAR_ERR_ARG;
    p->next = cfg;
    return p->open ? SONAR_OK : switch_config(p);
}

/*
 * The sweep's detections into the tracker, over the gradians and ranges the sweep scanned. Then
 * the track_m gate of the next sweep follows the tracks, predicted one sweep on, instead of this
 * sweep's detections: confirmed and coasting ones, and tentative ones hit this sweep (leaving
 * those out cost AquaScan sonar11 0.013 of F1: a person's second sighting needs the gate).
 */
static int track(struct sonar_pipeline *p)
{
    struct sonar_tracker_obs obs[SONAR_MAX_CLUSTERS];
    struct sonar_tracker_sweep sw;
    uint8_t cover[SONAR_GRAD_TURN / 8], i, n = 0;
    float gx[SONAR_MAX_CLUSTERS], gy[SONAR_MAX_CLUSTERS];
    float off = p->cfg->detector.angle_offset;
    int64_t ahead;
    int r;
    for (i = 0; i < p->out.count; i++) {
        obs[i].x_m = p->out.det[i].x_m;
        obs[i].y_m = p->out.det[i].y_m;
        obs[i].utime = p->out.det[i].utime;
    }
    sonar_tracker_cover(cover, p->det.angles, p->out.beams, p->cfg->max_step,
                        (int)(off >= 0.0f ? off + 0.5f : off - 0.5f));
    sw.utime = p->out.utime;
    sw.beams = p->out.beams;
    sw.cover = cover;
    sw.min_range_m = p->cfg->detector.min_range_m;
    sw.max_range_m = p->range_m;
    if ((r = sonar_tracker_update(&p->trk, obs, p->out.count, &sw)) != SONAR_OK)
        return r;
    if (!(p->cfg->detector.track_m > 0.0f))
        return SONAR_OK;
    ahead = p->out.utime + (p->out.utime - p->det.t0);
    for (i = 0; i < p->trk.n; i++) {
        const struct sonar_track *t = &p->trk.t[i];
        if ((t->state == SONAR_TRACK_TENTATIVE && t->det < 0) || n >= SONAR_MAX_CLUSTERS)
            continue;
        sonar_tracker_predict(t, ahead, &gx[n], &gy[n]);
        n++;
    }
    return sonar_detector_set_tracks(&p->det, gx, gy, n);
}

static int end_sweep(struct sonar_pipeline *p)
{
    struct sonar_median_row meta;
    int r;
    if (!p->open)
        return SONAR_OK;
    if (p->cfg->median2d != 0)
        while ((r = sonar_median2d_flush(&p->m2d, p->filt, &meta)) == 1)
            if ((r = after_median(p, meta.utime, meta.angle)) != SONAR_OK)
                return r;
    if ((r = sonar_detector_end(&p->det, &p->out)) < 0)
        return r;
    if (p->cfg->track && (r = track(p)) != SONAR_OK)
        return r;
    p->open = 0;
    p->sweeps++;
    if (p->cfg->on_sweep != NULL)
        p->cfg->on_sweep(p->cfg->user, &p->out);
    return p->next != NULL ? switch_config(p) : SONAR_OK;
}

int sonar_pipeline_push(struct sonar_pipeline *p, const struct sonar_beam *b)
{
    int r, cut;
    int changed;
    if (p == NULL || p->cfg == NULL || b == NULL || b->samples == NULL || b->n == 0 || b->n > SONAR_MAX_SAMPLES ||
        b->angle > SONAR_GRAD_MAX || !(b->range_m > 0.0f && b->range_m <= (float)SONAR_PIPE_MAX_RANGE_M))
        return SONAR_ERR_ARG;
    changed = p->n != 0 && (b->n != p->n || b->range_m != p->range_m);
    if (changed) {
        /* New geometry: the old background and the open sweep's cells no longer line up. */
        if ((r = end_sweep(p)) != SONAR_OK)
            return r;
        sonar_background_reset(&p->bg);
        if ((r = sonar_sweep_init(&p->sweep, p->cfg->max_step, SONAR_MAX_SWEEP_BEAMS)) != SONAR_OK)
            return r;
    }
    p->n = b->n;
    p->range_m = b->range_m;
    emit(p, SONAR_STAGE_RAW, b->utime, b->angle, b->samples);
    cut = sonar_sweep_step(&p->sweep, b->angle);
    if (cut != SONAR_SWEEP_SAME && (r = end_sweep(p)) != SONAR_OK)
        return r;
    p->open = 1;
    p->beams++;
    if (p->cfg->median2d != 0) {
        struct sonar_median_row in, out;
        in.utime = b->utime;
        in.angle = b->angle;
        in.tag = 0;
        r = sonar_median2d_push(&p->m2d, b->samples, b->n, &in, p->filt, &out);
        if (r < 0)
            return r;
        return r == 1 ? after_median(p, out.utime, out.angle) : SONAR_OK;
    }
    if (p->cfg->median == 1)
        memcpy(p->filt, b->samples, b->n);
    else if ((r = sonar_median_1d(b->samples, p->filt, b->n, p->cfg->median)) != SONAR_OK)
        return r;
    return after_median(p, b->utime, b->angle);
}

int sonar_pipeline_finish(struct sonar_pipeline *p)
{
    if (p == NULL || p->cfg == NULL)
        return SONAR_ERR_ARG;
    return end_sweep(p);
}
