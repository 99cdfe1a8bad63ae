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

/* Centres up to this many get the neighbour lists below (stack: PRUNE_K^2 * 9 bytes); more use the plain search. */
#define PRUNE_K 16

/*
 * For each centre a, the other centres a point labelled a may move to (its part's, or all),
 * nearest first: nb[a][t] with q[a][t] = |c_a - c_nb|^2 ascending.
 */
struct neighbours {
    int64_t q[PRUNE_K][PRUNE_K - 1];
    uint8_t nb[PRUNE_K][PRUNE_K - 1];
    uint8_t cnt[PRUNE_K];
};

static void neighbours_build(struct neighbours *n, const struct sonar_xy *c, const uint8_t *part, uint8_t k)
{
    uint8_t a, j;
    for (a = 0; a < k; a++) {
        uint8_t m = 0;
        for (j = 0; j < k; j++) {
            struct sonar_point pa;
            int64_t q;
            uint8_t t;
            if (j == a || (part != NULL && part[j] != part[a]))
                continue;
            pa.x = c[a].x;
            pa.y = c[a].y;
            pa.w = 1;
            q = dist2(&pa, &c[j]);
            /* Insertion by distance; j ascends, so equal distances stay in index order. */
            for (t = m; t > 0 && n->q[a][t - 1] > q; t--) {
                n->q[a][t] = n->q[a][t - 1];
                n->nb[a][t] = n->nb[a][t - 1];
            }
            n->q[a][t] = q;
            n->nb[a][t] = j;
            m++;
        }
        n->cnt[a] = m;
    }
}

/*
 * The nearest centre to p among a's list, lowest index on ties: the same answer as a full
 * search. A centre j with |c_a - c_j| > 2 |p - c_a| is strictly farther from p than c_a (triangle
 * inequality), and the list is sorted, so the scan stops at the first such j. All integer: the
 * test is |c_a - c_j|^2 > 4 |p - c_a|^2.
 */
static uint8_t nearest_pruned(const struct sonar_point *p, const struct sonar_xy *c, const struct neighbours *n,
                              uint8_t a)
{
    int64_t da = dist2(p, &c[a]), bd = da, lim = 4 * da;
    uint8_t t, best = a;
    for (t = 0; t < n->cnt[a] && n->q[a][t] <= lim; t++) {
        uint8_t j = n->nb[a][t];
        int64_t d = dist2(p, &c[j]);
        if (d < bd || (d == bd && j < best)) {
            bd = d;
            best = j;
        }
    }
    return best;
}

/* Lloyd's rounds, unconstrained (part == NULL) or kept inside parts; arguments already checked. */
static int lloyd(const struct sonar_point *pts, uint16_t n, uint8_t *labels, struct sonar_xy *c,
                 const uint8_t *part, uint8_t k, uint8_t iterations)
{
    int64_t sx[SONAR_KMEANS_MAX_K], sy[SONAR_KMEANS_MAX_K];
    uint64_t sw[SONAR_KMEANS_MAX_K];
    struct neighbours nbr;
    unsigned it;
    uint16_t i;
    uint8_t j;
    for (it = 0; it < iterations; it++) {
        unsigned changed = 0;
        int prune = k <= PRUNE_K;
        memset(sx, 0, sizeof(sx));
        memset(sy, 0, sizeof(sy));
        memset(sw, 0, sizeof(sw));
        if (prune)
            neighbours_build(&nbr, c, part, k);
        for (i = 0; i < n; i++) {
            uint8_t l;
            if (pts[i].w == 0)
                continue;
            if (prune && labels[i] < k)
                l = nearest_pruned(&pts[i], c, &nbr, labels[i]);
            else
                l = part == NULL ? nearest(&pts[i], c, k, NULL) : nearest_in(&pts[i], c, part, k, labels[i]);
            changed += l != labels[i];
            labels[i] = l;
            sx[l] += (int64_t)pts[i].x * pts[i].w;
            sy[l] += (int64_t)pts[i].y * pts[i].w;
            sw[l] += pts[i].w;
        }
        /*
         * Moving the centres when nothing changed leaves them where they were, except in a first
         * round inside parts: entry centres need not be their parts' means yet.
         */
        for (j = 0; j < k; j++)
            if (sw[j] > 0) {
                c[j].x = rounded_mean(sx[j], sw[j]);
                c[j].y = rounded_mean(sy[j], sw[j]);
            }
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
