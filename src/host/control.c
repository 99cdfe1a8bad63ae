/* control.c -- sonard --control (control.h): SONAR_CONTROL decoded, checked and rate-limited; a survey recorded while the sonar runs, then checked, written and loaded with no restart; O(1) a command, the survey's O(cells) once at its end. */
#include "control.h"

#include <lcm/lcm.h>
#include <poll.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "bgstore.h"
#include "sinks.h"
#include "sonar_control_t.h"

static int answer(struct control *c, int32_t seq, int result, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

/* The command's answer, for the next SONAR_STATUS and the journal. */
static int answer(struct control *c, int32_t seq, int result, const char *fmt, ...)
{
    va_list ap;
    c->seq = seq > 0 ? (uint32_t)seq : 0u;
    c->result = result;
    va_start(ap, fmt);
    vsnprintf(c->said, sizeof(c->said), fmt, ap);
    va_end(ap);
    if (result == SONAR_CONTROL_REFUSED) {
        c->refused++;
        app_warn(c->app, "control: command %ld refused: %s", (long)seq, c->said);
    } else {
        app_say(c->app, "control: command %ld: %s", (long)seq, c->said);
    }
    return result;
}

/* Why a survey cannot be recorded with these options now, or NULL. */
static const char *cannot_record(const struct control *c, char *why, size_t len)
{
    const struct sonard_options *o = c->opt;
    const char *moving = options_moving(o);
    int mode = sonar_pipeline_running(app_pipeline(c->app))->background.mode;
    if (o->survey == NULL)
        snprintf(why, len, "no survey file is configured: give survey = PATH in sonard's configuration");
    else if (moving != NULL)
        snprintf(why, len, "with %s the sonar moves (the world frame): a survey is of a fixed site", moving);
    else if (mode != SONAR_BACKGROUND_PER_ANGLE && mode != SONAR_BACKGROUND_AUTO)
        snprintf(why, len, "the background is not a per-angle model: a survey goes with --background auto or per-angle");
    else if (o->gain_auto)
        snprintf(why, len, "--gain auto may change the gain during it: a survey is recorded at one gain");
    else
        return NULL;
    return why;
}

int control_command(struct control *c, int32_t seq, int command, int sweeps, int64_t now_us)
{
    char why[200];
    int64_t since = now_us - c->last_us;
    c->received++;
    if (c->last_us != 0 && since >= 0 && since < CONTROL_GAP_US)
        return answer(c, seq, SONAR_CONTROL_REFUSED, "%.2f s after the last command: at most one a second",
                      (double)since * 1e-6);
    c->last_us = now_us;
    if (seq <= 0)
        return answer(c, seq, SONAR_CONTROL_REFUSED, "seq %ld: a command's seq is 1 or more", (long)seq);
    if (command == CONTROL_CANCEL_SURVEY) {
        if (c->rec != SONAR_CONTROL_REC_RECORDING)
            return answer(c, seq, SONAR_CONTROL_REFUSED, "no survey is being recorded");
        app_record_survey(c->app, NULL, 0);
        c->rec = SONAR_CONTROL_REC_CANCELLED;
        snprintf(c->rec_said, sizeof(c->rec_said), "cancelled after %u of %u sweeps: nothing written",
                 (unsigned)c->run->rec.sweeps, (unsigned)c->rec_of);
        return answer(c, seq, SONAR_CONTROL_TAKEN, "survey %s", c->rec_said);
    }
    if (command != CONTROL_RECORD_SURVEY)
        return answer(c, seq, SONAR_CONTROL_REFUSED, "command %d is not one sonard takes (1 record a survey, 2 cancel it)",
                      command);
    if (sweeps < CONTROL_SWEEPS_MIN || sweeps > CONTROL_SWEEPS_MAX)
        return answer(c, seq, SONAR_CONTROL_REFUSED, "sweeps %d: a survey is %d..%d sweeps", sweeps, CONTROL_SWEEPS_MIN,
                      CONTROL_SWEEPS_MAX);
    if (c->rec == SONAR_CONTROL_REC_RECORDING)
        return answer(c, seq, SONAR_CONTROL_REFUSED, "a survey is being recorded (%u of %u sweeps): cancel it first",
                      (unsigned)c->run->rec.sweeps, (unsigned)c->rec_of);
    if (cannot_record(c, why, sizeof(why)) != NULL)
        return answer(c, seq, SONAR_CONTROL_REFUSED, "%s", why);
    survey_run_start(c->run, c->app, 0);
    c->rec = SONAR_CONTROL_REC_RECORDING;
    c->rec_of = (uint32_t)sweeps;
    snprintf(c->rec_said, sizeof(c->rec_said), "recording %d sweeps into %s", sweeps, c->opt->survey);
    return answer(c, seq, SONAR_CONTROL_TAKEN, "survey: %s (the site must be empty and still; the file there now is "
                                               "replaced only if this one is kept)", c->rec_said);
}

void control_tick(struct control *c)
{
    char err[320];
    int r;
    if (c->rec != SONAR_CONTROL_REC_RECORDING ||
        (c->run->rec.why == SONAR_SURVEY_OK && c->run->rec.sweeps < c->rec_of))
        return;
    r = survey_run_finish(c->run, c->app, c->opt, (long)c->rec_of, stderr, err, sizeof(err));
    if (r == HOST_OK)
        r = bgstore_load(c->app, "survey", c->opt->survey, err, sizeof(err));
    if (r == HOST_OK) {
        c->rec = SONAR_CONTROL_REC_WRITTEN;
        snprintf(c->rec_said, sizeof(c->rec_said), "written to %s after %u sweeps: in use from sweep %u", c->opt->survey,
                 (unsigned)c->run->rec.sweeps, (unsigned)app_sweeps(c->app) + 1u);
        app_say(c->app, "control: survey %s", c->rec_said);
        return;
    }
    c->rec = r == HOST_ERR_REFUSED ? SONAR_CONTROL_REC_REFUSED : SONAR_CONTROL_REC_FAILED;
    snprintf(c->rec_said, sizeof(c->rec_said), "%s", err);
    app_warn(c->app, "control: %s", err);
}

void control_close(struct control *c)
{
    if (c->rec != SONAR_CONTROL_REC_RECORDING)
        return;
    app_record_survey(c->app, NULL, 0);
    c->rec = SONAR_CONTROL_REC_REFUSED;
    snprintf(c->rec_said, sizeof(c->rec_said), "sonard stopped after %u of %u sweeps: nothing written",
             (unsigned)c->run->rec.sweeps, (unsigned)c->rec_of);
    app_warn(c->app, "control: survey %s", c->rec_said);
}

static void on_control(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    struct control *c = user;
    sonar_control_t m;
    (void)channel;
    if (rbuf->data_size > 64 || sonar_control_t_decode(rbuf->data, 0, (int)rbuf->data_size, &m) < 0) {
        c->received++;
        c->bad++;
        answer(c, 0, SONAR_CONTROL_REFUSED, "a SONAR_CONTROL message of %u bytes that is not a sonar.control_t: ignored",
               (unsigned)rbuf->data_size);
        return;
    }
    control_command(c, m.seq, m.command, m.sweeps, app_mono_us(c->app));
    sonar_control_t_decode_cleanup(&m);
    control_tick(c);
}

/* The control's part of a status: the last answer, the recording's progress. */
static void fill(const void *self, struct sonar_status *s)
{
    const struct control *c = self;
    s->control.on = 1;
    s->control.seq = c->seq;
    s->control.result = c->result;
    s->control.said = c->said;
    s->control.rec = c->rec;
    s->control.rec_sweeps = c->rec == SONAR_CONTROL_REC_NONE ? 0u : c->run->rec.sweeps;
    s->control.rec_of = c->rec_of;
    s->control.rec_said = c->rec_said;
}

int control_open(struct control *c, void *lcm, const char *prefix, struct app *a, const struct sonard_options *o,
                 struct survey_run *run, char *err, size_t errlen)
{
    memset(c, 0, sizeof(*c));
    c->lcm = lcm;
    c->app = a;
    c->opt = o;
    c->run = run;
    snprintf(c->channel, sizeof(c->channel), "%.30sSONAR_CONTROL", prefix);
    c->sink.name = "control";
    c->sink.self = c;
    c->sink.fill = fill;
    if (lcm == NULL || lcm_subscribe((lcm_t *)lcm, c->channel, on_control, c) == NULL) {
        snprintf(err, errlen, "--control: cannot subscribe to %s on sonard's LCM", c->channel);
        return HOST_ERR_IO;
    }
    if (app_add_sink(a, &c->sink) != HOST_OK) {
        snprintf(err, errlen, "--control: the app's sinks are full");
        return HOST_ERR_CONFIG;
    }
    return HOST_OK;
}

static void ct_start(void *self, struct app *a, int64_t now)
{
    (void)self;
    (void)a;
    (void)now;
}

static int ct_fd(const void *self, short *events)
{
    const struct control *c = self;
    *events = POLLIN;
    return lcm_get_fileno((lcm_t *)c->lcm);
}

static void ct_ready(void *self, short revents, int64_t now)
{
    const struct control *c = self;
    (void)revents;
    (void)now;
    (void)sink_lcm_handle_waiting(c->lcm, 16); /* a flood is also refused by the rate limit */
}

/* Four times a second: a recording that has its sweeps (or was refused) is finished within a quarter second. */
static int64_t ct_timers(void *self, int64_t now)
{
    control_tick(self);
    return now + 250000;
}

static void ct_close(void *self)
{
    control_close(self);
}

static const struct live_io_ops ct_ops = {ct_start, ct_fd, ct_ready, ct_timers, ct_close};

void control_live(struct control *c, struct live_aux *out)
{
    out->ops = &ct_ops;
    out->self = c;
}
