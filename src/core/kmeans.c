/* kmeans.c -- integer weighted k-means; O(n k) per iteration, no heap. */
#include "sonar/kmeans.h"

#include <string.h>

/* Both within SONAR_KMEANS_MAX_COORD (checked at the entry points): the differences fit an int32, so
 * each square is one 32 x 32 -> 64 multiply (SMULL/SMLAL on a Cortex-M) instead of a 64-bit one. */
static int64_t dist2(const struct sonar_point *p, const struct sonar_xy *c)
{
    int32_t dx = p->x - c->x, dy = p->y - c->y;
    return (int64_t)dx * dx + (int64_t)dy * dy;
}

/* For sonar_kmeans_inertia, which has no error to return for out-of-bound input: 64-bit throughout. */
static int64_t dist2_wide(const struct sonar_point *p, const struct sonar_xy *c)
{
    int64_t dx = (int64_t)p->x - c->x, dy = (int64_t)p->y - c->y;
    return dx * dx + dy * dy;
}

static int in_bounds(int32_t v)
{
    return v >= -SONAR_KMEANS_MAX_COORD && v <= SONAR_KMEANS_MAX_COORD;
}

/* Every weighted point and every given centre within the bound. */
static int bounded(const struct sonar_point *pts, uint16_t n, const struct sonar_xy *c, uint8_t k)
{
    uint16_t i;
    for (i = 0; i < n; i++)
        if (pts[i].w > 0 && !(in_bounds(pts[i].x) && in_bounds(pts[i].y)))
            return 0;
    for (i = 0; i < k; i++)
        if (!(in_bounds(c[i].x) && in_bounds(c[i].y)))
            return 0;
    return 1;
}

static uint8_t nearest(const struct sonar_point *p, const struct sonar_xy *c, uint8_t k, int64_t *best_d)
{
    uint8_t j, best = 0;
    int64_t bd = dist2(p, &c[0]);
    for (j = 1; j < k; j++) {
        int64_t d = dist2(p, &c[j]);
        if (d < bd) {
            bd = d;
            best = j;
        }
    }
    if (best_d != NULL)
        *best_d = bd;
    return best;
}

int sonar_kmeans_seed(const struct sonar_point *pts, uint16_t n, struct sonar_xy *c, uint8_t k)
{
    uint16_t i;
    uint8_t m = 0;
    if (pts == NULL || c == NULL || k < 1 || k > SONAR_KMEANS_MAX_K || !bounded(pts, n, c, 0))
        return SONAR_ERR_ARG;
    for (i = 0; i < n && m == 0; i++)
        if (pts[i].w > 0) {
            c[0].x = pts[i].x;
            c[0].y = pts[i].y;
            m = 1;
        }
    while (m > 0 && m < k) {
        int64_t far_d = 0;
        int32_t far_i = -1;
        for (i = 0; i < n; i++) {
            int64_t d;
            if (pts[i].w == 0)
                continue;
            (void)nearest(&pts[i], c, m, &d);
            if (d > far_d) {
                far_d = d;
                far_i = i;
            }
        }
        if (far_i < 0)
            break; /* every point coincides with a centre */
        c[m].x = pts[far_i].x;
        c[m].y = pts[far_i].y;
        m++;
    }
    return m;
}

/* Weighted mean rounded half away from zero, so results do not depend on the platform's division. */
static int32_t rounded_mean(int64_t sum, uint64_t w)
{
    int64_t half = (int64_t)(w / 2u);
    return (int32_t)(sum >= 0 ? (sum + half) / (int64_t)w : -((-sum + half) / (int64_t)w));
}

/* Nearest centre sharing part tag `tag`; `from` is one such centre, so there is always an answer. */
static uint8_t nearest_in(const struct sonar_point *p, const struct sonar_xy *c, const uint8_t *part, uint8_t k,
                          uint8_t from)
{
    uint8_t j, best = from, tag = part[from];
    int64_t bd = dist2(p, &c[from]);
    for (j = 0; j < k; j++) {
        int64_t d;
        if (part[j] != tag || j == from)
            continue;
        d = dist2(p, &c[j]);
        if (d < bd || (d == bd && j < best)) {
            bd = d;
            best = j;
        }
    }
    return best;
}

/* Centres up to this many get the gap table below (stack: PRUNE_K * (NEAR * 9 + 9) bytes); more use the plain search. */
#define PRUNE_K 16
#define NEAR 4 /* the nearest centres each centre lists, nearest first */

/*
 * For each centre a, the NEAR centres a point labelled a may move to (its part's, or all) nearest
 * to c_a, nearest first: near[a][t] at nq[a][t] = |c_a - c_near|^2 (cnt[a] of them: fewer when the
 * part has fewer other centres); stay[a] the largest |p - c_a|^2 for which even the nearest is
 * beyond the pruning bound (nq > 4 |p - c_a|^2), so that p stays with a.
 */
struct gaps {
    int64_t stay[PRUNE_K];
    int64_t nq[PRUNE_K][NEAR];
    uint8_t near[PRUNE_K][NEAR];
    uint8_t cnt[PRUNE_K];
};

/* Lists centre j at gap q among a's nearest, if it is one. */
static void near_add(struct gaps *g, uint8_t a, uint8_t j, int64_t q)
{
    uint8_t t = g->cnt[a];
    if (t == NEAR && g->nq[a][NEAR - 1] <= q)
        return;
    if (t < NEAR)
        g->cnt[a]++;
    else
        t = NEAR - 1;
    for (; t > 0 && g->nq[a][t - 1] > q; t--) {
        g->nq[a][t] = g->nq[a][t - 1];
        g->near[a][t] = g->near[a][t - 1];
    }
    g->nq[a][t] = q;
    g->near[a][t] = j;
}

static void gaps_build(struct gaps *g, const struct sonar_xy *c, const uint8_t *part, uint8_t k)
{
    uint8_t a, j;
    for (a = 0; a < k; a++)
        g->cnt[a] = 0;
    for (a = 0; a < k; a++)
        for (j = (uint8_t)(a + 1); j < k; j++)
            if (part == NULL || part[j] == part[a]) {
                int32_t dx = c[a].x - c[j].x, dy = c[a].y - c[j].y;
                int64_t q = (int64_t)dx * dx + (int64_t)dy * dy;
                near_add(g, a, j, q);
                near_add(g, j, a, q);
            }
    for (a = 0; a < k; a++)
        /* nq > 4 d <=> d <= (nq - 1) / 4 for nq >= 1; a centre on c_a (nq = 0) keeps no point. */
        g->stay[a] = g->cnt[a] == 0 ? INT64_MAX : g->nq[a][0] == 0 ? -1 : (g->nq[a][0] - 1) / 4;
}

/*
 * The nearest centre to p, lowest index on ties, for a point labelled a: the same answer as a full
 * search of a's part. A centre j with |c_a - c_j| > 2 |p - c_a| is strictly farther from p than
 * c_a (triangle inequality), so only a's nearest centres are measured, in order until one is that
 * far (most points stop at the first); when all NEAR are near enough, the whole part is searched.
 * All integer: the test is |c_a - c_j|^2 > 4 |p - c_a|^2. |p - c_a|^2 is measured again here
 * although lloyd's inline test had it: only the few points that get this far pay for it, and
 * passing it down cost every point more on the Cortex-M7 (make mcu-bench).
 */
static uint8_t nearest_pruned(const struct sonar_point *p, const struct sonar_xy *c, const struct gaps *g,
                              const uint8_t *part, uint8_t k, uint8_t a)
{
    int64_t da = dist2(p, &c[a]), bd = da, lim = 4 * da;
    uint8_t j, t, best = a;
    for (t = 0; t < g->cnt[a] && g->nq[a][t] <= lim; t++) {
        int64_t d = dist2(p, &c[g->near[a][t]]);
        j = g->near[a][t];
        if (d < bd || (d == bd && j < best)) {
            bd = d;
            best = j;
        }
    }
    if (t < NEAR)
        return best;
    return part == NULL ? nearest(p, c, k, NULL) : nearest_in(p, c, part, k, a);
}

/* The nearest centre to p of label a's part (of all when a >= k: a free point's first round). */
static uint8_t assign(const struct sonar_point *p, const struct sonar_xy *c, const struct gaps *g, const uint8_t *part,
                      uint8_t k, uint8_t a)
{
    if (a < k && g != NULL)
        return nearest_pruned(p, c, g, part, k, a);
    if (a >= k || part == NULL)
        return nearest(p, c, k, NULL);
    return nearest_in(p, c, part, k, a);
}

/* The centres whose points the next round must search: those of every part where a centre moved. */
static void mark_hot(uint8_t *hot, const uint8_t *moved, const uint8_t *part, uint8_t k)
{
    uint8_t a, j;
    for (a = 0; a < k; a++) {
        hot[a] = 0;
        for (j = 0; j < k && !hot[a]; j++)
            hot[a] = moved[j] && (part == NULL || part[j] == part[a]);
    }
}

/*
 * Lloyd's rounds, unconstrained (part == NULL) or kept inside parts; arguments already checked.
 * Two shortcuts give the plain rounds' labels, centres and round count exactly:
 *  - after the first round the centre sums are moved with the points that change centre
 *    (integer sums, so the same sums), and only centres whose sums changed are divided again;
 *  - a round skips the points of parts where no centre moved: the search's answer (the nearest
 *    centre of the part, lowest index on ties) depends only on the part's centres.
 */
static int lloyd(const struct sonar_point *pts, uint16_t n, uint8_t *labels, struct sonar_xy *c,
                 const uint8_t *part, uint8_t k, uint8_t iterations)
{
    int64_t sx[SONAR_KMEANS_MAX_K], sy[SONAR_KMEANS_MAX_K];
    uint64_t sw[SONAR_KMEANS_MAX_K];
    uint8_t dirty[SONAR_KMEANS_MAX_K], hot[SONAR_KMEANS_MAX_K];
    struct gaps gap;
    const struct gaps *g = k <= PRUNE_K ? &gap : NULL;
    unsigned it;
    uint16_t i;
    uint8_t j;
    memset(hot, 1, sizeof(hot));
    for (it = 0; it < iterations; it++) {
        unsigned changed = 0;
        if (g != NULL)
            gaps_build(&gap, c, part, k);
        if (it > 0)
            mark_hot(hot, dirty, part, k); /* dirty holds which centres moved */
        memset(dirty, 0, sizeof(dirty));
        for (i = 0; i < n; i++) {
            const struct sonar_point *p = &pts[i];
            uint8_t l, a = labels[i];
            /* A label below k is a weighted point's (weight-0 points keep SONAR_KMEANS_SKIP). */
            if (a < k) {
                /* nearest_pruned's first test, inline: most points stay, for one distance. */
                if (!hot[a] || (g != NULL && dist2(p, &c[a]) <= g->stay[a]))
                    continue;
            } else if (p->w == 0) {
                continue;
            }
            l = assign(p, c, g, part, k, a);
            if (l == a)
                continue;
            changed++;
            labels[i] = l;
            if (it > 0) {
                sx[a] -= (int64_t)p->x * p->w;
                sy[a] -= (int64_t)p->y * p->w;
                sw[a] -= p->w;
                sx[l] += (int64_t)p->x * p->w;
                sy[l] += (int64_t)p->y * p->w;
                sw[l] += p->w;
                dirty[a] = dirty[l] = 1;
            }
        }
        if (it == 0) {
            /* The entry labels need not match any sums, and entry centres need not be their means. */
            memset(sx, 0, sizeof(sx));
            memset(sy, 0, sizeof(sy));
            memset(sw, 0, sizeof(sw));
            for (i = 0; i < n; i++)
                if (pts[i].w > 0) {
                    sx[labels[i]] += (int64_t)pts[i].x * pts[i].w;
                    sy[labels[i]] += (int64_t)pts[i].y * pts[i].w;
                    sw[labels[i]] += pts[i].w;
                }
            memset(dirty, 1, sizeof(dirty));
        }
        /* dirty: sums changed; after this loop, the centre moved. */
        for (j = 0; j < k; j++) {
            struct sonar_xy was = c[j];
            if (!dirty[j] || sw[j] == 0) {
                dirty[j] = 0;
                continue;
            }
            c[j].x = rounded_mean(sx[j], sw[j]);
            c[j].y = rounded_mean(sy[j], sw[j]);
            dirty[j] = c[j].x != was.x || c[j].y != was.y;
        }
        /* After a round that moved nothing the centres are where they were (the first round inside parts aside). */
        if (changed == 0 && (it > 0 || part == NULL))
            return (int)it + 1;
    }
    return (int)iterations;
}

int sonar_kmeans_lloyd(const struct sonar_point *pts, uint16_t n, uint8_t *labels, struct sonar_xy *c,
                       uint8_t k, uint8_t iterations)
{
    if (pts == NULL || labels == NULL || c == NULL || k < 1 || k > SONAR_KMEANS_MAX_K || iterations < 1 ||
        !bounded(pts, n, c, k))
        return SONAR_ERR_ARG;
    memset(labels, SONAR_KMEANS_SKIP, n);
    return lloyd(pts, n, labels, c, NULL, k, iterations);
}

int sonar_kmeans_lloyd_within(const struct sonar_point *pts, uint16_t n, uint8_t *labels, struct sonar_xy *c,
                              const uint8_t *part, uint8_t k, uint8_t iterations)
{
    uint16_t i;
    if (pts == NULL || labels == NULL || c == NULL || part == NULL || k < 1 || k > SONAR_KMEANS_MAX_K ||
        iterations < 1 || !bounded(pts, n, c, k))
        return SONAR_ERR_ARG;
    for (i = 0; i < n; i++) {
        if (pts[i].w == 0)
            labels[i] = SONAR_KMEANS_SKIP;
        else if (labels[i] >= k)
            return SONAR_ERR_ARG;
    }
    return lloyd(pts, n, labels, c, part, k, iterations);
}

double sonar_kmeans_inertia(const struct sonar_point *pts, uint16_t n, const uint8_t *labels,
                            const struct sonar_xy *c)
{
    double s = 0.0;
    uint16_t i;
    for (i = 0; i < n; i++)
        if (pts[i].w > 0 && labels[i] != SONAR_KMEANS_SKIP)
            s += (double)pts[i].w * (double)dist2_wide(&pts[i], &c[labels[i]]);
    return s;
}
