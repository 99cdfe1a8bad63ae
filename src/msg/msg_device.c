/* msg_device.c -- beam records, status records, poses and the obstacle map <-> their LCM messages, field by field, both ways; O(fields) per call, no heap (messages point into the caller's structs). */
#include "msg.h"

#include <string.h>

void msg_beam(const struct sonar_record *b, sonar_beam_t *m)
{
    m->utime = b->utime;
    m->angle = (int16_t)b->angle;
    m->gain = (int8_t)b->gain;
    m->sample_period = b->sample_period;
    m->transmit_duration = b->transmit_duration;
    m->transmit_frequency = b->transmit_frequency;
    m->speed_of_sound = b->speed_of_sound;
    m->range_m = b->range_m;
    m->stage = (int8_t)b->stage;
    m->has_pose = (int8_t)(b->has_pose != 0);
    m->north_m = b->has_pose ? b->north_m : 0.0f;
    m->east_m = b->has_pose ? b->east_m : 0.0f;
    m->yaw_deg = b->has_pose ? b->yaw_deg : 0.0f;
    m->number_of_samples = (int16_t)b->n;
    m->samples = (uint8_t *)(uintptr_t)b->samples; /* encode only reads it */
}

void msg_beam_in(const sonar_beam_t *m, struct sonar_record *b)
{
    b->utime = m->utime;
    b->angle = (uint16_t)(m->angle < 0 ? 0 : m->angle);
    b->n = (uint16_t)(m->number_of_samples < 0 ? 0 : m->number_of_samples);
    b->gain = m->gain;
    b->sample_period = m->sample_period;
    b->transmit_duration = m->transmit_duration;
    b->transmit_frequency = m->transmit_frequency;
    b->speed_of_sound = m->speed_of_sound;
    b->range_m = m->range_m;
    b->stage = (uint8_t)(m->stage < 0 ? 0 : m->stage);
    b->has_pose = (uint8_t)(m->has_pose != 0);
    b->north_m = b->has_pose ? m->north_m : 0.0f;
    b->east_m = b->has_pose ? m->east_m : 0.0f;
    b->yaw_deg = b->has_pose ? m->yaw_deg : 0.0f;
    b->samples = m->samples;
}

static uint32_t to_u32(int64_t v)
{
    return v < 0 ? 0u : v > 4294967295 ? 4294967295u : (uint32_t)v;
}

/* Long: one line a field of the record (status.h), in the message's order; splitting it would split the list. */
void msg_status(const struct sonar_status *s, sonar_status_t *m)
{
    memset(m, 0, sizeof(*m));
    m->utime = s->utime;
    m->link_state = (int8_t)s->link_state;
    m->link = (char *)(uintptr_t)(s->link != NULL ? s->link : ""); /* encode only reads it */
    m->fw_major = (int8_t)s->fw[0];
    m->fw_minor = (int8_t)s->fw[1];
    m->fw_patch = (int8_t)s->fw[2];
    m->frames = s->parser.frames;
    m->checksum_errors = s->parser.checksum_errors;
    m->resyncs = s->parser.resyncs;
    m->oversize = s->parser.oversize;
    m->bytes_dropped = s->parser.bytes_dropped;
    m->timeouts = s->driver.timeouts;
    m->retries = s->driver.retries;
    m->nacks = s->driver.nacks;
    m->reconnects = s->driver.reconnects;
    m->off_angle = s->driver.off_angle;
    m->foreign = s->driver.foreign;
    m->beams = s->driver.beams;
    m->sweeps = s->sweeps;
    m->beams_rejected = s->beams_rejected;
    m->blank_beams = s->blank_beams;
    m->interference_beams = s->interference_beams;
    m->rows_bad = s->rows_bad;
    m->sink_errors = s->sink_errors;
    m->last_sweep_s = s->last_sweep_s;
    m->beam_us_p50 = s->beam_us_p50;
    m->beam_us_p99 = s->beam_us_p99;
    m->stack_used = (int32_t)(s->stack_used > 2147483647u ? 2147483647u : s->stack_used);
    m->tracks = (int16_t)(s->tracker.live > 32767u ? 32767u : s->tracker.live);
    m->tracks_ended = s->tracker.ended;
    m->track_bad_detections = s->tracker.bad_detections;
    m->track_clock_back = s->tracker.clock_back;
    m->track_overflow = s->tracker.overflow;
    m->track_dropped = s->tracker.dropped;
    m->track_out_of_order = s->tracker.out_of_order;
    m->track_revisions = s->tracker.revisions;
    m->track_hyp_overflow = s->tracker.hyp_overflow;
    m->track_activity_unplaced = s->tracker.activity_unplaced;
    m->clutter_looks = s->tracker.clutter.looks;
    m->clutter_cells = (int16_t)s->tracker.clutter.cells_seen;
    m->clutter_site = s->tracker.clutter.site;
    m->clutter_per_look = s->tracker.clutter.per_look;
    m->clutter_peak = s->tracker.clutter.peak;
    m->clutter_peak_range_m = s->tracker.clutter.peak_range_m;
    m->clutter_peak_bearing_grad = s->tracker.clutter.peak_bearing_g;
    m->pose_state = (int8_t)s->pose.state;
    m->pose_accepted = s->pose.accepted;
    m->pose_out_of_order = s->pose.out_of_order;
    m->pose_jumps = s->pose.jumps;
    m->pose_bad = s->pose.bad;
    m->pose_stale = s->pose.stale;
    m->world_sweeps = s->pose.world_sweeps;
    m->body_sweeps = s->pose.body_sweeps;
    m->coproc_rx_crc_errors = s->coproc.rx_crc_errors;
    m->coproc_tx_dropped = s->coproc.tx_dropped;
    m->coproc_config_refused = s->coproc.config_refused;
    m->coproc_frames_bad = s->coproc.frames_bad;
    m->autopilot_sysid = (int16_t)(s->autopilot.sysid > 255u ? 255u : s->autopilot.sysid);
    m->autopilot_pose_hz = s->autopilot.pose_hz;
    m->autopilot_interval_requests = s->autopilot.interval_requests;
    m->autopilot_interval_refused = s->autopilot.interval_refused;
    m->autopilot_acks_other = s->autopilot.acks_other;
    m->autopilot_pose_held = (int8_t)(s->autopilot.pose_held != 0);
    m->obstacle_distance_sent = s->autopilot.od_sent;
    m->obstacle_distance_withheld = s->autopilot.od_withheld;
    m->autopilot_rx_other = s->autopilot.rx_other;
    m->gain = (int8_t)(s->acq.gain < 0 ? -1 : s->acq.gain > 127 ? 127 : s->acq.gain);
    m->gain_auto = (int8_t)(s->acq.gain_auto != 0);
    m->gain_changes = s->acq.gain_changes;
    m->gain_refused = s->acq.gain_refused;
    m->background_restarts = s->acq.background_restarts;
    m->scan_mode = (int8_t)(s->scan.mode < 0 ? -1 : s->scan.mode > 127 ? 127 : s->scan.mode);
    m->scan_interleave = (int16_t)(s->scan.interleave > 32767u ? 32767u : s->scan.interleave);
    m->scan_target_pings = s->scan.target_pings;
    m->scan_surveil_pings = s->scan.surveil_pings;
    m->scan_late_looks = s->scan.late_looks;
    m->scan_targets_dropped = s->scan.targets_dropped;
    m->structure_places = (int16_t)(s->structure.places > 32767u ? 32767u : s->structure.places);
    m->structure_learnt = (int16_t)(s->structure.learnt > 32767u ? 32767u : s->structure.learnt);
    m->structure_promoted = s->structure.promoted;
    m->structure_detections = s->structure.detections;
    m->structure_restarts = s->structure.restarts;
    m->passive = (int8_t)(s->passive.on != 0);
    m->passive_idle = (int8_t)(s->passive.idle != 0);
    m->passive_range_m = s->passive.range_m;
    m->passive_samples = (int16_t)(s->passive.samples > 32767 ? 32767 : s->passive.samples < 0 ? 0 : s->passive.samples);
    m->passive_changes = s->passive.changes;
    m->passive_hellos = s->driver.hellos;
    m->passive_idles = s->driver.idles;
    m->survey_state = (int8_t)s->survey.state;
    m->survey_why = (int8_t)s->survey.why;
    m->survey_fixed = (int8_t)(s->survey.fixed != 0);
    m->survey_utime = s->survey.utime;
    m->survey_sweeps = (int32_t)(s->survey.sweeps > INT32_MAX ? INT32_MAX : s->survey.sweeps);
    m->survey_turn_grad = (int16_t)(s->survey.turn_grad < -400 ? -400 : s->survey.turn_grad > 400 ? 400 : s->survey.turn_grad);
    m->survey_places = (int16_t)(s->survey.nplaces > 32767u ? 32767u : s->survey.nplaces);
    m->survey_unfits = s->survey.unfits;
    m->survey_agree = (float)s->survey.agree16 / 16.0f;
    m->survey_standout = (float)s->survey.standout1000 / 1000.0f;
    m->control = (int8_t)(s->control.on != 0);
    m->control_seq = (int32_t)(s->control.seq > INT32_MAX ? INT32_MAX : s->control.seq);
    m->control_result = (int8_t)s->control.result;
    m->control_said = (char *)(uintptr_t)(s->control.said != NULL ? s->control.said : "");
    m->survey_rec = (int8_t)s->control.rec;
    m->survey_rec_sweeps = (int16_t)(s->control.rec_sweeps > 32767u ? 32767u : s->control.rec_sweeps);
    m->survey_rec_of = (int16_t)(s->control.rec_of > 32767u ? 32767u : s->control.rec_of);
    m->survey_rec_said = (char *)(uintptr_t)(s->control.rec_said != NULL ? s->control.rec_said : "");
}

/* Long: one line a field, as msg_status. */
void msg_status_in(const sonar_status_t *m, struct sonar_status *s)
{
    memset(s, 0, sizeof(*s));
    s->utime = m->utime;
    s->link_state = m->link_state;
    s->link = m->link;
    s->fw[0] = (uint8_t)m->fw_major;
    s->fw[1] = (uint8_t)m->fw_minor;
    s->fw[2] = (uint8_t)m->fw_patch;
    s->parser.frames = to_u32(m->frames);
    s->parser.checksum_errors = to_u32(m->checksum_errors);
    s->parser.resyncs = to_u32(m->resyncs);
    s->parser.oversize = to_u32(m->oversize);
    s->parser.bytes_dropped = to_u32(m->bytes_dropped);
    s->driver.timeouts = to_u32(m->timeouts);
    s->driver.retries = to_u32(m->retries);
    s->driver.nacks = to_u32(m->nacks);
    s->driver.reconnects = to_u32(m->reconnects);
    s->driver.off_angle = to_u32(m->off_angle);
    s->driver.foreign = to_u32(m->foreign);
    s->driver.beams = to_u32(m->beams);
    s->sweeps = to_u32(m->sweeps);
    s->beams_rejected = to_u32(m->beams_rejected);
    s->blank_beams = to_u32(m->blank_beams);
    s->interference_beams = to_u32(m->interference_beams);
    s->rows_bad = to_u32(m->rows_bad);
    s->sink_errors = to_u32(m->sink_errors);
    s->last_sweep_s = m->last_sweep_s;
    s->beam_us_p50 = m->beam_us_p50;
    s->beam_us_p99 = m->beam_us_p99;
    s->stack_used = to_u32(m->stack_used);
    s->tracker.live = to_u32(m->tracks);
    s->tracker.ended = to_u32(m->tracks_ended);
    s->tracker.bad_detections = to_u32(m->track_bad_detections);
    s->tracker.clock_back = to_u32(m->track_clock_back);
    s->tracker.overflow = to_u32(m->track_overflow);
    s->tracker.dropped = to_u32(m->track_dropped);
    s->tracker.out_of_order = to_u32(m->track_out_of_order);
    s->tracker.revisions = to_u32(m->track_revisions);
    s->tracker.hyp_overflow = to_u32(m->track_hyp_overflow);
    s->tracker.activity_unplaced = to_u32(m->track_activity_unplaced);
    s->tracker.clutter.looks = to_u32(m->clutter_looks);
    s->tracker.clutter.cells_seen = (uint16_t)(m->clutter_cells < 0 ? 0 : m->clutter_cells);
    s->tracker.clutter.site = m->clutter_site;
    s->tracker.clutter.per_look = m->clutter_per_look;
    s->tracker.clutter.peak = m->clutter_peak;
    s->tracker.clutter.peak_range_m = m->clutter_peak_range_m;
    s->tracker.clutter.peak_bearing_g = m->clutter_peak_bearing_grad;
    s->pose.state = m->pose_state;
    s->pose.accepted = to_u32(m->pose_accepted);
    s->pose.out_of_order = to_u32(m->pose_out_of_order);
    s->pose.jumps = to_u32(m->pose_jumps);
    s->pose.bad = to_u32(m->pose_bad);
    s->pose.stale = to_u32(m->pose_stale);
    s->pose.world_sweeps = to_u32(m->world_sweeps);
    s->pose.body_sweeps = to_u32(m->body_sweeps);
    s->coproc.rx_crc_errors = to_u32(m->coproc_rx_crc_errors);
    s->coproc.tx_dropped = to_u32(m->coproc_tx_dropped);
    s->coproc.config_refused = to_u32(m->coproc_config_refused);
    s->coproc.frames_bad = to_u32(m->coproc_frames_bad);
    s->autopilot.sysid = to_u32(m->autopilot_sysid);
    s->autopilot.pose_hz = m->autopilot_pose_hz;
    s->autopilot.interval_requests = to_u32(m->autopilot_interval_requests);
    s->autopilot.interval_refused = to_u32(m->autopilot_interval_refused);
    s->autopilot.acks_other = to_u32(m->autopilot_acks_other);
    s->autopilot.pose_held = m->autopilot_pose_held != 0;
    s->autopilot.od_sent = to_u32(m->obstacle_distance_sent);
    s->autopilot.od_withheld = to_u32(m->obstacle_distance_withheld);
    s->autopilot.rx_other = to_u32(m->autopilot_rx_other);
    s->acq.gain = m->gain;
    s->acq.gain_auto = m->gain_auto != 0;
    s->acq.gain_changes = to_u32(m->gain_changes);
    s->acq.gain_refused = to_u32(m->gain_refused);
    s->acq.background_restarts = to_u32(m->background_restarts);
    s->scan.mode = m->scan_mode;
    s->scan.interleave = m->scan_interleave < 0 ? 0u : (uint32_t)m->scan_interleave;
    s->scan.target_pings = to_u32(m->scan_target_pings);
    s->scan.surveil_pings = to_u32(m->scan_surveil_pings);
    s->scan.late_looks = to_u32(m->scan_late_looks);
    s->scan.targets_dropped = to_u32(m->scan_targets_dropped);
    s->structure.places = m->structure_places < 0 ? 0u : (uint32_t)m->structure_places;
    s->structure.learnt = m->structure_learnt < 0 ? 0u : (uint32_t)m->structure_learnt;
    s->structure.promoted = to_u32(m->structure_promoted);
    s->structure.detections = to_u32(m->structure_detections);
    s->structure.restarts = to_u32(m->structure_restarts);
    s->passive.on = m->passive != 0;
    s->passive.idle = m->passive_idle != 0;
    s->passive.range_m = m->passive_range_m;
    s->passive.samples = m->passive_samples;
    s->passive.changes = to_u32(m->passive_changes);
    s->driver.hellos = to_u32(m->passive_hellos);
    s->driver.idles = to_u32(m->passive_idles);
    s->survey.state = m->survey_state;
    s->survey.why = m->survey_why;
    s->survey.fixed = m->survey_fixed != 0;
    s->survey.utime = m->survey_utime;
    s->survey.sweeps = m->survey_sweeps < 0 ? 0u : (uint32_t)m->survey_sweeps;
    s->survey.turn_grad = m->survey_turn_grad;
    s->survey.nplaces = m->survey_places < 0 ? 0u : (uint32_t)m->survey_places;
    s->survey.places = NULL; /* the structure is not on SONAR_STATUS */
    s->survey.unfits = to_u32(m->survey_unfits);
    s->survey.agree16 = m->survey_agree > 0.0f ? (uint32_t)(m->survey_agree * 16.0f + 0.5f) : 0u;
    s->survey.standout1000 = m->survey_standout > 0.0f ? (uint32_t)(m->survey_standout * 1000.0f + 0.5f) : 0u;
    s->control.on = m->control != 0;
    s->control.seq = m->control_seq < 0 ? 0u : (uint32_t)m->control_seq;
    s->control.result = m->control_result;
    s->control.said = m->control_said;
    s->control.rec = m->survey_rec;
    s->control.rec_sweeps = m->survey_rec_sweeps < 0 ? 0u : (uint32_t)m->survey_rec_sweeps;
    s->control.rec_of = m->survey_rec_of < 0 ? 0u : (uint32_t)m->survey_rec_of;
    s->control.rec_said = m->survey_rec_said;
}

void msg_survey(const struct sonar_status *s, sonar_detection_t *det, sonar_survey_t *m)
{
    unsigned i, n = s->survey.places != NULL && s->survey.nplaces <= SONAR_MAX_CLUSTERS ? s->survey.nplaces : 0u;
    memset(det, 0, n * sizeof(*det));
    for (i = 0; i < n; i++) {
        const struct sonar_detection *o = &s->survey.places[i];
        det[i].x_m = o->x_m;
        det[i].y_m = o->y_m;
        det[i].range_m = o->range_m;
        det[i].kind = (int8_t)o->kind;
        det[i].hull_count = o->hull_count;
        det[i].hull_x = (float *)(uintptr_t)o->hull_x; /* encode only reads them */
        det[i].hull_y = (float *)(uintptr_t)o->hull_y;
    }
    m->utime = s->utime;
    m->state = (int8_t)s->survey.state;
    m->fixed = (int8_t)(s->survey.fixed != 0);
    m->recorded_utime = s->survey.utime;
    m->sweeps = (int32_t)(s->survey.sweeps > INT32_MAX ? INT32_MAX : s->survey.sweeps);
    m->count = (int16_t)n;
    m->places = det;
}

int msg_clutter(const struct sonar_status *s, float *density, sonar_clutter_t *m)
{
    const struct sonar_clutter *c = s->tracker.map;
    int b, k;
    if (c == NULL)
        return 0;
    for (b = 0; b < SONAR_CLUTTER_BANDS; b++)
        for (k = 0; k < SONAR_CLUTTER_SECTORS; k++)
            density[b * SONAR_CLUTTER_SECTORS + k] = sonar_clutter_cell(c, b, k);
    m->utime = s->utime;
    m->looks = s->tracker.clutter.looks;
    m->range_m = c->range_m;
    m->bands = SONAR_CLUTTER_BANDS;
    m->sectors = SONAR_CLUTTER_SECTORS;
    m->site = s->tracker.clutter.site;
    m->per_look = s->tracker.clutter.per_look;
    m->cells = SONAR_CLUTTER_BANDS * SONAR_CLUTTER_SECTORS;
    m->density = density;
    return 1;
}

void msg_pose(const struct sonar_pose *p, sonar_pose_t *m)
{
    m->utime = p->utime;
    m->north_m = p->north_m;
    m->east_m = p->east_m;
    m->yaw_deg = p->yaw_deg;
}

void msg_pose_in(const sonar_pose_t *m, struct sonar_pose *p)
{
    p->utime = m->utime;
    p->north_m = m->north_m;
    p->east_m = m->east_m;
    p->yaw_deg = m->yaw_deg;
}

void msg_obstacles(int64_t utime, const uint16_t *dist_cm, uint16_t min_cm, uint16_t max_cm, int32_t *cells,
                   sonar_obstacles_t *m)
{
    int k;
    m->utime = utime;
    m->sector_deg = (float)SONAR_OBS_SECTOR_DEG;
    m->min_cm = min_cm;
    m->max_cm = max_cm;
    m->count = SONAR_OBS_SECTORS;
    for (k = 0; k < SONAR_OBS_SECTORS; k++)
        cells[k] = dist_cm[k];
    m->distance_cm = cells;
}
