/* source_pose_lcm.c -- SONAR_POSE (sonar.pose_t) from LCM into the app's poses; O(1) a message. */
#include "source_pose_lcm.h"

#include <lcm/lcm.h>
#include <poll.h>
#include <stdio.h>
#include <string.h>

#include "msg.h"
#include "sinks.h"

static void on_pose(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
{
    struct source_pose_lcm *s = user;
    sonar_pose_t m;
    struct sonar_pose p;
    (void)channel;
    s->received++;
    if (sonar_pose_t_decode(rbuf->data, 0, (int)rbuf->data_size, &m) < 0) {
        s->bad++;
        return;
    }
    msg_pose_in(&m, &p);
    sonar_pose_t_decode_cleanup(&m);
    if (app_pose(s->app, &p, NULL) != HOST_OK)
        s->refused++;
}

int source_pose_lcm_open(struct source_pose_lcm *s, void *lcm, const char *url, const char *prefix, struct app *a,
                         char *err, size_t errlen)
{
    memset(s, 0, sizeof(*s));
    s->app = a;
    snprintf(s->channel, sizeof(s->channel), "%.30sSONAR_POSE", prefix);
    if (url != NULL) {
        if ((s->lcm = lcm_create(url)) == NULL) {
            snprintf(err, errlen, "--pose-lcm %s: LCM could not start this provider", url);
            return HOST_ERR_IO;
        }
        s->owned = 1;
    } else {
        s->lcm = lcm;
    }
    if (s->lcm == NULL || lcm_subscribe((lcm_t *)s->lcm, s->channel, on_pose, s) == NULL) {
        snprintf(err, errlen, "SONAR_POSE: cannot subscribe on %s", url ? url : "sonard's LCM");
        return HOST_ERR_IO;
    }
    return HOST_OK;
}

void source_pose_lcm_poll(struct source_pose_lcm *s)
{
    (void)sink_lcm_handle_waiting(s->lcm, 64);
}

static void pl_start(void *self, struct app *a, int64_t now)
{
    (void)self;
    (void)a;
    (void)now;
}

static int pl_fd(const void *self, short *events)
{
    const struct source_pose_lcm *s = self;
    *events = POLLIN;
    return lcm_get_fileno((lcm_t *)s->lcm);
}

static void pl_ready(void *self, short revents, int64_t now)
{
    (void)revents;
    (void)now;
    source_pose_lcm_poll(self);
}

static int64_t pl_timers(void *self, int64_t now)
{
    (void)self;
    (void)now;
    return INT64_MAX;
}

static void pl_close(void *self)
{
    source_pose_lcm_close(self);
}

static const struct live_io_ops pl_ops = {pl_start, pl_fd, pl_ready, pl_timers, pl_close};

void source_pose_lcm_live(struct source_pose_lcm *s, struct live_aux *out)
{
    out->ops = &pl_ops;
    out->self = s;
}

void source_pose_lcm_close(struct source_pose_lcm *s)
{
    if (s->owned && s->lcm != NULL)
        lcm_destroy((lcm_t *)s->lcm);
    s->lcm = NULL;
    s->owned = 0;
}
