/* pipeline.c -- glue of the per-beam stages and the per-sweep detector; adds O(1) work per beam, no heap. */
#include "sonar/pipeline.h"

#include <math.h>
#include <string.h>

#include "sonar/frame.h"


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
    cfg->detector.link_beams = 2;
    cfg->detector.min_points = 12;
    cfg->detector.link_m = 0.15f;
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
    p->prev_width = 1.8f; /* two gradians, until a second beam gives the step */
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

static void tap(const struct sonar_pipeline *p, int stage, int64_t utime, uint16_t angle, const uint8_t *s)
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

/*
 * The auto background's kept discs in the world frame: about each confirmed or coasting track where
 * it was last seen, of its last detection's radius (at least SONAR_PIPE_KEEP_MIN_M). The grid does
 * not learn the cells inside them, as keep_spans below does for the per-angle rows.
 */
static uint8_t keep_discs(const struct sonar_pipeline *p, struct sonar_bg_disc *d)
{
    uint8_t k, m = 0;
    if (p->cfg->background.mode != SONAR_BACKGROUND_AUTO || !p->cfg->track || !p->trk.world)
        return 0;
    for (k = 0; k < p->trk.n && m < SONAR_BG_DISCS_MAX; k++) {
        const struct sonar_track *t = &p->trk.t[k];
        float rad = (float)t->size_dm * 0.1f;
        if (t->state == SONAR_TRACK_TENTATIVE)
            continue;
        d[m].north_m = t->px;
        d[m].east_m = t->py;
        d[m].radius_m = rad > SONAR_PIPE_KEEP_MIN_M ? rad : SONAR_PIPE_KEEP_MIN_M;
        m++;
    }
    return m;
}

/*
 * With a pose at the beam's time (per-angle or auto mode): the background in the world grid, the
 * beam's footprint reaching back to the heading of the beam before (a jump beyond max_step, or
 * none: one step's worth); in auto mode the tracks' discs are not learnt.
 */
static int world_background(struct sonar_pipeline *p, int64_t utime, uint16_t angle, int *done)
{
    struct sonar_bg_disc discs[SONAR_BG_DISCS_MAX];
    struct sonar_pose q;
    struct sonar_bg_ray ray;
    double d;
    *done = 0;
    if (p->poses == NULL || (p->cfg->background.mode != SONAR_BACKGROUND_PER_ANGLE &&
                             p->cfg->background.mode != SONAR_BACKGROUND_AUTO) ||
        !sonar_pose_at(p->poses, utime, &q)) {
        p->have_prev_bearing = 0;
        return SONAR_OK;
    }
    ray.north_m = (double)q.north_m;
    ray.east_m = (double)q.east_m;
    ray.bearing_deg = ((double)angle + (double)p->cfg->detector.angle_offset) * SONAR_DEG_PER_GRAD + (double)q.yaw_deg;
    d = p->have_prev_bearing ? fabs(remainder(ray.bearing_deg - (double)p->prev_bearing, 360.0)) : 0.0;
    ray.width_deg = d > 0.0 && d <= SONAR_DEG_PER_GRAD * (double)p->cfg->max_step ? d : (double)p->prev_width;
    p->prev_width = (float)ray.width_deg;
    ray.range_m = p->range_m;
    ray.near_m = p->cfg->detector.min_range_m > SONAR_PIPE_NEAR_M ? p->cfg->detector.min_range_m : SONAR_PIPE_NEAR_M;
    p->prev_bearing = (float)fmod(ray.bearing_deg, 360.0);
    p->have_prev_bearing = 1;
    p->world_beams++;
    *done = 1;
    return sonar_background_apply_world_keep(&p->bg, &ray, p->buf[p->cur], p->buf[p->cur], p->n, discs,
                                             keep_discs(p, discs));
}

/*
 * The auto background's keep spans for a beam at angle (body frame only): the samples within the
 * disc about each confirmed or coasting track, where it was last seen, of its last detection's
 * radius (at least SONAR_PIPE_KEEP_MIN_M), when the beam's axis crosses that disc. Computed here
 * per beam from the tracks (a cosine and a sine, then a few products a track), so nothing is
 * stored for it.
 */
static uint8_t keep_spans(const struct sonar_pipeline *p, uint16_t angle, struct sonar_bg_span *sp)
{
    double th, c, s, per_m;
    uint8_t k, m = 0;
    if (p->cfg->background.mode != SONAR_BACKGROUND_AUTO || !p->cfg->track || p->trk.world)
        return 0;
    th = sonar_frame_rad((double)angle + (double)p->cfg->detector.angle_offset);
    c = cos(th);
    s = sin(th);
    per_m = (double)p->n / (double)p->range_m;
    for (k = 0; k < p->trk.n && m < SONAR_MAX_TRACKS; k++) {
        const struct sonar_track *t = &p->trk.t[k];
        double rad = (double)t->size_dm * 0.1, along, perp, r, lo, hi;
        if (t->state == SONAR_TRACK_TENTATIVE)
            continue;
        rad = rad > (double)SONAR_PIPE_KEEP_MIN_M ? rad : (double)SONAR_PIPE_KEEP_MIN_M;
        along = (double)t->px * c + (double)t->py * s;
        perp = fabs((double)t->py * c - (double)t->px * s);
        if (!(along > 0.0) || !(perp <= rad))
            continue;
        r = sqrt((double)t->px * t->px + (double)t->py * t->py);
        lo = (r - rad) * per_m;
        hi = (r + rad) * per_m + 1.0;
        if (hi <= 0.0 || lo >= (double)p->n)
            continue;
        sp[m].lo = (uint16_t)(lo > 0.0 ? lo : 0.0);
        sp[m].hi = (uint16_t)(hi < (double)p->n ? hi : (double)p->n);
        m++;
    }
    return m;
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
    const uint16_t *before = p->have_before && sonar_frame_gap(p->before_angle, p->wait_angle) <= SONAR_PIPE_ACROSS_GAP
                                 ? p->before
                                 : NULL;
    if (next != NULL && sonar_frame_gap(next_angle, p->wait_angle) > SONAR_PIPE_ACROSS_GAP)
        next = NULL;
    r = sonar_cfar_blocks_sums(&p->cfg->detector.cfar, alone ? NULL : before, p->wait_sums, alone ? NULL : next, p->n, on,
                               NULL);
    if (r < 0)
        return r;
    r = sonar_detector_add_blocks(&p->det, p->wait_angle, fg, on, p->n, p->range_m, p->wait_utime);
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
    struct sonar_bg_span sp[SONAR_MAX_TRACKS];
    uint16_t sums[SONAR_CFAR_MAX_BLOCKS];
    uint8_t *b = p->buf[p->cur];
    int r, done, seeding = sonar_background_seeding(&p->bg, angle);
    tap(p, SONAR_STAGE_MEDIAN, utime, angle, b);
    if ((r = world_background(p, utime, angle, &done)) != SONAR_OK)
        return r;
    if (!done && (r = sonar_background_apply_keep(&p->bg, angle, b, b, p->n, sp, keep_spans(p, angle, sp))) != SONAR_OK)
        return r;
    tap(p, SONAR_STAGE_FOREGROUND, utime, angle, b);
    if (!across(p)) {
        r = sonar_detector_add(&p->det, angle, b, p->n, p->range_m, utime);
        return r == SONAR_ERR_FULL ? SONAR_OK : r;
    }
    if ((r = sonar_cfar_sums(b, p->n, sums)) < 0)
        return r;
    if (p->waiting && (r = release(p, sums, angle)) != SONAR_OK)
        return r;
    memcpy(p->wait_sums, sums, sizeof(sums));
    p->waiting = 1;
    p->wait_alone = (uint8_t)seeding;
    p->wait_angle = angle;
    p->wait_utime = utime;
    p->cur ^= 1u;
    return SONAR_OK;
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

void sonar_pipeline_set_poses(struct sonar_pipeline *p, const struct sonar_pose_ring *poses)
{
    p->poses = poses;
}

/* The angle offset in whole gradians, as the cover map takes it. */
static int offset_grad(const struct sonar_pipeline *p)
{
    float off = p->cfg->detector.angle_offset;
    return (int)(off >= 0.0f ? off + 0.5f : off - 0.5f);
}

/* Time of the sweep's i-th beam. */
static int64_t beam_utime(const struct sonar_pipeline *p, uint16_t i)
{
    return p->det.t0 + (int64_t)p->det.dt_ms[i] * 1000;
}

/* The gradian a beam pointed at in the world (from north), offset included: yaw is 400/360 gradians a degree. */
static int world_grad(const struct sonar_pipeline *p, uint16_t i, const struct sonar_pose *q)
{
    return sonar_frame_wrap((int)p->det.angles[i] + offset_grad(p) + (int)floor((double)q->yaw_deg / SONAR_DEG_PER_GRAD + 0.5));
}

/*
 * sonar_tracker_cover in world gradians: each beam at its own heading, and the gradians between
 * consecutive beams with poses up to max_step apart. A beam without a pose scanned nowhere known.
 */
static void world_cover(const struct sonar_pipeline *p, uint8_t *cover)
{
    uint16_t i;
    int prev = -1;
    memset(cover, 0, SONAR_GRAD_TURN / 8);
    for (i = 0; i < p->out.beams; i++) {
        struct sonar_pose q;
        int g, d;
        if (!sonar_pose_at(p->poses, beam_utime(p, i), &q)) {
            prev = -1;
            continue;
        }
        g = world_grad(p, i, &q);
        d = prev < 0 ? 0 : sonar_frame_delta((uint16_t)prev, (uint16_t)g);
        /* From g back to the beam before, if it is a step and not a jump. */
        sonar_frame_mark_arc(cover, g, (d < 0 ? -d : d) <= (int)p->cfg->max_step ? g - d : g);
        prev = g;
    }
}

/* Tracks the track_m gate follows: confirmed and coasting ones, and tentative ones hit last sweep. */
static int gated(const struct sonar_track *t)
{
    return !(t->state == SONAR_TRACK_TENTATIVE && t->det < 0);
}

/*
 * The track_m gate for the sweep about to end, with world-frame tracks: each track where the
 * beam that looked along its predicted bearing saw it, in that beam's body frame (the vehicle
 * turns and moves under the sweep, so one pose for the sweep would put the gates seconds off).
 * O(beams x tracks) pose lookups.
 */
static int world_gates(struct sonar_pipeline *p)
{
    float gx[SONAR_MAX_CLUSTERS], gy[SONAR_MAX_CLUSTERS], best[SONAR_MAX_CLUSTERS];
    uint8_t idx[SONAR_MAX_CLUSTERS], n = 0, j, m = 0;
    uint16_t i;
    for (j = 0; j < p->trk.n && n < SONAR_MAX_CLUSTERS; j++)
        if (gated(&p->trk.t[j])) {
            best[n] = 1e9f;
            idx[n++] = j;
        }
    for (i = 0; i < p->det.beams; i++) {
        struct sonar_pose q;
        int64_t t = beam_utime(p, i);
        double th = ((double)p->det.angles[i] + (double)p->cfg->detector.angle_offset) * SONAR_DEG_PER_GRAD;
        if (!sonar_pose_at(p->poses, t, &q))
            continue;
        for (j = 0; j < n; j++) {
            float wx, wy, bx, by, e;
            sonar_tracker_predict(&p->trk.t[idx[j]], t, &wx, &wy);
            sonar_pose_to_body(&q, wx, wy, &bx, &by);
            e = (float)fabs(remainder(sonar_frame_bearing_deg((double)bx, (double)by) - th, 360.0));
            if (e < best[j]) {
                best[j] = e;
                gx[j] = bx;
                gy[j] = by;
            }
        }
    }
    /* A track whose bearing no beam came near (outside a sector) expects nothing this sweep. */
    for (j = 0; j < n; j++)
        if (best[j] <= (float)SONAR_DEG_PER_GRAD * (float)p->cfg->max_step) {
            gx[m] = gx[j];
            gy[m] = gy[j];
            m++;
        }
    return sonar_detector_set_tracks(&p->det, gx, gy, m);
}

/* A detection's radius: centroid to its farthest hull vertex, metres. */
static float det_radius(const struct sonar_detection *d)
{
    float best = 0.0f;
    uint8_t v;
    for (v = 0; v < d->hull_count; v++) {
        float dx = d->hull_x[v] - d->x_m, dy = d->hull_y[v] - d->y_m, e = sqrtf(dx * dx + dy * dy);
        best = e > best ? e : best;
    }
    return best;
}

/* Where a sweep's detections were in the world, when the poses say. */
struct located {
    uint8_t world;                 /* every detection and the sweep's last beam have a pose */
    uint8_t ok[SONAR_MAX_CLUSTERS]; /* this one has */
    float north[SONAR_MAX_CLUSTERS], east[SONAR_MAX_CLUSTERS];
    struct sonar_pose pose;        /* the vehicle at the sweep's last beam (world) */
};

static void locate(const struct sonar_pipeline *p, const struct sonar_detections *d, struct located *w)
{
    uint8_t i;
    memset(w, 0, sizeof(*w));
    if (p->poses == NULL || !sonar_pose_at(p->poses, d->utime, &w->pose))
        return;
    w->world = 1;
    for (i = 0; i < d->count; i++) {
        struct sonar_pose q;
        if (sonar_pose_at(p->poses, d->det[i].utime, &q)) {
            sonar_pose_to_world(&q, d->det[i].x_m, d->det[i].y_m, &w->north[i], &w->east[i]);
            w->ok[i] = 1;
        } else {
            w->world = 0;
        }
    }
}

/*
 * A turning vehicle's sweep can look at the same part of the world twice (the head turns one
 * way and the heading with it: one turn of the head covers more than one of the world). A
 * detection within SONAR_PIPE_DUP_M in the world of a larger one seen more than
 * SONAR_PIPE_DUP_US apart is that object seen again: dropped (counted), so the sweep reports
 * each object once, as the tracker expects. Objects side by side are seen within a beam or two.
 */
static void drop_repeats(struct sonar_pipeline *p, struct sonar_detections *d, struct located *w)
{
    uint8_t i, j, k = 0;
    for (i = 0; i < d->count; i++) {
        int dup = 0;
        for (j = 0; j < i && !dup; j++) {
            float dn = w->north[j] - w->north[i], de = w->east[j] - w->east[i];
            int64_t dt = d->det[j].utime - d->det[i].utime;
            dup = w->ok[i] && w->ok[j] && dn * dn + de * de < SONAR_PIPE_DUP_M * SONAR_PIPE_DUP_M &&
                  (dt < 0 ? -dt : dt) > SONAR_PIPE_DUP_US;
        }
        if (dup) {
            p->repeats++;
            continue;
        }
        if (k != i) {
            d->det[k] = d->det[i];
            w->ok[k] = w->ok[i];
            w->north[k] = w->north[i];
            w->east[k] = w->east[i];
        }
        k++;
    }
    d->count = k;
}

/*
 * The sweep's detections (p->out) into the tracker, over the gradians and ranges the sweep
 * scanned (cover 0: unknown, every track in view), in the world frame when the sweep has it.
 * Then, in the body frame, the track_m gate of the next sweep follows the tracks, predicted one
 * sweep on, instead of this sweep's detections: confirmed and coasting ones, and tentative ones
 * hit this sweep (leaving those out cost AquaScan sonar11 0.013 of F1: a person's second sighting
 * needs the gate). In the world frame world_gates places them when that sweep ends.
 */
static int track(struct sonar_pipeline *p, const struct located *w, int have_cover)
{
    struct sonar_tracker_obs obs[SONAR_MAX_CLUSTERS];
    struct sonar_tracker_sweep sw;
    uint8_t cover[SONAR_GRAD_TURN / 8], i, n = 0;
    float gx[SONAR_MAX_CLUSTERS], gy[SONAR_MAX_CLUSTERS];
    const int world = w->world;
    int64_t ahead;
    int r;
    if (world) {
        sonar_tracker_reframe(&p->trk, &w->pose, 1);
        p->last_pose = w->pose;
        p->world_sweeps++;
    } else {
        /* Stale: back to the body frame where the vehicle was last known to be. */
        sonar_tracker_reframe(&p->trk, &p->last_pose, 0);
        p->body_sweeps++;
    }
    for (i = 0; i < p->out.count; i++) {
        obs[i].x_m = world ? w->north[i] : p->out.det[i].x_m;
        obs[i].y_m = world ? w->east[i] : p->out.det[i].y_m;
        obs[i].utime = p->out.det[i].utime;
        obs[i].size_m = det_radius(&p->out.det[i]);
    }
    if (have_cover && world)
        world_cover(p, cover);
    else if (have_cover)
        sonar_tracker_cover(cover, p->det.angles, p->out.beams, p->cfg->max_step, offset_grad(p));
    sw.utime = p->out.utime;
    sw.beams = p->out.beams;
    sw.cover = have_cover ? cover : NULL;
    sw.min_range_m = p->cfg->detector.min_range_m;
    sw.max_range_m = have_cover ? p->range_m : (float)SONAR_PIPE_MAX_RANGE_M;
    sw.origin_x = world ? w->pose.north_m : 0.0f;
    sw.origin_y = world ? w->pose.east_m : 0.0f;
    if ((r = sonar_tracker_update(&p->trk, obs, p->out.count, &sw)) != SONAR_OK)
        return r;
    if (!(p->cfg->detector.track_m > 0.0f) || world || !have_cover)
        return SONAR_OK;
    ahead = p->out.utime + (p->out.utime - p->det.t0);
    for (i = 0; i < p->trk.n; i++) {
        const struct sonar_track *t = &p->trk.t[i];
        if (!gated(t) || n >= SONAR_MAX_CLUSTERS)
            continue;
        sonar_tracker_predict(t, ahead, &gx[n], &gy[n]);
        n++;
    }
    return sonar_detector_set_tracks(&p->det, gx, gy, n);
}

/* The last steps of a sweep, the pipeline's own or another's: locate, drop repeats, track. */
static int finish_detections(struct sonar_pipeline *p, int have_cover)
{
    struct located w;
    locate(p, &p->out, &w);
    drop_repeats(p, &p->out, &w);
    p->out.world = (uint8_t)(w.world && p->cfg->track);
    return p->cfg->track ? track(p, &w, have_cover) : SONAR_OK;
}

int sonar_pipeline_track(struct sonar_pipeline *p, const struct sonar_detections *d)
{
    if (p == NULL || p->cfg == NULL || d == NULL || d->count > SONAR_MAX_CLUSTERS)
        return SONAR_ERR_ARG;
    p->out = *d;
    return finish_detections(p, 0);
}

void sonar_pipeline_view(const struct sonar_pipeline *p, struct sonar_view *v)
{
    const struct sonar_detections *d = &p->out;
    uint8_t i;
    memset(v, 0, sizeof(*v));
    v->world = p->out.world && p->trk.world;
    if (p->poses != NULL)
        v->have_pose = (uint8_t)sonar_pose_at(p->poses, d->utime, &v->pose);
    for (i = 0; i < d->count; i++) {
        struct sonar_pose q;
        if (p->poses != NULL && sonar_pose_at(p->poses, d->det[i].utime, &q)) {
            sonar_pose_to_world(&q, d->det[i].x_m, d->det[i].y_m, &v->det_north[i], &v->det_east[i]);
            v->det_world[i] = 1;
        }
    }
    for (i = 0; i < p->trk.n && p->cfg->track; i++) {
        const struct sonar_track *t = &p->trk.t[i];
        struct sonar_pose q;
        if (!p->trk.world) {
            v->trk_x[i] = t->px;
            v->trk_y[i] = t->py;
            v->trk_vx[i] = t->vx;
            v->trk_vy[i] = t->vy;
            continue;
        }
        if (!sonar_pose_at(p->poses, t->utime, &q))
            q = p->last_pose; /* a track last seen before the poses kept: the latest pose */
        sonar_pose_to_body(&q, t->px, t->py, &v->trk_x[i], &v->trk_y[i]);
        sonar_pose_rotate(-q.yaw_deg, t->vx, t->vy, &v->trk_vx[i], &v->trk_vy[i]);
    }
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
        sonar_pose_at(p->poses, p->det.utime, &q) && (r = world_gates(p)) != SONAR_OK)
        return r;
    if ((r = sonar_detector_end(&p->det, &p->out)) < 0)
        return r;
    if ((r = finish_detections(p, 1)) != SONAR_OK)
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
        p->geometry_changes++;
        sonar_background_reset(&p->bg);
        if ((r = sonar_sweep_init(&p->sweep, p->cfg->max_step, SONAR_MAX_SWEEP_BEAMS)) != SONAR_OK)
            return r;
    }
    p->n = b->n;
    p->range_m = b->range_m;
    tap(p, SONAR_STAGE_RAW, b->utime, b->angle, b->samples);
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
