/* test_discover.c -- the Ping360 discovery reply: the device's own text, its variants, every malformed form named; the subnet check. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "discover.h"

static int parse(const char *text, struct discover_device *d, char *err, size_t n)
{
    return discover_parse_reply((const uint8_t *)text, strlen(text), d, err, n);
}

static void test_device_reply(void **state)
{
    struct discover_device d;
    char err[160];
    (void)state;
    /* as ping.md quotes the device (ping360asciiprotocol), zero-padded octets */
    assert_int_equal(parse("SONAR PING360  \r\nBlue Robotics\r\nMAC Address:- 54-10-EC-79-7D-C5\r\nIP Address:- 192.168.000.111\r\n",
                           &d, err, sizeof(err)),
                     HOST_OK);
    assert_string_equal(d.name, "SONAR PING360");
    assert_int_equal(d.mac[0], 0x54);
    assert_int_equal(d.mac[5], 0xC5);
    assert_int_equal(d.ip, 0xC0A8006Fu);
    assert_int_equal(d.fw_known, 0);
    /* LF only, the lines in another order, lower-case hex */
    assert_int_equal(parse("SONAR PING360\nIP Address:- 10.1.2.3\nMAC Address:- 54-10-ec-00-00-01\n", &d, err, sizeof(err)), HOST_OK);
    assert_int_equal(d.ip, 0x0A010203u);
    assert_int_equal(d.mac[3], 0);
}

static void test_format_round_trip(void **state)
{
    static const uint8_t mac[6] = {0x54, 0x10, 0xEC, 0xAB, 0xCD, 0xEF};
    struct discover_device d;
    char buf[256], err[160];
    size_t n;
    (void)state;
    n = discover_format_reply(buf, sizeof(buf), mac, 0x7F000001u);
    assert_true(n > 0 && n == strlen(buf));
    assert_non_null(strstr(buf, "IP Address:- 127.000.000.001\r\n"));
    assert_int_equal(discover_parse_reply((const uint8_t *)buf, n, &d, err, sizeof(err)), HOST_OK);
    assert_memory_equal(d.mac, mac, 6);
    assert_int_equal(d.ip, 0x7F000001u);
    /* a buffer too small is cut, never overrun */
    n = discover_format_reply(buf, 10, mac, 1u);
    assert_int_equal(n, 9);
}

static void expect_bad(const uint8_t *b, size_t len, const char *want)
{
    struct discover_device d;
    char err[160];
    assert_int_equal(discover_parse_reply(b, len, &d, err, sizeof(err)), HOST_ERR_ROW);
    if (strstr(err, want) == NULL)
        fail_msg("got '%s', want '%s'", err, want);
}

static void expect_bad_text(const char *text, const char *want)
{
    expect_bad((const uint8_t *)text, strlen(text), want);
}

static void test_malformed_replies_named(void **state)
{
    static const uint8_t binary[] = {'B', 'R', 0x00, 0x05};
    static uint8_t big[600];
    (void)state;
    expect_bad(binary, sizeof(binary), "not text: byte 2 is 0x00");
    expect_bad(binary, 0, "0 bytes");
    memset(big, 'A', sizeof(big));
    expect_bad(big, sizeof(big), "600 bytes");
    expect_bad_text("Discovery", "not a Ping360");
    expect_bad_text("\r\n\r\n", "no 'SONAR PING360' line");
    expect_bad_text("SONAR PING360\r\nIP Address:- 192.168.2.2\r\n", "no 'MAC Address:-' line");
    expect_bad_text("SONAR PING360\r\nMAC Address:- 54-10-EC-79-7D-C5\r\n", "no 'IP Address:-' line");
    expect_bad_text("SONAR PING360\r\nMAC Address:- 54-10-EC-79-7D\r\nIP Address:- 1.2.3.4\r\n", "MAC '54-10-EC-79-7D'");
    expect_bad_text("SONAR PING360\r\nMAC Address:- 54:10:EC:79:7D:C5\r\nIP Address:- 1.2.3.4\r\n", "is not six hex pairs");
    expect_bad_text("SONAR PING360\r\nMAC Address:- 54-10-EC-79-7D-C5\r\nIP Address:- 192.168.2.256\r\n", "IP '192.168.2.256'");
    expect_bad_text("SONAR PING360\r\nMAC Address:- 54-10-EC-79-7D-C5\r\nIP Address:- 192.168.2\r\n", "is not a dotted quad");
    expect_bad_text("SONAR PING360\r\nMAC Address:- 54-10-EC-79-7D-C5\r\nIP Address:- 1.2.3.4x\r\n", "is not a dotted quad");
}

static void test_loopback_is_local(void **state)
{
    char ifs[512];
    (void)state;
    /* every Linux machine, and a network namespace after `ip link set lo up`, has lo 127.0.0.1/8 */
    assert_int_equal(discover_on_local_subnet(0x7F000005u, ifs, sizeof(ifs)), 1);
    assert_non_null(strstr(ifs, "127.0.0.1/8"));
    /* 0.0.0.0/8 is no interface's subnet */
    assert_int_equal(discover_on_local_subnet(0x00000005u, ifs, sizeof(ifs)), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_device_reply),
        cmocka_unit_test(test_format_round_trip),
        cmocka_unit_test(test_malformed_replies_named),
        cmocka_unit_test(test_loopback_is_local),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
