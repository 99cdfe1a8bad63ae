/* obstacle.c -- nearest echo per 5-degree sector against a running-median noise floor, from remembered echo points and the lines joining them; O(n) a beam, O(SONAR_MAX_OBS_ECHOES) a map, no heap. */
#include "sonar/obstacle.h"

#include <math.h>
#include <string.h>

#include "sonar/frame.h"

void sonar_obstacle_defaults(struct sonar_obstacle_config *cfg)
{
    cfg->min_range_m = 0.5f;
    cfg->margin = 32;
    cfg->min_level = 24;
}

static void reset(struct sonar_obstacle *o)
{
    memset(o->floor, 0, sizeof(o->floor));
    memset(o->sector, 0, sizeof(o->sector));
    o->head = o->count = 0;
    o->prev_echo = 0;
    o->n = 0;
    o->range_m = 0.0f;
}

int sonar_obstacle_init(struct sonar_obstacle *o, const struct sonar_obstacle_config *cfg)
{
    if (o == NULL || cfg == NULL || !(cfg->min_range_m >= 0.0f && cfg->min_range_m <= SONAR_OBSTACLE_MAX_RANGE_M) || cfg->margin > 64 ||
        cfg->min_level < 1)
        return SONAR_ERR_ARG;
    memset(o, 0, sizeof(*o));
    o->cfg = *cfg;
    reset(o);
    return SONAR_OK;
}

int sonar_obstacle_set_min_range(struct sonar_obstacle *o, float min_range_m)
{
    if (o == NULL || !(min_range_m >= 0.0f && min_range_m <= SONAR_OBSTACLE_MAX_RANGE_M))
        return SONAR_ERR_ARG;
    o->cfg.min_range_m = min_range_m;
    return SONAR_OK;
}

/* The sector of a bearing in degrees (any value): round(bearing / 5) modulo 72. */
static int sector_at(double bearing_deg)
{
    double b = fmod(bearing_deg, 360.0);
    b = b < 0.0 ? b + 360.0 : b;
    return (int)floor(b / SONAR_OBS_SECTOR_DEG + 0.5) % SONAR_OBS_SECTORS;
}

/* Sample i's level above the floor, in grey levels (negative below it). */
static double excess(const struct sonar_obstacle *o, const uint8_t *s, uint16_t i)
{
    return (double)s[i] - (double)((o->floor[i] + 4u) >> 3);
}

/* Sample i stands above the floor f by max(min_level, f x margin / 16); an unseeded floor has no echo. */
static int above_floor(const struct sonar_obstacle *o, const uint8_t *s, uint16_t i)
{
    unsigned f = (o->floor[i] + 4u) >> 3, gate = (f * o->cfg.margin) >> 4;
    return f != 0 && s[i] > f + (gate > o->cfg.min_level ? gate : o->cfg.min_level);
}

/* e's point from its origin, range, bearing and side (a beam half-width toward it). */
static void place(struct sonar_obstacle_echo *e)
{
    double th = ((double)e->bearing_deg + (double)e->side * SONAR_OBS_HALF_BEAM_DEG) * SONAR_RAD_PER_DEG;
    e->x_m = (float)((double)e->ox + (double)e->range_m * cos(th));
    e->y_m = (float)((double)e->oy + (double)e->range_m * sin(th));
}

/* Long: one beam is placed, its echoes found and the map aged in one pass over its samples (per beam, on the host
   beside the pipeline); the steps share the beam's bearing and pose, so they stay together. */
int sonar_obstacle_beam(struct sonar_obstacle *o, int64_t utime, float bearing_deg, const struct sonar_pose *pose,
                        const uint8_t *s, uint16_t n, float range_m)
{
    struct sonar_obstacle_sector *sec;
    double b, at = 0.0;
    uint16_t i, first;
    int k, hit = -1;
    if (o == NULL || s == NULL || n == 0 || n > SONAR_MAX_SAMPLES || !(range_m > 0.0f && range_m <= 1000.0f) ||
        !isfinite(bearing_deg))
        return SONAR_ERR_ARG;
    if (n != o->n || range_m != o->range_m) {
        reset(o);
        o->n = n;
        o->range_m = range_m;
    }
    /* Sample i covers (i + 0.5) range / n: the first one past min_range. */
    first = (uint16_t)fmin((double)n, ceil((double)o->cfg.min_range_m * n / range_m - 0.5));
    for (i = first; i < n && hit < 0; i++)
        if (above_floor(o, s, i))
            hit = i;
    /*
     * An echo starts at the nearest surface inside the beam, and that is what the autopilot must
     * keep clear of: the echo's range is its return's leading edge, where the level first reaches
     * half the return's mean above the floor (a one-sample dip does not end the return),
     * interpolated between samples. Neither the peak nor the centre: both lie inside the return,
     * which runs past the surface by the pulse and the footprint (docs/results.md).
     */
    if (hit >= 0) {
        double sw = 0.0, half, lo;
        unsigned cnt = 0;
        for (i = (uint16_t)hit; i < n && (above_floor(o, s, i) || (i + 1u < n && above_floor(o, s, (uint16_t)(i + 1u)))); i++) {
            sw += fmax(0.0, excess(o, s, i));
            cnt++;
        }
        half = 0.5 * sw / (double)cnt;
        for (i = (uint16_t)hit; excess(o, s, i) < half; i++)
            ; /* ends: the return's mean is reached by at least one of its samples */
        lo = i > first ? fmax(0.0, excess(o, s, (uint16_t)(i - 1u))) : 0.0;
        /* Between sample i - 1 and i, where the level crosses half (lo < half <= excess(i)). */
        at = lo < half ? (double)i - 1.0 + (half - lo) / (excess(o, s, i) - lo) : (double)i - 1.0;
    }
    /* With a pose, the memory is kept by world bearing. */
    b = fmod((double)bearing_deg + (pose != NULL ? (double)pose->yaw_deg : 0.0), 360.0);
    b = b < 0.0 ? b + 360.0 : b;
    k = sector_at(b);
    sec = &o->sector[k];
    if (!(sec->utime != 0 && utime >= sec->utime && utime - sec->utime < SONAR_OBS_PASS_US)) {
        /* A new pass retires the old one's echoes (they stay in the ring, older than pass_us). */
        sec->pass_us = utime;
        sec->echo = 0;
    }
    sec->utime = utime;
    sec->world = pose != NULL;
    if (hit >= 0) {
        /* Sample position at covers (at + 0.5) range / n. */
        struct sonar_obstacle_echo *e = &o->echo[o->head];
        struct sonar_obstacle_echo *prev = &o->echo[(o->head + SONAR_MAX_OBS_ECHOES - 1u) % SONAR_MAX_OBS_ECHOES];
        double step = remainder(b - o->prev_bearing, 360.0);
        e->utime = utime;
        e->world = pose != NULL;
        e->ox = pose != NULL ? pose->north_m : 0.0f;
        e->oy = pose != NULL ? pose->east_m : 0.0f;
        e->range_m = (float)((at + 0.5) * range_m / n);
        e->bearing_deg = (float)b;
        e->side = 0;
        e->sector = (uint8_t)k;
        e->linked = 0;
        place(e);
        if (o->prev_echo && prev->world == e->world && utime >= prev->utime && fabs(step) <= SONAR_OBS_LINK_DEG) {
            double dx = (double)e->x_m - (double)prev->x_m, dy = (double)e->y_m - (double)prev->y_m;
            /* A surface at incidence a puts two beams' echoes r x step / cos(a) apart: 3 x the arc is ~70 degrees. */
            e->linked = sqrt(dx * dx + dy * dy) <= 0.2 + 3.0 * (double)e->range_m * fabs(step) * SONAR_RAD_PER_DEG;
        }
        if (e->linked) {
            /*
             * The leading edge is the nearest surface anywhere in the beam: on a surface whose range
             * grows from prev to this beam, that is each beam's edge toward prev. Placed there, the
             * two echoes lie on the surface, not a beam half-width nearer (17 cm at 10 m and 45
             * degrees). An echo whose two pairs disagree (the beam holding the surface's nearest
             * point) stays on its axis.
             */
            int side = e->range_m > prev->range_m ? (step > 0.0 ? -1 : 1) : e->range_m < prev->range_m ? (step > 0.0 ? 1 : -1) : 0;
            e->side = (int8_t)side;
            place(e);
            if (!prev->linked)
                prev->side = (int8_t)side;
            else if (prev->side != side)
                prev->side = 0;
            place(prev);
        }
        o->head = (uint16_t)((o->head + 1u) % SONAR_MAX_OBS_ECHOES);
        o->count = (uint16_t)(o->count < SONAR_MAX_OBS_ECHOES ? o->count + 1u : o->count);
        sec->echo = 1;
    }
    o->prev_echo = hit >= 0;
    o->prev_bearing = b;
    o->beams++;
    o->echoes += hit >= 0;
    o->newest = utime > o->newest ? utime : o->newest;
    /* The floor learns every beam, an eighth of a level toward it (never to 0, "unseeded"). */
    for (i = 0; i < n; i++) {
        unsigned f = o->floor[i], x = 8u * s[i];
        if (f == 0)
            f = x > 0 ? x : 1u;
        else if (x > f)
            f++;
        else if (x < f && f > 1u)
            f--;
        o->floor[i] = (uint16_t)f;
    }
    return SONAR_OK;
}

/* An echo that still stands at now_us: within the age limit and of its sector's current pass. */
static int standing(const struct sonar_obstacle *o, const struct sonar_obstacle_echo *e, int64_t now_us, int64_t max_age_us,
                    const struct sonar_pose *pose)
{
    return now_us - e->utime <= max_age_us && e->utime >= o->sector[e->sector].pass_us && (!e->world || pose != NULL);
}

/* An echo in the body frame at pose. */
static void body(const struct sonar_obstacle_echo *e, const struct sonar_pose *pose, double *x, double *y)
{
    float bx = e->x_m, by = e->y_m;
    if (e->world)
        sonar_pose_to_body(pose, e->x_m, e->y_m, &bx, &by);
    *x = (double)bx;
    *y = (double)by;
}

static int sector_of(double x, double y)
{
    return sector_at(x == 0.0 && y == 0.0 ? 0.0 : atan2(y, x) * 180.0 / SONAR_PI);
}

/* Sector at takes a point d metres away if nearer than what it holds; beyond the range it is not an echo. */
static void offer(uint16_t *dist_cm, int at, double d, uint16_t min_cm, uint16_t max_cm)
{
    double cm = floor(d * 100.0 + 0.5);
    if (cm > (double)max_cm)
        return;
    cm = cm < (double)min_cm ? (double)min_cm : cm;
    if (dist_cm[at] == SONAR_OBS_UNKNOWN || cm < (double)dist_cm[at])
        dist_cm[at] = (uint16_t)cm;
}

/*
 * The line from (ax, ay) to (bx, by) in the body frame: each sector it crosses takes the nearest
 * point of the part inside it. Bearing along a line that misses the origin is monotone, so the
 * sectors are walked from a's to b's and each part is cut at the sectors' edges.
 */
static void offer_line(uint16_t *dist_cm, double ax, double ay, double bx, double by, uint16_t min_cm, uint16_t max_cm)
{
    const double dx = bx - ax, dy = by - ay, len2 = dx * dx + dy * dy;
    int s = sector_of(ax, ay), last = sector_of(bx, by), dir, guard;
    double turn, tfoot;
    if (len2 <= 0.0)
        return;
    turn = remainder(atan2(by, bx) - atan2(ay, ax), 2.0 * SONAR_PI);
    dir = turn >= 0.0 ? 1 : -1;
    tfoot = -(ax * dx + ay * dy) / len2; /* where the line passes nearest the origin */
    for (guard = 0; guard < SONAR_OBS_SECTORS; guard++) {
        double t0 = 0.0, t1 = 1.0, t;
        if (s != last) {
            /* The edge this part leaves by: bearing (s +- 1/2) sectors; where the line meets it. */
            double e = ((double)s + 0.5 * dir) * SONAR_OBS_SECTOR_DEG * SONAR_RAD_PER_DEG, ux = cos(e), uy = sin(e);
            double den = dx * uy - dy * ux;
            t1 = den != 0.0 ? -(ax * uy - ay * ux) / den : 1.0;
            t1 = t1 < 0.0 ? 0.0 : t1 > 1.0 ? 1.0 : t1;
        }
        if (guard > 0) {
            double e = ((double)s - 0.5 * dir) * SONAR_OBS_SECTOR_DEG * SONAR_RAD_PER_DEG, ux = cos(e), uy = sin(e);
            double den = dx * uy - dy * ux;
            t0 = den != 0.0 ? -(ax * uy - ay * ux) / den : 0.0;
            t0 = t0 < 0.0 ? 0.0 : t0 > 1.0 ? 1.0 : t0;
        }
        t = tfoot < t0 ? t0 : tfoot > t1 ? t1 : tfoot;
        offer(dist_cm, s, sqrt((ax + t * dx) * (ax + t * dx) + (ay + t * dy) * (ay + t * dy)), min_cm, max_cm);
        if (s == last)
            break;
        s = (s + dir + SONAR_OBS_SECTORS) % SONAR_OBS_SECTORS;
    }
}

void sonar_obstacle_map(const struct sonar_obstacle *o, int64_t now_us, int64_t max_age_us, const struct sonar_pose *pose,
                        uint16_t *dist_cm, uint16_t *min_cm, uint16_t *max_cm)
{
    double mx = floor((double)o->range_m * 100.0 + 0.5), px = 0.0, py = 0.0;
    uint16_t i;
    int k, prev_ok = 0;
    *max_cm = (uint16_t)(mx > 65533.0 ? 65533.0 : mx);
    *min_cm = (uint16_t)fmax(1.0, floor((double)o->cfg.min_range_m * 100.0 + 0.5));
    for (k = 0; k < SONAR_OBS_SECTORS; k++)
        dist_cm[k] = SONAR_OBS_UNKNOWN;
    /*
     * Echoes first, each and the line to the one before it, from the oldest held on. The one
     * before it in the ring is the previous iteration's: it must be held (i > 0) and standing.
     */
    for (i = 0; i < o->count; i++) {
        const struct sonar_obstacle_echo *e = &o->echo[(o->head + SONAR_MAX_OBS_ECHOES - o->count + i) % SONAR_MAX_OBS_ECHOES];
        double x, y;
        if (!standing(o, e, now_us, max_age_us, pose)) {
            prev_ok = 0;
            continue;
        }
        body(e, pose, &x, &y);
        offer(dist_cm, sector_of(x, y), sqrt(x * x + y * y), *min_cm, *max_cm);
        if (e->linked && prev_ok)
            offer_line(dist_cm, px, py, x, y, *min_cm, *max_cm);
        px = x;
        py = y;
        prev_ok = 1;
    }
    /* Then "clear" where a pass without an echo was the last, and no echo landed. */
    for (k = 0; k < SONAR_OBS_SECTORS; k++) {
        const struct sonar_obstacle_sector *sec = &o->sector[k];
        int at;
        if (sec->utime == 0 || now_us - sec->utime > max_age_us || sec->echo || (sec->world && pose == NULL))
            continue;
        at = sector_at((double)k * SONAR_OBS_SECTOR_DEG - (sec->world ? (double)pose->yaw_deg : 0.0));
        if (dist_cm[at] == SONAR_OBS_UNKNOWN)
            dist_cm[at] = (uint16_t)(*max_cm + 1u);
    }
}

uint32_t sonar_obstacle_beams(const struct sonar_obstacle *o)
{
    return o->beams;
}
