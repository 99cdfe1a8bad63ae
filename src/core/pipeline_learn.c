/* pipeline_learn.c -- what the background may learn of a beam: the world grid's footprint with the tracks' discs kept out, and the per-angle rows' keep spans (tracks) and learn spans (structure); a cosine, a sine and a few products a disc, nothing stored. */
#include <math.h>

#include "pipeline_internal.h"
#include "sonar/frame.h"

/*
 * The auto background's kept discs in the world frame: about each confirmed or coasting track where
 * it was last seen, of its last detection's radius (at least SONAR_PIPE_KEEP_MIN_M). The grid does
 * not learn the cells inside them, as sonar_pipe_keep_spans below does for the per-angle rows.
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
int sonar_pipe_world_background(struct sonar_pipeline *p, int64_t utime, uint16_t angle, int *done)
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
    ray.near_m = sonar_pipe_near_m(p);
    p->prev_bearing = (float)fmod(ray.bearing_deg, 360.0);
    p->have_prev_bearing = 1;
    p->world_beams++;
    *done = 1;
    return sonar_background_apply_world_keep(p->bg, &ray, p->buf[p->cur], p->buf[p->cur], p->n, discs,
                                             keep_discs(p, discs));
}

/*
 * The samples of a beam at angle whose axis crosses the disc of radius rad about (x, y) (metres,
 * output frame; c, s the axis's cosine and sine, per_m samples a metre), as a span; 0 if none.
 */
static int disc_span(const struct sonar_pipeline *p, double c, double s, double per_m, double x, double y, double rad,
                     struct sonar_bg_span *sp)
{
    double along = x * c + y * s, perp = fabs(y * c - x * s), r, lo, hi;
    if (!(along > 0.0) || !(perp <= rad))
        return 0;
    r = sqrt(x * x + y * y);
    lo = (r - rad) * per_m;
    hi = (r + rad) * per_m + 1.0;
    if (hi <= 0.0 || lo >= (double)p->n)
        return 0;
    sp->lo = (uint16_t)(lo > 0.0 ? lo : 0.0);
    sp->hi = (uint16_t)(hi < (double)p->n ? hi : (double)p->n);
    return 1;
}

/*
 * The background's spans for a beam at angle (body frame only). Keep (auto mode, never learnt): the
 * samples within the disc about each confirmed or coasting track, where it was last seen, of its last
 * detection's radius (at least SONAR_PIPE_KEEP_MIN_M). Learn (per-angle and auto mode, learnt at
 * once): the disc of each structure place (structure.h). Computed here per beam (a cosine and a
 * sine, then a few products a disc), so nothing is stored for it. Returns the keep spans' count;
 * *nlearn the learn spans'.
 */
uint8_t sonar_pipe_keep_spans(const struct sonar_pipeline *p, uint16_t angle, struct sonar_bg_span *sp,
                              struct sonar_bg_span *learn, uint8_t *nlearn)
{
    double th, c, s, per_m;
    uint8_t k, m = 0;
    const int auto_mode = p->cfg->background.mode == SONAR_BACKGROUND_AUTO;
    *nlearn = 0;
    if ((!auto_mode && p->cfg->background.mode != SONAR_BACKGROUND_PER_ANGLE) || p->trk.world)
        return 0;
    th = sonar_frame_rad((double)angle + (double)p->cfg->detector.angle_offset);
    c = cos(th);
    s = sin(th);
    per_m = (double)p->n / (double)p->range_m;
    for (k = 0; auto_mode && p->cfg->track && k < p->trk.n && m < SONAR_MAX_TRACKS; k++) {
        const struct sonar_track *t = &p->trk.t[k];
        double rad = (double)t->size_dm * 0.1;
        if (t->state == SONAR_TRACK_TENTATIVE)
            continue;
        rad = rad > (double)SONAR_PIPE_KEEP_MIN_M ? rad : (double)SONAR_PIPE_KEEP_MIN_M;
        m = (uint8_t)(m + disc_span(p, c, s, per_m, (double)t->px, (double)t->py, rad, &sp[m]));
    }
    for (k = 0; k < p->st.n && *nlearn < SONAR_PIPE_LEARN_MAX; k++) {
        const struct sonar_place *q = &p->st.p[k];
        double rad = (double)q->radius > (double)SONAR_PIPE_KEEP_MIN_M ? (double)q->radius : (double)SONAR_PIPE_KEEP_MIN_M;
        if (q->structure)
            *nlearn = (uint8_t)(*nlearn + disc_span(p, c, s, per_m, (double)q->x, (double)q->y, rad, &learn[*nlearn]));
    }
    return m;
}
