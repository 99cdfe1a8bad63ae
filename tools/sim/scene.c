/* scene.c -- simulated Ping360 scenes: ring-down, range-dependent speckle, pool walls with shadows, objects with beam spreading; deterministic. */
#define _POSIX_C_SOURCE 200809L
#include "scene.h"

#include <math.h>
#include <string.h>

#define PI 3.14159265358979323846

double scene_uniform(struct scene_rng *g)
{
    /* xorshift64*: fixed seed, identical streams on every machine */
    g->s ^= g->s >> 12;
    g->s ^= g->s << 25;
    g->s ^= g->s >> 27;
    return ((double)((g->s * 2685821657736338717ull) >> 11) + 0.5) / 9007199254740992.0;
}

static double rayleigh(struct scene_rng *g)
{
    return sqrt(-2.0 * log(scene_uniform(g)));
}

/*
 * Scenes with the AquaScan recordings' statistics (SCENE_SPECKLE_POOL): a Ping360 on a pool's side
 * sweeping the 180-degree sector 100..300 back and forth at 3 gradians, 500 samples over 15 m, as
 * that batch was recorded; people are discs of 0.35 m whose echo is a Rayleigh amplitude of rms
 * 140-160, the far ones 95-105 (so that the beams' means through them are sonar4's: 110, 87 and 76
 * at the centre of the three near people, 41 for the far one).
 *   occupied: five people there from the first ping (two standing, one struggling on the spot, one
 *             swimming 5 m lengths near the sonar at 0.33 m/s, one faint at 9.5 m drifting at 0.03 m/s) and a
 *             wall at 14.5 m; the truth says the activity of the first four (standing, struggling, moving).
 *   far:      faint targets at 8.5-12.5 m, two of them drifting, in open water.
 *   still:    one person standing from the first ping, and one who swims for 60 s and then floats
 *             still for three minutes.
 *   faint:    three targets barely above the clutter at 12-14 m (rms 80-85, where the water is
 *             spikiest), drifting at 0.01-0.03 m/s, in open water (30 passes).
 *   lanes:    the sonar on a pool's side wall (the sector's edges look along it), a 25 x 14.6 m pool
 *             with two swaying lane ropes and a ladder (structure, there from the first ping); two
 *             swimmers doing lengths from 10 s and 20 s, and one who swims for 20 s and then rests
 *             (40 passes).
 *   turns:    the lanes' pool without ropes or ladder, four swimmers doing lengths along it turned at the end
 *             walls (each centre 0.5 m out): 25 m at 1.0 and 1.5 m/s, and 5 m at 0.3 and 0.6 m/s, one at each end
 *             (40 passes).
 *   laps:     full turns at 4 gradians, 600 samples over 15 m (6.3 s a turn): the sonar hangs in the
 *             middle of a 16 x 25 m pool, walls all round (its corners beyond the range), two swaying
 *             lane ropes, a ladder (structure); three swimmers doing lengths at 0.5-0.6 m/s turned 0.5 m
 *             out from the end walls, one standing from the first ping, a steady echo (30 turns); the truth
 *             says their activity.
 */
static int pool_scene(struct scene *s, const char *name)
{
    static const struct scene_wall wall = {-14.5, -12, -14.5, 12};
    s->speckle = SCENE_SPECKLE_POOL;
    s->range_m = 15.0;
    s->samples = 500;
    s->step = 3;
    s->start = 100;
    s->stop = 300;
    if (strcmp(name, "occupied") == 0) {
        static const struct scene_object o[] = {
            {"stand_a", -4.0, 2.4, 0.35, 0, 0, 160, 0, 0, {0}, {0}, {0}, 0, 0},
            {"stand_b", -5.9, 0.9, 0.35, 0, 0, 150, 0, 0, {0}, {0}, {0}, 0, 0},
            {"struggle", 0, 0, 0.35, 0, 0, 140, 0, 7, {0, 20, 40, 60, 80, 100, 200}, {-7.3, -7.0, -7.4, -7.1, -7.3, -7.0, -7.2},
             {-1.0, -0.8, -1.2, -0.9, -1.1, -0.8, -1.0}, 0, 0},
            {"swimmer", 0, 0, 0.35, 0, 0, 160, 0, 10, {0, 15, 30, 45, 60, 75, 90, 105, 120, 200},
             {-2.3, -2.0, -2.4, -2.2, -2.5, -2.1, -2.3, -2.0, -2.4, -2.4}, {4.0, -1.0, 4.0, -1.0, 4.0, -1.0, 4.0, -1.0, 4.0, 3.0},
             0, 0},
            {"far", 0, 0, 0.35, 0, 0, 100, 0, 3, {0, 100, 200}, {-9.5, -9.3, -9.7}, {-0.6, 2.4, 0.6}, 0, 0},
        };
        /* One of each of the labels' states (issue 46): the standers' echo steady, the struggler's fresh each look. */
        static const int acts[] = {SCENE_ACT_STANDING, SCENE_ACT_STANDING, SCENE_ACT_STRUGGLING, SCENE_ACT_MOVING,
                                   SCENE_ACT_NONE};
        s->wall[0] = wall;
        s->nwall = 1;
        s->sweeps = 30;
        memcpy(s->obj, o, sizeof(o));
        memcpy(s->act, acts, sizeof(acts));
        s->nobj = (int)(sizeof(o) / sizeof(o[0]));
    } else if (strcmp(name, "far") == 0) {
        static const struct scene_object o[] = {
            {"far_a", -8.5, 3.0, 0.35, 0, 0, 105, 0, 0, {0}, {0}, {0}, 0, 0},
            {"far_b", 0, 0, 0.35, 0, 0, 100, 0, 2, {0, 200}, {-10.5, -11.0}, {-2.0, 2.5}, 0, 0},
            {"far_c", -12.5, 0.5, 0.35, 0, 0, 100, 0, 0, {0}, {0}, {0}, 0, 0},
            {"far_d", 0, 0, 0.35, 0, 0, 95, 0, 2, {0, 200}, {-9.0, -8.0}, {-4.5, -6.0}, 0, 0},
        };
        s->sweeps = 30;
        memcpy(s->obj, o, sizeof(o));
        s->nobj = (int)(sizeof(o) / sizeof(o[0]));
    } else if (strcmp(name, "faint") == 0) {
        static const struct scene_object o[] = {
            {"faint_a", 0, 0, 0.35, 0, 0, 85, 0, 2, {0, 200}, {-12.0, -11.0}, {1.0, 2.5}, 0, 0},
            {"faint_b", 0, 0, 0.35, 0, 0, 80, 0, 2, {0, 200}, {-13.0, -12.5}, {-3.5, 3.0}, 0, 0},
            {"faint_c", 0, 0, 0.35, 0, 0, 80, 0, 2, {0, 200}, {-13.5, -12.0}, {3.5, 6.5}, 0, 0},
        };
        s->sweeps = 30;
        memcpy(s->obj, o, sizeof(o));
        s->nobj = (int)(sizeof(o) / sizeof(o[0]));
    } else if (strcmp(name, "lanes") == 0) {
        static const struct scene_wall w[4] = {{0.1, -12.5, 0.1, 12.5}, {-14.5, -12.5, -14.5, 12.5},
                                               {0.1, -12.5, -14.5, -12.5}, {0.1, 12.5, -14.5, 12.5}};
        static const struct scene_rope r[2] = {{-4.5, -12.5, 12.5, 80, 0.15, 6.0}, {-9.5, -12.5, 12.5, 80, 0.15, 7.0}};
        static const struct scene_object o[] = {
            {"ladder", -0.45, 8.0, 0.15, 0, 0, 170, 0, 0, {0}, {0}, {0}, 0, 1},
            {"swim_a", 0, 0, 0.35, 0, 0, 150, 0, 4, {10, 47, 84, 121}, {-2.3, -2.3, -2.3, -2.3}, {-11, 11, -11, 11}, 0, 0},
            {"swim_b", 0, 0, 0.35, 0, 0, 150, 0, 5, {20, 45, 70, 95, 120}, {-7.0, -7.0, -7.0, -7.0, -7.0},
             {10, -10, 10, -10, 10}, 0, 0},
            {"rester", 0, 0, 0.35, 0, 0, 140, 0, 3, {5, 25, 400}, {-12, -12, -12}, {-8, 2, 2}, 0, 0},
        };
        memcpy(s->wall, w, sizeof(w));
        s->nwall = 4;
        memcpy(s->rope, r, sizeof(r));
        s->nrope = 2;
        s->sweeps = 40;
        memcpy(s->obj, o, sizeof(o));
        s->nobj = (int)(sizeof(o) / sizeof(o[0]));
    } else if (strcmp(name, "turns") == 0) {
        /* Lengths turned at the walls, as AquaScan's swimmers do: 25 m at 1.0 and 1.5 m/s, 5 m at 0.3 and 0.6 m/s,
           each centre turning 0.5 m out from the wall. */
        static const struct scene_wall w[4] = {{0.1, -12.5, 0.1, 12.5}, {-14.5, -12.5, -14.5, 12.5},
                                               {0.1, -12.5, -14.5, -12.5}, {0.1, 12.5, -14.5, 12.5}};
        static const struct scene_object o[] = {
            {"len25_a", 0, 0, 0.35, 0, 0, 150, 0, 8, {0, 24, 48, 72, 96, 120, 144, 168},
             {-1, -1, -1, -1, -1, -1, -1, -1}, {-12, 12, -12, 12, -12, 12, -12, 12}, 0, 0},
            {"len25_b", 0, 0, 0.35, 0, 0, 150, 0, 11, {5, 21, 37, 53, 69, 85, 101, 117, 133, 149, 165},
             {-8, -8, -8, -8, -8, -8, -8, -8, -8, -8, -8}, {12, -12, 12, -12, 12, -12, 12, -12, 12, -12, 12}, 0, 0},
            {"len5_a", 0, 0, 0.35, 0, 0, 145, 0, 11, {0, 16.67, 33.33, 50, 66.67, 83.33, 100, 116.67, 133.33, 150, 166.67},
             {-4.5, -4.5, -4.5, -4.5, -4.5, -4.5, -4.5, -4.5, -4.5, -4.5, -4.5}, {7, 12, 7, 12, 7, 12, 7, 12, 7, 12, 7}, 0, 0},
            {"len5_b", 0, 0, 0.35, 0, 0, 150, 0, 19,
             {10, 18.33, 26.67, 35, 43.33, 51.67, 60, 68.33, 76.67, 85, 93.33, 101.67, 110, 118.33, 126.67, 135, 143.33,
              151.67, 160},
             {-4.5, -4.5, -4.5, -4.5, -4.5, -4.5, -4.5, -4.5, -4.5, -4.5, -4.5, -4.5, -4.5, -4.5, -4.5, -4.5, -4.5, -4.5, -4.5},
             {-12, -7, -12, -7, -12, -7, -12, -7, -12, -7, -12, -7, -12, -7, -12, -7, -12, -7, -12}, 0, 0},
        };
        static const int acts[] = {SCENE_ACT_MOVING, SCENE_ACT_MOVING, SCENE_ACT_MOVING, SCENE_ACT_MOVING};
        memcpy(s->wall, w, sizeof(w));
        s->nwall = 4;
        s->sweeps = 40;
        memcpy(s->obj, o, sizeof(o));
        memcpy(s->act, acts, sizeof(acts));
        s->nobj = (int)(sizeof(o) / sizeof(o[0]));
    } else if (strcmp(name, "laps") == 0 || strcmp(name, "activity") == 0) {
        static const struct scene_wall w[4] = {{-8, -12.5, 8, -12.5}, {8, -12.5, 8, 12.5}, {8, 12.5, -8, 12.5},
                                               {-8, 12.5, -8, -12.5}};
        static const struct scene_rope r[2] = {{-4.0, -12.5, 12.5, 80, 0.15, 6.0}, {4.0, -12.5, 12.5, 80, 0.15, 7.0}};
        static const struct scene_object o[] = {
            {"ladder", 7.6, 9.0, 0.15, 0, 0, 170, 0, 0, {0}, {0}, {0}, 0, 1},
            {"swim_a", 0, 0, 0.35, 0, 0, 150, 0, 7, {0, 40, 80, 120, 160, 200, 212}, {-6.0, -6.0, -6.0, -6.0, -6.0, -6.0, -6.0},
             {-12, 12, -12, 12, -12, 12, 5}, 0, 0},
            {"swim_b", 0, 0, 0.35, 0, 0, 150, 0, 7, {12, 52, 92, 132, 172, 212, 222}, {2.0, 2.0, 2.0, 2.0, 2.0, 2.0, 2.0},
             {12, -12, 12, -12, 12, -12, -6}, 0, 0},
            {"swim_c", 0, 0, 0.35, 0, 0, 145, 0, 5, {30, 78, 126, 174, 222}, {6.0, 6.0, 6.0, 6.0, 6.0},
             {-12, 12, -12, 12, -12}, 0, 0},
            {"stand", -2.0, -6.0, 0.35, 0, 0, 150, 0, 0, {0}, {0}, {0}, 0, 0},
        };
        memcpy(s->wall, w, sizeof(w));
        s->nwall = 4;
        memcpy(s->rope, r, sizeof(r));
        s->nrope = 2;
        /* Full turns from the +y axis: the sonar hangs in the middle of the pool, and a turn ends where no lane runs. */
        s->start = s->stop = 100;
        s->samples = 600;
        s->step = 4;
        s->sweeps = 30;
        memcpy(s->obj, o, sizeof(o));
        s->nobj = (int)(sizeof(o) / sizeof(o[0]));
        {
            static const int laps_acts[] = {SCENE_ACT_NONE, SCENE_ACT_MOVING, SCENE_ACT_MOVING, SCENE_ACT_MOVING,
                                            SCENE_ACT_STANDING};
            memcpy(s->act, laps_acts, sizeof(laps_acts));
        }
        if (strcmp(name, "activity") == 0) {
            /* The same pool with the AquaScan recordings' three states: a swimmer doing lengths, one standing, one
               struggling (within a metre, a fresh echo each look), each from the first ping. */
            static const struct scene_object a[] = {
                {"ladder", 7.6, 9.0, 0.15, 0, 0, 170, 0, 0, {0}, {0}, {0}, 0, 1},
                {"swimmer", 0, 0, 0.35, 0, 0, 150, 0, 7, {0, 37, 74, 111, 148, 185, 200}, {-6.0, -6.0, -6.0, -6.0, -6.0, -6.0, -6.0},
                 {-11, 11, -11, 11, -11, 11, 2}, 0, 0},
                {"stander", -2.0, 6.0, 0.35, 0, 0, 150, 0, 0, {0}, {0}, {0}, 0, 0},
                {"struggler", 2.5, -5.0, 0.35, 0, 0, 150, 0, 0, {0}, {0}, {0}, 0, 0},
            };
            static const int acts[] = {SCENE_ACT_NONE, SCENE_ACT_MOVING, SCENE_ACT_STANDING, SCENE_ACT_STRUGGLING};
            memcpy(s->obj, a, sizeof(a));
            memcpy(s->act, acts, sizeof(acts));
            s->nobj = (int)(sizeof(a) / sizeof(a[0]));
            s->sweeps = 20;
        }
    } else {
        static const struct scene_object o[] = {
            {"stand", -4.5, 1.5, 0.35, 0, 0, 150, 0, 0, {0}, {0}, {0}, 0, 0},
            {"floater", 0, 0, 0.35, 0, 0, 140, 0, 4, {0, 30, 60, 400}, {-3.0, -6.0, -6.5, -6.5}, {-3.0, -1.0, 1.0, 1.0}, 0, 0},
        };
        s->wall[0] = wall;
        s->nwall = 1;
        s->sweeps = 64; /* 60 s swimming and 3 minutes still at 3.8 s a pass */
        memcpy(s->obj, o, sizeof(o));
        s->nobj = (int)(sizeof(o) / sizeof(o[0]));
    }
    return 0;
}

int scene_make(struct scene *s, const char *name)
{
    memset(s, 0, sizeof(*s));
    s->name = name;
    s->range_m = 12.0;
    s->samples = 1200;
    s->step = 1;
    if (strcmp(name, "pool") == 0) {
        /* A 20 x 12 m pool; the sonar sits off-centre, so some walls are beyond range. */
        struct scene_wall w[4] = {{-6, -5, 14, -5}, {14, -5, 14, 7}, {14, 7, -6, 7}, {-6, 7, -6, -5}};
        memcpy(s->wall, w, sizeof(w));
        s->nwall = 4;
        s->sweeps = 7;
        s->obj[0] = (struct scene_object){"gate_post_left", 5.0, 2.0, 0.10, 0, 0, 170, 2, 0, {0}, {0}, {0}, 0, 0};
        s->obj[1] = (struct scene_object){"gate_post_right", 5.0, 3.6, 0.10, 0, 0, 170, 2, 0, {0}, {0}, {0}, 0, 0};
        s->obj[2] = (struct scene_object){"buoy", -3.0, -2.0, 0.25, 0.35, 0.1, 190, 3, 0, {0}, {0}, {0}, 0, 0};
        s->nobj = 3;
    } else if (strcmp(name, "open") == 0) {
        /* Open water: no walls, objects there from the first ping. */
        s->sweeps = 4;
        s->obj[0] = (struct scene_object){"gate_post", 4.0, 1.0, 0.10, 0, 0, 170, 0, 0, {0}, {0}, {0}, 0, 0};
        s->obj[1] = (struct scene_object){"buoy", -2.0, 3.0, 0.25, 0.3, 0.0, 190, 0, 0, {0}, {0}, {0}, 0, 0};
        s->obj[2] = (struct scene_object){"diver", 1.0, -6.0, 0.30, 0.0, 0.4, 150, 0, 0, {0}, {0}, {0}, 0, 0};
        s->nobj = 3;
    } else if (strcmp(name, "near") == 0) {
        /* Open water at a 5 m range (1200 samples, 1-gradian steps): three 0.2 m buoys close to the sonar, at 0.66,
           0.9 and 1.2 m, in its first 4 turns; an object the size of a point target's footprint at most. */
        s->range_m = 5.0;
        s->sweeps = 4;
        s->obj[0] = (struct scene_object){"buoy_066", 0.66 * 0.7071, 0.66 * 0.7071, 0.10, 0, 0, 190, 0, 0, {0}, {0}, {0}, 0, 0};
        s->obj[1] = (struct scene_object){"buoy_090", -0.9, 0.0, 0.10, 0, 0, 190, 0, 0, {0}, {0}, {0}, 0, 0};
        s->obj[2] = (struct scene_object){"buoy_120", 0.0, -1.2, 0.10, 0, 0, 190, 0, 0, {0}, {0}, {0}, 0, 0};
        s->nobj = 3;
    } else if (strcmp(name, "faces") == 0) {
        /*
         * Open water, two posts ahead: a near one 10 degrees to starboard (3 m) and a far one 10 degrees
         * to port (6 m). Both lie in ArduPilot's forward face; the autopilot must be told the near one.
         */
        s->range_m = 8.0;
        s->sweeps = 4;
        s->obj[0] = (struct scene_object){"near_post", 2.954, 0.521, 0.15, 0, 0, 190, 0, 0, {0}, {0}, {0}, 0, 0};
        s->obj[1] = (struct scene_object){"far_post", 5.909, -1.042, 0.15, 0, 0, 190, 0, 0, {0}, {0}, {0}, 0, 0};
        s->nobj = 2;
    } else if (strcmp(name, "moving") == 0) {
        /*
         * Open water, full turns at 4 gradians a step (6.3 s a turn at 15 m), 24 turns: two swimmers
         * at 0.5 m/s going to and fro 0.5 m apart (they cross three times), a diver at 1 m/s who turns
         * four times and leaves, a fast one at 1.5 m/s going twice round the sonar (an octagon: 45
         * degrees every 5.6 s), a drifting buoy that fades for two turns and then one, and a late one
         * at 1 m/s who arrives, turns and leaves. The first two turns are the background's warm-up.
         */
        static const struct scene_object o[] = {
            {"swimmer_a", 0, 0, 0.25, 0, 0, 160, 0, 4, {16, 52, 88, 124}, {-9, 9, -9, 9}, {6.25, 6.25, 6.25, 6.25}, 0, 0},
            {"swimmer_b", 0, 0, 0.25, 0, 0, 160, 0, 4, {16, 52, 88, 124}, {9, -9, 9, -9}, {5.75, 5.75, 5.75, 5.75}, 0, 0},
            {"diver", 0, 0, 0.30, 0, 0, 150, 0, 6, {18, 38, 50, 64, 76, 82}, {4, 4, -8, -8, 4, 4}, {-10, 10, 10, -4, -4, -10}, 0, 0},
            {"fast", 0, 0, 0.25, 0, 0, 170, 0, 17,
             {22.0, 27.61, 33.23, 38.84, 44.45, 50.06, 55.68, 61.29, 66.9, 72.51, 78.13, 83.74, 89.35, 94.96, 100.58, 106.19, 111.8},
             {0.0, 7.78, 11.0, 7.78, 0.0, -7.78, -11.0, -7.78, -0.0, 7.78, 11.0, 7.78, 0.0, -7.78, -11.0, -7.78, -0.0},
             {-11.0, -7.78, 0.0, 7.78, 11.0, 7.78, 0.0, -7.78, -11.0, -7.78, -0.0, 7.78, 11.0, 7.78, 0.0, -7.78, -11.0}, 0, 0},
            {"buoy", 0, 0, 0.25, 0, 0, 190, 0, 2, {20, 152}, {-5, -2.5}, {-5, -6.5}, (1ull << 10) | (1ull << 11) | (1ull << 18), 0},
            {"late", 0, 0, 0.25, 0, 0, 160, 0, 4, {100, 114, 124, 136}, {11, 0, -9, -9}, {-3, -11, -8, 0}, 0, 0},
        };
        s->range_m = 15.0;
        s->samples = 600;
        s->step = 4;
        s->sweeps = 24;
        memcpy(s->obj, o, sizeof(o));
        s->nobj = (int)(sizeof(o) / sizeof(o[0]));
    } else if (strcmp(name, "sector") == 0) {
        /*
         * A 180-degree sector (gradians 100..300, the x < 0 half) scanned back and forth at 2
         * gradians a step (5 s a pass at 15 m), 26 passes: two people crossing at 0.3 m/s who turn
         * back, one at 0.8 m/s who walks out of the sector, one who arrives late, a runner at 1.2 m/s
         * crossing the far side; the first two passes are the background's warm-up.
         */
        static const struct scene_object o[] = {
            {"walker_a", 0, 0, 0.25, 0, 0, 160, 0, 3, {12, 72, 112}, {-4, -4, -4}, {-9, 9, -3}, 0, 0},
            {"walker_b", 0, 0, 0.25, 0, 0, 160, 0, 3, {12, 72, 112}, {-4.5, -4.5, -4.5}, {9, -9, 3}, 0, 0},
            {"leaver", 0, 0, 0.25, 0, 0, 170, 0, 2, {14, 31}, {-8, 5}, {-3, -7}, 0, 0},
            {"late", 0, 0, 0.25, 0, 0, 160, 0, 3, {36, 72, 104}, {-10, -2, -10}, {4, 4, -2}, 0, 0},
            {"runner", 0, 0, 0.25, 0, 0, 170, 0, 2, {64, 78.8}, {-13, 2}, {3, 12.5}, 0, 0},
        };
        s->range_m = 15.0;
        s->samples = 600;
        s->step = 2;
        s->start = 100;
        s->stop = 300;
        s->sweeps = 26;
        memcpy(s->obj, o, sizeof(o));
        s->nobj = (int)(sizeof(o) / sizeof(o[0]));
    } else if (strcmp(name, "vehicle") == 0) {
        /*
         * A 30 x 16 m pool seen from a moving vehicle (issue 11): it goes up and down the pool at
         * 0.5 m/s while its heading swings 180 degrees back and forth at 30 degrees/s; full turns of
         * the head at 4 gradians a step (6.3 s a turn at 15 m), 18 turns. Two posts and a buoy stand
         * still in the world from sweeps 3, 5 and 2; a diver swims at 0.5 m/s from 20 s to 100 s.
         */
        static const struct scene_wall w[4] = {{-15, -8, 15, -8}, {15, -8, 15, 8}, {15, 8, -15, 8}, {-15, 8, -15, -8}};
        static const struct scene_object o[] = {
            {"post_a", 4.0, 5.0, 0.20, 0, 0, 170, 3, 0, {0}, {0}, {0}, 0, 0},
            {"post_b", -5.0, -6.0, 0.20, 0, 0, 170, 5, 0, {0}, {0}, {0}, 0, 0},
            {"buoy", 0.5, 5.5, 0.25, 0, 0, 190, 2, 0, {0}, {0}, {0}, 0, 0},
            {"diver", 0, 0, 0.30, 0, 0, 150, 0, 4, {20, 60, 82, 100}, {10, -10, -10, 0}, {-6, -6, 5, 5}, 0, 0},
        };
        static const struct scene_vehicle v = {6, {0, 32, 40, 72, 80, 120}, {-8, 8, 8, -8, -8, 8}, {-3, -3, 1, 1, -3, -3},
                                               0.0, 30.0, 6.0};
        memcpy(s->wall, w, sizeof(w));
        s->nwall = 4;
        s->range_m = 15.0;
        s->samples = 600;
        s->step = 4;
        s->sweeps = 18;
        memcpy(s->obj, o, sizeof(o));
        s->nobj = (int)(sizeof(o) / sizeof(o[0]));
        s->veh = v;
    } else if (strcmp(name, "tank") == 0) {
        /*
         * A RoboSub robot in an 8 x 5 m tank (issue 54): a 5 m range, 1200 samples, a +-45 degree sector ahead
         * at 1 gradian, as the RoboSub sweeps were taken; it crosses the tank at 0.1 m/s and back while its
         * heading swings +-30 degrees, so walls come as close as 0.6 m and most places are seen once. Three
         * props stand still: a 0.2 m buoy 0.6 m before the far wall, another in open water, a gate's leg. The
         * walls echo at twice and three times their range, and streaks come as often as on those sweeps.
         */
        static const struct scene_wall w[4] = {{-4, -2.5, 4, -2.5}, {4, -2.5, 4, 2.5}, {4, 2.5, -4, 2.5}, {-4, 2.5, -4, -2.5}};
        static const struct scene_object o[] = {
            {"buoy_wall", 3.3, 0.3, 0.10, 0, 0, 170, 0, 0, {0}, {0}, {0}, 0, 0},
            {"buoy_open", 1.2, -1.2, 0.10, 0, 0, 170, 0, 0, {0}, {0}, {0}, 0, 0},
            {"gate_leg", 2.2, 1.6, 0.08, 0, 0, 160, 0, 0, {0}, {0}, {0}, 0, 0},
        };
        static const struct scene_vehicle v = {3, {0, 45, 90}, {-2.5, 1.8, -2.5}, {-0.8, 0.2, -0.8}, 180.0, 10.0, 6.0};
        memcpy(s->wall, w, sizeof(w));
        s->nwall = 4;
        s->range_m = 5.0;
        s->samples = 1200;
        s->step = 1;
        s->start = 150;
        s->stop = 250;
        s->sweeps = 40;
        memcpy(s->obj, o, sizeof(o));
        s->nobj = (int)(sizeof(o) / sizeof(o[0]));
        s->veh = v;
        /* tools/eval/tank_calib.py on session-2024-63sweeps: echo peaks 0.275 and 0.211 of the wall's level at 2x
           and 3x its range (medians of 981 and 769 beams), streaks 0.31 % of beams, 24.6 levels above their neighbours. */
        s->echo[0] = 0.275;
        s->echo[1] = 0.211;
        s->streak_rate = 0.0031;
        s->streak_level = 24.6;
    } else if (strcmp(name, "occupied") == 0 || strcmp(name, "far") == 0 || strcmp(name, "still") == 0 ||
               strcmp(name, "lanes") == 0 || strcmp(name, "faint") == 0 || strcmp(name, "laps") == 0 ||
               strcmp(name, "activity") == 0 || strcmp(name, "turns") == 0) {
        return pool_scene(s, name);
    } else {
        return -1;
    }
    return 0;
}

void scene_empty(struct scene *s)
{
    int k, m = 0;
    for (k = 0; k < s->nobj; k++)
        if (s->obj[k].structure) {
            s->act[m] = s->act[k];
            s->obj[m++] = s->obj[k];
        }
    s->nobj = m;
}

/*
 * The emptied sonar4's transients by range band (tools/eval/transients.py on sonard's default detections): born a
 * sweep (less what the simulated water's speckle already gives there), mean life in sweeps, drift a sweep (m),
 * radius (m) and rms echo; the echo calibrated so that the detections' median mean intensity is the recording's.
 */
static const struct {
    double lo, hi, born, life, step, r, strength;
} transient_band[] = {
    {0.5, 3.0, 0.90, 1.8, 0.6, 0.15, 160.0},  {3.0, 6.0, 1.00, 1.3, 0.8, 0.15, 150.0},
    {6.0, 9.0, 1.00, 1.3, 0.8, 0.15, 140.0},  {9.0, 12.0, 0.45, 2.6, 0.3, 0.15, 125.0},
    {12.0, 15.0, 2.00, 1.1, 0.9, 0.15, 140.0},
};

/* Poisson(mean) by counting uniform products (small means only). */
static int poisson(struct scene_rng *g, double mean)
{
    double l = exp(-mean), p = scene_uniform(g);
    int k = 0;
    while (p > l) {
        p *= scene_uniform(g);
        k++;
    }
    return k;
}

int scene_transients(struct scene *s, unsigned long long seed)
{
    struct scene_rng g = {0x2545F4914F6CDD1Dull ^ (seed * 0x9E3779B97F4A7C15ull)};
    double lo_th = s->start * PI / 200.0, span = s->start == s->stop ? 2.0 * PI : (s->stop - s->start) * PI / 200.0;
    int sweep, b, k;
    if (s->speckle != SCENE_SPECKLE_POOL)
        return -1;
    s->npatch = 0;
    for (sweep = 0; sweep < s->sweeps; sweep++)
        for (b = 0; b < (int)(sizeof(transient_band) / sizeof(transient_band[0])); b++) {
            /* Measured over the recording's 200-gradian sector: a scan of another span sees them in proportion. */
            int n = poisson(&g, transient_band[b].born * span / PI);
            for (k = 0; k < n && s->npatch < SCENE_MAX_PATCH; k++) {
                struct scene_patch *p = &s->patch[s->npatch++];
                double r = transient_band[b].lo + (transient_band[b].hi - transient_band[b].lo) * scene_uniform(&g);
                double th = lo_th + span * scene_uniform(&g), dir = 2.0 * PI * scene_uniform(&g);
                double step = transient_band[b].step * (0.5 + scene_uniform(&g));
                p->x = (float)(r * cos(th));
                p->y = (float)(r * sin(th));
                p->vx = (float)(step * cos(dir));
                p->vy = (float)(step * sin(dir));
                p->r = (float)transient_band[b].r;
                p->strength = (float)transient_band[b].strength;
                p->first = sweep;
                /* Geometric: each further sweep with probability 1 - 1 / life. */
                p->life = 1;
                while (scene_uniform(&g) > 1.0 / transient_band[b].life && p->life < 64)
                    p->life++;
            }
        }
    return 0;
}

void scene_vehicle_at(const struct scene *s, double t, double *n, double *e, double *yaw_deg)
{
    const struct scene_vehicle *v = &s->veh;
    double y;
    int w;
    *n = *e = *yaw_deg = 0.0;
    if (v->nwp == 0)
        return;
    for (w = 0; w + 2 < v->nwp && t > v->wp_t[w + 1]; w++)
        ;
    {
        double dt = v->wp_t[w + 1] - v->wp_t[w], f = dt > 0 ? (t - v->wp_t[w]) / dt : 0.0;
        f = f < 0 ? 0 : f > 1 ? 1 : f;
        *n = v->wp_n[w] + f * (v->wp_n[w + 1] - v->wp_n[w]);
        *e = v->wp_e[w] + f * (v->wp_e[w + 1] - v->wp_e[w]);
    }
    if (v->yaw_period_s > 0) {
        double ph = fmod(t, 2.0 * v->yaw_period_s);
        y = v->yaw0_deg + v->yaw_rate_dps * (ph < v->yaw_period_s ? ph : 2.0 * v->yaw_period_s - ph);
    } else {
        y = v->yaw0_deg + v->yaw_rate_dps * t;
    }
    y = fmod(y, 360.0);
    *yaw_deg = y < 0 ? y + 360.0 : y;
}

void scene_to_body(const struct scene *s, double t, double n, double e, double *x, double *y)
{
    double vn, ve, yaw, c, sn;
    scene_vehicle_at(s, t, &vn, &ve, &yaw);
    c = cos(yaw * PI / 180.0);
    sn = sin(yaw * PI / 180.0);
    /* body = R(-yaw) (world - position) */
    *x = c * (n - vn) + sn * (e - ve);
    *y = -sn * (n - vn) + c * (e - ve);
}

/* A uniform number in (0, 1) that is a function of (a, b, c) alone: the same on every call (splitmix64). */
static double hashed_uniform(unsigned long long a, long long b, long long c)
{
    unsigned long long z = a * 0x9E3779B97F4A7C15ull ^ (unsigned long long)b * 0xBF58476D1CE4E5B9ull ^
                           (unsigned long long)c * 0x94D049BB133111EBull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return ((double)(z >> 11) + 0.5) / 9007199254740992.0;
}

int scene_object_at(const struct scene *s, int k, int sweep, double t, double *x, double *y, double *vx, double *vy)
{
    const struct scene_object *o = &s->obj[k];
    int d = sweep - o->first_sweep, w;
    if (o->nwp == 0) {
        *x = o->x + o->vx * d;
        *y = o->y + o->vy * d;
        *vx = *vy = 0.0;
        if (s->act[k] == SCENE_ACT_STANDING) { /* sways 5 cm over 4 s */
            *x += 0.05 * sin(2.0 * PI * t / 4.0);
            *y += 0.03 * cos(2.0 * PI * t / 4.0);
        } else if (s->act[k] == SCENE_ACT_STRUGGLING) { /* the body's centre jumps within 0.25 m each look */
            *x += 0.25 * (2.0 * hashed_uniform((unsigned long long)k + 1u, sweep, 1) - 1.0);
            *y += 0.25 * (2.0 * hashed_uniform((unsigned long long)k + 1u, sweep, 2) - 1.0);
        }
        return sweep >= o->first_sweep;
    }
    if (t < o->wp_t[0] || t > o->wp_t[o->nwp - 1])
        return 0;
    for (w = 0; w + 2 < o->nwp && t > o->wp_t[w + 1]; w++)
        ;
    {
        double dt = o->wp_t[w + 1] - o->wp_t[w], f = dt > 0 ? (t - o->wp_t[w]) / dt : 0.0;
        *vx = dt > 0 ? (o->wp_x[w + 1] - o->wp_x[w]) / dt : 0.0;
        *vy = dt > 0 ? (o->wp_y[w + 1] - o->wp_y[w]) / dt : 0.0;
        *x = o->wp_x[w] + f * (o->wp_x[w + 1] - o->wp_x[w]);
        *y = o->wp_y[w] + f * (o->wp_y[w + 1] - o->wp_y[w]);
    }
    return 1;
}

int scene_angle(const struct scene *s, int sweep, int i)
{
    int n, a;
    if (s->start == s->stop) {
        /* Full turns from start. */
        a = i * s->step;
        return a < 400 ? (s->start + a) % 400 : -1;
    }
    /* Sweep 0 is start..stop; after that each pass leaves out the end it turned at. */
    n = (s->stop - s->start) / s->step + (sweep == 0);
    if (i >= n)
        return -1;
    if (sweep == 0)
        return s->start + i * s->step;
    return sweep % 2 ? s->stop - (i + 1) * s->step : s->start + (i + 1) * s->step;
}

#define HALF_BEAM (1.0 * PI / 180.0) /* the 2-degree beam's half-power half-width */
#define WALL_PULSE_M 0.04             /* a wall's return lasts this past its footprint (the pulse) ... */
#define WALL_TAIL_M 0.05              /* ... then decays over this (reverberation in the wall's roughness) */

/* Distance along the unit ray (ux, uy) to a wall segment, and |cos| of the incidence; < 0 if missed. */
static double ray_wall(const struct scene_wall *w, double ux, double uy, double *cosinc)
{
    double ex = w->x1 - w->x0, ey = w->y1 - w->y0;
    double den = ux * ey - uy * ex;
    double t, s, len;
    if (fabs(den) < 1e-12)
        return -1.0;
    t = (w->x0 * ey - w->y0 * ex) / den;
    s = (w->x0 * uy - w->y0 * ux) / den;
    if (t <= 0.0 || s < 0.0 || s > 1.0)
        return -1.0;
    len = sqrt(ex * ex + ey * ey);
    *cosinc = fabs(ux * ey - uy * ex) / len;
    return t;
}

/* The nearest point of a wall segment (origin-relative) inside the cone th +- hw; < 0 if none. */
static double cone_near(const struct scene_wall *w, double th, double hw)
{
    double best = -1.0, c, ex = w->x1 - w->x0, ey = w->y1 - w->y0, len2 = ex * ex + ey * ey, t, px, py;
    double cand[3][2];
    int k, m = 0;
    for (k = -1; k <= 1; k += 2) {
        double d = ray_wall(w, cos(th + k * hw), sin(th + k * hw), &c);
        if (d > 0.0) {
            cand[m][0] = d * cos(th + k * hw);
            cand[m++][1] = d * sin(th + k * hw);
        }
    }
    /* The foot of the normal from the sonar, and the segment's ends, where the cone holds them. */
    t = len2 > 0.0 ? -(w->x0 * ex + w->y0 * ey) / len2 : 0.0;
    t = t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
    px = w->x0 + t * ex;
    py = w->y0 + t * ey;
    cand[m][0] = px;
    cand[m++][1] = py;
    for (k = 0; k < m; k++) {
        double d = sqrt(cand[k][0] * cand[k][0] + cand[k][1] * cand[k][1]);
        double off = fabs(remainder(atan2(cand[k][1], cand[k][0]) - th, 2.0 * PI));
        if (off <= hw + 1e-9 && (best < 0.0 || d < best))
            best = d;
    }
    return best;
}

/* A wall made relative to the vehicle at (vn, ve). */
static void relative(struct scene_wall *w, double vn, double ve)
{
    w->x0 -= vn;
    w->x1 -= vn;
    w->y0 -= ve;
    w->y1 -= ve;
}

/* Distance from the vehicle at (vn, ve) along bearing th to the first wall, and |cos| of its incidence; < 0 if none. */
static double walls_ray(const struct scene *s, double vn, double ve, double th, double *cosinc)
{
    double best = -1.0, ux = cos(th), uy = sin(th);
    int k;
    for (k = 0; k < s->nwall; k++) {
        struct scene_wall rel = s->wall[k];
        double c, d;
        relative(&rel, vn, ve);
        d = ray_wall(&rel, ux, uy, &c);
        if (d > 0.0 && (best < 0.0 || d < best)) {
            best = d;
            *cosinc = c;
        }
    }
    return best;
}

/* A standard normal (Box-Muller; the second value is dropped, so the stream stays simple). */
static double normal(struct scene_rng *g)
{
    return sqrt(-2.0 * log(scene_uniform(g))) * cos(2.0 * PI * scene_uniform(g));
}

/* Gamma(shape k, scale 1) by Marsaglia and Tsang; k < 1 through Gamma(k + 1) U^(1/k). */
static double gamma_draw(struct scene_rng *g, double k)
{
    double d, c, x, v, u;
    if (k < 1.0)
        return gamma_draw(g, k + 1.0) * pow(scene_uniform(g), 1.0 / k);
    d = k - 1.0 / 3.0;
    c = 1.0 / sqrt(9.0 * d);
    for (;;) {
        do {
            x = normal(g);
            v = 1.0 + c * x;
        } while (v <= 0.0);
        v = v * v * v;
        u = scene_uniform(g);
        if (log(u) < 0.5 * x * x + d - d * v + d * log(v))
            return d * v;
    }
}

/* A Rayleigh amplitude of unit mean power. */
static double rayleigh_unit(struct scene_rng *g)
{
    return sqrt(-log(scene_uniform(g)));
}

/*
 * A steady reflector's Rayleigh amplitude (unit mean power) in sample i of a beam at bearing th
 * (radians): fixed complex returns at each whole gradian, summed under the beam's amplitude pattern,
 * a Gaussian of 1.3 gradians (its power's full width at half maximum 2.2 gradians: the Ping360's 2
 * degrees), so that beams a gradian or two apart see much of the same echo. A back-and-forth
 * sector's passes come a gradian apart; AquaScan sonar4's standers correlate 0.45-0.80 across them
 * (median 0.60-0.65), the occupied scene's 0.41-0.79 (median 0.64-0.69).
 */
#define STEADY_SIGMA 1.3
static double steady_unit(int k, int i, double th)
{
    double g = th * 200.0 / PI, re = 0.0, im = 0.0, w2 = 0.0;
    long long g0 = (long long)floor(g), j;
    for (j = g0 - 2; j <= g0 + 3; j++) {
        double d = ((double)j - g) / STEADY_SIGMA, w = exp(-0.5 * d * d), a = sqrt(-log(hashed_uniform((unsigned long long)k + 1u, i, j)));
        double ph = 2.0 * PI * hashed_uniform((unsigned long long)k + 101u, i, j);
        re += w * a * cos(ph);
        im += w * a * sin(ph);
        w2 += w * w;
    }
    return sqrt((re * re + im * im) / w2);
}

/*
 * The water's K-distribution at range r (metres): shape nu, mean power mu, and the noise floor c
 * subtracted after; fitted by tools/eval/speckle_fit.py on AquaScan sonar4's unlabelled cells in five
 * range bands (docs/results.md section 8), interpolated between the bands' centres (log nu, mu, c).
 */
static void pool_water(double r, double *nu, double *mu, double *c)
{
    static const double at[5] = {3.0, 5.0, 7.5, 10.5, 13.5};
    static const double k_nu[5] = {23.3, 200.0, 6.36, 1.37, 0.55};
    static const double k_mu[5] = {4817.0, 4604.0, 4425.0, 2563.0, 1331.0};
    static const double k_c[5] = {49.2, 52.5, 54.3, 44.2, 39.7};
    int j = 0;
    double f;
    if (r <= at[0]) {
        *nu = k_nu[0], *mu = k_mu[0], *c = k_c[0];
        return;
    }
    if (r >= at[4]) {
        *nu = k_nu[4], *mu = k_mu[4], *c = k_c[4];
        return;
    }
    while (r > at[j + 1])
        j++;
    f = (r - at[j]) / (at[j + 1] - at[j]);
    *nu = exp(log(k_nu[j]) + f * (log(k_nu[j + 1]) - log(k_nu[j])));
    *mu = k_mu[j] + f * (k_mu[j + 1] - k_mu[j]);
    *c = k_c[j] + f * (k_c[j + 1] - k_c[j]);
}

#define POOL_SEGMENT 12 /* samples a water texture holds along the beam */

/*
 * One beam of a SCENE_SPECKLE_POOL scene along bearing th from (vn, ve): water, the wall's return
 * between wall_near and wall_far (< 0: none), the objects, summed in power; the noise floor
 * subtracted; clipped to 0..255.
 */
/*
 * Object k as the beam at th (radians) sees it at time t from (vn, ve): its distance d, the
 * bearing off the beam's axis delta, its half-width alpha, and the beam pattern's gain (Gaussian of
 * sigma sig_beam beyond its edge); 0 when it is absent (not there yet, gone, faded this sweep) or
 * below 2 % of the axis.
 */
/* A disc of radius r at (x, y) from the beam's origin, seen by the beam at th: its distance d, bearing off the axis delta, half-width alpha, and the pattern's gain beyond its edge (0 below 2 %). */
static double disc_gain(double x, double y, double r, double th, double sig_beam, double *d, double *delta, double *alpha)
{
    double e, gain;
    *d = sqrt(x * x + y * y);
    *delta = fabs(remainder(th - atan2(y, x), 2.0 * PI));
    *alpha = asin(fmin(1.0, r / *d));
    e = *delta > *alpha ? *delta - *alpha : 0.0;
    gain = exp(-0.5 * (e / sig_beam) * (e / sig_beam));
    return gain < 0.02 ? 0.0 : gain;
}

static double object_gain(const struct scene *s, int k, int sweep, double t, double th, double vn, double ve,
                          double sig_beam, double *d, double *delta, double *alpha)
{
    const struct scene_object *o = &s->obj[k];
    double ox, oy, ovx, ovy;
    if (!scene_object_at(s, k, sweep, t, &ox, &oy, &ovx, &ovy) || (sweep < 64 && (o->fade >> sweep) & 1u))
        return 0.0;
    return disc_gain(ox - vn, oy - ve, o->r, th, sig_beam, d, delta, alpha);
}

/*
 * The recordings' people spread over about 10 degrees between half-brightness points at every
 * range (3 to 4 beams of 2.7 degrees, measured on sonar4's labels): the Ping360's 2-degree beam
 * seen through its intensity scale. So SCENE_SPECKLE_POOL's pattern is a Gaussian of that width.
 */
#define POOL_SIG_BEAM (4.2 * PI / 180.0)

/*
 * Adds the objects' echoes at bearing th (radians) from (vn, ve), in power, to pw (n samples over range_m):
 * SCENE_SPECKLE_POOL's people, on simulated water or on a recording's (scene_draw_on).
 */
static void pool_objects(const struct scene *s, int sweep, double t, double th, double vn, double ve, double range_m,
                         int n, struct scene_rng *g, double *pw)
{
    int i, k;
    for (k = 0; k < s->nobj; k++) {
        const struct scene_object *o = &s->obj[k];
        double d, delta, alpha, near, far, gain = object_gain(s, k, sweep, t, th, vn, ve, POOL_SIG_BEAM, &d, &delta, &alpha);
        if (gain == 0.0)
            continue;
        /* A body's echo lasts through it (the labelled people are 0.7-1 m deep); it casts no shadow a sweep shows. */
        near = d - o->r;
        far = d + o->r + 0.05;
        for (i = 0; i < n; i++) {
            double r = (i + 0.5) * range_m / n;
            if (r >= near && r <= far) {
                /* A standing body returns the same echo to a fixed sonar look after look: its pattern is a function
                   of the cell, not drawn afresh each look; its sway only moves the beam pattern's gain a little. */
                double u = s->act[k] == SCENE_ACT_STANDING ? steady_unit(k, i, th) : rayleigh_unit(g);
                double a = o->strength * gain * u;
                pw[i] += a * a;
            }
        }
    }
}

/* Adds the water's transients present this sweep (scene_transients) at bearing th, in power: a fresh echo each look. */
static void pool_transients(const struct scene *s, int sweep, double th, double vn, double ve, double range_m, int n,
                            struct scene_rng *g, double *pw)
{
    int k, i;
    for (k = 0; k < s->npatch; k++) {
        const struct scene_patch *p = &s->patch[k];
        double d, delta, alpha, gain;
        if (sweep < p->first || sweep >= p->first + p->life)
            continue;
        /* Spread across beams as a person's echo is. */
        gain = disc_gain(p->x + (sweep - p->first) * p->vx - vn, p->y + (sweep - p->first) * p->vy - ve, p->r, th,
                         POOL_SIG_BEAM, &d, &delta, &alpha);
        if (gain == 0.0 || d - p->r > range_m)
            continue;
        for (i = 0; i < n; i++) {
            double r = (i + 0.5) * range_m / n;
            if (r >= d - p->r && r <= d + p->r) {
                double a = p->strength * gain * rayleigh_unit(g);
                pw[i] += a * a;
            }
        }
    }
}

static void pool_beam(const struct scene *s, int sweep, double t, double th, double vn, double ve, double wall_near,
                      double wall_far, double range_m, int n, struct scene_rng *g, uint8_t *out)
{
    double pw[1200], shadow[1200], floor_c[1200], tau = 1.0;
    int i, k;
    for (i = 0; i < n; i++) {
        double r = (i + 0.5) * range_m / n, nu, mu, c, a;
        pool_water(r, &nu, &mu, &c);
        if (i % POOL_SEGMENT == 0)
            tau = gamma_draw(g, nu) / nu;
        a = sqrt(tau * mu) * rayleigh_unit(g) + 230.0 * exp(-r / 0.12);
        pw[i] = a * a;
        floor_c[i] = c;
        shadow[i] = 1.0;
        if (wall_near > 0.0 && r >= wall_near && r <= wall_far + WALL_PULSE_M) {
            double w = 150.0 * rayleigh_unit(g);
            pw[i] += w * w;
        } else if (wall_near > 0.0 && r > wall_far + WALL_PULSE_M) {
            shadow[i] = 0.3;
        }
    }
    for (k = 0; k < s->nrope; k++) {
        /* Where the beam's axis crosses the rope (swayed at the crossing's y), and its return there. */
        const struct scene_rope *rp = &s->rope[k];
        double ux = cos(th), uy = sin(th), x, d, y;
        if (fabs(ux) < 1e-6)
            continue;
        d = (rp->x0 - vn) / ux;
        y = ve + d * uy;
        x = rp->x0 + rp->sway_m * sin(2.0 * PI * t / rp->period_s + 0.4 * y);
        d = (x - vn) / ux;
        y = ve + d * uy;
        if (d <= 0.0 || y < rp->y0 || y > rp->y1)
            continue;
        for (i = 0; i < n; i++) {
            double r = (i + 0.5) * range_m / n;
            if (r >= d - 0.05 && r <= d + 0.08) {
                double a = rp->strength * rayleigh_unit(g);
                pw[i] += a * a;
            }
        }
    }
    pool_objects(s, sweep, t, th, vn, ve, range_m, n, g, pw);
    pool_transients(s, sweep, th, vn, ve, range_m, n, g, pw);
    for (i = 0; i < n; i++) {
        double v = sqrt(pw[i]) * shadow[i] - floor_c[i];
        out[i] = (uint8_t)(v < 0 ? 0 : v > 255 ? 255 : floor(v + 0.5));
    }
}

int scene_draw_on(const struct scene *s, int sweep, double t, int angle, double range_m, int n, struct scene_rng *g,
                  uint8_t *inout)
{
    double pw[1200], floor_c[1200], vn, ve, yaw, th;
    int i;
    if (s->speckle != SCENE_SPECKLE_POOL || n > 1200)
        return -1;
    scene_vehicle_at(s, t, &vn, &ve, &yaw);
    th = angle * PI / 200.0 + yaw * PI / 180.0;
    for (i = 0; i < n; i++) {
        double r = (i + 0.5) * range_m / n, nu, mu, a;
        pool_water(r, &nu, &mu, &floor_c[i]);
        /*
         * The device subtracted its noise floor and clipped at 0: a recorded v > 0 was an amplitude of v + c; a 0
         * was anything below c, drawn here uniformly (a person's echo, 95-160 rms, is what decides those cells).
         */
        a = inout[i] > 0 ? inout[i] + floor_c[i] : floor_c[i] * scene_uniform(g);
        pw[i] = a * a;
    }
    pool_objects(s, sweep, t, th, vn, ve, range_m, n, g, pw);
    for (i = 0; i < n; i++) {
        double v = sqrt(pw[i]) - floor_c[i];
        inout[i] = (uint8_t)(v < 0 ? 0 : v > 255 ? 255 : floor(v + 0.5));
    }
    return 0;
}

double scene_streak(const struct scene *s, int sweep, int angle)
{
    int prev = angle - s->step;
    if (s->streak_rate <= 0.0)
        return 0.0;
    if (hashed_uniform(9001u, sweep, angle) < s->streak_rate ||
        (hashed_uniform(9001u, sweep, prev) < s->streak_rate && hashed_uniform(9002u, sweep, angle) < SCENE_STREAK_ON))
        return s->streak_level * (0.8 + 0.4 * hashed_uniform(9003u, sweep, angle));
    return 0.0;
}

void scene_beam(const struct scene *s, int sweep, double t, int angle, double range_m, int n, struct scene_rng *g,
                uint8_t *out)
{
    double vn, ve, yaw, th;
    double sig_beam = 0.85 * PI / 180.0; /* 2 degree beam: Gaussian sigma of the two-way pattern */
    double wall_d = -1.0, wall_cos = 1.0, wall_near = -1.0, wall_far = -1.0;
    double buf[1200];
    int i, k;
    /* The ray in the scene's frame: from the vehicle, along the beam turned by its heading. */
    scene_vehicle_at(s, t, &vn, &ve, &yaw);
    th = angle * PI / 200.0 + yaw * PI / 180.0;
    if (n > 1200)
        n = 1200;
    wall_d = walls_ray(s, vn, ve, th, &wall_cos);
    for (k = 0; k < s->nwall; k++) {
        struct scene_wall rel = s->wall[k];
        double d;
        relative(&rel, vn, ve);
        d = cone_near(&rel, th, HALF_BEAM);
        if (d > 0.0 && (wall_near < 0.0 || d < wall_near))
            wall_near = d;
    }
    if (wall_d > 0.0) {
        /* The far side of the footprint: the farther beam edge, on whichever wall each edge meets first. */
        int side;
        wall_far = wall_d;
        for (side = -1; side <= 1; side += 2) {
            double c, e = walls_ray(s, vn, ve, th + side * HALF_BEAM, &c);
            if (e > wall_far && e < wall_d * 1.5)
                wall_far = e;
        }
        if (wall_near < 0.0 || wall_near > wall_d)
            wall_near = wall_d;
    }
    if (s->speckle == SCENE_SPECKLE_POOL) {
        pool_beam(s, sweep, t, th, vn, ve, wall_near, wall_far, range_m, n, g, out);
        return;
    }
    for (i = 0; i < n; i++) {
        double r = (i + 0.5) * range_m / n;
        double sigma = 7.0 + 22.0 * exp(-r / 2.0);
        double v = sigma * rayleigh(g) + 230.0 * exp(-r / 0.12);
        if (wall_d > 0.0) {
            /*
             * Causal, as an echo is: the return starts at the nearest point of wall inside the beam
             * (its half-power edges, or the foot of the normal when the beam holds it) and lasts
             * across the footprint to the far edge, plus the pulse, then decays (reverberation in the
             * wall's roughness); the wall shadows what lies behind.
             */
            double a = 70.0 * sqrt(wall_cos) + 50.0, end = wall_far + WALL_PULSE_M;
            int m;
            if (r >= wall_near && r <= end)
                v += a * (0.6 + 0.8 * scene_uniform(g));
            else if (r > end)
                v = v * 0.3 + a * exp(-(r - end) / WALL_TAIL_M) * (0.6 + 0.8 * scene_uniform(g));
            /* The round trips between the wall and the vehicle: the wall's return again at m times its range. */
            for (m = 2; m <= 3; m++)
                if (s->echo[m - 2] > 0.0 && r >= m * wall_near && r <= m * wall_far + WALL_PULSE_M)
                    v += a * s->echo[m - 2] * (0.6 + 0.8 * scene_uniform(g));
        }
        buf[i] = v;
    }
    for (k = 0; k < s->nobj; k++) {
        const struct scene_object *o = &s->obj[k];
        double d, delta, alpha, near, far, gain = object_gain(s, k, sweep, t, th, vn, ve, sig_beam, &d, &delta, &alpha);
        if (gain == 0.0)
            continue;
        near = d - o->r;
        far = d + 0.3 * o->r + 0.05;
        for (i = 0; i < n; i++) {
            double r = (i + 0.5) * range_m / n;
            if (r >= near && r <= far)
                buf[i] += o->strength * gain * (0.75 + 0.5 * scene_uniform(g));
            else if (r > far && delta < alpha)
                buf[i] *= 0.2; /* acoustic shadow behind the object */
        }
    }
    {
        /* Interference: another source heard along the whole beam past the ring-down. */
        double st = scene_streak(s, sweep, angle);
        for (i = 0; st > 0.0 && i < n; i++)
            if ((i + 0.5) * range_m / n > 0.3)
                buf[i] += st * (0.6 + 0.8 * scene_uniform(g));
    }
    for (i = 0; i < n; i++)
        out[i] = (uint8_t)(buf[i] < 0 ? 0 : buf[i] > 255 ? 255 : floor(buf[i] + 0.5));
}


int scene_write_truth(FILE *f, const struct scene *s, int sweeps, const struct scene_seen *seen, long long t0_us)
{
    int sweep, k;
    int beams = 0;
    while (scene_angle(s, 1, beams) >= 0)
        beams++;
    fprintf(f, "{\"scene\":\"%s\",\"range_m\":%.3f,\"samples\":%d,\"beams_per_sweep\":%d,\"walls\":[", s->name,
            s->range_m, s->samples, beams);
    for (k = 0; k < s->nwall; k++)
        fprintf(f, "%s[%.3f,%.3f,%.3f,%.3f]", k ? "," : "", s->wall[k].x0, s->wall[k].y0, s->wall[k].x1, s->wall[k].y1);
    fputs("],\"sweeps\":[", f);
    for (sweep = 0; sweep < sweeps; sweep++) {
        int first = 1;
        fprintf(f, "%s{\"sweep\":%d,\"objects\":[", sweep ? "," : "", sweep);
        for (k = 0; k < s->nobj; k++) {
            const struct scene_seen *v = &seen[sweep * SCENE_MAX_OBJ + k];
            if (!v->visible || s->obj[k].structure)
                continue;
            fprintf(f, "%s{\"id\":\"%s\",\"x\":%.3f,\"y\":%.3f,\"radius\":%.3f,\"t_us\":%lld,\"vx\":%.3f,\"vy\":%.3f",
                    first ? "" : ",", s->obj[k].id, v->x, v->y, s->obj[k].r, t0_us + (long long)floor(v->t * 1e6 + 0.5),
                    v->vx, v->vy);
            if (s->veh.nwp > 0)
                fprintf(f, ",\"bx\":%.3f,\"by\":%.3f", v->bx, v->by);
            if (s->act[k] != SCENE_ACT_NONE)
                fprintf(f, ",\"activity\":\"%s\"", s->act[k] == SCENE_ACT_MOVING     ? "moving"
                                                    : s->act[k] == SCENE_ACT_STANDING ? "standing"
                                                                                      : "struggling");
            fputc('}', f);
            first = 0;
        }
        if (s->streak_rate > 0.0) {
            /* The beams a streak was drawn in. */
            int i, a;
            fputs("],\"streaks\":[", f);
            for (i = 0, first = 1; (a = scene_angle(s, sweep, i)) >= 0; i++)
                if (scene_streak(s, sweep, a) > 0.0) {
                    fprintf(f, "%s%d", first ? "" : ",", a);
                    first = 0;
                }
        }
        /* There but not seen (faded, or no beam crossed it): a tracker coasting on it is neither right nor wrong. */
        fputs("],\"hidden\":[", f);
        first = 1;
        for (k = 0; k < s->nobj; k++) {
            const struct scene_seen *v = &seen[sweep * SCENE_MAX_OBJ + k];
            if (!v->present || v->visible || s->obj[k].structure || hypot(v->bx, v->by) > s->range_m)
                continue;
            fprintf(f, "%s{\"id\":\"%s\",\"x\":%.3f,\"y\":%.3f,\"t_us\":%lld", first ? "" : ",", s->obj[k].id, v->x,
                    v->y, t0_us + (long long)floor(v->t * 1e6 + 0.5));
            if (s->veh.nwp > 0)
                fprintf(f, ",\"bx\":%.3f,\"by\":%.3f", v->bx, v->by);
            fputc('}', f);
            first = 0;
        }
        fputs("]}", f);
    }
    fputs("]}\n", f);
    return ferror(f) ? -1 : 0;
}
