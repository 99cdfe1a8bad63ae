/* config.h -- compile-time limits of the sonar core; every limit is overridable (-D) and states its RAM cost. */
#ifndef SONAR_CONFIG_H
#define SONAR_CONFIG_H

/*
 * Angular cells of the per-angle background. The head has 400 gradian positions; with fewer
 * cells, angle a maps to cell a * SONAR_MAX_ANGLES / 400. RAM: SONAR_MAX_ANGLES rows of SONAR_MAX_SAMPLES + 1
 * bytes, SONAR_MAX_ANGLES * SONAR_MAX_SAMPLES + SONAR_MAX_ANGLES = 480 400 B, in
 * sizeof(struct sonar_background) = 481 632 B.
 */
#ifndef SONAR_MAX_ANGLES
#define SONAR_MAX_ANGLES 400
#endif

/*
 * Samples per beam (the Ping360 sends 200..1200). RAM: the background above, the 2-D median's rows
 * (below), and two beams in struct sonar_pipeline: 2 * SONAR_MAX_SAMPLES = 2 400 B.
 */
#ifndef SONAR_MAX_SAMPLES
#define SONAR_MAX_SAMPLES 1200
#endif

/* Largest odd 1-D median window along range (3, 5, 7 or 9). Stack only: window * 64 bytes. */
#ifndef SONAR_MAX_MEDIAN
#define SONAR_MAX_MEDIAN 9
#endif

/* Largest K of the K x K median over adjacent beams (3 or 5). RAM: sizeof(struct sonar_median2d) = 6 120 B (median.h). */
#ifndef SONAR_MAX_MEDIAN2D
#define SONAR_MAX_MEDIAN2D 5
#endif

/* Largest Ping Protocol payload accepted; Ping360's largest is 1220. RAM: SONAR_PING_MAX_PAYLOAD + 40 = 2 088 B a parser. */
#ifndef SONAR_PING_MAX_PAYLOAD
#define SONAR_PING_MAX_PAYLOAD 2048
#endif

/* Beams held in one sweep; a sweep is cut when it reaches this. RAM: 7 bytes each in the detector (the angle and time logs, the leading edge and its level). */
#ifndef SONAR_MAX_SWEEP_BEAMS
#define SONAR_MAX_SWEEP_BEAMS 400
#endif

/*
 * Foreground runs (contiguous above-threshold samples of one beam) kept per sweep; more are
 * counted as dropped. RAM: sizeof(struct sonar_point) + sizeof(struct sonar_detector_run) + 1 = 25 B each (a
 * centre, the run, a label), SONAR_MAX_RUNS * 25 = 24 250 B. The most any recording or scene gives
 * is 904 (AquaScan sonar4 with the per-angle background and global threshold; 422 under the
 * defaults); 970 rather than 1024 leaves room in 512 KB for the CFAR's beam of block sums and the
 * structure rule's places.
 */
#ifndef SONAR_MAX_RUNS
#define SONAR_MAX_RUNS 970
#endif

/* Clusters k-means may use per sweep, and detections reported. RAM: sizeof(struct sonar_detection) = 168 B each. */
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
 * what stood there since. RAM: sizeof(struct sonar_place) = 40 B each, SONAR_MAX_PLACES * 40 = 640 B, in struct
 * sonar_pipeline; at most 32.
 */
#ifndef SONAR_MAX_PLACES
#define SONAR_MAX_PLACES 16
#endif

/*
 * Tracks the tracker keeps (tracker.h). RAM: sizeof(struct sonar_track) = 184 B each (three models of 32 B),
 * SONAR_MAX_TRACKS * 184 = 5 888 B; an update's float cost matrix is on the stack, SONAR_MAX_CLUSTERS *
 * SONAR_MAX_TRACKS * 4 = 2 048 B.
 */
#ifndef SONAR_MAX_TRACKS
#define SONAR_MAX_TRACKS 32
#endif

/*
 * Tracks whose activity (activity.h) is judged: each keeps two looks' raw windows. RAM:
 * sizeof(struct sonar_act_slot) = 616 B each, SONAR_ACT_SLOTS * 616 = 19 712 B (struct sonar_activity, the
 * caller's: the host's app, the firmware's large bank). Tracks beyond it are unknown, and counted.
 */
#ifndef SONAR_ACT_SLOTS
#define SONAR_ACT_SLOTS SONAR_MAX_TRACKS
#endif

/*
 * The clutter map's grid (clutter.h): range bands of 1/SONAR_CLUTTER_BANDS of the range scanned by
 * bearing sectors of 400/SONAR_CLUTTER_SECTORS gradians about the sonar. RAM: 4 B a cell,
 * SONAR_CLUTTER_BANDS * SONAR_CLUTTER_SECTORS * 4 = 1 600 B in sizeof(struct sonar_clutter) = 1 624 B
 * (the caller's: the host's app, the firmware's large bank).
 */
#ifndef SONAR_CLUTTER_BANDS
#define SONAR_CLUTTER_BANDS 16
#endif
#ifndef SONAR_CLUTTER_SECTORS
#define SONAR_CLUTTER_SECTORS 25
#endif

/*
 * Walls the tracker turns its predictions at (tracker.h, sonar_tracker_set_walls): the site
 * survey's lines. RAM: 48 B each in sizeof(struct sonar_tracker) (its ends, its box and this update's line
 * where a swimmer turns), SONAR_TRK_MAX_WALLS * 48 = 768 B; at most 16 (a track's near_walls is a bit each).
 */
#ifndef SONAR_TRK_MAX_WALLS
#define SONAR_TRK_MAX_WALLS 16
#endif

/*
 * Assignment hypotheses the tracker weighs for a sweep until the next look (tracker.h): the one
 * published and up to this - 1 others, each holding two tracks' states. RAM:
 * sizeof(struct sonar_trk_alt) = 384 B each, (SONAR_TRK_HYPOTHESES - 1) * 384 = 2 688 B.
 */
#ifndef SONAR_TRK_HYPOTHESES
#define SONAR_TRK_HYPOTHESES 8
#endif

/*
 * Vehicle poses kept for interpolation (pose.h). RAM: sizeof(struct sonar_pose) = 24 B each,
 * SONAR_MAX_POSES * 24 = 24 576 B, in the
 * host's app (the pipeline holds a pointer); at one stored every 50 ms they span 51 s, so a
 * detection from early in a 40 s turn still finds its pose. 200 ms samples cut the corner of a
 * heading that reverses at 30 degrees/s by up to 3 degrees, half a metre at 10 m.
 */
#ifndef SONAR_MAX_POSES
#define SONAR_MAX_POSES 1024
#endif

/*
 * Echoes the obstacle map (obstacle.h) remembers: one a beam, so a sweep of 1-gradian beams and a
 * fifth more, as the map ages them after 1.2 sweeps. RAM: sizeof(struct sonar_obstacle_echo) = 40 B each,
 * SONAR_MAX_OBS_ECHOES * 40 = 20 480 B, in
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
SONAR_STATIC_ASSERT(SONAR_ACT_SLOTS >= 1 && SONAR_ACT_SLOTS <= 64, act_slots_1_64);
SONAR_STATIC_ASSERT(SONAR_TRK_HYPOTHESES >= 2 && SONAR_TRK_HYPOTHESES <= 16, hypotheses_2_16);
SONAR_STATIC_ASSERT(SONAR_TRK_MAX_WALLS >= 1 && SONAR_TRK_MAX_WALLS <= 16, walls_fit_a_track_mask); /* sonar_track.near_walls */
SONAR_STATIC_ASSERT(SONAR_MAX_PLACES >= 1 && SONAR_MAX_PLACES <= 32, places_1_32);
SONAR_STATIC_ASSERT(SONAR_MAX_POSES >= 2 && SONAR_MAX_POSES <= 65535, poses_2_65535);
SONAR_STATIC_ASSERT(SONAR_CLUTTER_BANDS >= 1 && SONAR_CLUTTER_BANDS <= 64, clutter_bands_1_64);
SONAR_STATIC_ASSERT(SONAR_CLUTTER_SECTORS >= 1 && SONAR_CLUTTER_SECTORS <= 400 && 400 % SONAR_CLUTTER_SECTORS == 0, clutter_sectors_divide_400);
SONAR_STATIC_ASSERT(SONAR_MAX_SWEEP_BEAMS >= 8 && SONAR_MAX_SWEEP_BEAMS < 65535, sweep_beams);

#endif
