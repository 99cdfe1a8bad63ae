/* obsmap.h -- the obstacle map as sonard keeps it: median-filtered beams in at the pipeline's output frame, the vehicle's own arcs kept out, read out per sector in the body frame for the autopilot and LCM; sizeof(struct obsmap) = 24 848 B, most of it the map (obstacle.h). */
#ifndef SONARD_OBSMAP_H
#define SONARD_OBSMAP_H

#include <stddef.h>
#include <stdint.h>

#include "app.h"
#include "sonar/obstacle.h"

#define OBSMAP_MAX_IGNORE 8       /* --ignore-deg arcs */
#define OBSMAP_OUT_US 100000      /* the map is handed out after a beam at most this often, in beam time */

/* The map read at one time: sector k centred on k * SONAR_OBS_SECTOR_DEG degrees clockwise from ahead. */
struct obsmap_read {
    int64_t utime;                    /* us since the epoch the map was read at */
    uint16_t dist_cm[SONAR_OBS_SECTORS]; /* the nearest echo (raised to min_cm), max_cm + 1 clear, SONAR_OBS_UNKNOWN */
    uint16_t min_cm, max_cm;          /* min_cm at least 1 (MAVLink's 0 is "invalid"); max_cm 0 before any beam */
};

/* Called with each map handed out (sonard's LCM sink); the read is the callee's only for the call. */
typedef void (*obsmap_out_fn)(void *user, const struct obsmap_read *r);

struct obsmap {
    struct sonar_obstacle obs;
    struct app *app;
    float min_range_m;           /* the pipeline's --min-range the map holds now (app_frame) */
    uint8_t n_ignore;            /* arcs of the vehicle's own echoes: ignore[i] = {from, to}, degrees clockwise from ahead */
    float ignore[OBSMAP_MAX_IGNORE][2];
    obsmap_out_fn out;
    void *out_user;
    int64_t out_at;              /* utime of the beam the map was last handed out after; 0: never */
    struct app_sink sink;        /* when the map has a sink of its own (obsmap_attach) */
};

/*
 * Sets up the map with the obstacle defaults and n_ignore arcs (each {from, to} in degrees clockwise
 * from ahead, 0..360, from > to crossing ahead; at most OBSMAP_MAX_IGNORE). Returns HOST_OK, or
 * HOST_ERR_CONFIG with err naming what is wrong.
 */
HOST_CHECK int obsmap_init(struct obsmap *o, const float (*ignore)[2], unsigned n_ignore, char *err, size_t errlen);

/* Whether the map can take a --min-range of min_range_m metres (0..100): HOST_OK, or HOST_ERR_CONFIG with err naming the value. */
HOST_CHECK int obsmap_check_min_range(float min_range_m, char *err, size_t errlen);

/*
 * Binds the app whose pipeline's output frame (angle offset, min range) the map follows at each beam, so
 * that it turns with the detections when a reload takes over. obsmap_bind: the owner feeds the map
 * (obsmap_beam) from its own sink; obsmap_attach: the map adds a sink of its own (median-filtered beams).
 * Return HOST_OK, HOST_ERR_CONFIG (the app's min range too far) or HOST_ERR_FULL.
 */
HOST_CHECK int obsmap_bind(struct obsmap *o, struct app *a);
HOST_CHECK int obsmap_attach(struct obsmap *o, struct app *a);

/* Hands the map to fn(user, ...) after a beam, at most every OBSMAP_OUT_US of beam time; fn NULL: never. */
void obsmap_on_read(struct obsmap *o, obsmap_out_fn fn, void *user);

/*
 * One median-filtered beam into the map at its bearing in the output frame, with its pose when it has
 * one; a beam in an ignored arc is left out. Returns HOST_OK, HOST_ERR_CONFIG (a min range the map
 * cannot take: refused before a reload, so not reached) or HOST_ERR_IO (the map refused the beam).
 */
HOST_CHECK int obsmap_beam(struct obsmap *o, const struct sonar_record *b);

/*
 * The map at now_us in the body frame at pose (NULL: unknown; what was kept in the world frame is
 * then left out): ignored arcs SONAR_OBS_UNKNOWN, an echo nearer than min_cm raised to it.
 */
void obsmap_read(const struct obsmap *o, int64_t now_us, const struct sonar_pose *pose, struct obsmap_read *r);

/* How old a sector may be: a little over one sweep (the last one's time; 40 s, the slowest, before any). */
int64_t obsmap_max_age_us(const struct obsmap *o);

/* Beams taken into the map since the start. */
uint32_t obsmap_beams(const struct obsmap *o);

#endif
