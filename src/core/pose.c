/* pose.c -- vehicle pose ring: ordered, jump-checked samples, interpolation (yaw the short way), body <-> world; O(log n) a lookup, no heap. */
#include "sonar/pose.h"

#include <math.h>
#include <string.h>

#include "sonar/frame.h"

#define DEG SONAR_RAD_PER_DEG

void sonar_pose_limits_default(struct sonar_pose_limits *lim)
{
    lim->max_speed_mps = 50.0f;
    lim->max_yaw_rate_dps = 720.0f;
    lim->min_gap_us = 50000;
}

int sonar_pose_init(struct sonar_pose_ring *r, const struct sonar_pose_limits *lim)
{
    if (r == NULL || lim == NULL || !(lim->max_speed_mps >= 0.1f && lim->max_speed_mps <= 1000.0f) ||
        !(lim->max_yaw_rate_dps >= 1.0f && lim->max_yaw_rate_dps <= 100000.0f) || lim->min_gap_us < 0 ||
        lim->min_gap_us > 10000000)
        return SONAR_ERR_ARG;
    memset(r, 0, sizeof(*r));
    r->lim = *lim;
    return SONAR_OK;
}

static const struct sonar_pose *at(const struct sonar_pose_ring *r, unsigned i)
{
    return &r->s[(r->head + i) % SONAR_MAX_POSES];
}

/* b - a in degrees, the short way round: -180..180. */
static double yaw_delta(double a, double b)
{
    double d = fmod(b - a, 360.0);
    if (d > 180.0)
        d -= 360.0;
    else if (d < -180.0)
        d += 360.0;
    return d;
}

static float wrap360(double y)
{
    double w = fmod(y, 360.0);
    if (w < 0.0)
        w += 360.0;
    /* fmod of a value just below 0 can round up to exactly 360 */
    return w >= 360.0 ? 0.0f : (float)w;
}

int sonar_pose_push(struct sonar_pose_ring *r, const struct sonar_pose *p)
{
    struct sonar_pose q;
    if (r == NULL || p == NULL)
        return SONAR_ERR_ARG;
    if (!isfinite(p->north_m) || !isfinite(p->east_m) || !isfinite(p->yaw_deg) ||
        fabsf(p->north_m) > SONAR_POSE_COORD_MAX || fabsf(p->east_m) > SONAR_POSE_COORD_MAX ||
        fabsf(p->yaw_deg) > 1.0e6f) {
        r->bad++;
        return SONAR_ERR_RANGE;
    }
    q = *p;
    q.yaw_deg = wrap360((double)p->yaw_deg);
    if (r->n > 0) {
        const struct sonar_pose *last = at(r, r->n - 1u);
        int64_t gap = q.utime - last->utime;
        if (gap <= 0) {
            r->out_of_order++;
            return SONAR_ERR_RANGE;
        }
        if (gap <= SONAR_POSE_STALE_US) {
            /* Allow one metre and ten degrees beyond the limits, for the sources' own jitter. */
            double dt = (double)gap * 1e-6, dn = (double)q.north_m - last->north_m, de = (double)q.east_m - last->east_m;
            if (sqrt(dn * dn + de * de) > r->lim.max_speed_mps * dt + 1.0 ||
                fabs(yaw_delta(last->yaw_deg, q.yaw_deg)) > r->lim.max_yaw_rate_dps * dt + 10.0) {
                r->jumps++;
                return SONAR_ERR_RANGE;
            }
            /*
             * Thinning keeps the newest sample: it takes the place of the last one while that one
             * is less than min_gap after the one before it, so a beam just after a fresh sample
             * still finds it (dropping it instead left the pose up to min_gap old at the newest beams).
             */
            if (r->n >= 2u && last->utime - at(r, r->n - 2u)->utime < r->lim.min_gap_us) {
                r->s[(r->head + r->n - 1u) % SONAR_MAX_POSES] = q;
                r->thinned++;
                return SONAR_OK;
            }
        }
    }
    if (r->n == SONAR_MAX_POSES) {
        r->head = (uint16_t)((r->head + 1u) % SONAR_MAX_POSES);
        r->n--;
    }
    r->s[(r->head + r->n) % SONAR_MAX_POSES] = q;
    r->n++;
    r->accepted++;
    return SONAR_OK;
}

int sonar_pose_at(const struct sonar_pose_ring *r, int64_t utime, struct sonar_pose *out)
{
    unsigned lo, hi;
    const struct sonar_pose *a, *b;
    double f;
    if (r == NULL || out == NULL || r->n == 0)
        return 0;
    a = at(r, 0);
    b = at(r, r->n - 1u);
    if (utime <= a->utime || utime >= b->utime) {
        const struct sonar_pose *e = utime <= a->utime ? a : b;
        int64_t d = utime - e->utime;
        if (d > SONAR_POSE_STALE_US || d < -SONAR_POSE_STALE_US)
            return 0;
        *out = *e;
        out->utime = utime;
        return 1;
    }
    /* The last sample at or before utime: a binary search, the ring being in time order. */
    lo = 0;
    hi = r->n - 1u;
    while (hi - lo > 1u) {
        unsigned mid = lo + (hi - lo) / 2u;
        if (at(r, mid)->utime <= utime)
            lo = mid;
        else
            hi = mid;
    }
    a = at(r, lo);
    b = at(r, hi);
    /* Interpolating across a gap longer than the staleness limit would invent a path. */
    if (b->utime - a->utime > 2 * SONAR_POSE_STALE_US && utime - a->utime > SONAR_POSE_STALE_US &&
        b->utime - utime > SONAR_POSE_STALE_US)
        return 0;
    f = (double)(utime - a->utime) / (double)(b->utime - a->utime);
    out->utime = utime;
    out->north_m = (float)(a->north_m + f * ((double)b->north_m - a->north_m));
    out->east_m = (float)(a->east_m + f * ((double)b->east_m - a->east_m));
    out->yaw_deg = wrap360(a->yaw_deg + f * yaw_delta(a->yaw_deg, b->yaw_deg));
    return 1;
}

void sonar_pose_rotate(float yaw_deg, float x, float y, float *north, float *east)
{
    double c = cos((double)yaw_deg * DEG), s = sin((double)yaw_deg * DEG);
    *north = (float)(c * x - s * y);
    *east = (float)(s * x + c * y);
}

void sonar_pose_to_world(const struct sonar_pose *p, float x_m, float y_m, float *north_m, float *east_m)
{
    float n, e;
    sonar_pose_rotate(p->yaw_deg, x_m, y_m, &n, &e);
    *north_m = p->north_m + n;
    *east_m = p->east_m + e;
}

void sonar_pose_to_body(const struct sonar_pose *p, float north_m, float east_m, float *x_m, float *y_m)
{
    /* R(yaw) is a rotation: its inverse is R(-yaw). */
    sonar_pose_rotate(-p->yaw_deg, north_m - p->north_m, east_m - p->east_m, x_m, y_m);
}

const char *sonar_pose_push_why(struct sonar_pose_ring *r, const struct sonar_pose *p)
{
    uint32_t ooo = r->out_of_order, jumps = r->jumps;
    if (sonar_pose_push(r, p) == SONAR_OK)
        return NULL;
    return r->out_of_order != ooo ? "not later than the pose before it"
           : r->jumps != jumps   ? "a jump from the pose before it (faster than 50 m/s or 720 deg/s)"
                                 : "a value that is not a number or is beyond 10^6 m";
}

uint32_t sonar_pose_accepted(const struct sonar_pose_ring *r)
{
    return r->accepted;
}
