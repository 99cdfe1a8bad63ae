/* pipeline.c -- glue of the per-beam stages (blank beams and streaks out, median, background, in the world grid with a pose, CFAR one beam late) and the per-sweep detector; adds O(1) work per beam, no heap. What the background may learn is pipeline_learn.c, the sweep's tracking pipeline_tracks.c. */
#include "sonar/pipeline.h"
#include "sonar/bgfile.h"

#include <math.h>
#include <string.h>

#include "pipeline_internal.h"
#include "sonar/edge.h"
#include "sonar/frame.h"


int sonar_pipeline_init(struct sonar_pipeline *p, struct sonar_background *bg, const struct sonar_pipeline_config *cfg)
{
    int r;
    if (p == NULL || bg == NULL || cfg == NULL || sonar_pipeline_config_check(cfg) != NULL)
        return SONAR_ERR_ARG;
    memset(p, 0, sizeof(*p));
    p->cfg = cfg;
    p->bg = bg;
    p->prev_width = 1.8f; /* two gradians, until a second beam gives the step */
    p->last_gain = -1;
    if ((r = sonar_sweep_init(&p->sweep, cfg->max_step, SONAR_MAX_SWEEP_BEAMS)) != SONAR_OK)
        return r;
    if (cfg->median2d != 0 && (r = sonar_median2d_init(&p->m2d, cfg->median2d)) != SONAR_OK)
        return r;
    if ((r = sonar_background_init(p->bg, &cfg->background)) != SONAR_OK)
        return r;
    if (cfg->track && (r = sonar_tracker_init(&p->trk, &cfg->tracker)) != SONAR_OK)
        return r;
    if ((r = sonar_structure_init(&p->st, cfg->structure_s)) != SONAR_OK)
        return r;
    return sonar_detector_init(&p->det, &cfg->detector);
}

void sonar_pipeline_restart_background(struct sonar_pipeline *p)
{
    /* The survey's levels are in the background's rows: a restart gives it up (why already set when it was a misfit). */
    sonar_survey_lost(p->sv, SONAR_SURVEY_RESTART);
    sonar_background_reset(p->bg);
    sonar_structure_restart(&p->st);
    p->bg_sweeps = 0;
}

int sonar_pipeline_load_background(struct sonar_pipeline *p, const uint8_t *img, size_t len, const char **why)
{
    int r;
    if (p == NULL || p->cfg == NULL)
        return SONAR_ERR_ARG;
    if ((r = p->sv != NULL ? sonar_survey_use(p->sv, p->bg, img, len, why) : sonar_bgfile_load(p->bg, img, len, why)) !=
        SONAR_OK)
        return r;
    sonar_structure_restart(&p->st);
    p->bg_sweeps = 0;
    return SONAR_OK;
}

void sonar_pipeline_set_activity(struct sonar_pipeline *p, struct sonar_activity *act)
{
    p->act = act;
}

void sonar_pipeline_set_clutter(struct sonar_pipeline *p, struct sonar_clutter *clutter)
{
    p->clutter = clutter;
}

void sonar_pipeline_set_survey(struct sonar_pipeline *p, struct sonar_survey *sv)
{
    p->sv = sv;
}

void sonar_pipeline_set_recording(struct sonar_pipeline *p, struct sonar_survey_rec *rec)
{
    p->rec = rec;
}

/*
 * A survey being recorded: the beam judged against what it holds so far (returns 1: done; 0: the
 * background judges it), then added to it. A refusal is kept in the recording (rec->why, its
 * SONAR_ERR_STATE): the beams still go through.
 */
static int record(struct sonar_pipeline *p, int64_t utime, uint16_t angle, uint8_t *b)
{
    uint8_t kept[SONAR_MAX_SAMPLES];
    int done, r;
    if (p->rec == NULL)
        return 0;
    memcpy(kept, b, p->n);
    done = sonar_survey_rec_apply(p->rec, angle, kept, b, p->n, p->cfg->background.margin);
    r = sonar_survey_rec_beam(p->rec, angle, kept, p->n, p->range_m, p->last_gain, utime);
    return r == SONAR_ERR_ARG ? r : done;
}

static void tap(const struct sonar_pipeline *p, int stage, int64_t utime, uint16_t angle, const uint8_t *s)
{
    struct sonar_beam b;
    if (p->cfg->on_beam == NULL)
        return;
    b.utime = utime;
    b.angle = angle;
    b.gain = p->last_gain;
    b.n = p->n;
    b.range_m = p->range_m;
    b.samples = s;
    p->cfg->on_beam(p->cfg->user, stage, &b);
}

/* Does the detector take each beam with its neighbours (the CFAR window across beams), one beam late? */
static int across(const struct sonar_pipeline *p)
{
    return p->cfg->detector.threshold_mode == SONAR_DET_CFAR && p->cfg->detector.cfar.across;
}

/*
 * The waiting beam to the detector, its window spread over the beam before it and next (block
 * sums; NULL: none); its own sums become the next one's "before".
 */
static int release(struct sonar_pipeline *p, const uint16_t *next, uint16_t next_angle)
{
    uint8_t on[SONAR_CFAR_MAX_BLOCKS];
    const uint8_t *fg = p->buf[p->cur ^ 1u];
    /*
     * A beam compared with the across-beam model (its row still seeding) keeps its window on
     * itself: walls stand out from that model too, and spread over neighbours an oblique wall's
     * echo breaks into wall-sized pieces that the extent rule no longer sees as one.
     */
    int alone = p->wait_alone, r;
    const uint16_t *before = p->have_before && sonar_frame_gap(p->before_angle, p->wait_angle) <= p->wait_gap ? p->before
                                                                                                             : NULL;
    if (next != NULL && sonar_frame_gap(next_angle, p->wait_angle) > p->wait_gap)
        next = NULL;
    /*
     * A beam with one neighbour (a sector's end, where the head turns back; a sweep's first or last
     * beam) takes that neighbour for the missing one too: a window over two beams instead of three
     * is noisier (a speck in the edge beam, or the beam that looks along the wall the sonar is
     * mounted on, is diluted by one neighbour instead of two) and passed more often than the same
     * echo inside the sector.
     */
    if (before == NULL && next != NULL)
        before = next;
    else if (next == NULL && before != NULL)
        next = before;
    r = sonar_cfar_blocks_sums(&p->cfg->detector.cfar, alone ? NULL : before, p->wait_sums, alone ? NULL : next, p->n, on,
                               NULL);
    if (r < 0)
        return r;
    r = sonar_detector_add_blocks(&p->det, p->wait_angle, fg, on, p->n, p->range_m, p->wait_utime);
    if (r == SONAR_OK)
        sonar_detector_set_edge(&p->det, p->wait_edge, p->wait_top);
    p->waiting = 0;
    p->before_angle = p->wait_angle;
    p->have_before = 1;
    memcpy(p->before, p->wait_sums, sizeof(p->before));
    /* The sweep tracker cuts at SONAR_MAX_SWEEP_BEAMS, so FULL cannot happen here. */
    return r == SONAR_ERR_FULL ? SONAR_OK : r;
}

/* Median output (in buf[cur]) -> background, in place -> detector. */
static int after_median(struct sonar_pipeline *p, int64_t utime, uint16_t angle)
{
    struct sonar_bg_span sp[SONAR_MAX_TRACKS], learn[SONAR_PIPE_LEARN_MAX];
    uint16_t sums[SONAR_CFAR_MAX_BLOCKS];
    uint8_t *b = p->buf[p->cur], nkeep, nlearn, top;
    int r, done, judged = 0, seeding = sonar_background_seeding(p->bg, angle);
    uint16_t from = sonar_streak_from(b, p->n), edge;
    float near;
    tap(p, SONAR_STAGE_MEDIAN, utime, angle, b);
    if (sonar_streak_judge(&p->streak, angle, utime,
                           sonar_streak_standing(p->bg, angle, b, p->n, from,
                                                     p->bg->margin > SONAR_STREAK_MARGIN ? p->bg->margin : SONAR_STREAK_MARGIN),
                           (uint16_t)(p->n - from))) {
        /*
         * Interference: neither background (nothing learns it) nor object (the detector never sees it), and
         * no neighbour either: the beams beside it take their CFAR windows without it, as at a gap.
         */
        memset(b, 0, p->n);
        tap(p, SONAR_STAGE_FOREGROUND, utime, angle, b);
        if (across(p) && p->waiting && (r = release(p, NULL, 0)) != SONAR_OK)
            return r;
        p->have_before = 0;
        return SONAR_OK;
    }
    sonar_survey_look(p->sv, p->bg, angle, b, p->n);
    if ((r = sonar_pipe_world_background(p, utime, angle, &done)) != SONAR_OK)
        return r;
    if (done)
        sonar_survey_lost(p->sv, SONAR_SURVEY_WORLD); /* the grid takes the background's bytes: the survey's levels go */
    else if ((judged = record(p, utime, angle, b)) < 0)
        return judged;
    else if (!judged && !(judged = sonar_survey_apply(p->sv, p->bg, angle, b, b, p->n))) {
        nkeep = sonar_pipe_keep_spans(p, angle, sp, learn, &nlearn);
        if ((r = sonar_background_apply_spans(p->bg, angle, b, b, p->n, sp, nkeep, learn, nlearn)) != SONAR_OK)
            return r;
    }
    tap(p, SONAR_STAGE_FOREGROUND, utime, angle, b);
    /*
     * The leading edge of what stands out (detector.h, SONAR_DET_EDGE_JUMP_M), from the CFAR's block sums: the
     * background takes away the ring-down's reverberation, which on a real Ping360 is as strong as a wall.
     */
    edge = p->n; /* none: without structure rules (max_extent_m 0) nothing reads it */
    top = 0;
    if ((across(p) || p->cfg->detector.max_extent_m > 0.0f) && (r = sonar_cfar_sums(b, p->n, sums)) < 0)
        return r;
    if (p->cfg->detector.max_extent_m > 0.0f) {
        near = sonar_pipe_near_m(p) * (float)p->n / p->range_m + 1.0f; /* rounded up */
        edge = sonar_edge_leading(b, sums, (uint16_t)(near < (float)p->n ? near : (float)p->n), p->n, &top);
    }
    if (!across(p)) {
        r = sonar_detector_add(&p->det, angle, b, p->n, p->range_m, utime);
        if (r == SONAR_OK)
            sonar_detector_set_edge(&p->det, edge, top);
        return r == SONAR_ERR_FULL ? SONAR_OK : r;
    }
    if (p->waiting && (r = release(p, sums, angle)) != SONAR_OK)
        return r;
    memcpy(p->wait_sums, sums, sizeof(sums));
    p->waiting = 1;
    p->wait_alone = (uint8_t)seeding;
    p->wait_gap = judged ? SONAR_PIPE_ACROSS_GAP_SURVEY : SONAR_PIPE_ACROSS_GAP;
    p->wait_angle = angle;
    p->wait_utime = utime;
    p->wait_edge = edge;
    p->wait_top = top;
    p->cur ^= 1u;
    return SONAR_OK;
}

/* What the pipeline keeps in its output frame turns with a new angle offset: the structure places and the tracks. */
static void turn_frame(struct sonar_pipeline *p, float deg)
{
    struct sonar_pose q;
    int have = p->trk.world && p->poses != NULL && sonar_pose_at(p->poses, sonar_detector_utime(&p->det), &q);
    sonar_structure_turn(&p->st, deg);
    sonar_tracker_turn(&p->trk, deg, have ? &q : NULL);
}

/* Moves to p->next at a sweep boundary (no sweep open). */
static int switch_config(struct sonar_pipeline *p)
{
    const struct sonar_pipeline_config *old = p->cfg, *c = p->next;
    int r, fresh;
    float turn = (c->detector.angle_offset - old->detector.angle_offset) * (float)SONAR_DEG_PER_GRAD;
    p->next = NULL;
    /* A new angle offset re-declares the mount: a world grid learnt through the old one lies turned about the
       vehicle, so it is learnt afresh; a per-angle model is by head angle and stays. */
    fresh = c->median != old->median || c->median2d != old->median2d || c->max_step != old->max_step ||
            c->background.mode != old->background.mode || c->background.warmup != old->background.warmup ||
            (turn != 0.0f && p->bg->world);
    p->cfg = c;
    if (turn != 0.0f)
        turn_frame(p, turn);
    if ((r = sonar_detector_set_config(&p->det, &c->detector)) != SONAR_OK)
        return r;
    /* Tracks survive a reload; turning tracking on starts a fresh tracker (IDs from 1). */
    if (c->track && (r = old->track ? sonar_tracker_tune(&p->trk, &c->tracker)
                                    : sonar_tracker_init(&p->trk, &c->tracker)) != SONAR_OK)
        return r;
    if (c->track && !old->track && p->act != NULL && (r = sonar_activity_init(p->act)) != SONAR_OK)
        return r;
    if ((r = sonar_structure_tune(&p->st, c->structure_s)) != SONAR_OK)
        return r;
    if (!fresh)
        return sonar_background_tune(p->bg, &c->background);
    sonar_structure_restart(&p->st);
    /* The filtered values the model learned no longer match: relearn from the next beam. */
    if ((r = sonar_sweep_init(&p->sweep, c->max_step, SONAR_MAX_SWEEP_BEAMS)) != SONAR_OK)
        return r;
    if (c->median2d != 0 && (r = sonar_median2d_init(&p->m2d, c->median2d)) != SONAR_OK)
        return r;
    return sonar_background_init(p->bg, &c->background);
}

int sonar_pipeline_reconfigure(struct sonar_pipeline *p, const struct sonar_pipeline_config *cfg)
{
    if (p == NULL || p->cfg == NULL || cfg == NULL || sonar_pipeline_config_check(cfg) != NULL)
        return SONAR_ERR_ARG;
    p->next = cfg;
    return p->open ? SONAR_OK : switch_config(p);
}

void sonar_pipeline_frame(const struct sonar_pipeline *p, float *angle_offset, float *min_range_m)
{
    *angle_offset = p->cfg->detector.angle_offset;
    *min_range_m = p->cfg->detector.min_range_m;
}

void sonar_pipeline_set_poses(struct sonar_pipeline *p, const struct sonar_pose_ring *poses)
{
    p->poses = poses;
}

/* The sweep's detections of kind structure: lines wider than any object (the survey in use should hold them). */
static unsigned structures(const struct sonar_detections *d)
{
    unsigned k, n = 0;
    for (k = 0; k < d->count; k++)
        n += d->det[k].kind == SONAR_DET_STRUCTURE;
    return n;
}

static int end_sweep(struct sonar_pipeline *p)
{
    struct sonar_median_row meta;
    struct sonar_pose q;
    int r;
    if (!p->open)
        return SONAR_OK;
    if (p->cfg->median2d != 0)
        while ((r = sonar_median2d_flush(&p->m2d, p->buf[p->cur], &meta)) == 1)
            if ((r = after_median(p, meta.utime, meta.angle)) != SONAR_OK)
                return r;
    /* The sweep's last beam has no next neighbour; the next sweep's first none before it. */
    if (p->waiting && (r = release(p, NULL, 0)) != SONAR_OK)
        return r;
    p->have_before = 0;
    if (p->cfg->track && p->trk.world && p->cfg->detector.track_m > 0.0f && p->poses != NULL &&
        sonar_pose_at(p->poses, sonar_detector_utime(&p->det), &q) && (r = sonar_pipe_world_gates(p)) != SONAR_OK)
        return r;
    if ((r = sonar_detector_end(&p->det, &p->out)) < 0)
        return r;
    if ((r = sonar_pipe_finish_sweep(p, 1)) != SONAR_OK)
        return r;
    if (p->rec != NULL && sonar_survey_rec_sweep(p->rec, p->cfg->track ? &p->trk : NULL, p->out.world) != SONAR_OK) {
        /* Refused: said by its recorder (rec->why); the sweep goes out as usual. */
    }
    if (sonar_survey_sweep(p->sv, structures(&p->out))) {
        /* The survey no longer fits (said through the survey's why): the background learns afresh from the next beam. */
        sonar_pipeline_restart_background(p);
        p->survey_unfit_sweep = p->sweeps + 1u;
    }
    p->open = 0;
    p->sweeps++;
    p->bg_sweeps++;
    if (p->cfg->on_sweep != NULL)
        p->cfg->on_sweep(p->cfg->user, &p->out);
    return p->next != NULL ? switch_config(p) : SONAR_OK;
}

/* Every sample 0, or every one 255: nothing heard, or all saturated (sonar_pipeline_blank_beams). */
static int blank(const uint8_t *s, uint16_t n)
{
    uint16_t i;
    if (s[0] != 0u && s[0] != 255u)
        return 0;
    for (i = 1; i < n; i++)
        if (s[i] != s[0])
            return 0;
    return 1;
}

int sonar_pipeline_push(struct sonar_pipeline *p, const struct sonar_beam *b)
{
    int r, cut;
    int changed;
    if (p == NULL || p->cfg == NULL || b == NULL || b->samples == NULL || b->n == 0 || b->n > SONAR_MAX_SAMPLES ||
        b->angle > SONAR_GRAD_MAX || !(b->range_m > 0.0f && b->range_m <= (float)SONAR_PIPE_MAX_RANGE_M))
        return SONAR_ERR_ARG;
    if (blank(b->samples, b->n)) {
        p->blank_beams++;
        return SONAR_OK;
    }
    if ((r = sonar_survey_fits_beam(p->sv, b->n, b->range_m, b->gain)) != SONAR_SURVEY_OK) {
        /* Another setting than the survey's: its levels would call everything foreground (or nothing). */
        sonar_survey_lost(p->sv, r);
        sonar_pipeline_restart_background(p);
    }
    if (b->gain >= 0) {
        /* The echoes' scale changed: a model learnt at the old gain would call everything foreground (or nothing). */
        if (p->last_gain >= 0 && b->gain != p->last_gain) {
            sonar_pipeline_restart_background(p);
            p->gain_restarts++;
        }
        p->last_gain = b->gain;
    }
    changed = p->n != 0 && (b->n != p->n || b->range_m != p->range_m);
    if (changed) {
        /* New geometry: the old background and the open sweep's cells no longer line up. */
        if ((r = end_sweep(p)) != SONAR_OK)
            return r;
        p->geometry_changes++;
        sonar_pipeline_restart_background(p);
        if ((r = sonar_sweep_init(&p->sweep, p->cfg->max_step, SONAR_MAX_SWEEP_BEAMS)) != SONAR_OK)
            return r;
    }
    /* A pause in the beams (the program driving a head stopped, then resumed) ends the sweep, as a wrap would. */
    if (p->cfg->sweep_gap_s > 0.0f && p->open && b->utime - p->last_utime > (int64_t)(p->cfg->sweep_gap_s * 1e6f)) {
        if ((r = end_sweep(p)) != SONAR_OK)
            return r;
        p->gap_cuts++;
        if ((r = sonar_sweep_init(&p->sweep, p->cfg->max_step, SONAR_MAX_SWEEP_BEAMS)) != SONAR_OK)
            return r;
    }
    p->last_utime = b->utime;
    p->n = b->n;
    p->range_m = b->range_m;
    tap(p, SONAR_STAGE_RAW, b->utime, b->angle, b->samples);
    cut = sonar_sweep_step(&p->sweep, b->angle);
    if (cut != SONAR_SWEEP_SAME && (r = end_sweep(p)) != SONAR_OK)
        return r;
    p->open = 1;
    p->beams++;
    if (p->cfg->track)
        sonar_activity_beam(p->act, b->angle, b->samples, b->n, b->range_m, b->gain);
    if (p->cfg->median2d != 0) {
        struct sonar_median_row in, out;
        in.utime = b->utime;
        in.angle = b->angle;
        in.tag = 0;
        r = sonar_median2d_push(&p->m2d, b->samples, b->n, &in, p->buf[p->cur], &out);
        if (r < 0)
            return r;
        return r == 1 ? after_median(p, out.utime, out.angle) : SONAR_OK;
    }
    if (p->cfg->median == 1)
        memcpy(p->buf[p->cur], b->samples, b->n);
    else if ((r = sonar_median_1d(b->samples, p->buf[p->cur], b->n, p->cfg->median)) != SONAR_OK)
        return r;
    return after_median(p, b->utime, b->angle);
}

int sonar_pipeline_finish(struct sonar_pipeline *p)
{
    if (p == NULL || p->cfg == NULL)
        return SONAR_ERR_ARG;
    return end_sweep(p);
}
