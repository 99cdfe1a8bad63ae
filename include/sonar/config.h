/* config.h -- compile-time limits of the sonar core; every limit is overridable (-D) and states its RAM cost. */
#ifndef SONAR_CONFIG_H
#define SONAR_CONFIG_H

/*
 * Angular cells of the per-angle background. The head has 400 gradian positions; with fewer
 * cells, angle a maps to cell a * SONAR_MAX_ANGLES / 400. RAM: SONAR_MAX_ANGLES *
 * (SONAR_MAX_SAMPLES + 1) bytes in struct sonar_background (480 400 B at 400 x 1200, plus its other fields:
 * docs/sizes.md has the whole).
 */
#ifndef SONAR_MAX_ANGLES
#define SONAR_MAX_ANGLES 400
#endif

/*
 * Samples per beam (the Ping360 sends 200..1200). RAM: the background above, plus
 * (SONAR_MAX_MEDIAN2D + 2) * SONAR_MAX_SAMPLES bytes of beam buffers in struct sonar_pipeline.
 */
#ifndef SONAR_MAX_SAMPLES
#define SONAR_MAX_SAMPLES 1200
#endif

/* Largest odd 1-D median window along range (3, 5, 7 or 9). Stack only: window * 64 bytes. */
#ifndef SONAR_MAX_MEDIAN
#define SONAR_MAX_MEDIAN 9
#endif

/* Largest K of the K x K median over adjacent beams (3 or 5). RAM: K * (SONAR_MAX_SAMPLES + 28) bytes. */
#ifndef SONAR_MAX_MEDIAN2D
#define SONAR_MAX_MEDIAN2D 5
#endif

/* Largest Ping Protocol payload accepted; Ping360's largest is 1220. RAM: payload + 40 bytes per parser. */
#ifndef SONAR_PING_MAX_PAYLOAD
#define SONAR_PING_MAX_PAYLOAD 2048
#endif

/* Beams held in one sweep; a sweep is cut when it reaches this. RAM: 2 bytes each (angle log). */
#ifndef SONAR_MAX_SWEEP_BEAMS
#define SONAR_MAX_SWEEP_BEAMS 400
#endif

/*
 * Foreground runs (contiguous above-threshold samples of one beam) kept per sweep; more are
 * counted as dropped. RAM: 25 bytes each (24 250 B at 970). The most any recording or scene gives
 * is 904 (AquaScan sonar4 with the per-angle background and global threshold; 422 under the
 * defaults); 970 rather than 1024 leaves room in 512 KB for the CFAR's beam of block sums and the
 * structure rule's places.
 */
#ifndef SONAR_MAX_RUNS
#define SONAR_MAX_RUNS 970
#endif

/* Clusters k-means may use per sweep, and detections reported. RAM: 24 + SONAR_MAX_HULL * 8 + 16 bytes each. */
#ifndef SONAR_MAX_CLUSTERS
#define SONAR_MAX_CLUSTERS 16
#endif

/* Hull vertices reported per detection; longer hulls are thinned evenly (still convex). */
#ifndef SONAR_MAX_HULL
#define SONAR_MAX_HULL 16
#endif

/* Points the incremental hull holds before it folds them into the hull so far. Stack: 24 bytes each, while a detection is made. */
#ifndef SONAR_HULL_WORK
#define SONAR_HULL_WORK 64
#endif

/*
 * Places the structure rule keeps (structure.h): where detections at a first look stand, to learn
 * what stood there since. RAM: 32 bytes each (512 B at 16) in struct sonar_pipeline; at most 32.
 */
#ifndef SONAR_MAX_PLACES
#define SONAR_MAX_PLACES 16
#endif

/*
 * Tracks the tracker keeps (tracker.h). RAM: 64 bytes each (2 048 B at 32); an update's
 * SONAR_MAX_CLUSTERS x SONAR_MAX_TRACKS float cost matrix is on the stack (2 048 B).
 */
#ifndef SONAR_MAX_TRACKS
#define SONAR_MAX_TRACKS 32
#endif

/*
 * Vehicle poses kept for interpolation (pose.h). RAM: 24 bytes each (24 576 B at 1024), in the
 * host's app (the pipeline holds a pointer); at one stored every 50 ms they span 51 s, so a
 * detection from early in a 40 s turn still finds its pose. 200 ms samples cut the corner of a
 * heading that reverses at 30 degrees/s by up to 3 degrees, half a metre at 10 m.
 */
#ifndef SONAR_MAX_POSES
#define SONAR_MAX_POSES 1024
#endif

/*
 * Echoes the obstacle map (obstacle.h) remembers: one a beam, so a sweep of 1-gradian beams and a
 * fifth more, as the map ages them after 1.2 sweeps. RAM: 40 bytes each (20 480 B at 512) in
 * struct sonar_obstacle, which only the host's MAVLink endpoint holds.
 */
#ifndef SONAR_MAX_OBS_ECHOES
#define SONAR_MAX_OBS_ECHOES 512
#endif

/* C99 has no _Static_assert: a negative array size stops the build when a relation fails. */
#define SONAR_STATIC_ASSERT(cond, name) typedef char sonar_static_assert_##name[(cond) ? 1 : -1]

SONAR_STATIC_ASSERT(SONAR_MAX_ANGLES >= 1 && SONAR_MAX_ANGLES <= 400, angles_in_1_400);
SONAR_STATIC_ASSERT(SONAR_MAX_OBS_ECHOES >= 2 && SONAR_MAX_OBS_ECHOES <= 65535, obs_echoes_in_2_65535);
SONAR_STATIC_ASSERT(SONAR_MAX_SAMPLES >= 16 && SONAR_MAX_SAMPLES <= 4096, samples_in_16_4096);
SONAR_STATIC_ASSERT(SONAR_MAX_MEDIAN == 3 || SONAR_MAX_MEDIAN == 5 || SONAR_MAX_MEDIAN == 7 || SONAR_MAX_MEDIAN == 9, median_3_to_9);
SONAR_STATIC_ASSERT(SONAR_MAX_MEDIAN2D == 3 || SONAR_MAX_MEDIAN2D == 5, median2d_3_or_5);
SONAR_STATIC_ASSERT(SONAR_PING_MAX_PAYLOAD >= 1220 && SONAR_PING_MAX_PAYLOAD <= 65535, payload_fits_ping360);
SONAR_STATIC_ASSERT(SONAR_MAX_RUNS >= 16 && SONAR_MAX_RUNS < 65535, runs_fit_u16);
SONAR_STATIC_ASSERT(SONAR_MAX_CLUSTERS >= 1 && SONAR_MAX_CLUSTERS <= 64, clusters_1_64);
SONAR_STATIC_ASSERT(SONAR_MAX_HULL >= 3, hull_at_least_triangle);
SONAR_STATIC_ASSERT(SONAR_HULL_WORK >= 2 * SONAR_MAX_HULL + 8, hull_work_holds_hull);
SONAR_STATIC_ASSERT(SONAR_MAX_TRACKS >= 1 && SONAR_MAX_TRACKS <= 64, tracks_1_64);
SONAR_STATIC_ASSERT(SONAR_MAX_PLACES >= 1 && SONAR_MAX_PLACES <= 32, places_1_32);
SONAR_STATIC_ASSERT(SONAR_MAX_POSES >= 2 && SONAR_MAX_POSES <= 65535, poses_2_65535);
SONAR_STATIC_ASSERT(SONAR_MAX_SWEEP_BEAMS >= 8 && SONAR_MAX_SWEEP_BEAMS < 65535, sweep_beams);

#endif
