/* sinks.c -- LCM, CSV and JSON/text sinks: each maps an app record onto its format once; LCM types from lcm-gen --c-no-pubsub, encoded into the sink's buffer. */
#include "sinks.h"

#include <lcm/lcm.h>
#include <string.h>

#include "csv.h"
#include "msg.h"
#include "obsmap.h"
#include "report.h"
#include "sonar_beam_t.h"
#include "sonar_clutter_t.h"
#include "sonar_detections_t.h"
#include "sonar_obstacles_t.h"
#include "sonar_status_t.h"
#include "sonar_survey_t.h"
#include "sonar_tracks_t.h"

static int lcm_send(struct sink_lcm *s, const char *channel, int len)
{
    if (len < 0)
        return HOST_ERR_PUBLISH; /* the message did not fit the buffer */
    return s->tx(s->tx_user, channel, s->buf, (size_t)len) == 0 ? HOST_OK : HOST_ERR_PUBLISH;
}

static int lcm_beam(void *self, const struct sonar_record *b)
{
    struct sink_lcm *s = self;
    sonar_beam_t m;
    msg_beam(b, &m);
    return lcm_send(s, b->stage == SONAR_STAGE_RAW ? s->beam : s->filtered,
                    sonar_beam_t_encode(s->buf, 0, (int)sizeof(s->buf), &m));
}

static int lcm_detections(void *self, const struct sonar_detections *d, const struct sonar_tracker *tk,
                          const struct msg_view *v)
{
    struct sink_lcm *s = self;
    sonar_detection_t det[SONAR_MAX_CLUSTERS];
    sonar_detections_t m;
    sonar_track_t trk[SONAR_MAX_TRACKS];
    sonar_tracks_t t;
    struct msg_revisions rv;
    int r;
    msg_detections(d, v, det, &m);
    r = lcm_send(s, s->detections, sonar_detections_t_encode(s->buf, 0, (int)sizeof(s->buf), &m));
    if (r != HOST_OK || tk == NULL)
        return r;
    msg_tracks(tk, d, v, trk, &rv, &t);
    return lcm_send(s, s->tracks, sonar_tracks_t_encode(s->buf, 0, (int)sizeof(s->buf), &t));
}

static int lcm_status(void *self, const struct sonar_status *st)
{
    struct sink_lcm *s = self;
    sonar_status_t m;
    sonar_detection_t det[SONAR_MAX_CLUSTERS];
    sonar_survey_t sv;
    sonar_clutter_t cm;
    float density[SONAR_CLUTTER_BANDS * SONAR_CLUTTER_SECTORS];
    int r;
    msg_status(st, &m);
    r = lcm_send(s, s->status, sonar_status_t_encode(s->buf, 0, (int)sizeof(s->buf), &m));
    /* The clutter map with each status while one is learnt, for a view's layer. */
    if (r == HOST_OK && msg_clutter(st, density, &cm))
        r = lcm_send(s, s->clutter, sonar_clutter_t_encode(s->buf, 0, (int)sizeof(s->buf), &cm));
    if (r != HOST_OK || st->survey.state == SONAR_SURVEY_NONE)
        return r;
    /* The survey's structure with each status while there is one, for a view that joins late. */
    msg_survey(st, det, &sv);
    return lcm_send(s, s->survey, sonar_survey_t_encode(s->buf, 0, (int)sizeof(s->buf), &sv));
}

void sink_lcm_obstacles(void *self, const struct obsmap_read *r)
{
    struct sink_lcm *s = self;
    sonar_obstacles_t m;
    int32_t cells[SONAR_OBS_SECTORS];
    msg_obstacles(r->utime, r->dist_cm, r->min_cm, r->max_cm, cells, &m);
    if (lcm_send(s, s->obstacles, sonar_obstacles_t_encode(s->buf, 0, (int)sizeof(s->buf), &m)) != HOST_OK)
        s->sink.errors++;
}

void sink_lcm_init(struct sink_lcm *s, sink_lcm_tx tx, void *user, const char *prefix, int filtered)
{
    memset(s, 0, sizeof(*s));
    s->tx = tx;
    s->tx_user = user;
    snprintf(s->beam, sizeof(s->beam), "%.30sSONAR_BEAM", prefix);
    snprintf(s->filtered, sizeof(s->filtered), "%.30sSONAR_BEAM_FILTERED", prefix);
    snprintf(s->detections, sizeof(s->detections), "%.30sSONAR_DETECTIONS", prefix);
    snprintf(s->status, sizeof(s->status), "%.30sSONAR_STATUS", prefix);
    snprintf(s->tracks, sizeof(s->tracks), "%.30sSONAR_TRACKS", prefix);
    snprintf(s->survey, sizeof(s->survey), "%.30sSONAR_SURVEY", prefix);
    snprintf(s->clutter, sizeof(s->clutter), "%.30sSONAR_CLUTTER", prefix);
    snprintf(s->obstacles, sizeof(s->obstacles), "%.30sSONAR_OBSTACLES", prefix);
    s->sink.name = "lcm";
    s->sink.self = s;
    s->sink.stages = (uint8_t)(1u << SONAR_STAGE_RAW | (filtered ? 1u << SONAR_STAGE_FOREGROUND : 0u));
    s->sink.beam = lcm_beam;
    s->sink.detections = lcm_detections;
    s->sink.status = lcm_status;
}

static int lcm_tx(void *user, const char *channel, const uint8_t *buf, size_t len)
{
    return lcm_publish((lcm_t *)user, channel, buf, (unsigned)len);
}

int sink_lcm_open(struct sink_lcm *s, const char *url, const char *prefix, int filtered, char *err, size_t errlen)
{
    lcm_t *l = lcm_create(url);
    if (l == NULL) {
        snprintf(err, errlen, "--lcm %s: LCM could not start this provider (for udpm: is there a multicast route?)",
                 url ? url : "(default)");
        return HOST_ERR_IO;
    }
    sink_lcm_init(s, lcm_tx, l, prefix, filtered);
    s->lcm = l;
    return HOST_OK;
}

void sink_lcm_close(struct sink_lcm *s)
{
    if (s->lcm != NULL)
        lcm_destroy((lcm_t *)s->lcm);
    s->lcm = NULL;
}

static int csv_beam(void *self, const struct sonar_record *b)
{
    struct sink_csv *s = self;
    struct csv_meta m = csv_meta_none();
    m.range_m = (double)b->range_m;
    m.gain = b->gain;
    m.sample_period = b->sample_period;
    m.transmit_duration = b->transmit_duration;
    m.transmit_frequency = b->transmit_frequency;
    m.speed_of_sound = (double)b->speed_of_sound;
    m.has_pose = b->has_pose;
    m.north_m = (double)b->north_m;
    m.east_m = (double)b->east_m;
    m.yaw_deg = (double)b->yaw_deg;
    /* floor division: a timestamp before the epoch still gives nsec in 0..999999999 */
    return csv_write(s->f, b->utime / 1000000 - (b->utime % 1000000 < 0),
                     (uint32_t)((b->utime % 1000000 + 1000000) % 1000000) * 1000u, b->angle, b->samples, b->n, &m) == 0
               ? HOST_OK
               : HOST_ERR_IO;
}

void sink_csv_init(struct sink_csv *s, FILE *f, int stage)
{
    memset(s, 0, sizeof(*s));
    s->f = f;
    s->sink.name = "csv";
    s->sink.self = s;
    s->sink.stages = (uint8_t)(1u << stage);
    s->sink.beam = csv_beam;
}

static int report_detections(void *self, const struct sonar_detections *d, const struct sonar_tracker *tk,
                             const struct msg_view *v)
{
    struct sink_report *s = self;
    int r = s->json ? report_json(s->f, d, tk, v) : report_text(s->f, d, tk, v);
    return r == 0 && fflush(s->f) == 0 ? HOST_OK : HOST_ERR_IO;
}

void sink_report_init(struct sink_report *s, FILE *f, int json)
{
    memset(s, 0, sizeof(*s));
    s->f = f;
    s->json = json;
    s->sink.name = json ? "json" : "text";
    s->sink.self = s;
    s->sink.detections = report_detections;
}

int sink_lcm_handle_waiting(void *lcm, int max)
{
    int k;
    for (k = 0; k < max && lcm_handle_timeout((lcm_t *)lcm, 0) > 0; k++)
        ;
    return k;
}
