/* test_link.c -- the one link lifecycle on 127.0.0.1: URL forms and refusals naming the option, a TCP connect that succeeds and one that is refused (retried a second later), a lost link reopened after its delay, a UDP listener answering its sender, a closed link staying closed. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include "link.h"

#include <cmocka.h>

#define ALL (LINK_ALLOW_SERIAL | LINK_ALLOW_UDP | LINK_ALLOW_TCP)

static void forms_and_refusals(void **state)
{
    struct link l;
    char err[256], d[160];
    (void)state;
    assert_int_equal(link_parse(&l, "--sonar", "tcp:127.0.0.1:9092", ALL, 0, err, sizeof(err)), HOST_OK);
    assert_int_equal(l.kind, LINK_TCP);
    assert_string_equal(link_describe(&l, d, sizeof(d)), "tcp:127.0.0.1:9092");
    assert_int_equal(link_parse(&l, "--sonar", "serial:/dev/ttyUSB0:921600", ALL, 0, err, sizeof(err)), HOST_OK);
    assert_int_equal(l.baud, 921600);
    assert_int_equal(link_parse(&l, "--sonar", "serial:/dev/ttyUSB0", ALL, -1, err, sizeof(err)), HOST_OK);
    assert_int_equal(l.autobaud, 1);
    assert_int_equal(link_parse(&l, "--mavlink", "udpout:[::1]:14550", LINK_ALLOW_UDP, 0, err, sizeof(err)), HOST_OK);
    assert_int_equal(l.kind, LINK_UDP);
    assert_string_equal(l.host, "::1");
    assert_string_equal(link_describe(&l, d, sizeof(d)), "udp:[::1]:14550");
    assert_int_equal(link_parse(&l, "--mavlink", "udpin:0.0.0.0:14660", LINK_ALLOW_LISTEN, 0, err, sizeof(err)), HOST_OK);
    assert_int_equal(l.kind, LINK_UDP_LISTEN);
    /* Each refusal names the option the URL came from. */
    assert_int_equal(link_parse(&l, "--coprocessor", "tcp:127.0.0.1:0", ALL, 0, err, sizeof(err)), HOST_ERR_CONFIG);
    assert_string_equal(err, "--coprocessor tcp:127.0.0.1:0: expected tcp:HOST:PORT with a port 1..65535");
    assert_int_equal(link_parse(&l, "--sonar", "serial:/dev/x:12345", ALL, 0, err, sizeof(err)), HOST_ERR_CONFIG);
    assert_non_null(strstr(err, "--sonar serial:/dev/x:12345: baud '12345'"));
    assert_int_equal(link_parse(&l, "--sonar", "udpin:0.0.0.0:5000", ALL, 0, err, sizeof(err)), HOST_ERR_CONFIG);
    assert_string_equal(err, "--sonar udpin:0.0.0.0:5000: not serial:PATH[:BAUD], udp:HOST:PORT or tcp:HOST:PORT");
    assert_int_equal(link_parse(&l, "--mavlink", "tcp:1.2.3.4:5", LINK_ALLOW_UDP, 0, err, sizeof(err)), HOST_ERR_CONFIG);
    assert_string_equal(err, "--mavlink tcp:1.2.3.4:5: not udp:HOST:PORT");
}

/* A listening TCP socket on 127.0.0.1 and its port. */
static int listener(int type, char *port, size_t n)
{
    struct sockaddr_in a;
    socklen_t len = sizeof(a);
    int fd = socket(AF_INET, type, 0);
    memset(&a, 0, sizeof(a));
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    assert_int_equal(bind(fd, (struct sockaddr *)&a, sizeof(a)), 0);
    if (type == SOCK_STREAM)
        assert_int_equal(listen(fd, 1), 0);
    assert_int_equal(getsockname(fd, (struct sockaddr *)&a, &len), 0);
    snprintf(port, n, "%u", ntohs(a.sin_port));
    return fd;
}

/* Runs the link until it says something other than NONE, at most 2 s of polling. */
static int until_event(struct link *l, int64_t now, char *err, size_t n)
{
    int k, ev = link_service_timers(l, now, err, n);
    for (k = 0; ev == LINK_EV_NONE && k < 200; k++) {
        struct pollfd p;
        p.fd = link_poll_fd(l, &p.events);
        p.revents = 0;
        if (p.fd < 0 || poll(&p, 1, 10) <= 0)
            continue;
        ev = link_service_fd(l, p.revents, now, err, n);
    }
    return ev;
}

static void tcp_up_lost_reopened(void **state)
{
    struct link l;
    char port[16], url[64], err[256];
    uint8_t buf[16];
    int srv = listener(SOCK_STREAM, port, sizeof(port)), peer;
    (void)state;
    snprintf(url, sizeof(url), "tcp:127.0.0.1:%s", port);
    assert_int_equal(link_parse(&l, "--sonar", url, ALL, 0, err, sizeof(err)), HOST_OK);
    assert_true(link_wake(&l) <= 0); /* due at once */
    assert_int_equal(until_event(&l, 1000, err, sizeof(err)), LINK_EV_UP);
    assert_int_equal(l.connecting, 0);
    assert_true((peer = accept(srv, NULL, NULL)) >= 0);
    assert_int_equal(link_write(&l, (const uint8_t *)"ping", 4), HOST_OK);
    assert_int_equal(read(peer, buf, sizeof(buf)), 4);
    assert_int_equal(write(peer, "pong", 4), 4);
    assert_int_equal(until_event(&l, 1000, err, sizeof(err)), LINK_EV_DATA);
    assert_int_equal(link_read(&l, buf, sizeof(buf)), 4);
    /* The peer goes: the read says so, the caller gives the link up for 2.5 s. */
    close(peer);
    assert_int_equal(until_event(&l, 1000, err, sizeof(err)), LINK_EV_DATA);
    assert_int_equal(link_read(&l, buf, sizeof(buf)), HOST_ERR_CLOSED);
    link_lost(&l, 2000, 2500000);
    assert_int_equal(l.fd, -1);
    assert_true(link_wake(&l) == 2502000);
    assert_int_equal(link_service_timers(&l, 2501999, err, sizeof(err)), LINK_EV_NONE); /* not yet */
    assert_int_equal(l.fd, -1);
    assert_int_equal(until_event(&l, 2502000, err, sizeof(err)), LINK_EV_UP);
    /* Closed for good: never due again. */
    link_close(&l);
    assert_true(link_wake(&l) == INT64_MAX);
    assert_int_equal(link_service_timers(&l, INT64_MAX - 1, err, sizeof(err)), LINK_EV_NONE);
    assert_int_equal(l.fd, -1);
    close(srv);
}

static void refused_connect_retries_a_second_later(void **state)
{
    struct link l;
    char port[16], url[64], err[256];
    int srv = listener(SOCK_STREAM, port, sizeof(port));
    (void)state;
    close(srv); /* nobody there now */
    snprintf(url, sizeof(url), "tcp:127.0.0.1:%s", port);
    assert_int_equal(link_parse(&l, "--sonar", url, ALL, 0, err, sizeof(err)), HOST_OK);
    assert_int_equal(until_event(&l, 5000, err, sizeof(err)), LINK_EV_FAILED);
    assert_non_null(strstr(err, "127.0.0.1"));
    assert_int_equal(l.fd, -1);
    assert_true(link_wake(&l) == 5000 + LINK_RETRY_US);
}

static void listener_answers_its_sender(void **state)
{
    struct link l;
    char port[16], url[64], err[256];
    uint8_t buf[16];
    struct sockaddr_in to;
    int peer = listener(SOCK_DGRAM, port, sizeof(port)), fd;
    (void)state;
    /* Find a free port for the listener, then let it bind there. */
    fd = listener(SOCK_DGRAM, port, sizeof(port));
    close(fd);
    snprintf(url, sizeof(url), "udpin:127.0.0.1:%s", port);
    assert_int_equal(link_parse(&l, "--mavlink", url, LINK_ALLOW_LISTEN, 0, err, sizeof(err)), HOST_OK);
    assert_int_equal(link_service_timers(&l, 0, err, sizeof(err)), LINK_EV_UP);
    memset(&to, 0, sizeof(to));
    to.sin_family = AF_INET;
    to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    to.sin_port = htons((uint16_t)atoi(port));
    assert_int_equal(sendto(peer, "hb", 2, 0, (struct sockaddr *)&to, sizeof(to)), 2);
    assert_int_equal(until_event(&l, 0, err, sizeof(err)), LINK_EV_DATA);
    assert_int_equal(link_read(&l, buf, sizeof(buf)), 2);
    assert_int_equal(link_read(&l, buf, sizeof(buf)), 0); /* nothing more, and a listener is never closed */
    assert_int_equal(link_send_to(&l, (const uint8_t *)"ok", 2, &l.from, l.from_len), HOST_OK);
    assert_int_equal(recv(peer, buf, sizeof(buf), 0), 2);
    assert_memory_equal(buf, "ok", 2);
    link_close(&l);
    close(peer);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(forms_and_refusals),
        cmocka_unit_test(tcp_up_lost_reopened),
        cmocka_unit_test(refused_connect_retries_a_second_later),
        cmocka_unit_test(listener_answers_its_sender),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
