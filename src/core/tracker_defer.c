/* tracker_defer.c -- association deferred by one sweep: the likeliest other assignments of a sweep kept with their two tracks' states (SONAR_TRK_HYPOTHESES - 1), and at the next look the one that explains it better adopted, its ID changes recorded as revisions; O(hits x tracks) pair costs to offer, two small assignments a hypothesis to decide; no heap. */
#include <math.h>
#include <string.h>

#include "tracker_internal.h"

/* Alternatives more than this costlier than the assignment published (-2 ln: 100 times less likely) are not kept. */
#define DEFER_MARGIN 9.21f
/* A revision is made only when the alternative explains both looks this much better: revisions cost their consumers. */
#define REVISE_BY 2.0f

enum { SWAP = 0, STEAL = 1, NEWBORN = 2 };

struct cand {
    float delta;
    uint8_t how, i, j; /* i loses its detection (or, NEWBORN, is born from it), j takes it */
    uint8_t det;       /* the detection j takes */
};

/* Keeps c among the cheapest in kept[0 .. *n), at most SONAR_TRK_HYPOTHESES - 1; counts what falls off within the margin. */
static void keep(struct sonar_tracker *tk, struct cand *kept, uint8_t *n, const struct cand *c)
{
    uint8_t k;
    if (!(c->delta <= DEFER_MARGIN))
        return;
    if (*n == SONAR_TRK_HYPOTHESES - 1) {
        tk->hyp_overflow++;
        if (!(c->delta < kept[*n - 1].delta))
            return;
        (*n)--;
    }
    for (k = *n; k > 0 && c->delta < kept[k - 1].delta; k--)
        kept[k] = kept[k - 1];
    kept[k] = *c;
    (*n)++;
}

/* The pair costs an offer weighs: the sweep's tracks, detections and gate, each track's cost of a miss. */
struct offer {
    struct sonar_tracker *tk;
    float r2;
    int *clipped;
    float miss[SONAR_MAX_TRACKS];
};

/* Two tracks that swap their detections (a crossing), or a detection a track that found none could have taken. */
static void offer_moves(struct offer *f, struct cand *kept, uint8_t *n)
{
    struct sonar_tracker *tk = f->tk;
    struct cand c;
    uint8_t i, j;
    for (i = 0; i < tk->n; i++) {
        const struct sonar_track *ti = &tk->t[i];
        float cia;
        if (ti->det < 0)
            continue;
        cia = sonar_trk_cost(tk, i, (uint8_t)ti->det, f->r2, ti->chance, f->clipped);
        for (j = 0; j < tk->n; j++) {
            const struct sonar_track *tj = &tk->t[j];
            float cja;
            if (j == i || (tj->det >= 0 && j < i))
                continue; /* a swap once, from its lower slot */
            cja = sonar_trk_cost(tk, j, (uint8_t)ti->det, f->r2, 0, f->clipped);
            if (cja >= SONAR_TRK_OUTSIDE)
                continue;
            c.i = i;
            c.j = j;
            c.det = (uint8_t)ti->det;
            if (tj->det >= 0) {
                float cib = sonar_trk_cost(tk, i, (uint8_t)tj->det, f->r2, 0, f->clipped);
                if (cib >= SONAR_TRK_OUTSIDE)
                    continue;
                c.how = SWAP;
                c.delta = cib + cja - cia - sonar_trk_cost(tk, j, (uint8_t)tj->det, f->r2, tj->chance, f->clipped);
            } else {
                c.how = STEAL; /* i misses instead of j */
                c.delta = (cja - f->miss[j]) - (cia - f->miss[i]);
            }
            keep(tk, kept, n, &c);
        }
    }
}

/* A birth that a track which found nothing could have continued instead. */
static void offer_births(struct offer *f, const uint8_t *left, uint8_t nl, struct cand *kept, uint8_t *n)
{
    struct sonar_tracker *tk = f->tk;
    const float fresh = sonar_trk_fresh(tk, f->r2);
    struct cand c;
    uint8_t k, j;
    for (k = 0; k < nl; k++)
        for (j = 0; j < tk->n; j++) {
            float cja;
            if (tk->t[j].det >= 0)
                continue;
            cja = sonar_trk_cost(tk, j, left[k], f->r2, 0, f->clipped);
            if (cja >= SONAR_TRK_OUTSIDE)
                continue;
            c.how = NEWBORN;
            c.i = 0;
            c.j = j;
            c.det = left[k];
            c.delta = cja - f->miss[j] - fresh;
            keep(tk, kept, n, &c);
        }
}

/* A kept alternative's two tracks as they would be: hit, missed where they were seen, or never born. */
static void alternative(struct sonar_tracker *tk, struct sonar_trk_alt *a, const struct cand *h,
                        const struct sonar_tracker_obs *obs, float r2, int *clipped)
{
    memset(a, 0, sizeof(*a));
    a->delta = h->delta;
    a->born_det = -1;
    a->t[1] = tk->t[h->j];
    a->id[1] = a->t[1].id;
    sonar_trk_hit(tk, &a->t[1], &obs[h->det], h->det, r2, clipped);
    (void)sonar_trk_account(tk, &a->t[1], 1, 1);
    if (h->how == NEWBORN) {
        a->absent = 1;
        a->born_det = (int8_t)h->det;
        return;
    }
    a->t[0] = tk->t[h->i];
    a->id[0] = a->t[0].id;
    if (h->how == SWAP) {
        const struct sonar_tracker_obs *o = &obs[tk->t[h->j].det];
        sonar_trk_hit(tk, &a->t[0], o, (uint8_t)tk->t[h->j].det, r2, clipped);
        (void)sonar_trk_account(tk, &a->t[0], 1, 1);
    } else {
        a->t[0].det = -1;
        a->absent = (uint8_t)!sonar_trk_account(tk, &a->t[0], 0, 1);
    }
}

void sonar_trk_defer_offer(struct sonar_tracker *tk, const struct sonar_tracker_obs *obs, const uint8_t *left, uint8_t nl,
                           float r2, int *clipped)
{
    struct cand kept[SONAR_TRK_HYPOTHESES - 1];
    struct offer f;
    uint8_t n = 0, i, k;
    f.tk = tk;
    f.r2 = r2;
    f.clipped = clipped;
    for (i = 0; i < tk->n; i++)
        f.miss[i] = sonar_trk_miss_cost(&tk->t[i]);
    offer_moves(&f, kept, &n);
    offer_births(&f, left, nl, kept, &n);
    for (k = 0; k < n; k++)
        alternative(tk, &tk->alt[k], &kept[k], obs, r2, clipped);
    tk->nalt = n;
}

void sonar_trk_defer_born(struct sonar_tracker *tk, uint8_t det, uint32_t id)
{
    uint8_t k;
    for (k = 0; k < tk->nalt; k++)
        if (tk->alt[k].born_det == (int8_t)det) {
            tk->alt[k].id[0] = id;
            tk->alt[k].born_det = -1;
        }
}

static int slot_of(const struct sonar_tracker *tk, uint32_t id)
{
    uint8_t k;
    for (k = 0; k < tk->n; k++)
        if (tk->t[k].id == id)
            return k;
    return -1;
}

/*
 * The local part of this sweep's assignment that an alternative changes, both ways: the least
 * cost of the detections near either pair of tracks (four[0..1] as published, four[2..3] had the
 * alternative been chosen; NULL: no such track; slot4[k] a live track's slot, -1 for another) and of the other live tracks that reach those
 * detections, as published (*now) and as the alternative would have it (*then). Misses included.
 */
static void local_costs(struct sonar_tracker *tk, float (*cost)[SONAR_MAX_TRACKS], const struct sonar_track *four[4],
                        const int slot4[4], const uint32_t not_id[2], const struct sonar_tracker_obs *obs, const uint8_t *rows, uint8_t nr,
                        float r2, int *clipped, float *now, float *then)
{
    float c4[SONAR_MAX_CLUSTERS][4], misses = 0.0f, fresh = sonar_trk_fresh(tk, r2), miss4[4];
    uint8_t dets[SONAR_MAX_CLUSTERS], nd = 0, nc = 2, i, k, d;
    for (k = 0; k < 4; k++)
        miss4[k] = four[k] != NULL ? sonar_trk_miss_cost(four[k]) : 0.0f;
    for (i = 0; i < nr; i++) {
        int near = 0;
        for (k = 0; k < 4; k++) {
            c4[nd][k] = four[k] == NULL ? SONAR_TRK_OUTSIDE
                        : slot4[k] >= 0 ? sonar_trk_cost(tk, (uint8_t)slot4[k], rows[i], r2, 0, clipped)
                                        : sonar_trk_pair_cost(tk, four[k], &obs[rows[i]], r2, 0, clipped);
            near |= c4[nd][k] < SONAR_TRK_OUTSIDE;
        }
        if (near)
            dets[nd++] = rows[i];
    }
    /* Columns 0 and 1: the pair in question; then every other live track that reaches one of the detections. */
    for (k = 0; nd > 0 && k < tk->n && nc < SONAR_MAX_TRACKS; k++) {
        const struct sonar_track *t = &tk->t[k];
        float miss;
        int near = 0;
        if (t->id == not_id[0] || t->id == not_id[1])
            continue;
        miss = sonar_trk_miss_cost(t);
        for (d = 0; d < nd; d++) {
            float c = sonar_trk_cost(tk, k, dets[d], r2, 0, clipped);
            cost[d][nc] = c < SONAR_TRK_OUTSIDE ? c - miss : c; /* each miss paid below, refunded on a pair */
            near |= c < SONAR_TRK_OUTSIDE;
        }
        if (near) {
            misses += miss;
            nc++;
        }
    }
    for (k = 0; k < 2; k++) {
        for (d = 0; d < nd; d++)
            cost[d][k] = c4[d][k] < SONAR_TRK_OUTSIDE ? c4[d][k] - miss4[k] : c4[d][k];
    }
    *now = misses + miss4[0] + miss4[1] + (nd > 0 ? sonar_trk_best_total((const float (*)[SONAR_MAX_TRACKS])cost, nd, nc, fresh) : 0.0f);
    for (k = 0; k < 2; k++) {
        for (d = 0; d < nd; d++)
            cost[d][k] = c4[d][k + 2] < SONAR_TRK_OUTSIDE ? c4[d][k + 2] - miss4[k + 2] : c4[d][k + 2];
    }
    *then = misses + miss4[2] + miss4[3] + (nd > 0 ? sonar_trk_best_total((const float (*)[SONAR_MAX_TRACKS])cost, nd, nc, fresh) : 0.0f);
}

/* Puts the alternative's tracks in place of the live ones, in birth (ID) order. */
static void adopt(struct sonar_tracker *tk, struct sonar_trk_alt *a)
{
    uint8_t k, j, m;
    for (k = 0, j = 0; k < tk->n; k++)
        if (tk->t[k].id != a->id[0] && tk->t[k].id != a->id[1])
            tk->t[j++] = tk->t[k];
    tk->n = j;
    for (m = a->absent ? 1 : 0; m < 2; m++) {
        struct sonar_track *t = &a->t[m];
        if (tk->n >= SONAR_MAX_TRACKS) {
            tk->overflow++;
            continue;
        }
        t->det = -1;
        t->age = (uint16_t)(t->age < UINT16_MAX ? t->age + 1u : t->age);
        for (k = tk->n; k > 0 && tk->t[k - 1].id > t->id; k--)
            tk->t[k] = tk->t[k - 1];
        tk->t[k] = *t;
        tk->n++;
    }
    tk->rev[0].from = a->id[0];
    tk->rev[0].to = a->id[1];
    tk->rev[1].from = a->id[1];
    tk->rev[1].to = a->absent ? 0 : a->id[0];
    tk->nrev = 2;
    tk->revisions++;
    sonar_trk_cache_reset(tk, tk->cache_obs); /* the slots moved */
}

void sonar_trk_defer_decide(struct sonar_tracker *tk, float (*cost)[SONAR_MAX_TRACKS], const struct sonar_tracker_obs *obs,
                            const uint8_t *rows, uint8_t nr, float r2, int *clipped)
{
    float best = -REVISE_BY;
    int pick = -1;
    uint8_t h;
    for (h = 0; h < tk->nalt; h++) {
        struct sonar_trk_alt *a = &tk->alt[h];
        const struct sonar_track *four[4];
        int s0 = a->id[0] != 0 ? slot_of(tk, a->id[0]) : -1, s1 = slot_of(tk, a->id[1]);
        float now, then, score;
        if (a->id[0] == 0)
            continue; /* its birth did not happen (the table was full) */
        four[0] = s0 >= 0 ? &tk->t[s0] : NULL;
        four[1] = s1 >= 0 ? &tk->t[s1] : NULL;
        four[2] = a->absent ? NULL : &a->t[0];
        four[3] = &a->t[1];
        {
            const int slot4[4] = {s0, s1, -1, -1};
            local_costs(tk, cost, four, slot4, a->id, obs, rows, nr, r2, clipped, &now, &then);
        }
        score = a->delta + then - now;
        if (score < best) {
            best = score;
            pick = h;
        }
    }
    if (pick >= 0)
        adopt(tk, &tk->alt[pick]);
}
