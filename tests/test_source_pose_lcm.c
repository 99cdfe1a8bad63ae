/* test_source_pose_lcm.c -- SONAR_POSE over LCM (memq://, in the process): poses into the app, what does not decode and what the ring refuses counted. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

/* Before cmocka.h, which wraps the allocator's names under UNIT_TESTING. */
#include <lcm/lcm.h>

#include "sonar_pose_t.h"
#include "source_pose_lcm.h"

#include <cmocka.h>

static struct app_storage app_mem;
static struct app *app;
static struct source_pose_lcm src;

static int64_t zero(void *u)
{
    (void)u;
    return 0;
}

static void publish(int64_t t, float n, float e, float y)
{
    sonar_pose_t m;
    uint8_t buf[64];
    int len;
    m.utime = t;
    m.north_m = n;
    m.east_m = e;
    m.yaw_deg = y;
    len = sonar_pose_t_encode(buf, 0, (int)sizeof(buf), &m);
    assert_true(len > 0);
    assert_int_equal(lcm_publish((lcm_t *)src.lcm, "PORT_SONAR_POSE", buf, (unsigned)len), 0);
}

static void test_poses_over_lcm(void **state)
{
    struct sonar_pipeline_config c;
    struct app_clock clk = {zero, zero, NULL};
    struct sonar_pose p;
    char err[160];
    (void)state;
    sonar_pipeline_defaults(&c);
    assert_int_equal(app_init(&app, &app_mem, &c, NULL, NULL, &clk, 0, err, sizeof(err)), HOST_OK);
    assert_int_equal(source_pose_lcm_open(&src, NULL, "memq://", "PORT_", app, err, sizeof(err)), HOST_OK);
    assert_string_equal(src.channel, "PORT_SONAR_POSE");
    publish(1000000, 3.0f, 4.0f, 90.0f);
    publish(1100000, 3.1f, 4.0f, 91.0f);
    publish(1050000, 3.0f, 4.0f, 90.0f); /* out of order */
    assert_int_equal(lcm_publish((lcm_t *)src.lcm, "PORT_SONAR_POSE", "\x01\x02", 2), 0); /* does not decode */
    source_pose_lcm_poll(&src);
    assert_int_equal(src.received, 4);
    assert_int_equal(src.bad, 1);
    assert_int_equal(src.refused, 1);
    assert_int_equal(sonar_pose_at(app_poses(app), 1050000, &p), 1);
    assert_true(p.north_m > 3.04f && p.north_m < 3.06f && p.yaw_deg > 90.4f && p.yaw_deg < 90.6f);
    source_pose_lcm_close(&src);
    assert_int_equal(source_pose_lcm_open(&src, NULL, "nosuch://", "", app, err, sizeof(err)), HOST_ERR_IO);
    assert_non_null(strstr(err, "--pose-lcm nosuch://: LCM could not start this provider"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_poses_over_lcm),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
