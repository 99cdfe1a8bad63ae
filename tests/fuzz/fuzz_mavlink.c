/* fuzz_mavlink.c -- libFuzzer: any bytes from the vehicle's network into sonard's MAVLink endpoint (the generated parser, HEARTBEAT, ATTITUDE, LOCAL_POSITION_NED, COMMAND_ACK); nothing crashes, no pose is taken before an autopilot is known or from another system, and the messages out still pack. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "mav_internal.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static int64_t mono_ns;

static int64_t mono(void *u)
{
    (void)u;
    return mono_ns;
}

static int64_t wall(void *u)
{
    (void)u;
    return 1700000000000000 + mono_ns / 1000;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static struct app_storage mem;
    static struct mav m;
    struct app *a;
    struct sonar_pipeline_config c;
    struct app_clock clk = {mono, wall, NULL};
    struct mav_config mc;
    uint8_t out[MAVLINK_MAX_PACKET_LEN];
    char err[256];
    size_t at = 0;
    memset(&mc, 0, sizeof(mc));
    mc.url = "udpin:127.0.0.1:14550"; /* parsed, never opened: what it would send is dropped and counted */
    mc.compid = 158;
    mc.rate_hz = 10.0f;
    mc.pose_rate_hz = 10.0f;
    mc.fail_closed = 1;
    mc.autopilot = size > 0 ? (uint8_t)(data[0] & 3u) : 0; /* 0: the first heard; else that system */
    mono_ns = 5000000000;
    sonar_pipeline_defaults(&c);
    if (app_init(&a, &mem, &c, NULL, NULL, &clk, 0, err, sizeof(err)) != HOST_OK || mav_init(&m, &mc, err, sizeof(err)) != HOST_OK ||
        mav_attach(&m, a) != HOST_OK)
        abort();
    /* In chunks of up to 64 bytes, 20 ms apart: the rate windows and the request timer run too. */
    while (at < size) {
        size_t n = size - at < 64 ? size - at : 64;
        mav_bytes(&m, data + at, n, wall(NULL));
        at += n;
        mono_ns += 20000000;
        mav_ask_pose(&m, app_mono_us(a));
        mav_rx_timers(&m, app_mono_us(a));
    }
    if (m.ap_sysid == 0 && (m.n.attitudes != 0 || m.n.positions != 0))
        abort(); /* a pose before any autopilot was known */
    if (mc.autopilot != 0 && m.ap_sysid != 0 && m.ap_sysid != mc.autopilot)
        abort(); /* another system than the one asked for */
    if (app_poses(a)->accepted > m.n.attitudes)
        abort();
    if (mav_obstacle_distance(&m, out, wall(NULL), app_mono_us(a)) > sizeof(out))
        abort();
    return 0;
}
