/* fuzz_ping360.c -- libFuzzer: bytes arriving as device replies, through the Ping parser into the Ping360 driver, with the clock moving; checks the parser's and the driver's contracts. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "sonar/ping360.h"

static int sent;

static int fake_send(void *user, const uint8_t *buf, size_t len)
{
    (void)user;
    if (buf == NULL || len == 0 || len > 64)
        abort(); /* requests are small */
    sent++;
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static struct sonar_ping_parser p;
    static struct sonar_ping360 d;
    struct sonar_ping360_config c;
    struct sonar_ping360_io io = {fake_send, NULL, NULL, NULL, NULL};
    int64_t now = 1000;
    size_t off = 0;
    memset(&c, 0, sizeof(c));
    /* The first byte picks the configuration: mode, sector, step. */
    c.range_m = 2.0f + (float)(size ? data[0] % 50 : 0);
    c.speed_of_sound = 1500.0f;
    c.frequency = 750;
    c.step = (uint8_t)(1 + (size ? data[0] % 10 : 0));
    c.use_auto = (uint8_t)(size && (data[0] & 0x80));
    c.full_circle = (uint8_t)!(size && (data[0] & 0x40));
    c.start_angle = 100;
    c.stop_angle = 300;
    if (sonar_ping360_init(&d, &c, &io) != SONAR_OK || sonar_ping_parser_init(&p, 0) != SONAR_OK)
        abort();
    if (sonar_ping360_connected(&d, now) != SONAR_OK)
        abort();
    while (off < size) {
        /* Chunks of 1..64 bytes, as reads deliver them; a time step between chunks. */
        size_t chunk = 1 + (data[off] & 63u), left;
        const uint8_t *in;
        struct sonar_ping_frame f;
        struct sonar_ping360_event ev;
        if (chunk > size - off)
            chunk = size - off;
        in = data + off;
        left = chunk;
        now += (int64_t)(data[off] >> 6) * 20000;
        while (sonar_ping_parser_next(&p, &in, &left, &f) == 1) {
            if (f.payload_len > SONAR_PING_MAX_PAYLOAD ||
                (f.payload_len && (f.payload < p.buf || f.payload + f.payload_len > p.buf + sizeof(p.buf))))
                abort();
            if (sonar_ping360_handle(&d, &f, now, &ev) != SONAR_OK)
                continue;
            if (ev.kind == SONAR_P360_EV_BEAM &&
                (ev.data.angle > 399 || ev.data.data_length > SONAR_PING_MAX_PAYLOAD || ev.data.data == NULL))
                abort();
        }
        if (left != 0)
            abort(); /* every byte consumed or buffered */
        if (sonar_ping360_poll(&d, now, &ev) == SONAR_OK && ev.kind == SONAR_P360_EV_LINK_LOST &&
            d.state != SONAR_P360_DOWN)
            abort();
        if (d.state > SONAR_P360_STOPPED || d.state == SONAR_P360_CONNECTING)
            abort();
        off += chunk;
    }
    /* Stopping must always be possible. */
    (void)sonar_ping360_stop(&d, now);
    return 0;
}
