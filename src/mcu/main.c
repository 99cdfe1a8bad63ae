/* main.c -- the co-processor firmware: the core's Ping360 driver and pipeline on UART0, co-processor frames of LCM messages on UART1 (docs/coprocessor.md); no heap, no OS; RAM: struct fw (the pipeline, a frame, the device) and the background in the board's large bank, as `make firmware` prints them bank by bank. */
#include <string.h>

#include "board.h"
#include "msg.h"
#include "sonar/cpframe.h"
#include "sonar/device.h"
#include "sonar/geometry.h"
#include "sonar/pipeline.h"
#include "sonar/status.h"

#define STATUS_US 1000000

struct fw {
    struct sonar_device dev;         /* the Ping360 on UART0 */
    struct sonar_cpf_parser host;    /* UART1 framing */
    struct sonar_ping360_config dcfg;
    struct sonar_pipeline_config pcfg, next; /* running; a configuration being checked */
    struct sonar_pipeline pipe;
    struct sonar_background *bg;     /* the pipeline's, in the board's large bank (BOARD_LARGE) */
    struct sonar_activity *act;      /* the pipeline's tracks' echo windows, in the large bank too */
    struct sonar_clutter *clutter;   /* the site's clutter map the tracks are judged against, in the large bank too */
    uint16_t beam_every;             /* forward every Nth raw beam; 0 = none */
    uint32_t beams, sweeps, frames_dropped, config_errors, rejected;
    uint8_t long_said;               /* a beam longer than the build holds was said to the host, this configuration */
    int64_t next_status;
    /* One frame buffer: messages are encoded at its payload offset and framed in place (4 KB less RAM). */
    uint8_t out[SONAR_CPF_MAX_PAYLOAD + SONAR_CPF_OVERHEAD];
};

#define MSG(f) ((f)->out + SONAR_CPF_HEADER)
#define MSG_CAP ((int)SONAR_CPF_MAX_PAYLOAD)

static int sonar_send(void *user, const uint8_t *buf, size_t len)
{
    (void)user;
    /* A request that does not fit is not sent: the driver's timeout sends it again. */
    if (board_uart_room(BOARD_UART_SONAR) < len)
        return SONAR_ERR_SPACE;
    return board_uart_write(BOARD_UART_SONAR, buf, len) == len ? SONAR_OK : SONAR_ERR_SPACE;
}

/* A frame to the host, whole or not at all: a host that stops reading costs frames, never the loop. */
static void host_send(struct fw *f, uint8_t channel, int len)
{
    int n;
    if (len < 0 || (n = sonar_cpf_encode(f->out, sizeof(f->out), channel, MSG(f), (uint16_t)len)) < 0 ||
        board_uart_room(BOARD_UART_HOST) < (size_t)n) {
        f->frames_dropped++;
        return;
    }
    (void)board_uart_write(BOARD_UART_HOST, f->out, (size_t)n);
}

static void reply(struct fw *f, const char *what, const char *why)
{
    size_t a = strlen(what), b = why ? strlen(why) : 0;
    if (a + b + 2 > (size_t)MSG_CAP)
        return;
    memcpy(MSG(f), what, a);
    if (why != NULL) {
        MSG(f)[a] = ':';
        MSG(f)[a + 1] = ' ';
        memcpy(MSG(f) + a + 2, why, b);
        a += b + 2;
    }
    host_send(f, SONAR_CPF_REPLY, (int)a);
}

static void on_sweep(void *user, const struct sonar_detections *d)
{
    struct fw *f = user;
    sonar_detection_t det[SONAR_MAX_CLUSTERS];
    sonar_detections_t m;
    f->sweeps++;
    msg_detections(d, NULL, det, &m); /* the vehicle's pose is the host's */
    host_send(f, SONAR_CPF_DETECTIONS, sonar_detections_t_encode(MSG(f), 0, MSG_CAP, &m));
}

/* Once a configuration: the sonar sent a beam of n samples, more than this build holds; none such is processed. */
static void say_too_long(struct fw *f, uint32_t n)
{
    static const char head[] = "beam: ", tail[] = " samples from the sonar, more than this board's build holds (" SONAR_STR(
        SONAR_MAX_SAMPLES) ", SONAR_MAX_SAMPLES): not processed";
    char why[sizeof(head) + 10 + sizeof(tail)], digits[10];
    size_t k = 0, d = 0;
    if (f->long_said)
        return;
    f->long_said = 1;
    do
        digits[d++] = (char)('0' + n % 10u);
    while ((n /= 10u) != 0 && d < sizeof(digits));
    memcpy(why, head, sizeof(head) - 1);
    k = sizeof(head) - 1;
    while (d > 0)
        why[k++] = digits[--d];
    memcpy(why + k, tail, sizeof(tail));
    reply(f, "warning", why);
}

static void beam_in(struct fw *f, struct sonar_record *r, int64_t now)
{
    struct sonar_beam b;
    r->utime = now;
    f->beams++;
    if (f->beam_every > 0 && f->beams % f->beam_every == 0) {
        sonar_beam_t m;
        msg_beam(r, &m); /* no pose: the vehicle's is the host's, which fills it in when it records the beam */
        host_send(f, SONAR_CPF_BEAM, sonar_beam_t_encode(MSG(f), 0, MSG_CAP, &m));
    }
    sonar_device_beam(r, &b);
    if (r->n > SONAR_MAX_SAMPLES)
        say_too_long(f, r->n); /* a sonar that answers with more than was asked: never cut to fit */
    if (sonar_pipeline_push(&f->pipe, &b) != SONAR_OK)
        f->rejected++; /* bad geometry from the device: not processed, counted in status */
}

static void on_event(struct fw *f, struct sonar_device_event *ev, int64_t now)
{
    /* A LINK_LOST needs nothing here: the device keeps when to probe again (sonar_device_reconnect_at). */
    if (ev->kind == SONAR_P360_EV_BEAM)
        beam_in(f, &ev->beam, now);
}

/* Opens the Ping360 again (a UART cannot be reopened: the probe is the reconnect). One that cannot go out is
   tried again when the device's policy says (sonar_device_reconnect_at). */
static void probe(struct fw *f, int64_t now)
{
    int r = sonar_device_up(&f->dev, now);
    (void)r;
}

static void status(struct fw *f, int64_t now)
{
    struct sonar_status st;
    sonar_status_t m;
    memset(&st, 0, sizeof(st));
    st.utime = now;
    st.link_state = sonar_device_state(&f->dev);
    st.link = "coprocessor:uart0";
    sonar_status_fill(&st, &f->dev, &f->pipe);
    st.sweeps = f->sweeps;
    st.beams_rejected = f->rejected;
    st.stack_used = board_stack_used();
    st.coproc.rx_crc_errors = f->host.counters.crc_errors;
    st.coproc.tx_dropped = f->frames_dropped;
    st.coproc.config_refused = f->config_errors;
    msg_status(&st, &m);
    host_send(f, SONAR_CPF_STATUS, sonar_status_t_encode(MSG(f), 0, MSG_CAP, &m));
}

static const struct sonar_ping360_io io = {sonar_send, NULL, NULL, NULL, NULL};

/*
 * NULL when the beams asked fit this build's grid; a smaller board's build says which setting does not, by name.
 * Samples beyond SONAR_MAX_SAMPLES cannot be held; steps finer than its angle cells (SONAR_MAX_ANGLES across a turn)
 * would share a cell of the background between two beams, which the host's grid keeps apart: a different answer.
 */
static const char *fits_build(const struct sonar_ping360_config *d)
{
#if SONAR_MAX_SAMPLES < SONAR_DEVICE_MAX_SAMPLES
    if (d->samples == 0 || d->samples > SONAR_MAX_SAMPLES)
        return "samples: 200.." SONAR_STR(SONAR_MAX_SAMPLES) " on this board's build (SONAR_MAX_SAMPLES; 0, the most the range allows, may be more)";
#endif
#if SONAR_MAX_ANGLES < SONAR_GRAD_TURN
    if ((unsigned)d->step * SONAR_MAX_ANGLES < SONAR_GRAD_TURN)
        return "step: at least 400 gradians / " SONAR_STR(SONAR_MAX_ANGLES) " angle cells on this board's build "
               "(SONAR_MAX_ANGLES: a finer step would put two beams in one cell)";
#endif
    (void)d;
    return NULL;
}

/* The host's sonar.config_t: checked whole with the core's checks, applied, or refused by name. */
static void configure(struct fw *f, const uint8_t *p, uint16_t len, int64_t now)
{
    struct sonar_ping360_config d;
    struct sonar_pipeline_config *next = &f->next;
    sonar_config_t c;
    uint16_t beam_every;
    const char *why;
    if (sonar_config_t_decode(p, 0, len, &c) < 0) {
        f->config_errors++;
        reply(f, "error", "config: not a sonar.config_t");
        return;
    }
    *next = f->pcfg;
    msg_config_in(&c, BOARD_SONAR_BAUD, &d, next, &beam_every);
    /* Nothing changes unless all of it is valid, and fits the grid this image was built for. */
    if ((why = sonar_ping360_config_check(&d)) != NULL || (why = sonar_pipeline_config_check(next)) != NULL ||
        (why = fits_build(&d)) != NULL) {
        f->config_errors++;
        reply(f, "error", why);
        return;
    }
    if (memcmp(&d, &f->dcfg, sizeof(d)) != 0) {
        /* New acquisition settings: the counters carry on, the probe starts again (or when the device says). */
        int r = sonar_device_reconfigure(&f->dev, &d, now);
        if (r == SONAR_ERR_ARG || r == SONAR_ERR_RANGE) {
            f->config_errors++;
            reply(f, "error", "range_m, samples: no sample period of 80..40000 ticks gives them");
            return;
        }
        f->dcfg = d;
    }
    /* A configuration restarts processing: the open sweep is dropped, the background relearns and
     * sweeps count from 0, so everything after the reply comes from the new settings. */
    f->pcfg = *next;
    if (sonar_pipeline_init(&f->pipe, f->bg, &f->pcfg) != SONAR_OK || sonar_activity_init(f->act) != SONAR_OK) {
        f->config_errors++;
        reply(f, "error", "pipeline: rejected");
        return;
    }
    sonar_pipeline_set_activity(&f->pipe, f->act);
    sonar_clutter_init(f->clutter); /* learnt afresh, as the host's is when sonard starts */
    sonar_pipeline_set_clutter(&f->pipe, f->clutter);
    f->long_said = 0;
    f->sweeps = 0;
    f->beams = 0;
    f->beam_every = beam_every;
    reply(f, "ok", NULL);
}

static void host_in(struct fw *f, int64_t now)
{
    uint8_t buf[256];
    size_t n;
    while ((n = board_uart_read(BOARD_UART_HOST, buf, sizeof(buf))) > 0) {
        const uint8_t *in = buf;
        struct sonar_cpf_frame fr;
        while (sonar_cpf_next(&f->host, &in, &n, &fr) == 1)
            if (fr.channel == SONAR_CPF_CONFIG)
                configure(f, fr.payload, fr.len, now);
    }
}

static void sonar_in(struct fw *f, int64_t now)
{
    uint8_t buf[256];
    size_t n;
    while ((n = board_uart_read(BOARD_UART_SONAR, buf, sizeof(buf))) > 0) {
        const uint8_t *in = buf;
        struct sonar_device_event ev;
        while (sonar_device_bytes(&f->dev, &in, &n, now, &ev) == 1)
            on_event(f, &ev, now);
    }
}

int main(void)
{
    static struct fw f;                          /* main's own, not a shared global */
    static struct sonar_background bg BOARD_LARGE; /* sizeof(struct sonar_background): docs/sizes.md */
    static struct sonar_activity act BOARD_LARGE;  /* the tracks' echo windows (activity.h) */
    static struct sonar_clutter clutter BOARD_LARGE; /* the site's clutter map (clutter.h) */
    int64_t now;
    board_init();
    memset(&f, 0, sizeof(f));
    f.bg = &bg;
    sonar_cpf_parser_init(&f.host);
    sonar_pipeline_defaults(&f.pcfg);
    f.pcfg.on_sweep = on_sweep;
    f.pcfg.user = &f;
    /* Until the host configures it: Ping Viewer's defaults, 2 m, full turns, stepping. */
    f.dcfg.range_m = 2.0f;
    f.dcfg.speed_of_sound = 1500.0f;
    f.dcfg.frequency = 750;
    f.dcfg.step = 1;
    f.dcfg.full_circle = 1;
    f.dcfg.baud = BOARD_SONAR_BAUD;
    if (sonar_pipeline_init(&f.pipe, f.bg, &f.pcfg) != SONAR_OK || sonar_device_init(&f.dev, &f.dcfg, &io) != SONAR_OK ||
        sonar_activity_init(&act) != SONAR_OK)
        return 1;
    f.act = &act;
    sonar_pipeline_set_activity(&f.pipe, f.act);
    f.clutter = &clutter;
    sonar_clutter_init(f.clutter);
    sonar_pipeline_set_clutter(&f.pipe, f.clutter);
    now = board_micros();
    probe(&f, now);
    f.next_status = now + STATUS_US;
    for (;;) {
        struct sonar_device_event ev;
        now = board_micros();
        sonar_in(&f, now);
        host_in(&f, now);
        {
            int64_t at = sonar_device_reconnect_at(&f.dev);
            if (at != 0 && now >= at)
                probe(&f, now);
        }
        if (sonar_device_poll(&f.dev, now, &ev) == 1)
            on_event(&f, &ev, now);
        if (now >= f.next_status) {
            status(&f, now);
            f.next_status = now + STATUS_US;
        }
        board_uart_pump();
        board_idle();
    }
}
