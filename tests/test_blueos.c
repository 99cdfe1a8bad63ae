/* test_blueos.c -- BlueOS's ping service: its sensors list as the service writes it, the Ping360's URL, every malformed reply named, the --sonar blueos forms, the bounded fallback. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <time.h>
#include <netinet/in.h>
#include <arpa/inet.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cmocka.h>

#include "blueos.h"

/* The shape of BlueOS's PingDeviceDescriptorModel list: a Ping1D bridged first, then a serial Ping360. */
static const char two_devices[] =
    "[{\"ping_type\":\"Ping1D\",\"device_id\":1,\"device_model\":1,\"device_revision\":1,"
    "\"firmware_version_major\":3,\"firmware_version_minor\":29,\"firmware_version_patch\":0,"
    "\"port\":\"/dev/ttyUSB1\",\"ethernet_discovery_info\":\"\","
    "\"driver_status\":{\"udp_port\":9090,\"mavlink_driver_enabled\":true}},\n"
    " {\"ping_type\": \"Ping360\", \"device_id\": 2, \"device_model\": 2, \"device_revision\": 1,"
    " \"firmware_version_major\": 3, \"firmware_version_minor\": 3, \"firmware_version_patch\": 1,"
    " \"port\": \"/dev/ttyUSB0\", \"ethernet_discovery_info\": \"\","
    " \"driver_status\": {\"udp_port\": 9092, \"mavlink_driver_enabled\": false}}]";

static int parse(const char *body, struct blueos_sensors *s, char *err, size_t n)
{
    return blueos_parse_sensors(body, strlen(body), s, err, n);
}

static void test_service_list(void **state)
{
    struct blueos_sensors s;
    char err[128], url[96];
    (void)state;
    assert_int_equal(parse(two_devices, &s, err, sizeof err), HOST_OK);
    assert_int_equal(s.found, 1);
    assert_int_equal(s.others, 1);
    assert_string_equal(s.ping360.ping_type, "Ping360");
    assert_string_equal(s.ping360.port, "/dev/ttyUSB0");
    assert_int_equal(s.ping360.udp_port, 9092);
    assert_int_equal(blueos_sensor_url(&s, "192.168.2.2", url, sizeof url, err, sizeof err), HOST_OK);
    assert_string_equal(url, "udp:192.168.2.2:9092");
    /* an Ethernet Ping360: its own address, no bridge */
    assert_int_equal(parse("[{\"ping_type\":\"Ping360\",\"port\":\"\",\"ethernet_discovery_info\":\"192.168.2.10:12345\","
                           "\"driver_status\":{}}]", &s, err, sizeof err), HOST_OK);
    assert_int_equal(blueos_sensor_url(&s, "blueos.local", url, sizeof url, err, sizeof err), HOST_OK);
    assert_string_equal(url, "udp:192.168.2.10:12345");
    /* escapes, nulls, arrays and floats in fields sonard does not read */
    assert_int_equal(parse("[{\"x\":[1,[2,{\"a\":null}],-3.5e2],\"ping_type\":\"Ping\\u0033360\",\"port\":\"a\\\"b\","
                           "\"driver_status\":{\"udp_port\":9093.0,\"s\":\"t\"}}]", &s, err, sizeof err), HOST_OK);
    assert_int_equal(s.found, 0); /* "Ping?360" is not a Ping360 */
    assert_int_equal(s.others, 1);
}

static void test_no_ping360(void **state)
{
    struct blueos_sensors s;
    char err[128], url[96];
    (void)state;
    assert_int_equal(parse(" [ ] ", &s, err, sizeof err), HOST_OK);
    assert_int_equal(blueos_sensor_url(&s, "h", url, sizeof url, err, sizeof err), HOST_ERR_ROW);
    assert_string_equal(err, "no Ping360 listed (0 other devices)");
    assert_int_equal(parse("[{\"ping_type\":\"Ping1D\",\"driver_status\":{\"udp_port\":9090}}]", &s, err, sizeof err), HOST_OK);
    assert_int_equal(blueos_sensor_url(&s, "h", url, sizeof url, err, sizeof err), HOST_ERR_ROW);
    assert_string_equal(err, "no Ping360 listed (1 other device)");
    /* a Ping360 the service has not bridged yet */
    assert_int_equal(parse("[{\"ping_type\":\"Ping360\",\"port\":\"/dev/ttyACM0\",\"driver_status\":{}}]", &s, err, sizeof err), HOST_OK);
    assert_int_equal(blueos_sensor_url(&s, "h", url, sizeof url, err, sizeof err), HOST_ERR_ROW);
    assert_non_null(strstr(err, "'/dev/ttyACM0' has no bridge port"));
}

static void test_garbage_named(void **state)
{
    static const struct {
        const char *body, *err;
    } cases[] = {
        {"", "byte 0: expected the sensors' array"},
        {"<html>Internal Server Error</html>", "byte 0: expected the sensors' array"},
        {"{\"detail\":\"Not Found\"}", "byte 0: expected the sensors' array"},
        {"[{\"ping_type\" \"Ping360\"}]", "byte 14: expected ':' after a key"},
        {"[{\"ping_type\":\"Ping360", "byte 22: string not closed"},
        {"[{\"a\":1}", "byte 8: expected ',' or ']' between sensors"},
        {"[{\"a\":1}] x", "byte 10: bytes after the sensors' array"},
        {"[{\"a\":}]", "byte 6: expected a value"},
        {"[{\"a\":\"\x01\"}]", "byte 8: control character in a string"},
        {"[{\"a\":[[[[[[[[[[[[[[[[[[1]]]]]]]]]]]]]]]]]]}]", "byte 21: nested too deep"},
        {"[1]", "byte 1: expected an object"},
    };
    size_t i;
    (void)state;
    for (i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        struct blueos_sensors s;
        char err[128] = "";
        assert_int_equal(parse(cases[i].body, &s, err, sizeof err), HOST_ERR_ROW);
        assert_string_equal(err, cases[i].err);
    }
}

static void test_spec_forms(void **state)
{
    char host[64], err[160];
    int port;
    (void)state;
    assert_int_equal(blueos_spec("udp:127.0.0.1:9092", host, sizeof host, &port, err, sizeof err), 0);
    assert_int_equal(blueos_spec("blueosx", host, sizeof host, &port, err, sizeof err), 0);
    assert_int_equal(blueos_spec("blueos", host, sizeof host, &port, err, sizeof err), 1);
    assert_string_equal(host, "127.0.0.1");
    assert_int_equal(port, 9110);
    assert_int_equal(blueos_spec("blueos:192.168.2.2", host, sizeof host, &port, err, sizeof err), 1);
    assert_string_equal(host, "192.168.2.2");
    assert_int_equal(blueos_spec("blueos:h:19110", host, sizeof host, &port, err, sizeof err), 1);
    assert_string_equal(host, "h");
    assert_int_equal(port, 19110);
    assert_int_equal(blueos_spec("blueos:", host, sizeof host, &port, err, sizeof err), HOST_ERR_CONFIG);
    assert_int_equal(blueos_spec("blueos:h:0", host, sizeof host, &port, err, sizeof err), HOST_ERR_CONFIG);
    assert_string_equal(err, "--sonar blueos:h:0: the ping service's port '0' is not 1..65535");
}

/* A port on 127.0.0.1 that accepts and never answers (a slow service), and one that is closed (no service). */
static int listener(int *port)
{
    struct sockaddr_in a;
    socklen_t al = sizeof a;
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    memset(&a, 0, sizeof a);
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    assert_int_equal(bind(fd, (struct sockaddr *)&a, sizeof a), 0);
    assert_int_equal(listen(fd, 4), 0);
    assert_int_equal(getsockname(fd, (struct sockaddr *)&a, &al), 0);
    *port = ntohs(a.sin_port);
    return fd;
}

static void test_fallback_bounded(void **state)
{
    char url[96];
    int port, fd = listener(&port);
    struct timespec t0, t1;
    FILE *log = tmpfile();
    char said[512] = "";
    (void)state;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    assert_int_equal(blueos_resolve("127.0.0.1", port, 150, 10, url, sizeof url, log), 0);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    assert_string_equal(url, "udp:127.0.0.1:9092");
    /* 3 asks of 150 ms: bounded, not a hang */
    assert_true((double)(t1.tv_sec - t0.tv_sec) + (double)(t1.tv_nsec - t0.tv_nsec) * 1e-9 < 2.0);
    close(fd); /* now nobody listens there */
    assert_int_equal(blueos_resolve("127.0.0.1", port, 150, 10, url, sizeof url, log), 0);
    rewind(log);
    assert_true(fread(said, 1, sizeof said - 1, log) > 0);
    assert_non_null(strstr(said, "no whole reply within 150 ms"));
    assert_non_null(strstr(said, "connect: Connection refused"));
    assert_non_null(strstr(said, "using udp:127.0.0.1:9092"));
    fclose(log);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_service_list),
        cmocka_unit_test(test_no_ping360),
        cmocka_unit_test(test_garbage_named),
        cmocka_unit_test(test_spec_forms),
        cmocka_unit_test(test_fallback_bounded),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
