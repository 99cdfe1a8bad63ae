/* pipeline_tracks.c -- a sweep's detections after the detector: located in the world when the poses say, repeated sightings dropped, tracked (body or world frame, with the sweep's coverage); O(detections x tracks) a sweep, no heap. */
#include "sonar/pipeline.h"

#include <math.h>
#include <string.h>

#include "pipeline_internal.h"
#include "sonar/frame.h"

/* The angle offset in whole gradians, as the cover map takes it. */
static int offset_grad(const struct sonar_pipeline *p)
{
    float off = p->cfg->detector.angle_offset;
    return (int)(off >= 0.0f ? off + 0.5f : off - 0.5f);
}

/* The gradian a beam pointed at in the world (from north), offset included: yaw is 400/360 gradians a degree. */
static int world_grad(const struct sonar_pipeline *p, uint16_t i, const struct sonar_pose *q)
{
    return sonar_frame_wrap((int)sonar_detector_angles(&p->det)[i] + offset_grad(p) + (int)floor((double)q->yaw_deg / SONAR_DEG_PER_GRAD + 0.5));
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
        if (!sonar_pose_at(p->poses, sonar_detector_beam_utime(&p->det, i), &q)) {
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
int sonar_pipe_world_gates(struct sonar_pipeline *p)
{
    float gx[SONAR_MAX_CLUSTERS], gy[SONAR_MAX_CLUSTERS], best[SONAR_MAX_CLUSTERS];
    uint8_t idx[SONAR_MAX_CLUSTERS], n = 0, j, m = 0;
    uint16_t i;
    for (j = 0; j < p->trk.n && n < SONAR_MAX_CLUSTERS; j++)
        if (gated(&p->trk.t[j])) {
            best[n] = 1e9f;
            idx[n++] = j;
        }
    for (i = 0; i < sonar_detector_beams(&p->det); i++) {
        struct sonar_pose q;
        int64_t t = sonar_detector_beam_utime(&p->det, i);
        double th = ((double)sonar_detector_angles(&p->det)[i] + (double)p->cfg->detector.angle_offset) * SONAR_DEG_PER_GRAD;
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

/* The segment between place d's two farthest hull vertices (a wall's line) into seg; 0 when shorter than 0.5 m. */
static int segment_of(const struct sonar_detection *d, float seg[4])
{
    float best = 0.25f;
    uint8_t a, b;
    int found = 0;
    for (a = 0; a < d->hull_count; a++)
        for (b = (uint8_t)(a + 1u); b < d->hull_count; b++) {
            float dx = d->hull_x[b] - d->hull_x[a], dy = d->hull_y[b] - d->hull_y[a];
            if (dx * dx + dy * dy > best) {
                best = dx * dx + dy * dy;
                seg[0] = d->hull_x[a];
                seg[1] = d->hull_y[a];
                seg[2] = d->hull_x[b];
                seg[3] = d->hull_y[b];
                found = 1;
            }
        }
    return found;
}

/*
 * The site's walls for the tracker: a survey in use's lines (its places of kind structure, walls and
 * lane ropes alike: a rope taken for a wall costs nothing, tracker.h), in the body frame only (a
 * survey is a fixed sonar's); none otherwise, and then the tracker predicts as it always has.
 */
static int site_walls(struct sonar_pipeline *p, int world)
{
    float seg[SONAR_TRK_MAX_WALLS][4];
    unsigned n = 0, k;
    const struct sonar_survey *sv = p->sv;
    if (!world && sv != NULL && sv->state == SONAR_SURVEY_IN_USE && sv->places != NULL)
        for (k = 0; k < sv->nplaces && n < SONAR_TRK_MAX_WALLS; k++)
            n += sv->places[k].kind == SONAR_DET_STRUCTURE && segment_of(&sv->places[k], seg[n]);
    return sonar_tracker_set_walls(&p->trk, (const float(*)[4])seg, n);
}

/*
 * Whether a detection is at a first look: in the background's first warm-up sweeps since it
 * (re)started or was loaded, or where it had not learnt the place when the sweep ended: the row of
 * the sweep's beam nearest its bearing (a sector scanned back and forth at 3 gradians visits a row
 * every other pass, and some rows never) still seeding or just seeded.
 */
static int first_look(const struct sonar_pipeline *p, const struct sonar_detection *d)
{
    const uint16_t *a = sonar_detector_angles(&p->det);
    double g = (double)d->bearing_deg / SONAR_DEG_PER_GRAD - (double)p->cfg->detector.angle_offset;
    int at = sonar_frame_wrap((int)floor(g + 0.5)), best = SONAR_GRAD_TURN, e;
    uint16_t i, row = (uint16_t)at;
    if (sonar_survey_covers(p->sv, row))
        return 0; /* the survey knew the place before anything was in it */
    if (p->bg_sweeps < p->cfg->background.warmup)
        return 1;
    for (i = 0; i < p->out.beams; i++)
        if ((e = sonar_frame_gap(a[i], (uint16_t)at)) < best) {
            best = e;
            row = a[i];
        }
    return !sonar_background_learnt(p->bg, row);
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
    uint8_t cover[SONAR_GRAD_TURN / 8], i, n = 0, no = 0, map[SONAR_MAX_CLUSTERS], still[SONAR_MAX_CLUSTERS];
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
    /* Objects only: structure and walls' echoes are not tracked (no track, so no keep, can hold them out of the background). */
    for (i = 0; i < p->out.count; i++) {
        if (!sonar_det_kind_tracked(p->out.det[i].kind))
            continue;
        map[no] = i;
        still[no] = p->out.det[i].kind == SONAR_DET_STATIC_START;
        obs[no].x_m = world ? w->north[i] : p->out.det[i].x_m;
        obs[no].y_m = world ? w->east[i] : p->out.det[i].y_m;
        obs[no].utime = p->out.det[i].utime;
        obs[no].size_m = det_radius(&p->out.det[i]);
        no++;
    }
    if (have_cover && world)
        world_cover(p, cover);
    else if (have_cover)
        sonar_tracker_cover(cover, sonar_detector_angles(&p->det), p->out.beams, p->cfg->max_step, offset_grad(p));
    sw.utime = p->out.utime;
    sw.beams = p->out.beams;
    sw.cover = have_cover ? cover : NULL;
    sw.min_range_m = p->cfg->detector.min_range_m;
    sw.max_range_m = have_cover ? p->range_m : (float)SONAR_PIPE_MAX_RANGE_M;
    sw.origin_x = world ? w->pose.north_m : 0.0f;
    sw.origin_y = world ? w->pose.east_m : 0.0f;
    sw.clutter = have_cover ? p->clutter : NULL; /* detections alone (no beams) say nothing of where they looked */
    if ((r = site_walls(p, world)) != SONAR_OK || (r = sonar_tracker_update(&p->trk, obs, no, &sw)) != SONAR_OK)
        return r;
    sonar_tracker_static_start(&p->trk, still, no);
    for (i = 0; i < p->trk.n; i++)
        if (p->trk.t[i].det >= 0)
            p->trk.t[i].det = (int8_t)map[p->trk.t[i].det]; /* back to the sweep's own numbering */
    sonar_activity_look(p->act, &p->trk, p->out.utime, p->cfg->detector.angle_offset, p->cfg->still_alarm_s, world);
    if (!(p->cfg->detector.track_m > 0.0f) || world || !have_cover)
        return SONAR_OK;
    ahead = p->out.utime + (p->out.utime - sonar_detector_t0(&p->det));
    for (i = 0; i < p->trk.n; i++) {
        const struct sonar_track *t = &p->trk.t[i];
        if (!gated(t) || n >= SONAR_MAX_CLUSTERS)
            continue;
        sonar_tracker_predict(t, ahead, &gx[n], &gy[n]);
        n++;
    }
    return sonar_detector_set_tracks(&p->det, gx, gy, n);
}

/*
 * The sweep's structure (structure.h), in the body frame (the world grid learns what stands still
 * there as it is): each detection joins its place, those at structure places become structure, and
 * those at places that have stood since the first look are objects of kind static since start. A
 * background with no per-angle rows knows no first look: there it runs only for --structure-s.
 */
static int structure(struct sonar_pipeline *p, const struct located *w)
{
    struct sonar_structure_obs o[SONAR_MAX_CLUSTERS];
    uint8_t kind[SONAR_MAX_CLUSTERS], i;
    int r;
    uint8_t n = 0, map[SONAR_MAX_CLUSTERS];
    const int rows = p->cfg->background.mode == SONAR_BACKGROUND_PER_ANGLE || p->cfg->background.mode == SONAR_BACKGROUND_AUTO;
    if (w->world || (!rows && p->cfg->structure_s <= 0.0f))
        return SONAR_OK;
    /* Objects only: what the detector called structure (wider than any object) is already that. */
    for (i = 0; i < p->out.count; i++) {
        if (p->out.det[i].kind != SONAR_DET_OBJECT)
            continue;
        map[n] = i;
        o[n].x_m = p->out.det[i].x_m;
        o[n].y_m = p->out.det[i].y_m;
        o[n].radius_m = det_radius(&p->out.det[i]);
        o[n].utime = p->out.det[i].utime;
        o[n].first_look = (uint8_t)first_look(p, &p->out.det[i]);
        n++;
    }
    if ((r = sonar_structure_sweep(&p->st, o, n, p->out.utime, kind)) < 0)
        return r;
    for (i = 0; i < n; i++)
        p->out.det[map[i]].kind = kind[i];
    return SONAR_OK;
}

int sonar_pipe_finish_sweep(struct sonar_pipeline *p, int have_cover)
{
    struct located w;
    int r;
    locate(p, &p->out, &w);
    drop_repeats(p, &p->out, &w);
    /* Structure is learnt where the beams were: a co-processor's sweep (no cover) has its own. */
    if (have_cover && (r = structure(p, &w)) != SONAR_OK)
        return r;
    p->out.world = (uint8_t)(w.world && p->cfg->track);
    return p->cfg->track ? track(p, &w, have_cover) : SONAR_OK;
}

int sonar_pipeline_track(struct sonar_pipeline *p, const struct sonar_detections *d)
{
    if (p == NULL || p->cfg == NULL || d == NULL || d->count > SONAR_MAX_CLUSTERS)
        return SONAR_ERR_ARG;
    p->out = *d;
    return sonar_pipe_finish_sweep(p, 0);
}

unsigned sonar_pipeline_targets(const struct sonar_pipeline *p, int64_t utime, struct sonar_scan_target *out, unsigned max)
{
    struct sonar_pose q;
    unsigned n = 0;
    uint8_t i;
    if (p == NULL || p->cfg == NULL || !p->cfg->track)
        return 0;
    if (p->trk.world && (p->poses == NULL || !sonar_pose_at(p->poses, utime, &q)))
        q = p->last_pose;
    for (i = 0; i < p->trk.n && n < max; i++) {
        const struct sonar_track *t = &p->trk.t[i];
        float x, y, r, across, dt, var;
        double g;
        if (t->state == SONAR_TRACK_TENTATIVE)
            continue;
        sonar_tracker_predict(t, utime, &x, &y);
        if (p->trk.world)
            sonar_pose_to_body(&q, x, y, &x, &y);
        r = sqrtf(x * x + y * y);
        g = sonar_frame_bearing_deg((double)x, (double)y) / SONAR_DEG_PER_GRAD - (double)p->cfg->detector.angle_offset;
        g = fmod(g, (double)SONAR_GRAD_TURN);
        out[n].angle = (float)(g < 0.0 ? g + (double)SONAR_GRAD_TURN : g);
        if (!(out[n].angle < (float)SONAR_GRAD_TURN))
            out[n].angle = 0.0f;
        /* Three sigma of the position carried to utime (position, cross and velocity terms) and the
           object's radius, seen from the sonar at its range. */
        dt = utime > t->utime ? (float)(utime - t->utime) * 1e-6f : 0.0f;
        var = t->pa + 2.0f * t->pb * dt + t->pc * dt * dt;
        across = 3.0f * sqrtf(var > 0.0f ? var : 0.0f) + (float)t->size_dm * 0.1f;
        out[n].half_width = r > across ? (float)(sonar_frame_deg(atan((double)(across / r))) / SONAR_DEG_PER_GRAD)
                                       : (float)SONAR_GRAD_HALF;
        if (out[n].half_width < 1.0f)
            out[n].half_width = 1.0f;
        n++;
    }
    return n;
}
