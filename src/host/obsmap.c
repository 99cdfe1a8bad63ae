/* obsmap.c -- the obstacle map as sonard keeps it (obsmap.h); O(samples) a beam, O(72 + echoes) a read. */
#include "obsmap.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "sonar/frame.h"
#include "sonar/pipeline.h"

int obsmap_init(struct obsmap *o, const float (*ignore)[2], unsigned n_ignore, char *err, size_t errlen)
{
    struct sonar_obstacle_config oc;
    unsigned i;
    memset(o, 0, sizeof(*o));
    if (n_ignore > OBSMAP_MAX_IGNORE) {
        snprintf(err, errlen, "--ignore-deg: %u arcs, at most %d", n_ignore, OBSMAP_MAX_IGNORE);
        return HOST_ERR_CONFIG;
    }
    for (i = 0; i < n_ignore; i++) {
        if (!(ignore[i][0] >= 0.0f && ignore[i][0] <= 360.0f && ignore[i][1] >= 0.0f && ignore[i][1] <= 360.0f)) {
            snprintf(err, errlen, "--ignore-deg %g:%g: degrees 0..360", (double)ignore[i][0], (double)ignore[i][1]);
            return HOST_ERR_CONFIG;
        }
        o->ignore[i][0] = ignore[i][0];
        o->ignore[i][1] = ignore[i][1];
    }
    o->n_ignore = (uint8_t)n_ignore;
    sonar_obstacle_defaults(&oc);
    oc.min_range_m = SONAR_PIPE_NEAR_M; /* the pipeline's comes with obsmap_bind */
    if (sonar_obstacle_init(&o->obs, &oc) != SONAR_OK) {
        snprintf(err, errlen, "the obstacle map's defaults: invalid");
        return HOST_ERR_CONFIG;
    }
    return HOST_OK;
}

int obsmap_check_min_range(float min_range_m, char *err, size_t errlen)
{
    if (min_range_m >= 0.0f && min_range_m <= SONAR_OBSTACLE_MAX_RANGE_M)
        return HOST_OK;
    snprintf(err, errlen, "--min-range %g: too far for the obstacle map (0..%g m)", (double)min_range_m,
             (double)SONAR_OBSTACLE_MAX_RANGE_M);
    return HOST_ERR_CONFIG;
}

/* The map's min range follows the pipeline's (a reload's takes over with its sweep); never nearer than the ring-down. */
static int follow_frame(struct obsmap *o, float *angle_offset)
{
    float min_range_m;
    app_frame(o->app, angle_offset, &min_range_m);
    if (min_range_m != o->min_range_m) {
        if (sonar_obstacle_set_min_range(&o->obs, min_range_m > SONAR_PIPE_NEAR_M ? min_range_m : SONAR_PIPE_NEAR_M) != SONAR_OK)
            return HOST_ERR_CONFIG;
        o->min_range_m = min_range_m;
    }
    return HOST_OK;
}

int obsmap_bind(struct obsmap *o, struct app *a)
{
    float off;
    o->app = a;
    o->min_range_m = -1.0f; /* none yet: the first follow sets it */
    return follow_frame(o, &off);
}

static int sink_beam(void *self, const struct sonar_record *b)
{
    return obsmap_beam(self, b);
}

int obsmap_attach(struct obsmap *o, struct app *a)
{
    int r = obsmap_bind(o, a);
    if (r != HOST_OK)
        return r;
    o->sink.name = "obstacles";
    o->sink.self = o;
    o->sink.stages = 1u << SONAR_STAGE_MEDIAN;
    o->sink.live = 1;
    o->sink.beam = sink_beam;
    return app_add_sink(a, &o->sink);
}

void obsmap_on_read(struct obsmap *o, obsmap_out_fn fn, void *user)
{
    o->out = fn;
    o->out_user = user;
}

/* Whether a body bearing (degrees clockwise from ahead) lies in an ignored arc. */
static int ignored(const struct obsmap *o, float deg)
{
    unsigned i;
    float b = (float)fmod(fmod((double)deg, 360.0) + 360.0, 360.0);
    for (i = 0; i < o->n_ignore; i++) {
        float from = o->ignore[i][0], to = o->ignore[i][1];
        if (from <= to ? (b >= from && b <= to) : (b >= from || b <= to)) /* an arc may cross ahead */
            return 1;
    }
    return 0;
}

int obsmap_beam(struct obsmap *o, const struct sonar_record *b)
{
    float bearing, angle_offset;
    struct sonar_pose q;
    if (follow_frame(o, &angle_offset) != HOST_OK)
        return HOST_ERR_CONFIG;
    bearing = ((float)b->angle + angle_offset) * (float)SONAR_DEG_PER_GRAD;
    if (ignored(o, bearing))
        return HOST_OK; /* the vehicle's own echoes never enter the map */
    q.utime = b->utime;
    q.north_m = b->north_m;
    q.east_m = b->east_m;
    q.yaw_deg = b->yaw_deg;
    if (sonar_obstacle_beam(&o->obs, b->utime, bearing, b->has_pose ? &q : NULL, b->samples, b->n, b->range_m) != SONAR_OK)
        return HOST_ERR_IO;
    if (o->out != NULL && (o->out_at == 0 || b->utime - o->out_at >= OBSMAP_OUT_US || b->utime < o->out_at)) {
        struct obsmap_read r;
        obsmap_read(o, b->utime, b->has_pose ? &q : NULL, &r);
        o->out_at = b->utime;
        o->out(o->out_user, &r);
    }
    return HOST_OK;
}

int64_t obsmap_max_age_us(const struct obsmap *o)
{
    double s = o->app != NULL && app_last_sweep_s(o->app) > 0.0f ? (double)app_last_sweep_s(o->app) : 40.0;
    return (int64_t)(s * 1.2e6);
}

void obsmap_read(const struct obsmap *o, int64_t now_us, const struct sonar_pose *pose, struct obsmap_read *r)
{
    int k;
    r->utime = now_us;
    sonar_obstacle_map(&o->obs, now_us, obsmap_max_age_us(o), pose, r->dist_cm, &r->min_cm, &r->max_cm);
    if (r->min_cm == 0)
        r->min_cm = 1; /* MAVLink's 0 is "invalid": every distance below is raised to min_distance */
    for (k = 0; k < SONAR_OBS_SECTORS; k++) {
        if (ignored(o, (float)(k * SONAR_OBS_SECTOR_DEG)))
            r->dist_cm[k] = SONAR_OBS_UNKNOWN;
        else if (r->dist_cm[k] < r->min_cm)
            r->dist_cm[k] = r->min_cm;
    }
}

uint32_t obsmap_beams(const struct obsmap *o)
{
    return sonar_obstacle_beams(&o->obs);
}
