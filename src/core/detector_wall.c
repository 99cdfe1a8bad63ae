/* detector_wall.c -- stage 5: thin objects that continue one another along a line are pieces of one wall (detector.h); O(n^2) hull unions over a sweep's objects and walls (at most 2 SONAR_MAX_CLUSTERS), 1.4 KB on the stack. */
#include <math.h>
#include <string.h>

#include "detector_internal.h"
#include "sonar/hull.h"

/* A detection's hull in mm (its vertices, at most SONAR_MAX_HULL). */
static uint16_t hull_mm(const struct sonar_detection *o, struct sonar_xy *p)
{
    uint16_t v;
    for (v = 0; v < o->hull_count; v++) {
        p[v].x = (int32_t)floor((double)o->hull_x[v] * 1000.0 + 0.5);
        p[v].y = (int32_t)floor((double)o->hull_y[v] * 1000.0 + 0.5);
    }
    return o->hull_count;
}

static uint8_t root(uint8_t *up, uint8_t i)
{
    while (up[i] != i)
        i = up[i] = up[up[i]];
    return i;
}

/* The nearest two vertices of hulls a and b apart, mm. */
static double gap_mm(const struct sonar_xy *a, uint16_t na, const struct sonar_xy *b, uint16_t nb)
{
    double best = -1.0;
    uint16_t i, k;
    for (i = 0; i < na; i++)
        for (k = 0; k < nb; k++) {
            double dx = (double)a[i].x - b[k].x, dy = (double)a[i].y - b[k].y, dd = dx * dx + dy * dy;
            best = best < 0.0 || dd < best ? dd : best;
        }
    return best < 0.0 ? 0.0 : sqrt(best);
}

void sonar_det_wall_pieces(const struct sonar_detection *det, uint8_t n, const struct sonar_detection *const *walls,
                           uint8_t nw, double smear_per_m, uint8_t *wall)
{
    struct sonar_xy h[2 * SONAR_MAX_CLUSTERS][SONAR_MAX_HULL];
    struct sonar_xy both[2 * SONAR_MAX_HULL], out[4 * SONAR_MAX_HULL];
    int64_t width[2 * SONAR_MAX_CLUSTERS];
    uint16_t nh[2 * SONAR_MAX_CLUSTERS];
    uint8_t up[2 * SONAR_MAX_CLUSTERS], thin[2 * SONAR_MAX_CLUSTERS], members[2 * SONAR_MAX_CLUSTERS];
    const int64_t thick = (int64_t)(SONAR_DET_WALL_THICK_M * 1000.0f);
    const uint8_t all = (uint8_t)(n + nw);
    uint8_t i, k;
    memset(wall, 0, n);
    /* Objects 0..n-1, then the walls already found: a wall is a line whatever its width. */
    for (i = 0; i < all; i++) {
        up[i] = i;
        nh[i] = hull_mm(i < n ? &det[i] : walls[i - n], h[i]);
        width[i] = nh[i] >= 2 ? sonar_hull_width(h[i], nh[i]) : 0;
        thin[i] = (uint8_t)(nh[i] >= 2 && (i >= n || width[i] <= thick));
    }
    /*
     * Two pieces continue one another when they nearly touch and their union is as thin as a wall (or, with a
     * wall found, hardly thicker than it): a buoy before a wall is as deep as itself and the gap.
     */
    for (i = 0; i < all; i++)
        for (k = (uint8_t)(i + 1u); k < all; k++) {
            int64_t lim = thick, wider = width[i] > width[k] ? width[i] : width[k];
            int m;
            if (!thin[i] || !thin[k] || (i >= n && k >= n) || root(up, i) == root(up, k) ||
                gap_mm(h[i], nh[i], h[k], nh[k]) > (double)SONAR_DET_WALL_GAP_M * 1000.0)
                continue;
            if (k >= n && wider + wider / 4 > lim)
                lim = wider + wider / 4;
            memcpy(both, h[i], nh[i] * sizeof(both[0]));
            memcpy(both + nh[i], h[k], nh[k] * sizeof(both[0]));
            m = sonar_hull_build(both, (uint16_t)(nh[i] + nh[k]), out, 4 * SONAR_MAX_HULL);
            if (m >= 2 && sonar_hull_width(out, (uint16_t)m) <= lim)
                up[root(up, k)] = root(up, i);
        }
    /* A line holding a wall, or of two or more pieces at least SONAR_DET_WALL_M long end to end, is a wall. */
    for (i = 0; i < n; i++) {
        uint8_t r = root(up, i), nm = 0, a, b, has_wall = 0;
        double far = 0.0, range_m = 0.0;
        if (!thin[i] || wall[i])
            continue;
        for (k = 0; k < all; k++)
            if (root(up, k) == r) {
                members[nm++] = k;
                has_wall |= (uint8_t)(k >= n);
                if (k < n && det[k].range_m > range_m)
                    range_m = det[k].range_m;
            }
        if (nm < 2)
            continue;
        for (a = 0; a < nm && !has_wall; a++)
            for (b = a; b < nm; b++) {
                const struct sonar_xy *p = h[members[a]], *q = h[members[b]];
                uint16_t u, v;
                for (u = 0; u < nh[members[a]]; u++)
                    for (v = 0; v < nh[members[b]]; v++) {
                        double dx = (double)p[u].x - q[v].x, dy = (double)p[u].y - q[v].y;
                        far = dx * dx + dy * dy > far ? dx * dx + dy * dy : far;
                    }
            }
        if (has_wall || sqrt(far) >= ((double)SONAR_DET_WALL_M + range_m * smear_per_m) * 1000.0)
            for (a = 0; a < nm; a++)
                if (members[a] < n)
                    wall[members[a]] = 1;
    }
}
