/* test_ping360.c -- the Ping360 driver on a fake clock and transport: probe, angle sequences, timeouts, retries, NACKs, reconnect, auto mode, stop. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "sonar/ping360.h"

/* The fake transport decodes what the driver sends. */
struct wire {
    uint16_t id[64];
    uint16_t angle[64]; /* for transducer */
    int n;
    int breaks;
};

static struct wire w;
static struct sonar_ping360 drv;
static uint8_t payload[64 + 1300];

static int fake_send(void *user, const uint8_t *buf, size_t len)
{
    struct wire *x = user;
    struct sonar_ping_parser p;
    struct sonar_ping_frame f;
    assert_int_equal(sonar_ping_parser_init(&p, 0), SONAR_OK);
    assert_int_equal(sonar_ping_parser_next(&p, &buf, &len, &f), 1);
    x->id[x->n % 64] = f.id;
    x->angle[x->n % 64] = (uint16_t)(f.id == SONAR_PING360_TRANSDUCER ? f.payload[2] | f.payload[3] << 8 : 0);
    x->n++;
    return 0;
}

static void fake_break(void *user)
{
    ((struct wire *)user)->breaks++;
}

static struct sonar_ping360_config base_cfg(void)
{
    struct sonar_ping360_config c;
    memset(&c, 0, sizeof(c));
    c.range_m = 2.0f;
    c.speed_of_sound = 1500.0f;
    c.gain = 0;
    c.frequency = 750;
    c.step = 1;
    c.full_circle = 1;
    return c;
}

/* Brings the driver up on io: connected, the probe answered by firmware 3.fw_minor.fw_patch. */
static void start_io(const struct sonar_ping360_config *c, const struct sonar_ping360_io *io, uint8_t fw_minor, uint8_t fw_patch)
{
    struct sonar_ping360_event ev;
    struct sonar_ping_frame f;
    memset(&w, 0, sizeof(w));
    assert_int_equal(sonar_ping360_init(&drv, c, io), SONAR_OK);
    assert_int_equal(sonar_ping360_connected(&drv, 1000), SONAR_OK);
    assert_int_equal(w.id[0], SONAR_PING_GENERAL_REQUEST);
    payload[0] = 2;
    payload[1] = 0;
    payload[2] = 3;
    payload[3] = fw_minor;
    payload[4] = fw_patch;
    payload[5] = 0;
    f.id = SONAR_PING_DEVICE_INFORMATION;
    f.payload = payload;
    f.payload_len = 6;
    f.src = 2;
    f.dst = 0;
    assert_int_equal(sonar_ping360_handle(&drv, &f, 2000, &ev), SONAR_OK);
    assert_int_equal(ev.kind, SONAR_P360_EV_READY);
}

static void start(const struct sonar_ping360_config *c, uint8_t fw_minor, uint8_t fw_patch)
{
    struct sonar_ping360_io io = {fake_send, fake_break, &w, NULL, NULL};
    start_io(c, &io, fw_minor, fw_patch);
}

/* A device_data (or auto_device_data) reply at angle a with n samples. */
static struct sonar_ping_frame reply(uint16_t a, int is_auto)
{
    struct sonar_ping_frame f;
    uint16_t n = 4, fixed = is_auto ? 20 : 14;
    memset(payload, 0, sizeof(payload));
    payload[0] = 1;
    payload[2] = (uint8_t)(a & 0xff);
    payload[3] = (uint8_t)(a >> 8);
    payload[is_auto ? 16 : 10] = (uint8_t)n;
    payload[is_auto ? 18 : 12] = (uint8_t)n;
    memset(payload + fixed, 77, n);
    f.id = is_auto ? SONAR_PING360_AUTO_DEVICE_DATA : SONAR_PING360_DEVICE_DATA;
    f.payload = payload;
    f.payload_len = (uint16_t)(fixed + n);
    f.src = 2;
    f.dst = 0;
    return f;
}

static uint16_t last_angle(void)
{
    return w.angle[(w.n - 1) % 64];
}

static void test_derived_settings_and_validation(void **state)
{
    struct sonar_ping360_config c = base_cfg();
    struct sonar_ping360_io io = {fake_send, NULL, &w, NULL, NULL};
    (void)state;
    assert_int_equal(sonar_ping360_init(&drv, &c, &io), SONAR_OK);
    assert_int_equal(drv.samples, 1200);
    assert_int_equal(drv.sample_period, 88);
    assert_int_equal(drv.tx_us, 11);
    /* 19.4 + 6 + 2.67 ms on a network link */
    assert_in_range(sonar_ping360_beam_time_us(&drv), 28000, 28100);
    c.baud = 115200; /* + 10 * 1248 bits at 115200: 108 ms */
    assert_int_equal(sonar_ping360_init(&drv, &c, &io), SONAR_OK);
    assert_in_range(sonar_ping360_beam_time_us(&drv), 136000, 137000);
    c = base_cfg();
    c.range_m = 0.5f;
    assert_int_equal(sonar_ping360_init(&drv, &c, &io), SONAR_ERR_ARG);
    c = base_cfg();
    c.gain = 3;
    assert_int_equal(sonar_ping360_init(&drv, &c, &io), SONAR_ERR_ARG);
    c = base_cfg();
    c.frequency = 1001;
    assert_int_equal(sonar_ping360_init(&drv, &c, &io), SONAR_ERR_ARG);
    c = base_cfg();
    c.samples = 150;
    assert_int_equal(sonar_ping360_init(&drv, &c, &io), SONAR_ERR_ARG);
    c = base_cfg();
    c.full_circle = 0;
    c.start_angle = c.stop_angle = 100;
    assert_int_equal(sonar_ping360_init(&drv, &c, &io), SONAR_ERR_ARG);
    c = base_cfg();
    c.use_auto = 1;
    c.step = 11;
    assert_int_equal(sonar_ping360_init(&drv, &c, &io), SONAR_ERR_ARG);
    c = base_cfg();
    c.samples = 1200;
    c.range_m = 1.0f; /* 53 ticks: below the firmware's 80 */
    assert_int_equal(sonar_ping360_init(&drv, &c, &io), SONAR_ERR_RANGE);
}

static void test_full_circle_sequence(void **state)
{
    struct sonar_ping360_config c = base_cfg();
    struct sonar_ping360_event ev;
    int i;
    int64_t t = 2000;
    (void)state;
    c.step = 3;
    c.start_angle = 390;
    start(&c, 3, 0);
    assert_int_equal(w.id[1], SONAR_PING360_TRANSDUCER);
    assert_int_equal(last_angle(), 390);
    for (i = 0; i < 200; i++) {
        struct sonar_ping_frame f = reply(last_angle(), 0);
        uint16_t asked = last_angle();
        t += 30000;
        assert_int_equal(sonar_ping360_handle(&drv, &f, t, &ev), SONAR_OK);
        assert_int_equal(ev.kind, SONAR_P360_EV_BEAM);
        assert_int_equal(ev.data.angle, asked);
        assert_int_equal(last_angle(), (390 + 3 * (i + 1)) % 400);
    }
    assert_int_equal(drv.counters.beams, 200);
    assert_int_equal(drv.counters.timeouts, 0);
}

/* A planner behind next_angle: asked when scanning starts and after each beam, with the time; retries keep the angle. */
static int64_t plan_at[64];
static int plan_calls;
static uint16_t plan(void *user, int64_t now)
{
    static const uint16_t order[] = {50, 310, 51, 399, 0};
    (void)user;
    plan_at[plan_calls % 64] = now;
    return (uint16_t)(order[plan_calls++ % 5] + 400u); /* taken mod 400 */
}

static void test_planner_chooses_angles(void **state)
{
    struct sonar_ping360_config c = base_cfg();
    struct sonar_ping360_io io = {fake_send, NULL, &w, plan, NULL};
    struct sonar_ping360_event ev;
    struct sonar_ping_frame f;
    int i;
    (void)state;
    plan_calls = 0;
    start_io(&c, &io, 3, 0);
    assert_int_equal(plan_calls, 1);
    assert_int_equal(last_angle(), 50);
    for (i = 1; i < 5; i++) {
        f = reply(last_angle(), 0);
        assert_int_equal(sonar_ping360_handle(&drv, &f, 2000 + 40000 * (int64_t)i, &ev), SONAR_OK);
        assert_int_equal(ev.kind, SONAR_P360_EV_BEAM);
        assert_int_equal(plan_at[i], 2000 + 40000 * (int64_t)i);
    }
    assert_int_equal(last_angle(), 0);
    /* a reply for another angle than requested: off_angle, the planner not asked */
    f = reply(51, 0);
    assert_int_equal(sonar_ping360_handle(&drv, &f, 300000, &ev), SONAR_OK);
    assert_int_equal(ev.kind, SONAR_P360_EV_NONE);
    assert_int_equal(plan_calls, 5);
    /* a timeout sends the same angle again without asking */
    assert_int_equal(sonar_ping360_poll(&drv, sonar_ping360_deadline(&drv), &ev), SONAR_OK);
    assert_int_equal(last_angle(), 0);
    assert_int_equal(plan_calls, 5);
    /* auto_transmit: the device steps itself and the planner is never asked */
    c.use_auto = 1;
    start_io(&c, &io, 3, 8);
    assert_int_equal(drv.state, SONAR_P360_AUTO);
    f = reply(10, 1);
    assert_int_equal(sonar_ping360_handle(&drv, &f, 40000, &ev), SONAR_OK);
    assert_int_equal(plan_calls, 5);
}

static void test_sector_bounces(void **state)
{
    static const uint16_t want[] = {350, 370, 390, 10, 30, 50, 30, 10, 390, 370, 350, 370};
    struct sonar_ping360_config c = base_cfg();
    struct sonar_ping360_event ev;
    unsigned i;
    (void)state;
    c.full_circle = 0;
    c.start_angle = 350; /* across 0: 350 -> 50 is 100 gradians */
    c.stop_angle = 50;
    c.step = 20;
    start(&c, 3, 0);
    for (i = 0; i < sizeof(want) / sizeof(want[0]); i++) {
        struct sonar_ping_frame f;
        assert_int_equal(last_angle(), want[i]);
        f = reply(want[i], 0);
        assert_int_equal(sonar_ping360_handle(&drv, &f, 10000 * (int64_t)i, &ev), SONAR_OK);
    }
    /* a step that does not divide the sector still reaches both ends */
    c.start_angle = 0;
    c.stop_angle = 10;
    c.step = 3;
    start(&c, 3, 0);
    {
        static const uint16_t w2[] = {0, 3, 6, 9, 10, 7, 4, 1, 0, 3};
        for (i = 0; i < sizeof(w2) / sizeof(w2[0]); i++) {
            struct sonar_ping_frame f;
            assert_int_equal(last_angle(), w2[i]);
            f = reply(w2[i], 0);
            assert_int_equal(sonar_ping360_handle(&drv, &f, 10000 * (int64_t)i, &ev), SONAR_OK);
        }
    }
}

static void test_timeout_retries_same_angle_quickly(void **state)
{
    struct sonar_ping360_config c = base_cfg();
    struct sonar_ping360_event ev;
    struct sonar_ping_frame f;
    int64_t t = 2000, dl;
    uint32_t beam;
    (void)state;
    start(&c, 3, 0);
    beam = sonar_ping360_beam_time_us(&drv);
    /* a few beams so the timeout leaves the first-command allowance */
    for (; drv.counters.beams < 5;) {
        f = reply(last_angle(), 0);
        t += beam;
        assert_int_equal(sonar_ping360_handle(&drv, &f, t, &ev), SONAR_OK);
    }
    /* the reply to the next request is lost */
    dl = sonar_ping360_deadline(&drv);
    assert_true(dl - t <= 2 * (int64_t)beam); /* never seconds for one lost reply */
    assert_true(dl - t >= beam);
    assert_int_equal(sonar_ping360_poll(&drv, dl - 1, &ev), SONAR_OK);
    assert_int_equal(drv.counters.timeouts, 0);
    assert_int_equal(sonar_ping360_poll(&drv, dl, &ev), SONAR_OK);
    assert_int_equal(ev.kind, SONAR_P360_EV_NONE);
    assert_int_equal(drv.counters.timeouts, 1);
    assert_int_equal(drv.counters.retries, 1);
    assert_int_equal(last_angle(), 5); /* the same angle again */
    assert_int_equal(w.angle[(w.n - 2) % 64], 5);
    /* it answers this time: the sweep goes on */
    f = reply(5, 0);
    assert_int_equal(sonar_ping360_handle(&drv, &f, dl + beam, &ev), SONAR_OK);
    assert_int_equal(ev.kind, SONAR_P360_EV_BEAM);
    assert_int_equal(last_angle(), 6);
    assert_int_equal(w.breaks, 0);
}

static void test_silence_gives_up_with_backoff(void **state)
{
    struct sonar_ping360_config c = base_cfg();
    struct sonar_ping360_event ev;
    int64_t t;
    int i;
    (void)state;
    start(&c, 3, 0);
    for (i = 0; i < 4; i++) {
        t = sonar_ping360_deadline(&drv);
        assert_int_equal(sonar_ping360_poll(&drv, t, &ev), SONAR_OK);
    }
    assert_int_equal(ev.kind, SONAR_P360_EV_LINK_LOST);
    assert_int_equal(ev.backoff_us, 250000);
    assert_int_equal(drv.state, SONAR_P360_DOWN);
    assert_int_equal(drv.counters.reconnects, 1);
    assert_int_equal(drv.counters.timeouts, 4);
    assert_true(w.breaks >= 1); /* line breaks while it went quiet (baud re-detection) */
    /* reconnect: probe again; if the probe goes unanswered the backoff grows */
    assert_int_equal(sonar_ping360_connected(&drv, t + 250000), SONAR_OK);
    assert_int_equal(drv.state, SONAR_P360_PROBING);
    for (i = 0; i < 5; i++)
        assert_int_equal(sonar_ping360_poll(&drv, sonar_ping360_deadline(&drv), &ev), SONAR_OK);
    assert_int_equal(ev.kind, SONAR_P360_EV_LINK_LOST);
    assert_int_equal(ev.backoff_us, 500000);
    /* a transport error reported by the host counts as a reconnect too */
    start(&c, 3, 0);
    sonar_ping360_link_lost(&drv, 5000);
    assert_int_equal(drv.state, SONAR_P360_DOWN);
    assert_int_equal(drv.counters.reconnects, 1);
}

static void test_nacks_and_stale_replies(void **state)
{
    struct sonar_ping360_config c = base_cfg();
    struct sonar_ping360_event ev;
    struct sonar_ping_frame f;
    int sent;
    (void)state;
    start(&c, 3, 0);
    /* a late reply for another angle is not taken for the pending one */
    f = reply(123, 0);
    assert_int_equal(sonar_ping360_handle(&drv, &f, 3000, &ev), SONAR_OK);
    assert_int_equal(ev.kind, SONAR_P360_EV_NONE);
    assert_int_equal(drv.counters.off_angle, 1);
    /* NACK: sent again at once; three in a row: probe again */
    payload[0] = (uint8_t)(SONAR_PING360_TRANSDUCER & 0xff);
    payload[1] = (uint8_t)(SONAR_PING360_TRANSDUCER >> 8);
    f.id = SONAR_PING_NACK;
    f.payload = payload;
    f.payload_len = 2;
    sent = w.n;
    assert_int_equal(sonar_ping360_handle(&drv, &f, 4000, &ev), SONAR_OK);
    assert_int_equal(w.n, sent + 1);
    assert_int_equal(w.id[(w.n - 1) % 64], SONAR_PING360_TRANSDUCER);
    assert_int_equal(sonar_ping360_handle(&drv, &f, 5000, &ev), SONAR_OK);
    assert_int_equal(sonar_ping360_handle(&drv, &f, 6000, &ev), SONAR_OK);
    assert_int_equal(drv.counters.nacks, 3);
    assert_int_equal(drv.state, SONAR_P360_PROBING);
    assert_int_equal(w.id[(w.n - 1) % 64], SONAR_PING_GENERAL_REQUEST);
}

/* A Ping1D behind the same BlueOS bridge: its device_information and its messages are another device's. */
static void test_other_device_on_the_bridge(void **state)
{
    struct sonar_ping360_config c = base_cfg();
    struct sonar_ping360_io io = {fake_send, fake_break, &w, NULL, NULL};
    struct sonar_ping360_event ev;
    struct sonar_ping_frame f;
    (void)state;
    memset(&w, 0, sizeof(w));
    assert_int_equal(sonar_ping360_init(&drv, &c, &io), SONAR_OK);
    assert_int_equal(sonar_ping360_connected(&drv, 1000), SONAR_OK);
    memset(payload, 0, 16);
    payload[0] = SONAR_PING_DEVICE_PING1D;
    payload[2] = 3;
    payload[3] = 29;
    f.id = SONAR_PING_DEVICE_INFORMATION;
    f.payload = payload;
    f.payload_len = 6;
    f.src = 1;
    f.dst = 0;
    assert_int_equal(sonar_ping360_handle(&drv, &f, 1500, &ev), SONAR_OK);
    assert_int_equal(ev.kind, SONAR_P360_EV_NONE); /* not taken for the Ping360 */
    assert_int_equal(drv.state, SONAR_P360_PROBING);
    f.id = 1211; /* distance_simple */
    f.payload_len = 5;
    assert_int_equal(sonar_ping360_handle(&drv, &f, 1600, &ev), SONAR_OK);
    assert_int_equal(drv.counters.foreign, 2);
    /* the Ping360's own answer still brings it up, and the counter carries on */
    payload[0] = SONAR_PING_DEVICE_PING360;
    payload[3] = 3;
    f.id = SONAR_PING_DEVICE_INFORMATION;
    f.payload_len = 6;
    assert_int_equal(sonar_ping360_handle(&drv, &f, 2000, &ev), SONAR_OK);
    assert_int_equal(ev.kind, SONAR_P360_EV_READY);
    payload[0] = SONAR_PING_DEVICE_PING1D;
    assert_int_equal(sonar_ping360_handle(&drv, &f, 2100, &ev), SONAR_OK);
    assert_int_equal(drv.counters.foreign, 3);
    assert_int_equal(drv.state, SONAR_P360_SCANNING);
}

/* Passive: one device_information request, then every beam at any angle and settings; idle and hellos on silence; nothing else ever sent. */
static void test_passive_listens_only(void **state)
{
    struct sonar_ping360_config c = base_cfg();
    struct sonar_ping360_io io = {fake_send, fake_break, &w, NULL, NULL};
    struct sonar_ping360_event ev;
    struct sonar_ping_frame f;
    int i;
    (void)state;
    c.passive = 1;
    memset(&w, 0, sizeof(w));
    assert_int_equal(sonar_ping360_init(&drv, &c, &io), SONAR_OK);
    assert_int_equal(sonar_ping360_connected(&drv, 1000), SONAR_OK);
    assert_int_equal(drv.state, SONAR_P360_PASSIVE);
    assert_string_equal(sonar_ping360_state_str(drv.state), "passive");
    /* beams of another program's choosing: stepped at 7 then 250, then auto_transmit's */
    f = reply(7, 0);
    assert_int_equal(sonar_ping360_handle(&drv, &f, 2000, &ev), SONAR_OK);
    assert_int_equal(ev.kind, SONAR_P360_EV_BEAM);
    assert_int_equal(ev.data.angle, 7);
    f = reply(250, 0);
    assert_int_equal(sonar_ping360_handle(&drv, &f, 3000, &ev), SONAR_OK);
    assert_int_equal(ev.kind, SONAR_P360_EV_BEAM);
    f = reply(251, 1);
    assert_int_equal(sonar_ping360_handle(&drv, &f, 4000, &ev), SONAR_OK);
    assert_int_equal(ev.kind, SONAR_P360_EV_BEAM);
    assert_int_equal(drv.counters.beams, 3);
    assert_int_equal(drv.counters.off_angle, 0);
    /* silence: idle once after 1.5 s, a request each second, never a link loss */
    for (i = 1; i <= 40; i++) {
        int64_t now = 4000 + (int64_t)i * 100000;
        if (now >= sonar_ping360_deadline(&drv)) {
            assert_int_equal(sonar_ping360_poll(&drv, now, &ev), SONAR_OK);
            assert_true(ev.kind == SONAR_P360_EV_NONE || ev.kind == SONAR_P360_EV_IDLE);
            if (ev.kind == SONAR_P360_EV_IDLE)
                assert_true(now - 4000 >= (int64_t)SONAR_P360_IDLE_US && now - 4000 <= (int64_t)SONAR_P360_IDLE_US + 250000);
        }
    }
    assert_int_equal(drv.counters.idles, 1);
    assert_int_equal(drv.counters.hellos, 4); /* at connect, then after 1 s of silence, once a second: 1.0, 2.0, 3.0 s */
    assert_int_equal(drv.state, SONAR_P360_PASSIVE);
    /* stopping leaves the head to its driver */
    assert_int_equal(sonar_ping360_stop(&drv, 5000000), SONAR_OK);
    assert_int_equal(drv.state, SONAR_P360_STOPPED);
    for (i = 0; i < w.n && i < 64; i++)
        assert_int_equal(w.id[i], SONAR_PING_GENERAL_REQUEST);
}

static void test_auto_mode_and_fallback(void **state)
{
    struct sonar_ping360_config c = base_cfg();
    struct sonar_ping360_event ev;
    struct sonar_ping_frame f;
    int i;
    (void)state;
    c.use_auto = 1;
    c.step = 2;
    start(&c, 3, 8); /* 3.3.8 > 3.3.0: auto */
    assert_int_equal(drv.state, SONAR_P360_AUTO);
    assert_int_equal(w.id[1], SONAR_PING360_AUTO_TRANSMIT);
    for (i = 0; i < 10; i++) {
        f = reply((uint16_t)(i * 2), 1);
        assert_int_equal(sonar_ping360_handle(&drv, &f, 3000 + 30000 * (int64_t)i, &ev), SONAR_OK);
        assert_int_equal(ev.kind, SONAR_P360_EV_BEAM);
        assert_int_equal(ev.data.is_auto, 1);
    }
    assert_int_equal(w.n, 2); /* the stream needs no requests */
    /* a stall: auto_transmit is sent again */
    assert_int_equal(sonar_ping360_poll(&drv, sonar_ping360_deadline(&drv), &ev), SONAR_OK);
    assert_int_equal(w.id[(w.n - 1) % 64], SONAR_PING360_AUTO_TRANSMIT);
    /* stepping replies are off-angle in auto mode */
    f = reply(4, 0);
    assert_int_equal(sonar_ping360_handle(&drv, &f, 9000000, &ev), SONAR_OK);
    assert_int_equal(ev.kind, SONAR_P360_EV_NONE);
    /* firmware 3.3.0: falls back to stepping */
    start(&c, 3, 0);
    assert_int_equal(drv.state, SONAR_P360_SCANNING);
    assert_int_equal(w.id[1], SONAR_PING360_TRANSDUCER);
}

static void test_stop_sends_motor_off(void **state)
{
    struct sonar_ping360_config c = base_cfg();
    struct sonar_ping360_event ev;
    struct sonar_ping_frame f;
    int i;
    (void)state;
    start(&c, 3, 0);
    assert_int_equal(sonar_ping360_stop(&drv, 5000), SONAR_OK);
    assert_int_equal(w.id[(w.n - 1) % 64], SONAR_PING360_MOTOR_OFF);
    assert_int_equal(drv.state, SONAR_P360_STOPPING);
    /* beams still in flight are ignored */
    f = reply(0, 0);
    assert_int_equal(sonar_ping360_handle(&drv, &f, 6000, &ev), SONAR_OK);
    assert_int_equal(ev.kind, SONAR_P360_EV_NONE);
    payload[0] = (uint8_t)(SONAR_PING360_MOTOR_OFF & 0xff);
    payload[1] = (uint8_t)(SONAR_PING360_MOTOR_OFF >> 8);
    f.id = SONAR_PING_ACK;
    f.payload = payload;
    f.payload_len = 2;
    assert_int_equal(sonar_ping360_handle(&drv, &f, 7000, &ev), SONAR_OK);
    assert_int_equal(ev.kind, SONAR_P360_EV_STOPPED);
    /* no ack (vanilla firmware): motor_off three times, then stopped anyway */
    start(&c, 3, 0);
    assert_int_equal(sonar_ping360_stop(&drv, 5000), SONAR_OK);
    for (i = 0; i < 3; i++)
        assert_int_equal(sonar_ping360_poll(&drv, sonar_ping360_deadline(&drv), &ev), SONAR_OK);
    assert_int_equal(ev.kind, SONAR_P360_EV_STOPPED);
    assert_int_equal(w.id[(w.n - 1) % 64], SONAR_PING360_MOTOR_OFF);
    assert_int_equal(w.id[(w.n - 2) % 64], SONAR_PING360_MOTOR_OFF);
    assert_int_equal(sonar_ping360_deadline(&drv), INT64_MAX);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_derived_settings_and_validation),
        cmocka_unit_test(test_full_circle_sequence),
        cmocka_unit_test(test_planner_chooses_angles),
        cmocka_unit_test(test_sector_bounces),
        cmocka_unit_test(test_timeout_retries_same_angle_quickly),
        cmocka_unit_test(test_silence_gives_up_with_backoff),
        cmocka_unit_test(test_nacks_and_stale_replies),
        cmocka_unit_test(test_other_device_on_the_bridge),
        cmocka_unit_test(test_passive_listens_only),
        cmocka_unit_test(test_auto_mode_and_fallback),
        cmocka_unit_test(test_stop_sends_motor_off),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
