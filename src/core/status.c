/* status.c -- the device's and the pipeline's counters into a status record; O(1), no heap. */
#include "sonar/status.h"

#include "sonar/pose.h"

void sonar_status_tracking(struct sonar_status *s, const struct sonar_pipeline *p)
{
    if (p->cfg != NULL && p->cfg->track) {
        s->tracker.live = p->trk.n;
        s->tracker.ended = p->trk.deleted;
        s->tracker.bad_detections = p->trk.bad_detections;
        s->tracker.clock_back = p->trk.clock_back;
        s->tracker.overflow = p->trk.overflow;
        s->tracker.dropped = p->trk.dropped;
        s->tracker.out_of_order = p->trk.out_of_order;
        s->tracker.revisions = p->trk.revisions;
        s->tracker.hyp_overflow = p->trk.hyp_overflow;
        s->tracker.activity_unplaced = p->act != NULL ? p->act->unplaced : 0u;
        sonar_clutter_summarise(p->clutter, &s->tracker.clutter);
        s->tracker.map = s->tracker.clutter.looks > 0 ? p->clutter : NULL;
    }
    s->pose.world_sweeps = p->world_sweeps;
    s->pose.body_sweeps = p->body_sweeps;
}

void sonar_status_survey(struct sonar_status *s, const struct sonar_survey *sv)
{
    if (sv == NULL || sv->state == SONAR_SURVEY_NONE)
        return;
    s->survey.state = sv->state;
    s->survey.why = sv->why;
    s->survey.fixed = sv->fixed;
    s->survey.utime = sv->meta.utime;
    s->survey.sweeps = sv->meta.sweeps;
    s->survey.turn_grad = sv->turn_grad;
    s->survey.unfits = sv->unfits;
    s->survey.agree16 = sv->agree16;
    s->survey.standout1000 = sv->standout1000;
    s->survey.nplaces = sv->places != NULL ? sv->nplaces : 0u;
    s->survey.places = sv->places;
}

void sonar_status_fill(struct sonar_status *s, const struct sonar_device *dev, const struct sonar_pipeline *p)
{
    if (dev != NULL) {
        s->fw[0] = dev->drv.info.fw_major;
        s->fw[1] = dev->drv.info.fw_minor;
        s->fw[2] = dev->drv.info.fw_patch;
        s->parser = dev->parser.counters;
        s->driver = dev->drv.counters;
    }
    if (p == NULL)
        return;
    sonar_status_tracking(s, p);
    s->structure.places = p->st.n;
    s->structure.learnt = sonar_structure_count(&p->st);
    s->structure.promoted = p->st.promoted;
    s->structure.detections = p->st.detections;
    s->structure.restarts = p->st.restarts;
    sonar_status_survey(s, p->sv);
    /* The gain the beams carry (the device's setting until one came), and the backgrounds a change of it restarted. */
    s->acq.gain = p->last_gain >= 0 ? p->last_gain : dev != NULL ? (int)dev->drv.cfg.gain : 0;
    s->acq.background_restarts = p->gain_restarts;
    s->blank_beams = p->blank_beams;
    s->interference_beams = p->streak.beams;
}

void sonar_status_poses(struct sonar_status *s, const struct sonar_pose_ring *r)
{
    s->pose.accepted = r->accepted;
    s->pose.out_of_order = r->out_of_order;
    s->pose.jumps = r->jumps;
    s->pose.bad = r->bad;
    s->pose.thinned = r->thinned;
}
