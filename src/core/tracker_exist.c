/* tracker_exist.c -- a track's life by its probability of existence against the site's clutter map (or by M of N hits), its birth and what its end teaches the map; O(1) a track, no heap. */
#include <math.h>

#include "sonar/tracker.h"
#include "tracker_internal.h"

static unsigned popcount8(unsigned v)
{
    unsigned n = 0;
    for (; v != 0; v &= v - 1u)
        n++;
    return n;
}

/*
 * Its own chance to be detected when in view: hits over looks, with two looks' worth of
 * SONAR_TRK_EXIST_PD to start from, between 0.5 and 0.95. A faint target seen every other look
 * loses less to a miss than a bright one that is never missed.
 */
static float own_pd(const struct sonar_track *t)
{
    float pd = ((float)t->hits + 2.0f * SONAR_TRK_EXIST_PD) / ((float)t->looks + 2.0f);
    return pd < 0.5f ? 0.5f : pd > 0.95f ? 0.95f : pd;
}

/*
 * The look's evidence on the odds that t is real (its hit's likelihood against the clutter density
 * where it is, or a miss in view, or nothing out of view), after it survived the look.
 */
static void update_existence(const struct sonar_tracker *tk, struct sonar_track *t, int hit, int seen)
{
    const struct sonar_tracker_sweep *sw = tk->cur_sw;
    float e = SONAR_TRK_EXIST_SURVIVE * t->existence, delta = 0.0f, pd = own_pd(t);
    if (hit) {
        float rho = sw != NULL ? sonar_clutter_density(sw->clutter, t->px - sw->origin_x, t->py - sw->origin_y)
                               : SONAR_CLUTTER_FLOOR;
        delta = pd * (SONAR_TRK_EXIST_PG - t->lik / rho);
    } else if (seen) {
        delta = pd * SONAR_TRK_EXIST_PG;
    }
    e = (1.0f - delta) * e / (1.0f - delta * e);
    t->existence = e > 1.0f ? 1.0f : e < 0.0f ? 0.0f : e;
    /* Established with hysteresis: a struggler missed for one look (its existence dips) keeps its alarm. */
    t->exists = (uint8_t)(t->existence >= SONAR_TRK_EXIST_ALARM ||
                               (t->exists && t->existence >= SONAR_TRK_EXIST_DOUBT));
}

void sonar_trk_exist_birth(const struct sonar_tracker *tk, struct sonar_track *t)
{
    t->state = !tk->cfg.existence && tk->cfg.confirm_m <= 1 ? SONAR_TRACK_CONFIRMED : SONAR_TRACK_TENTATIVE;
    t->history = 1;
    t->seen = 1;
    t->hits = 1;
    t->looks = 1;
    t->existence = SONAR_TRK_EXIST_BIRTH;
}

void sonar_trk_exist_teach(const struct sonar_tracker *tk, const struct sonar_tracker_obs *obs,
                           const struct sonar_tracker_sweep *sw)
{
    unsigned k;
    if (sw->clutter == NULL)
        return;
    for (k = 0; k < tk->n; k++) {
        const struct sonar_track *t = &tk->t[k];
        if (t->det >= 0 && t->state == SONAR_TRACK_TENTATIVE)
            sonar_clutter_teach(sw->clutter, obs[t->det].x_m - sw->origin_x, obs[t->det].y_m - sw->origin_y, 1.0f);
    }
}

int sonar_trk_account(const struct sonar_tracker *tk, struct sonar_track *t, int hit, int seen)
{
    const unsigned window = (1u << tk->cfg.confirm_n) - 1u;
    int keep = 1;
    update_existence(tk, t, hit, seen); /* kept by M of N too: the alarms' gate reads it */
    if (hit || seen)
        t->looks = sonar_trk_sat_inc(t->looks);
    if (hit) {
        t->hits = sonar_trk_sat_inc(t->hits);
        t->misses = 0;
        t->unseen = 0;
        t->history = (uint8_t)((((unsigned)t->history << 1) | 1u) & window);
        t->seen = (uint8_t)(t->seen < tk->cfg.confirm_n ? t->seen + 1u : t->seen);
        if (t->state == SONAR_TRACK_COASTING ||
            (t->state == SONAR_TRACK_TENTATIVE && (tk->cfg.existence ? t->existence >= SONAR_TRK_EXIST_CONFIRM
                                                                     : popcount8(t->history) >= tk->cfg.confirm_m)))
            t->state = SONAR_TRACK_CONFIRMED;
        if (tk->cfg.existence && t->existence < SONAR_TRK_EXIST_DOUBT)
            t->state = SONAR_TRACK_TENTATIVE;
        return 1;
    }
    if (seen) {
        t->misses = sonar_trk_sat_inc(t->misses);
        t->history = (uint8_t)(((unsigned)t->history << 1) & window);
        t->seen = (uint8_t)(t->seen < tk->cfg.confirm_n ? t->seen + 1u : t->seen);
        if (tk->cfg.existence) {
            keep = t->existence >= (t->state == SONAR_TRACK_TENTATIVE ? SONAR_TRK_EXIST_END_NEW : SONAR_TRK_EXIST_END);
            if (t->state != SONAR_TRACK_TENTATIVE)
                t->state = SONAR_TRACK_COASTING;
        } else if (t->state == SONAR_TRACK_TENTATIVE) {
            /* Dead once the misses in its window leave fewer than M possible hits. */
            keep = t->seen - popcount8(t->history) <= (unsigned)(tk->cfg.confirm_n - tk->cfg.confirm_m);
        } else {
            t->state = SONAR_TRACK_COASTING;
            keep = t->misses < tk->cfg.max_misses;
        }
    }
    /*
     * Out of view (gone round the edge of a sector, say) a track can be neither hit nor missed: it
     * coasts, and a bound on its sweeps without a hit ends it, so one that left for good is not
     * published for as long as its covariance takes to grow.
     */
    t->unseen = (uint8_t)(t->unseen < UINT8_MAX ? t->unseen + 1u : t->unseen);
    if (t->state == SONAR_TRACK_CONFIRMED)
        t->state = SONAR_TRACK_COASTING;
    if (t->unseen >= 2u * tk->cfg.max_misses)
        keep = 0;
    return keep;
}
