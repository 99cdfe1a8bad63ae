/* obstacle.h -- the autopilot's view: the nearest echo above the noise floor in each 5-degree sector of the sonar frame, walls included, aged by sweeps; RAM: 2 * SONAR_MAX_SAMPLES + SONAR_MAX_OBS_ECHOES * sizeof(struct sonar_obstacle_echo) + 72 * sizeof(struct sonar_obstacle_sector) + 48 = 24 656 B. */
#ifndef SONAR_OBSTACLE_H
#define SONAR_OBSTACLE_H

#include <stdint.h>

#include "sonar/config.h"
#include "sonar/err.h"
#include "sonar/geometry.h"
#include "sonar/pose.h"

/*
 * MAVLink's OBSTACLE_DISTANCE as ArduPilot reads it (AP_Proximity_MAV): 72 sectors of 5 degrees
 * in the body frame (FRD: 0 forward, clockwise), sector k centred on k x 5 degrees (angle_offset
 * 0); a beam at bearing b falls in sector round(b / 5) mod 72. Distances in cm. Background
 * subtraction serves detection, but a wall is what the autopilot must not hit: this map takes
 * every echo, against a noise floor per range sample: a slow running median across all beams (an
 * eighth of a level a beam toward each), so the ring-down and the gain curve are floor, and a
 * wall, seen in a run of beams at one range, is not (a level a beam learnt a 90-degree wall within
 * its own sweep). An echo exceeds the floor f by max(min_level, f x margin / 16): three times the
 * floor by default, as speckle's median-filtered tail stays under it. A beam's echo is the leading
 * edge of its first return above the floor beyond min_range (where it first reaches half the
 * return's mean level): the nearest surface inside the beam, which an echo starts at.
 */
#define SONAR_OBS_SECTORS 72
#define SONAR_OBS_SECTOR_DEG 5
#define SONAR_OBS_UNKNOWN 65535u    /* not scanned within the age limit */
#define SONAR_OBSTACLE_MAX_RANGE_M 100.0f /* min_range_m at most: OBSTACLE_DISTANCE's min_distance is a uint16 in cm */
#define SONAR_OBS_PASS_US 1000000   /* beams into one sector within this of each other are one pass: the nearest wins */

struct sonar_obstacle_config {
    float min_range_m;  /* echoes nearer are not reported (ring-down, the mount), 0..SONAR_OBSTACLE_MAX_RANGE_M */
    uint8_t margin;     /* an echo exceeds the floor f by f * margin / 16 ... , 0..64 */
    uint8_t min_level;  /* ... and by at least this many grey levels, 1..255 */
};

/*
 * Each beam's echo is remembered as a point: with the vehicle's pose, the world point it came from
 * (north, east), so a sector swept seconds ago on a turning, moving vehicle still points at its
 * wall from where the vehicle is now; without one, the point in the sonar frame as seen. Two
 * echoes of consecutive beams at most SONAR_OBS_LINK_DEG apart, whose points are no further
 * apart than a surface at up to ~70 degrees of incidence would put them (0.2 m + 3 x the arc
 * between the beams), are joined: the surface between them is taken as the straight line, so a
 * sector that the line crosses reports its nearest point there, not only where a beam happened to
 * land (a wall seen obliquely changes range by metres across one 5-degree sector). That nearest
 * surface lies at the beam's edge, not its axis, where the range changes across the beam: a
 * joined echo is placed SONAR_OBS_HALF_BEAM_DEG toward its neighbour of smaller range (on its
 * axis when its two neighbours disagree: the surface's nearest point is inside that beam).
 *
 * Sectors track passes by world bearing (with a pose) or body bearing (without): a sector's pass
 * is its run of beams less than SONAR_OBS_PASS_US apart; the echoes of its current pass stand, a
 * new pass retires the old one's, and a pass without an echo makes the sector clear.
 */
#define SONAR_OBS_LINK_DEG 10.0

/* Half the Ping360's beam: an echo's leading edge may lie up to this far off its axis. */
#define SONAR_OBS_HALF_BEAM_DEG (SONAR_BEAM_WIDTH_DEG / 2.0)

struct sonar_obstacle_echo {
    int64_t utime;      /* us since the epoch of its beam */
    float x_m, y_m;     /* its point: world north, east; else the sonar frame's x forward, y right; metres */
    float ox, oy;       /* the sonar at utime, same frame (0, 0 without a pose), metres */
    float range_m;      /* the leading edge's range from there, metres */
    float bearing_deg;  /* the beam's bearing, world with a pose, degrees 0..360 */
    int8_t side;        /* the point lies SONAR_OBS_HALF_BEAM_DEG this way off the axis: -1, 0, +1 */
    uint8_t sector;     /* the sector of its beam's pass (world bearing with a pose) */
    uint8_t world;      /* 1: x_m, y_m are north, east */
    uint8_t linked;     /* 1: joined to the echo before it in the ring (see above) */
};

struct sonar_obstacle_sector {
    int64_t utime;      /* us since the epoch of the last beam through it; 0 = never */
    int64_t pass_us;    /* utime of its current pass's first beam */
    uint8_t echo;       /* 1: the current pass has an echo; 0: clear */
    uint8_t world;      /* 1: a world bearing (the last beam had a pose) */
};

struct sonar_obstacle {
    struct sonar_obstacle_config cfg;
    uint16_t floor[SONAR_MAX_SAMPLES]; /* the noise floor per range sample, eighths of a level; 0 = not seeded */
    uint16_t n;                       /* samples per beam the floor holds */
    float range_m;                    /* the range of the beams so far (a new one resets the map) */
    uint32_t beams, echoes;           /* beams taken, beams with an echo */
    int64_t newest;                   /* utime of the newest beam taken */
    double prev_bearing;              /* the previous beam's bearing (world with a pose), degrees 0..360 */
    uint8_t prev_echo;                /* 1: the previous beam's echo is the newest in the ring */
    uint16_t head, count;             /* the ring: next slot, echoes held (<= SONAR_MAX_OBS_ECHOES) */
    struct sonar_obstacle_echo echo[SONAR_MAX_OBS_ECHOES];
    struct sonar_obstacle_sector sector[SONAR_OBS_SECTORS];
};

/* sonard's defaults: min_range 0.5 m, margin 32 (three times the floor), min_level 24. */
void sonar_obstacle_defaults(struct sonar_obstacle_config *cfg);

/* Beams the map has taken since sonar_obstacle_init (0: nothing scanned yet, every sector unknown). */
uint32_t sonar_obstacle_beams(const struct sonar_obstacle *o);

/* Validates cfg (copied) and empties the map. Returns SONAR_OK or SONAR_ERR_ARG. */
SONAR_CHECK int sonar_obstacle_init(struct sonar_obstacle *o, const struct sonar_obstacle_config *cfg);

/*
 * A new min_range (0..100 m) from the next beam on, the map kept: a reload must not empty the map an
 * autopilot avoids with. Returns SONAR_OK or SONAR_ERR_ARG.
 */
SONAR_CHECK int sonar_obstacle_set_min_range(struct sonar_obstacle *o, float min_range_m);

/*
 * One beam (filtered samples, n 1..SONAR_MAX_SAMPLES over range_m metres, (0, 1000]) at bearing_deg
 * in the body frame (any value; taken modulo 360), seen at utime with the vehicle at pose (NULL:
 * unknown): its nearest echo beyond min_range is remembered (the oldest echo held making way), or
 * its sector's pass is marked clear; the floor then learns the beam. A new n or range_m starts the map
 * afresh. Returns SONAR_OK or SONAR_ERR_ARG (nothing changed).
 */
SONAR_CHECK int sonar_obstacle_beam(struct sonar_obstacle *o, int64_t utime, float bearing_deg,
                                    const struct sonar_pose *pose, const uint8_t *s, uint16_t n, float range_m);

/*
 * The whole map at now_us for one message, in the body frame at pose (NULL: unknown; then what was
 * kept in the world cannot be placed and is left out): dist_cm[k] = the nearest point in sector k
 * of the standing echoes and the lines joining them (one that came nearer than min_range since is
 * reported at min_range), max_cm + 1 where it was
 * scanned and clear, SONAR_OBS_UNKNOWN where it was not scanned within max_age_us (a sweep, say).
 * *min_cm = min_range in cm (at least 1), *max_cm = the range in cm (0 before any beam).
 */
void sonar_obstacle_map(const struct sonar_obstacle *o, int64_t now_us, int64_t max_age_us, const struct sonar_pose *pose,
                        uint16_t *dist_cm, uint16_t *min_cm, uint16_t *max_cm);

#endif
