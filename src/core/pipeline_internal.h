/* pipeline_internal.h -- what pipeline.c (the beams) asks of pipeline_tracks.c (the sweep's tracking) and pipeline_learn.c (what the background learns); not part of the API; no RAM. */
#ifndef SONAR_PIPELINE_INTERNAL_H
#define SONAR_PIPELINE_INTERNAL_H

#include "sonar/pipeline.h"

/*
 * The detector's track_m gate for the sweep about to end, when the tracks are in the world frame:
 * each track where the beam that looked along it saw it, in that beam's body frame. Returns
 * SONAR_OK or the detector's error.
 */
int sonar_pipe_world_gates(struct sonar_pipeline *p);

/*
 * The last steps of a sweep in p->out, the pipeline's own or a co-processor's: locate, drop
 * repeats, structure, track (have_cover: the sweep's beams went through this pipeline, so they say
 * which gradians were scanned and its background is theirs; a co-processor's sweep learns its
 * structure there). Returns SONAR_OK or the structure rule's or the tracker's error.
 */
int sonar_pipe_finish_sweep(struct sonar_pipeline *p, int have_cover);

/*
 * With a pose at the beam's time (per-angle or auto mode): the beam's background in the world grid
 * (pipeline_learn.c), *done = 1; else nothing, *done = 0. Returns SONAR_OK or the background's error.
 */
int sonar_pipe_world_background(struct sonar_pipeline *p, int64_t utime, uint16_t angle, int *done);

/*
 * The per-angle background's spans for a beam at angle (pipeline_learn.c): sp, the tracks' cells it must
 * not learn (returns their count, at most SONAR_MAX_TRACKS); learn, structure's cells it learns at once
 * (*nlearn of them, at most SONAR_PIPE_LEARN_MAX).
 */
uint8_t sonar_pipe_keep_spans(const struct sonar_pipeline *p, uint16_t angle, struct sonar_bg_span *sp,
                              struct sonar_bg_span *learn, uint8_t *nlearn);

/* The ring-down's reach, metres: the detector's min_range_m, at least SONAR_PIPE_NEAR_M (no structure or edge nearer). */
static inline float sonar_pipe_near_m(const struct sonar_pipeline *p)
{
    return p->cfg->detector.min_range_m > SONAR_PIPE_NEAR_M ? p->cfg->detector.min_range_m : SONAR_PIPE_NEAR_M;
}

#endif
