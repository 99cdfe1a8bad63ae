/* pipeline_read.c -- what the pipeline's host may read of it, one getter each, so no host or firmware file names its fields; O(1) each (the structure count O(places)). */
#include "sonar/pipeline.h"

#include "sonar/bgfile.h"

const struct sonar_pipeline_config *sonar_pipeline_running(const struct sonar_pipeline *p)
{
    return p->cfg;
}

const struct sonar_detections *sonar_pipeline_detections(const struct sonar_pipeline *p)
{
    return &p->out;
}

const struct sonar_tracker *sonar_pipeline_tracker(const struct sonar_pipeline *p)
{
    return p->cfg->track ? &p->trk : NULL;
}

int sonar_pipeline_pose_at(const struct sonar_pipeline *p, int64_t utime, struct sonar_pose *q)
{
    return p->poses != NULL && sonar_pose_at(p->poses, utime, q);
}

void sonar_pipeline_track_pose(const struct sonar_pipeline *p, int64_t utime, struct sonar_pose *q)
{
    if (!sonar_pipeline_pose_at(p, utime, q))
        *q = p->last_pose;
}

void sonar_pipeline_geometry(const struct sonar_pipeline *p, uint16_t *n, float *range_m)
{
    *n = p->n;
    *range_m = p->range_m;
}

int sonar_pipeline_gain(const struct sonar_pipeline *p)
{
    return p->last_gain;
}

uint32_t sonar_pipeline_gain_restarts(const struct sonar_pipeline *p)
{
    return p->gain_restarts;
}

uint32_t sonar_pipeline_interference_beams(const struct sonar_pipeline *p)
{
    return p->streak.beams;
}

uint32_t sonar_pipeline_blank_beams(const struct sonar_pipeline *p)
{
    return p->blank_beams;
}

uint32_t sonar_pipeline_geometry_changes(const struct sonar_pipeline *p)
{
    return p->geometry_changes;
}

uint32_t sonar_pipeline_structure_promoted(const struct sonar_pipeline *p)
{
    return p->st.promoted;
}

unsigned sonar_pipeline_structure_count(const struct sonar_pipeline *p)
{
    return sonar_structure_count(&p->st);
}

int32_t sonar_pipeline_save_background(const struct sonar_pipeline *p, const struct sonar_bgfile_meta *m, uint8_t *out,
                                       size_t cap)
{
    return sonar_bgfile_write(p->bg, m, out, cap);
}

const struct sonar_survey *sonar_pipeline_survey(const struct sonar_pipeline *p)
{
    return p->sv;
}
