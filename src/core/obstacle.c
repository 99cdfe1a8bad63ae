/* obstacle.c -- nearest echo per 5-degree sector against a running-median noise floor; O(n) a beam, O(72) a map, no heap. */
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
    o->n = 0;
    o->range_m = 0.0f;
}

int sonar_obstacle_init(struct sonar_obstacle *o, const struct sonar_obstacle_config *cfg)
{
    if (o == NULL || cfg == NULL || !(cfg->min_range_m >= 0.0f && cfg->min_range_m <= 100.0f) || cfg->margin > 64 ||
        cfg->min_level < 1)
        return SONAR_ERR_ARG;
    memset(o, 0, sizeof(*o));
    o->cfg = *cfg;
    reset(o);
    return SONAR_OK;
}

/* Sample i stands above the floor f by max(min_level, f x margin / 16); an unseeded floor has no echo. */
static int echo(const struct sonar_obstacle *o, const uint8_t *s, uint16_t i)
{
    unsigned f = (o->floor[i] + 4u) >> 3, gate = (f * o->cfg.margin) >> 4;
    return f != 0 && s[i] > f + (gate > o->cfg.min_level ? gate : o->cfg.min_level);
}

int sonar_obstacle_beam(struct sonar_obstacle *o, int64_t utime, float bearing_deg, const struct sonar_pose *pose,
                        const uint8_t *s, uint16_t n, float range_m)
{
    struct sonar_obstacle_sector *sec;
    double b;
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
        if (echo(o, s, i))
            hit = i;
    /*
     * The echo's range is the peak of that first return, not where it first rises above the
     * floor: the pulse and the median put the rising edge 7 to 14 cm before a wall seen head-on
     * (sonar-sim's pool, through sonard --mavlink and pymavlink: 28 of 63 sectors within 0.1 m
     * with the edge, 53 with the peak).
     */
    if (hit >= 0)
        for (i = (uint16_t)(hit + 1); i < n && echo(o, s, i); i++)
            if (s[i] > s[hit])
                hit = i;
    /* With a pose, the memory is kept by world bearing. */
    b = fmod((double)bearing_deg + (pose != NULL ? (double)pose->yaw_deg : 0.0), 360.0);
    b = b < 0.0 ? b + 360.0 : b;
    k = (int)floor(b / SONAR_OBS_SECTOR_DEG + 0.5) % SONAR_OBS_SECTORS;
    sec = &o->sector[k];
    {
        /* The echo's range: the sample's centre, in cm. */
        uint16_t cm = hit < 0 ? 0 : (uint16_t)fmin(65534.0, floor(((double)hit + 0.5) * range_m / n * 100.0 + 0.5));
        int same = sec->utime != 0 && utime >= sec->utime && utime - sec->utime < SONAR_OBS_PASS_US;
        int take = !same || (cm != 0 && (sec->cm == 0 || cm < sec->cm));
        /* A new pass replaces the old one, echo or clear; within one pass the nearest echo of its beams wins. */
        if (take) {
            double th = b * SONAR_PI / 180.0, d = (double)cm / 100.0;
            sec->cm = cm;
            sec->world = pose != NULL;
            sec->north_m = pose != NULL ? (float)((double)pose->north_m + d * cos(th)) : 0.0f;
            sec->east_m = pose != NULL ? (float)((double)pose->east_m + d * sin(th)) : 0.0f;
        }
        sec->utime = utime;
    }
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

void sonar_obstacle_map(const struct sonar_obstacle *o, int64_t now_us, int64_t max_age_us, const struct sonar_pose *pose,
                        uint16_t *dist_cm, uint16_t *min_cm, uint16_t *max_cm)
{
    double mx = floor((double)o->range_m * 100.0 + 0.5);
    int k, pass;
    *max_cm = (uint16_t)(mx > 65533.0 ? 65533.0 : mx);
    *min_cm = (uint16_t)fmax(1.0, floor((double)o->cfg.min_range_m * 100.0 + 0.5));
    for (k = 0; k < SONAR_OBS_SECTORS; k++)
        dist_cm[k] = SONAR_OBS_UNKNOWN;
    /* Echoes first (the nearest in each sector), then "clear" where no echo landed. */
    for (pass = 0; pass < 2; pass++)
        for (k = 0; k < SONAR_OBS_SECTORS; k++) {
            const struct sonar_obstacle_sector *sec = &o->sector[k];
            double bearing = (double)k * SONAR_OBS_SECTOR_DEG, cm = (double)sec->cm;
            int at;
            if (sec->utime == 0 || now_us - sec->utime > max_age_us || (pass == 0) != (sec->cm != 0))
                continue;
            if (sec->world) {
                if (pose == NULL)
                    continue;
                if (sec->cm != 0) {
                    /* Where that echo is now, from where the vehicle is now. */
                    float x, y;
                    sonar_pose_to_body(pose, sec->north_m, sec->east_m, &x, &y);
                    cm = floor(sqrt((double)x * x + (double)y * y) * 100.0 + 0.5);
                    bearing = x == 0.0f && y == 0.0f ? 0.0 : atan2((double)y, (double)x) * 180.0 / SONAR_PI;
                    if (cm > (double)*max_cm)
                        continue;
                    cm = cm < (double)*min_cm ? (double)*min_cm : cm;
                } else {
                    bearing -= (double)pose->yaw_deg;
                }
            }
            bearing = fmod(bearing, 360.0);
            bearing = bearing < 0.0 ? bearing + 360.0 : bearing;
            at = (int)floor(bearing / SONAR_OBS_SECTOR_DEG + 0.5) % SONAR_OBS_SECTORS;
            if (pass == 0 && (dist_cm[at] == SONAR_OBS_UNKNOWN || cm < (double)dist_cm[at]))
                dist_cm[at] = (uint16_t)cm;
            else if (pass == 1 && dist_cm[at] == SONAR_OBS_UNKNOWN)
                dist_cm[at] = (uint16_t)(*max_cm + 1u);
        }
}
