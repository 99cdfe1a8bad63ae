/* hull.c -- monotone-chain convex hull after an in-place heapsort, O(n log n) time, O(1) extra space; a hull's diameter and width, O(n^2). */
#include "sonar/hull.h"

#include <math.h>
#include <stddef.h>

static int less(const struct sonar_xy *a, const struct sonar_xy *b)
{
    return a->x < b->x || (a->x == b->x && a->y < b->y);
}

static void sift(struct sonar_xy *p, uint16_t root, uint16_t n)
{
    for (;;) {
        uint32_t child = 2u * root + 1u;
        struct sonar_xy t;
        if (child >= n)
            return;
        if (child + 1u < n && less(&p[child], &p[child + 1u]))
            child++;
        if (!less(&p[root], &p[child]))
            return;
        t = p[root];
        p[root] = p[child];
        p[child] = t;
        root = (uint16_t)child;
    }
}

static void heapsort(struct sonar_xy *p, uint16_t n)
{
    uint16_t i;
    if (n < 2)
        return;
    for (i = (uint16_t)(n / 2u); i-- > 0;)
        sift(p, i, n);
    for (i = (uint16_t)(n - 1u); i > 0; i--) {
        struct sonar_xy t = p[0];
        p[0] = p[i];
        p[i] = t;
        sift(p, 0, i);
    }
}

/* (a - o) x (b - o): > 0 for a left (counter-clockwise) turn; exact since |coords| < 2^30. */
static int64_t cross(const struct sonar_xy *o, const struct sonar_xy *a, const struct sonar_xy *b)
{
    return ((int64_t)a->x - o->x) * ((int64_t)b->y - o->y) - ((int64_t)a->y - o->y) * ((int64_t)b->x - o->x);
}

int sonar_hull_build(struct sonar_xy *pts, uint16_t n, struct sonar_xy *out, uint16_t cap)
{
    uint32_t k = 0, lower;
    uint16_t i;
    if (pts == NULL || out == NULL || n == 0)
        return SONAR_ERR_ARG;
    if ((uint32_t)cap < 2u * (uint32_t)n)
        return SONAR_ERR_SPACE;
    if (n == 1) {
        out[0] = pts[0];
        return 1;
    }
    heapsort(pts, n);
    /* Lower chain: pop while the last turn is not strictly left (drops collinear and duplicates). */
    for (i = 0; i < n; i++) {
        while (k >= 2 && cross(&out[k - 2], &out[k - 1], &pts[i]) <= 0)
            k--;
        out[k++] = pts[i];
    }
    /* Upper chain, right to left; it may not pop below the lower chain's end. */
    lower = k + 1;
    for (i = (uint16_t)(n - 1u); i-- > 0;) {
        while (k >= lower && cross(&out[k - 2], &out[k - 1], &pts[i]) <= 0)
            k--;
        out[k++] = pts[i];
    }
    /* The last point repeats the first; all-equal input leaves two copies of one point. */
    k--;
    if (k == 2 && out[0].x == out[1].x && out[0].y == out[1].y)
        k = 1;
    return (int)k;
}

int64_t sonar_hull_area2(const struct sonar_xy *poly, uint16_t n)
{
    int64_t s = 0;
    uint16_t i;
    for (i = 0; i < n; i++) {
        const struct sonar_xy *a = &poly[i], *b = &poly[(i + 1u) % n];
        s += (int64_t)a->x * b->y - (int64_t)b->x * a->y;
    }
    return s;
}

int64_t sonar_hull_diameter(const struct sonar_xy *hull, uint16_t n)
{
    int64_t best = 0;
    uint16_t a, b;
    for (a = 0; a < n; a++)
        for (b = (uint16_t)(a + 1u); b < n; b++) {
            int64_t dx = (int64_t)hull[a].x - hull[b].x, dy = (int64_t)hull[a].y - hull[b].y;
            if (dx * dx + dy * dy > best)
                best = dx * dx + dy * dy;
        }
    return (int64_t)sqrt((double)best);
}

int64_t sonar_hull_width(const struct sonar_xy *hull, uint16_t n)
{
    double best = -1.0;
    uint16_t a, v;
    if (n < 3)
        return 0;
    for (a = 0; a < n; a++) {
        const struct sonar_xy *p = &hull[a], *q = &hull[(a + 1u) % n];
        double ex = (double)q->x - p->x, ey = (double)q->y - p->y, len = sqrt(ex * ex + ey * ey), far = 0.0;
        if (len <= 0.0)
            continue;
        for (v = 0; v < n; v++) {
            double dist = fabs(((double)hull[v].x - p->x) * ey - ((double)hull[v].y - p->y) * ex) / len;
            far = dist > far ? dist : far;
        }
        best = best < 0.0 || far < best ? far : best;
    }
    return best < 0.0 ? 0 : (int64_t)best;
}
