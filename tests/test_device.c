/* test_device.c -- the Ping360 on a byte stream (device.h), through its API only: probe, a beam as a record at its own settings, the gain and the planner set from outside, the deadline, reconfigure, stop, and the reconnect policy. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "sonar/device.h"
#include "sonar/status.h"

static uint16_t sent[32], sent_angle[32], sent_gain[32];
static int nsent;

static int fake_send(void *user, const uint8_t *buf, size_t len)
{
    struct sonar_ping_parser p;
    struct sonar_ping_frame f;
    (void)user;
    assert_int_equal(sonar_ping_parser_init(&p, 0), SONAR_OK);
    assert_int_equal(sonar_ping_parser_next(&p, &buf, &len, &f), 1);
    sent[nsent % 32] = f.id;
    sent_angle[nsent % 32] = (uint16_t)(f.id == SONAR_PING360_TRANSDUCER ? f.payload[2] | f.payload[3] << 8 : 0);
    sent_gain[nsent % 32] = (uint16_t)(f.id == SONAR_PING360_TRANSDUCER ? f.payload[1] : 0);
    nsent++;
    return 0;
}

static int full_send(void *user, const uint8_t *buf, size_t len)
{
    (void)user;
    (void)buf;
    (void)len;
    return SONAR_ERR_SPACE;
}

static uint16_t planned(void *user, int64_t now)
{
    (void)user;
    (void)now;
    return 123;
}

/* Bytes of a frame id with payload p (n bytes) into buf; returns its length. */
static size_t frame(uint8_t *buf, uint16_t id, const uint8_t *p, uint16_t n)
{
    int len = sonar_ping_encode(buf, 2048, id, p, n);
    assert_true(len > 0);
    return (size_t)len;
}

/* A Ping360 at 10 m, full turns, 1-gradian steps. */
static void config(struct sonar_ping360_config *c)
{
    memset(c, 0, sizeof(*c));
    c->range_m = 10.0f;
    c->speed_of_sound = 1500.0f;
    c->frequency = 750;
    c->step = 1;
    c->full_circle = 1;
}

static void test_device_through_its_api(void **state)
{
    static struct sonar_device d;
    struct sonar_ping360_config c;
    struct sonar_ping360_io io = {fake_send, NULL, NULL, NULL, NULL};
    struct sonar_device_event ev;
    uint8_t buf[2048], p[14 + 4];
    const uint8_t *in;
    size_t len;
    uint8_t fw[3];
    (void)state;
    config(&c);
    c.gain = 1;
    assert_int_equal(sonar_device_init(&d, &c, &io), SONAR_OK);
    assert_int_equal(sonar_device_config(&d)->gain, 1);
    assert_true(sonar_device_samples(&d) >= 200);
    assert_int_equal(sonar_device_set_gain(&d, 3), SONAR_ERR_ARG);
    assert_int_equal(sonar_device_set_gain(&d, 2), SONAR_OK);
    sonar_device_set_planner(&d, planned, NULL);
    assert_int_equal(sonar_device_up(&d, 1000), SONAR_OK);
    assert_int_equal(sent[nsent - 1], SONAR_PING_GENERAL_REQUEST);
    assert_true(sonar_device_deadline(&d) > 1000 && sonar_device_deadline(&d) < INT64_MAX);
    /* the probe answered: scanning at the planner's angle with the gain set from outside */
    memset(p, 0, sizeof(p));
    p[0] = SONAR_PING_DEVICE_PING360;
    p[2] = 3;
    p[3] = 3;
    len = frame(buf, SONAR_PING_DEVICE_INFORMATION, p, 6);
    in = buf;
    assert_int_equal(sonar_device_bytes(&d, &in, &len, 2000, &ev), 1);
    assert_int_equal(ev.kind, SONAR_P360_EV_READY);
    assert_int_equal(sonar_device_state(&d), SONAR_P360_SCANNING);
    sonar_device_firmware(&d, fw);
    assert_int_equal(fw[1], 3);
    assert_int_equal(sent[nsent - 1], SONAR_PING360_TRANSDUCER);
    assert_int_equal(sent_angle[nsent - 1], 123);
    assert_int_equal(sent_gain[nsent - 1], 2);
    /* its reply: a record at the reply's own settings */
    memset(p, 0, sizeof(p));
    p[1] = 2;       /* gain */
    p[2] = 123;     /* angle */
    p[6] = 0x10;    /* sample period 0x0210 = 528 ticks */
    p[7] = 0x02;
    p[12] = 4;      /* data_length */
    memset(p + 14, 77, 4);
    len = frame(buf, SONAR_PING360_DEVICE_DATA, p, 18);
    in = buf;
    assert_int_equal(sonar_device_bytes(&d, &in, &len, 3000, &ev), 1);
    assert_int_equal(ev.kind, SONAR_P360_EV_BEAM);
    assert_int_equal(ev.beam.angle, 123);
    assert_int_equal(ev.beam.gain, 2);
    assert_int_equal(ev.beam.sample_period, 528);
    assert_int_equal(ev.beam.n, 4);
    assert_true(ev.beam.range_m > 0.0f);
    assert_int_equal(ev.beam.samples[0], 77);
    assert_int_equal(sonar_device_bytes(&d, &in, &len, 3000, &ev), 0);
    /* reconfigure: a range no sample period gives is refused, nothing changed; a new one probes again, counters kept */
    {
        struct sonar_ping360_config r = c;
        uint32_t beams = 0;
        struct sonar_status st;
        memset(&st, 0, sizeof(st));
        sonar_status_fill(&st, &d, NULL);
        beams = st.driver.beams;
        r.range_m = 1000.0f;
        assert_true(sonar_device_reconfigure(&d, &r, 3500) < 0);
        assert_int_equal(sonar_device_state(&d), SONAR_P360_SCANNING);
        r.range_m = 20.0f;
        assert_int_equal(sonar_device_reconfigure(&d, &r, 3500), SONAR_OK);
        assert_int_equal(sent[nsent - 1], SONAR_PING_GENERAL_REQUEST);
        assert_int_equal(sonar_device_state(&d), SONAR_P360_PROBING);
        assert_true(sonar_device_config(&d)->range_m == 20.0f);
        memset(&st, 0, sizeof(st));
        sonar_status_fill(&st, &d, NULL);
        assert_int_equal(st.driver.beams, beams);
        assert_true(beams >= 1);
    }
    /* stop: motor_off, then STOPPED when acknowledged */
    assert_int_equal(sonar_device_stop(&d, 4000), SONAR_OK);
    assert_int_equal(sent[nsent - 1], SONAR_PING360_MOTOR_OFF);
    p[0] = (uint8_t)(SONAR_PING360_MOTOR_OFF & 0xff);
    p[1] = (uint8_t)(SONAR_PING360_MOTOR_OFF >> 8);
    len = frame(buf, SONAR_PING_ACK, p, 2);
    in = buf;
    assert_int_equal(sonar_device_bytes(&d, &in, &len, 5000, &ev), 1);
    assert_int_equal(ev.kind, SONAR_P360_EV_STOPPED);
    assert_int_equal(sonar_device_state(&d), SONAR_P360_STOPPED);
}

/* One reconnect policy for host and firmware: a probe that cannot go out, a silent head, a transport lost. */
static void test_reconnect_policy(void **state)
{
    static struct sonar_device d;
    struct sonar_ping360_config c;
    struct sonar_ping360_io full = {full_send, NULL, NULL, NULL, NULL}, io = {fake_send, NULL, NULL, NULL, NULL};
    struct sonar_device_event ev;
    int64_t t = 1000000, lost_at = 0;
    uint32_t first = 0;
    (void)state;
    config(&c);
    /* The output full: tried again soon; then a reconnect is due at that time, and the deadline says so. */
    assert_int_equal(sonar_device_init(&d, &c, &full), SONAR_OK);
    assert_int_equal(sonar_device_reconnect_at(&d), 0);
    assert_int_equal(sonar_device_up(&d, t), SONAR_ERR_SPACE);
    assert_true(sonar_device_reconnect_at(&d) == t + SONAR_DEVICE_SPACE_RETRY_US);
    assert_true(sonar_device_deadline(&d) <= t + SONAR_DEVICE_SPACE_RETRY_US);
    /* A head that never answers: the driver gives up with its backoff, and that is when to reconnect. */
    assert_int_equal(sonar_device_init(&d, &c, &io), SONAR_OK);
    assert_int_equal(sonar_device_up(&d, t), SONAR_OK);
    assert_int_equal(sonar_device_reconnect_at(&d), 0);
    for (; t < 60000000 && lost_at == 0; t += 10000)
        if (sonar_device_poll(&d, t, &ev) == 1 && ev.kind == SONAR_P360_EV_LINK_LOST) {
            lost_at = t;
            first = ev.backoff_us;
        }
    assert_true(lost_at > 0 && first > 0);
    assert_true(sonar_device_reconnect_at(&d) == lost_at + first);
    /* The transport lost after that: the next delay, never 0, and at least the first (it backs off). */
    {
        uint32_t next = sonar_device_down(&d, t);
        assert_true(next >= first);
        assert_true(sonar_device_reconnect_at(&d) == t + next);
    }
    /* Up again: nothing pending. A transport lost before the driver had any backoff: SONAR_DEVICE_RETRY_US or its own. */
    assert_int_equal(sonar_device_up(&d, t), SONAR_OK);
    assert_int_equal(sonar_device_reconnect_at(&d), 0);
    assert_int_equal(sonar_device_init(&d, &c, &io), SONAR_OK);
    assert_true(sonar_device_down(&d, t) > 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_device_through_its_api),
        cmocka_unit_test(test_reconnect_policy),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
