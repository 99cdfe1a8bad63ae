/* pipeline_internal.h -- what pipeline.c (the beams) asks of pipeline_tracks.c (the sweep's tracking); not part of the API; no RAM. */
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

#endif
