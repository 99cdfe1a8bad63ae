/* live.c -- sonard's live daemon: one poll loop over the sonar link, a signalfd and timers; beams flow through the pipeline as they arrive; LCM out. */
#define _GNU_SOURCE
#include "live.h"

#include <errno.h>
#include <inttypes.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/signalfd.h>
#include <time.h>
#include <unistd.h>

#include "csv.h"
#include "link.h"
#include "publish.h"
#include "report.h"
#include "sonar/geometry.h"
#include "sonar/ping360.h"
#include "sonar/pipeline.h"

#define PROC_RING 1024
#define LINK_RETRY_US 1000000

enum stop_reason { RUNNING = 0, STOP_SIGNAL, STOP_SWEEPS };

struct live {
    struct sonard_options *o;
    struct sonar_pipeline pipe;
    struct sonar_ping360 drv;
    struct sonar_ping_parser parser;
    struct link link;
    struct publisher pub;
    int have_pub;
    FILE *csv;
    int sigfd;
    int stop;            /* enum stop_reason */
    int done;
    int64_t reconnect_at;
    int64_t next_status;
    int64_t stop_deadline;
    int64_t sweep_t0;
    float last_sweep_s;
    unsigned long sweeps;
    unsigned long write_errors;
    float proc_us[PROC_RING];
    float sorted[PROC_RING]; /* scratch for the percentiles */
    unsigned long nproc;
    struct sonar_ping360_data cur; /* the beam being processed, for the filtered publish */
    int64_t cur_utime;
    char desc[160];
};

static int64_t mono_us(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (int64_t)t.tv_sec * 1000000 + t.tv_nsec / 1000;
}

static double mono_ns(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec * 1e9 + (double)t.tv_nsec;
}

static int64_t wall_us(void)
{
    struct timespec t;
    clock_gettime(CLOCK_REALTIME, &t);
    return (int64_t)t.tv_sec * 1000000 + t.tv_nsec / 1000;
}

static void say(const struct live *L, const char *fmt, const char *a, const char *b)
{
    if (!L->o->quiet) {
        fprintf(stderr, "sonard: ");
        fprintf(stderr, fmt, a, b);
        fputc('\n', stderr);
    }
}

static int io_send(void *user, const uint8_t *buf, size_t len)
{
    struct live *L = user;
    return link_write(&L->link, buf, len);
}

static void io_break(void *user)
{
    struct live *L = user;
    link_line_break(&L->link, mono_us());
}

static float range_of(const struct live *L, const struct sonar_ping360_data *d)
{
    return (float)sonar_geometry_range_m(d->sample_period, d->number_of_samples ? d->data_length : 0,
                                         L->o->speed_of_sound);
}

static void on_stage(void *user, int stage, const struct sonar_beam *b)
{
    struct live *L = user;
    struct publisher_beam pb;
    if (!L->have_pub || !L->o->publish_filtered || stage != SONAR_STAGE_FOREGROUND)
        return;
    pb.utime = b->utime;
    pb.angle = b->angle;
    pb.gain = L->cur.gain;
    pb.sample_period = L->cur.sample_period;
    pb.transmit_duration = L->cur.transmit_duration;
    pb.transmit_frequency = L->cur.transmit_frequency;
    pb.n = b->n;
    pb.speed_of_sound = (float)L->o->speed_of_sound;
    pb.range_m = b->range_m;
    pb.stage = stage;
    pb.samples = b->samples;
    (void)publish_beam(&L->pub, &pb, 1);
}

static void on_sweep(void *user, const struct sonar_detections *d)
{
    struct live *L = user;
    int64_t now = mono_us();
    L->sweeps++;
    if (L->sweep_t0 != 0)
        L->last_sweep_s = (float)((double)(now - L->sweep_t0) * 1e-6);
    L->sweep_t0 = now;
    if (L->have_pub)
        (void)publish_detections(&L->pub, d);
    if (L->o->json) {
        report_json(stdout, d);
        fflush(stdout);
    } else if (!L->o->quiet) {
        report_text(stdout, d);
        fflush(stdout);
    }
    if (L->o->sweeps > 0 && L->sweeps >= (unsigned long)L->o->sweeps && L->stop == RUNNING)
        L->stop = STOP_SWEEPS;
}

static void beam_in(struct live *L, const struct sonar_ping360_data *d)
{
    struct sonar_beam b;
    double t0;
    float range = range_of(L, d);
    L->cur = *d;
    L->cur_utime = wall_us();
    if (L->have_pub) {
        struct publisher_beam pb;
        pb.utime = L->cur_utime;
        pb.angle = d->angle;
        pb.gain = d->gain;
        pb.sample_period = d->sample_period;
        pb.transmit_duration = d->transmit_duration;
        pb.transmit_frequency = d->transmit_frequency;
        pb.n = d->data_length;
        pb.speed_of_sound = (float)L->o->speed_of_sound;
        pb.range_m = range;
        pb.stage = SONAR_STAGE_RAW;
        pb.samples = d->data;
        (void)publish_beam(&L->pub, &pb, 0);
    }
    if (L->csv != NULL) {
        struct csv_meta m = csv_meta_none();
        m.range_m = range;
        m.gain = d->gain;
        m.sample_period = d->sample_period;
        m.transmit_duration = d->transmit_duration;
        m.transmit_frequency = d->transmit_frequency;
        m.speed_of_sound = L->o->speed_of_sound;
        if (csv_write(L->csv, L->cur_utime / 1000000, (uint32_t)(L->cur_utime % 1000000) * 1000u, d->angle, d->data,
                      d->data_length, &m) != 0)
            L->write_errors++;
    }
    if (d->data_length == 0 || d->data_length > SONAR_MAX_SAMPLES || !(range > 0.0f))
        return;
    b.utime = L->cur_utime;
    b.angle = d->angle;
    b.n = d->data_length;
    b.range_m = range;
    b.samples = d->data;
    t0 = mono_ns();
    if (sonar_pipeline_push(&L->pipe, &b) != SONAR_OK)
        return;
    L->proc_us[L->nproc++ % PROC_RING] = (float)((mono_ns() - t0) * 1e-3);
}

static int cmpf(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return x < y ? -1 : x > y;
}

static void status(struct live *L, int64_t now)
{
    float *sorted = L->sorted;
    struct publisher_status s;
    unsigned n = (unsigned)(L->nproc < PROC_RING ? L->nproc : PROC_RING);
    memcpy(sorted, L->proc_us, n * sizeof(float));
    qsort(sorted, n, sizeof(float), cmpf);
    memset(&s, 0, sizeof(s));
    s.utime = wall_us();
    s.link_state = (int8_t)(L->link.fd >= 0 && L->link.connecting ? 1 : L->drv.state);
    s.link = L->desc;
    s.fw[0] = L->drv.info.fw_major;
    s.fw[1] = L->drv.info.fw_minor;
    s.fw[2] = L->drv.info.fw_patch;
    s.frames = L->parser.counters.frames;
    s.checksum_errors = L->parser.counters.checksum_errors;
    s.resyncs = L->parser.counters.resyncs;
    s.timeouts = L->drv.counters.timeouts;
    s.retries = L->drv.counters.retries;
    s.nacks = L->drv.counters.nacks;
    s.reconnects = L->drv.counters.reconnects;
    s.beams = L->drv.counters.beams;
    s.sweeps = (int64_t)L->sweeps;
    s.last_sweep_s = L->last_sweep_s;
    s.beam_us_p50 = n ? sorted[n / 2] : 0.0f;
    s.beam_us_p99 = n ? sorted[(n * 99) / 100] : 0.0f;
    if (L->have_pub)
        (void)publish_status(&L->pub, &s);
    (void)now;
}

static void summary(const struct live *L)
{
    if (L->o->quiet)
        return;
    fprintf(stderr,
            "sonard: status frames %" PRIu32 " checksum_errors %" PRIu32 " resyncs %" PRIu32 " timeouts %" PRIu32
            " retries %" PRIu32 " nacks %" PRIu32 " reconnects %" PRIu32 " stale %" PRIu32 " beams %" PRIu32 " sweeps %lu\n",
            L->parser.counters.frames, L->parser.counters.checksum_errors, L->parser.counters.resyncs,
            L->drv.counters.timeouts, L->drv.counters.retries, L->drv.counters.nacks, L->drv.counters.reconnects,
            L->drv.counters.stale, L->drv.counters.beams, L->sweeps);
}

/* Fresh framing for a new connection; the counters carry on. */
static void reset_parser(struct live *L)
{
    struct sonar_ping_counters c = L->parser.counters;
    if (sonar_ping_parser_init(&L->parser, 0) == SONAR_OK) /* cannot fail with these arguments */
        L->parser.counters = c;
}

static void drop_link(struct live *L, int64_t now, uint32_t backoff_us, const char *why)
{
    char buf[32];
    int was_probing = L->drv.state == SONAR_P360_PROBING || L->drv.state == SONAR_P360_DOWN;
    link_close(&L->link);
    reset_parser(L);
    if (L->stop != RUNNING) {
        L->done = 1;
        return;
    }
    /* Serial auto-baud: a silent probe means the wrong rate; try the next at once. */
    if (was_probing && L->link.autobaud && link_next_baud(&L->link) == 0) {
        L->reconnect_at = now;
        snprintf(buf, sizeof(buf), "%ld", L->link.baud);
        say(L, "no answer; trying %s baud%s", buf, "");
        return;
    }
    L->reconnect_at = now + backoff_us;
    snprintf(buf, sizeof(buf), "%.2f", backoff_us * 1e-6);
    say(L, "link lost (%s); reconnecting in %s s", why, buf);
}

static void try_open(struct live *L, int64_t now)
{
    char err[256];
    L->reconnect_at = INT64_MAX;
    if (link_open(&L->link, now, err, sizeof(err)) != 0) {
        L->reconnect_at = now + LINK_RETRY_US;
        say(L, "%s; retrying in 1 s%s", err, "");
        return;
    }
    link_describe(&L->link, L->desc, sizeof(L->desc));
    if (!L->link.connecting && sonar_ping360_connected(&L->drv, now) != SONAR_OK)
        drop_link(L, now, LINK_RETRY_US, "write failed");
}

static void on_event(struct live *L, const struct sonar_ping360_event *ev, int64_t now)
{
    char fw[32];
    switch (ev->kind) {
    case SONAR_P360_EV_READY:
        snprintf(fw, sizeof(fw), "%u.%u.%u", L->drv.info.fw_major, L->drv.info.fw_minor, L->drv.info.fw_patch);
        say(L, "Ping360 firmware %s on %s", fw, L->desc);
        say(L, "scanning (%s)%s", L->drv.state == SONAR_P360_AUTO ? "auto_transmit" : "stepping", "");
        break;
    case SONAR_P360_EV_BEAM:
        /* After the sweeps asked for, beams still in flight are not a new sweep. */
        if (L->stop != STOP_SWEEPS)
            beam_in(L, &ev->data);
        break;
    case SONAR_P360_EV_LINK_LOST:
        drop_link(L, now, ev->backoff_us, "no reply");
        break;
    case SONAR_P360_EV_STOPPED:
        L->done = 1;
        break;
    default:
        break;
    }
}

static void read_link(struct live *L, int64_t now)
{
    uint8_t buf[4096];
    const int was_running = L->stop == RUNNING;
    int reads;
    /*
     * A fast device (or sonar-feed --pace fast on loopback) answers each request before the next
     * read, so this could read for ever: bound it, and leave as soon as a stop becomes due, so
     * signals, timers and --sweeps are served by the poll loop (which then sends motor_off).
     */
    for (reads = 0; reads < 16 && !(was_running && L->stop != RUNNING); reads++) {
        ssize_t n = link_read(&L->link, buf, sizeof(buf));
        const uint8_t *in = buf;
        size_t len;
        struct sonar_ping_frame f;
        if (n < 0) {
            sonar_ping360_link_lost(&L->drv, now);
            drop_link(L, now, L->drv.backoff_us, "closed");
            return;
        }
        if (n == 0)
            return;
        len = (size_t)n;
        while (sonar_ping_parser_next(&L->parser, &in, &len, &f) == 1) {
            struct sonar_ping360_event ev;
            if (sonar_ping360_handle(&L->drv, &f, mono_us(), &ev) != SONAR_OK)
                ev.kind = SONAR_P360_EV_NONE; /* a failed send: the request's timeout retries it */
            on_event(L, &ev, now);
            if (L->link.fd < 0 || L->done)
                return;
        }
    }
}

static void begin_stop(struct live *L, int64_t now)
{
    say(L, "stopping: motor_off%s%s", "", "");
    L->stop_deadline = now + 1500000;
    if (sonar_ping360_stop(&L->drv, now) != SONAR_OK || L->drv.state == SONAR_P360_STOPPED)
        L->done = 1;
}

int live_run(struct sonard_options *o)
{
    static struct live L; /* ~0.6 MB: the pipeline's state */
    struct sonar_ping360_io io;
    sigset_t mask;
    char err[256];
    int stop_started = 0;
    memset(&L, 0, sizeof(L));
    L.o = o;
    o->pipeline.on_beam = on_stage;
    o->pipeline.on_sweep = on_sweep;
    o->pipeline.user = &L;
    if (link_parse(&L.link, o->sonar, o->baud, err, sizeof(err)) != 0) {
        fprintf(stderr, "sonard: %s\n", err);
        return 2;
    }
    o->device.baud = L.link.kind == LINK_SERIAL ? (uint32_t)L.link.baud : 0;
    io.send = io_send;
    io.line_break = io_break;
    io.user = &L;
    if (sonar_ping360_init(&L.drv, &o->device, &io) != SONAR_OK) {
        fprintf(stderr, "sonard: --range %.1f m with --samples %u cannot be set on a Ping360 (sample period outside "
                        "80..40000 ticks of 25 ns)\n", (double)o->device.range_m, o->device.samples);
        return 2;
    }
    if (sonar_pipeline_init(&L.pipe, &o->pipeline) != SONAR_OK || sonar_ping_parser_init(&L.parser, 0) != SONAR_OK) {
        fprintf(stderr, "sonard: the pipeline configuration is invalid\n");
        return 2;
    }
    if (!o->no_lcm) {
        if (publisher_open(&L.pub, o->lcm_url, o->channel_prefix, err, sizeof(err)) != 0) {
            fprintf(stderr, "sonard: %s\n", err);
            return 2;
        }
        L.have_pub = 1;
    }
    if (o->csv_out != NULL && (L.csv = fopen(o->csv_out, "w")) == NULL) {
        fprintf(stderr, "sonard: --csv-out %s: %s\n", o->csv_out, strerror(errno));
        return 2;
    }
    /* Signals arrive as readable bytes on a descriptor, so the loop never runs code in a handler. */
    sigemptyset(&mask);
    sigaddset(&mask, SIGINT);
    sigaddset(&mask, SIGTERM);
    sigprocmask(SIG_BLOCK, &mask, NULL);
    signal(SIGPIPE, SIG_IGN);
    L.sigfd = signalfd(-1, &mask, SFD_NONBLOCK | SFD_CLOEXEC);
    if (L.sigfd < 0) {
        fprintf(stderr, "sonard: signalfd: %s\n", strerror(errno));
        return 2;
    }
    link_describe(&L.link, L.desc, sizeof(L.desc));
    L.next_status = mono_us() + 1000000;
    L.stop_deadline = INT64_MAX;
    try_open(&L, mono_us());
    while (!L.done) {
        struct pollfd pfd[2];
        int64_t now = mono_us(), wake = L.next_status, t;
        struct sonar_ping360_event ev;
        int np = 1, ms;
        if (L.stop != RUNNING && !stop_started) {
            stop_started = 1;
            begin_stop(&L, now);
            continue;
        }
        if (now >= L.stop_deadline)
            break;
        if (L.link.fd < 0 && now >= L.reconnect_at) {
            if (L.stop != RUNNING)
                break;
            try_open(&L, now);
            continue;
        }
        if ((t = sonar_ping360_deadline(&L.drv)) < wake)
            wake = t;
        if (L.reconnect_at < wake)
            wake = L.reconnect_at;
        if (L.stop_deadline < wake)
            wake = L.stop_deadline;
        if ((t = link_timers(&L.link, now)) < wake)
            wake = t;
        ms = wake <= now ? 0 : (wake - now) / 1000 + 1 > 1000 ? 1000 : (int)((wake - now) / 1000 + 1);
        pfd[0].fd = L.sigfd;
        pfd[0].events = POLLIN;
        if (L.link.fd >= 0) {
            pfd[1].fd = L.link.fd;
            pfd[1].events = (short)(L.link.connecting ? POLLOUT : POLLIN);
            np = 2;
        }
        if (poll(pfd, (nfds_t)np, ms) < 0 && errno != EINTR)
            break;
        now = mono_us();
        if (pfd[0].revents & POLLIN) {
            struct signalfd_siginfo si;
            while (read(L.sigfd, &si, sizeof(si)) == (ssize_t)sizeof(si))
                if (L.stop == RUNNING)
                    L.stop = STOP_SIGNAL;
        }
        if (np == 2 && L.link.connecting && (pfd[1].revents & (POLLOUT | POLLERR | POLLHUP))) {
            if (link_finish_connect(&L.link, err, sizeof(err)) != 0) {
                link_close(&L.link);
                L.reconnect_at = now + LINK_RETRY_US;
                say(&L, "%s; retrying in 1 s%s", err, "");
            } else if (sonar_ping360_connected(&L.drv, now) != SONAR_OK) {
                drop_link(&L, now, LINK_RETRY_US, "write failed");
            }
        } else if (np == 2 && (pfd[1].revents & POLLIN)) {
            read_link(&L, now);
        } else if (np == 2 && (pfd[1].revents & (POLLERR | POLLHUP | POLLNVAL))) {
            /* the serial adapter was unplugged, or the peer hung up, with nothing left to read */
            sonar_ping360_link_lost(&L.drv, now);
            drop_link(&L, now, L.drv.backoff_us, "hung up");
        }
        if (L.done)
            break;
        now = mono_us();
        if (L.link.fd >= 0 && !L.link.connecting) {
            if (sonar_ping360_poll(&L.drv, now, &ev) != SONAR_OK)
                ev.kind = SONAR_P360_EV_NONE;
            on_event(&L, &ev, now);
        }
        if (now >= L.next_status) {
            status(&L, now);
            L.next_status = now + 1000000;
        }
    }
    /* An interrupted sweep is still worth publishing; a --sweeps run already has all it asked for. */
    if (L.stop == STOP_SIGNAL && sonar_pipeline_finish(&L.pipe) != SONAR_OK)
        fprintf(stderr, "sonard: finishing the last sweep failed\n");
    status(&L, mono_us());
    summary(&L);
    if (L.csv != NULL && fclose(L.csv) != 0)
        L.write_errors++;
    if (L.write_errors)
        fprintf(stderr, "sonard: --csv-out %s: %lu rows could not be written\n", o->csv_out, L.write_errors);
    link_close(&L.link);
    if (L.have_pub) {
        if (L.pub.errors)
            fprintf(stderr, "sonard: %lu LCM messages could not be published\n", L.pub.errors);
        publisher_close(&L.pub);
    }
    close(L.sigfd);
    return L.write_errors ? 1 : 0;
}
