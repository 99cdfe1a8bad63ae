/* blueos.c -- the ping service's sensor list: one bounded HTTP/1.0 GET, a strict JSON walk over its array, the Ping360's URL; O(reply) per ask, no heap. */
#include "blueos.h"

#include <errno.h>
#include <netdb.h>
#include <poll.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>
#include <fcntl.h>

#define DEPTH_MAX 16 /* nesting skipped at most: the service's objects are two deep */

struct walk {
    const char *s;
    size_t len, at;
    char *err;
    size_t errlen;
    int depth;
};

static int fail(struct walk *w, const char *what)
{
    if (w->err != NULL && w->errlen > 0)
        snprintf(w->err, w->errlen, "byte %zu: %s", w->at, what);
    return HOST_ERR_ROW;
}

static void blanks(struct walk *w)
{
    while (w->at < w->len && (w->s[w->at] == ' ' || w->s[w->at] == '\t' || w->s[w->at] == '\r' || w->s[w->at] == '\n'))
        w->at++;
}

static int peek(struct walk *w)
{
    blanks(w);
    return w->at < w->len ? (unsigned char)w->s[w->at] : -1;
}

/* A string into out (cut to cap - 1; escapes kept as the escaped character, \u as '?'), or skipped when out is NULL. */
static int string(struct walk *w, char *out, size_t cap)
{
    size_t n = 0;
    if (peek(w) != '"')
        return fail(w, "expected a string");
    w->at++;
    while (w->at < w->len) {
        char c = w->s[w->at++];
        if (c == '"') {
            if (out != NULL && cap > 0)
                out[n < cap ? n : cap - 1] = '\0';
            return HOST_OK;
        }
        if ((unsigned char)c < 0x20)
            return fail(w, "control character in a string");
        if (c == '\\') {
            if (w->at >= w->len)
                break;
            c = w->s[w->at++];
            if (c == 'u') {
                if (w->len - w->at < 4)
                    break;
                w->at += 4;
                c = '?';
            }
        }
        if (out != NULL && n + 1 < cap)
            out[n++] = c;
    }
    return fail(w, "string not closed");
}

static int value(struct walk *w, char *out, size_t cap, long *num);

/* Numbers, true, false and null: their bytes; a number's integer part into *num when asked. */
static int scalar(struct walk *w, long *num)
{
    size_t start = w->at;
    static const char *const words[] = {"true", "false", "null"};
    size_t i;
    for (i = 0; i < 3; i++) {
        size_t k = strlen(words[i]);
        if (w->len - w->at >= k && memcmp(w->s + w->at, words[i], k) == 0) {
            w->at += k;
            return HOST_OK;
        }
    }
    if (w->at < w->len && w->s[w->at] == '-')
        w->at++;
    while (w->at < w->len && (strchr("0123456789.eE+-", w->s[w->at]) != NULL) && w->s[w->at] != '\0')
        w->at++;
    if (w->at == start || (w->at == start + 1 && w->s[start] == '-'))
        return fail(w, "expected a value");
    if (num != NULL) {
        char tmp[32];
        size_t n = w->at - start < sizeof tmp - 1 ? w->at - start : sizeof tmp - 1;
        char *end;
        memcpy(tmp, w->s + start, n);
        tmp[n] = '\0';
        errno = 0;
        *num = strtol(tmp, &end, 10);
        if (errno != 0 || (*end != '\0' && *end != '.'))
            *num = -1;
    }
    return HOST_OK;
}

/* Calls each(key) on every member of an object; each reads the value. */
typedef int (*member_fn)(struct walk *w, const char *key, void *user);

static int object(struct walk *w, member_fn each, void *user)
{
    char key[32];
    int rc;
    if (peek(w) != '{')
        return fail(w, "expected an object");
    if (++w->depth > DEPTH_MAX)
        return fail(w, "nested too deep");
    w->at++;
    if (peek(w) == '}') {
        w->at++;
        w->depth--;
        return HOST_OK;
    }
    for (;;) {
        if ((rc = string(w, key, sizeof key)) != HOST_OK)
            return rc;
        if (peek(w) != ':')
            return fail(w, "expected ':' after a key");
        w->at++;
        rc = each != NULL ? each(w, key, user) : value(w, NULL, 0, NULL);
        if (rc != HOST_OK)
            return rc;
        rc = peek(w);
        if (rc != '}' && rc != ',')
            return fail(w, "expected ',' or '}' in an object");
        w->at++;
        if (rc == '}')
            break;
    }
    w->depth--;
    return HOST_OK;
}

static int value(struct walk *w, char *out, size_t cap, long *num)
{
    int c = peek(w), rc;
    if (out != NULL && cap > 0)
        out[0] = '\0';
    if (c == '"')
        return string(w, out, cap);
    if (c == '{')
        return object(w, NULL, NULL);
    if (c == '[') {
        if (++w->depth > DEPTH_MAX)
            return fail(w, "nested too deep");
        w->at++;
        if (peek(w) == ']') {
            w->at++;
            w->depth--;
            return HOST_OK;
        }
        for (;;) {
            if ((rc = value(w, NULL, 0, NULL)) != HOST_OK)
                return rc;
            c = peek(w);
            if (c != ']' && c != ',')
                return fail(w, "expected ',' or ']' in an array");
            w->at++;
            if (c == ']')
                break;
        }
        w->depth--;
        return HOST_OK;
    }
    if (c < 0)
        return fail(w, "the reply ends before a value");
    return scalar(w, num);
}

static int driver_member(struct walk *w, const char *key, void *user)
{
    struct blueos_sensor *d = user;
    if (strcmp(key, "udp_port") == 0 && peek(w) != '"' && peek(w) != '{' && peek(w) != '[')
        return value(w, NULL, 0, &d->udp_port);
    return value(w, NULL, 0, NULL);
}

static int sensor_member(struct walk *w, const char *key, void *user)
{
    struct blueos_sensor *d = user;
    if (strcmp(key, "ping_type") == 0)
        return value(w, d->ping_type, sizeof d->ping_type, NULL);
    if (strcmp(key, "port") == 0)
        return value(w, d->port, sizeof d->port, NULL);
    if (strcmp(key, "ethernet_discovery_info") == 0)
        return value(w, d->ethernet, sizeof d->ethernet, NULL);
    if (strcmp(key, "driver_status") == 0 && peek(w) == '{')
        return object(w, driver_member, d);
    return value(w, NULL, 0, NULL);
}

int blueos_parse_sensors(const char *body, size_t len, struct blueos_sensors *out, char *err, size_t errlen)
{
    struct walk w;
    int c, rc;
    if (body == NULL || out == NULL)
        return HOST_ERR_CONFIG;
    memset(out, 0, sizeof *out);
    memset(&w, 0, sizeof w);
    w.s = body;
    w.len = len;
    w.err = err;
    w.errlen = errlen;
    if (peek(&w) != '[')
        return fail(&w, "expected the sensors' array");
    w.at++;
    if (peek(&w) != ']') {
        for (;;) {
            struct blueos_sensor d;
            memset(&d, 0, sizeof d);
            d.udp_port = -1;
            if ((rc = object(&w, sensor_member, &d)) != HOST_OK)
                return rc;
            if (strcmp(d.ping_type, "Ping360") == 0) {
                if (!out->found)
                    out->ping360 = d;
                out->found = 1;
            } else {
                out->others++;
            }
            c = peek(&w);
            if (c != ']' && c != ',')
                return fail(&w, "expected ',' or ']' between sensors");
            w.at++;
            if (c == ']')
                break;
        }
    } else {
        w.at++;
    }
    if (peek(&w) != -1)
        return fail(&w, "bytes after the sensors' array");
    return HOST_OK;
}

int blueos_sensor_url(const struct blueos_sensors *s, const char *host, char *url, size_t cap, char *err, size_t errlen)
{
    const struct blueos_sensor *d = &s->ping360;
    if (!s->found) {
        snprintf(err, errlen, "no Ping360 listed (%d other device%s)", s->others, s->others == 1 ? "" : "s");
        return HOST_ERR_ROW;
    }
    if (d->ethernet[0] != '\0' && strchr(d->ethernet, ':') != NULL && strchr(d->ethernet, ' ') == NULL) {
        snprintf(url, cap, "udp:%s", d->ethernet);
        return HOST_OK;
    }
    if (d->udp_port < 1 || d->udp_port > 65535) {
        snprintf(err, errlen, "the Ping360 on '%s' has no bridge port (driver_status.udp_port)", d->port);
        return HOST_ERR_ROW;
    }
    snprintf(url, cap, "udp:%s:%ld", host, d->udp_port);
    return HOST_OK;
}

int blueos_spec(const char *spec, char *host, size_t hostcap, int *port, char *err, size_t errlen)
{
    const char *h, *colon;
    size_t hl;
    if (strncmp(spec, "blueos", 6) != 0 || (spec[6] != '\0' && spec[6] != ':'))
        return 0;
    *port = BLUEOS_PING_PORT;
    h = spec[6] == ':' ? spec + 7 : "127.0.0.1";
    colon = strchr(h, ':');
    hl = colon != NULL ? (size_t)(colon - h) : strlen(h);
    if (hl == 0 || hl >= hostcap) {
        snprintf(err, errlen, "--sonar %s: blueos[:HOST[:PORT]] wants a host of 1..%zu characters", spec, hostcap - 1);
        return HOST_ERR_CONFIG;
    }
    memcpy(host, h, hl);
    host[hl] = '\0';
    if (colon != NULL) {
        char *end;
        long p = strtol(colon + 1, &end, 10);
        if (*end != '\0' || p < 1 || p > 65535) {
            snprintf(err, errlen, "--sonar %s: the ping service's port '%s' is not 1..65535", spec, colon + 1);
            return HOST_ERR_CONFIG;
        }
        *port = (int)p;
    }
    return 1;
}

static int64_t now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (int64_t)t.tv_sec * 1000 + t.tv_nsec / 1000000;
}

/* Waits for ev on fd until deadline; 1 ready, 0 timed out, -1 error. */
static int wait_fd(int fd, short ev, int64_t deadline)
{
    for (;;) {
        struct pollfd p;
        int64_t left = deadline - now_ms();
        int r;
        if (left <= 0)
            return 0;
        p.fd = fd;
        p.events = ev;
        p.revents = 0;
        r = poll(&p, 1, (int)left);
        if (r < 0 && errno == EINTR)
            continue;
        return r < 0 ? -1 : r;
    }
}

/* An HTTP reply of got bytes in buf: its body moved to buf's start (NUL-terminated), its length returned; < 0 with why. */
static long http_body(char *buf, size_t got, char *why, size_t whylen)
{
    char *body;
    long n;
    if (got < 12 || strncmp(buf, "HTTP/1.", 7) != 0) {
        snprintf(why, whylen, "not an HTTP reply (%zu bytes)", got);
        return -1;
    }
    if (strncmp(buf + 9, "200", 3) != 0) {
        snprintf(why, whylen, "HTTP status %.3s", buf + 9);
        return -1;
    }
    body = strstr(buf, "\r\n\r\n");
    if (body == NULL) {
        snprintf(why, whylen, "the reply's header never ends");
        return -1;
    }
    body += 4;
    n = (long)(got - (size_t)(body - buf));
    memmove(buf, body, (size_t)n + 1);
    return n;
}

/* One GET /v1.0/sensors: the body into buf (NUL-terminated), its length returned, or < 0 with why. */
static long fetch(const char *host, int port, int timeout_ms, char *buf, size_t cap, char *why, size_t whylen)
{
    struct addrinfo hints, *ai = NULL;
    char ports[8], req[256];
    int64_t deadline = now_ms() + timeout_ms;
    size_t got = 0, sent = 0, reqlen;
    long rc = -1;
    int fd = -1, r;
    memset(&hints, 0, sizeof hints);
    hints.ai_family = AF_UNSPEC;
    hints.ai_socktype = SOCK_STREAM;
    snprintf(ports, sizeof ports, "%d", port);
    if ((r = getaddrinfo(host, ports, &hints, &ai)) != 0) {
        snprintf(why, whylen, "%s: %s", host, gai_strerror(r));
        return -1;
    }
    fd = socket(ai->ai_family, SOCK_STREAM, 0);
    if (fd < 0 || fcntl(fd, F_SETFL, O_NONBLOCK) != 0) {
        snprintf(why, whylen, "socket: %s", strerror(errno));
        goto out;
    }
    if (connect(fd, ai->ai_addr, ai->ai_addrlen) != 0 && errno != EINPROGRESS) {
        snprintf(why, whylen, "connect: %s", strerror(errno));
        goto out;
    }
    reqlen = (size_t)snprintf(req, sizeof req, "GET /v1.0/sensors HTTP/1.0\r\nHost: %s:%d\r\nAccept: application/json\r\n\r\n", host, port);
    while (sent < reqlen) {
        ssize_t n;
        if ((r = wait_fd(fd, POLLOUT, deadline)) <= 0) {
            snprintf(why, whylen, r == 0 ? "no connection within %d ms" : "poll: %d", r == 0 ? timeout_ms : errno);
            goto out;
        }
        n = send(fd, req + sent, reqlen - sent, MSG_NOSIGNAL);
        if (n < 0 && errno != EAGAIN && errno != EINTR) {
            snprintf(why, whylen, "connect: %s", strerror(errno));
            goto out;
        }
        if (n > 0)
            sent += (size_t)n;
    }
    for (;;) {
        ssize_t n;
        if ((r = wait_fd(fd, POLLIN, deadline)) <= 0) {
            snprintf(why, whylen, r == 0 ? "no whole reply within %d ms" : "poll: %d", r == 0 ? timeout_ms : errno);
            goto out;
        }
        if (got + 1 >= cap) {
            snprintf(why, whylen, "reply longer than %zu bytes", cap - 1);
            goto out;
        }
        n = recv(fd, buf + got, cap - 1 - got, 0);
        if (n == 0)
            break;
        if (n < 0) {
            if (errno == EAGAIN || errno == EINTR)
                continue;
            snprintf(why, whylen, "read: %s", strerror(errno));
            goto out;
        }
        got += (size_t)n;
    }
    buf[got] = '\0';
    rc = http_body(buf, got, why, whylen);
out:
    if (fd >= 0)
        close(fd);
    freeaddrinfo(ai);
    return rc;
}

int blueos_resolve(const char *host, int port, int timeout_ms, int retry_ms, char *url, size_t cap, FILE *errf)
{
    char buf[BLUEOS_REPLY_MAX];
    char why[160] = "";
    int i;
    for (i = 0; i < BLUEOS_TRIES; i++) {
        struct blueos_sensors s;
        char perr[96];
        long n;
        if (i > 0 && retry_ms > 0) {
            struct timespec t;
            t.tv_sec = retry_ms / 1000;
            t.tv_nsec = (long)(retry_ms % 1000) * 1000000L;
            nanosleep(&t, NULL);
        }
        n = fetch(host, port, timeout_ms, buf, sizeof buf, why, sizeof why);
        if (n < 0)
            continue;
        if (blueos_parse_sensors(buf, (size_t)n, &s, perr, sizeof perr) != HOST_OK) {
            snprintf(why, sizeof why, "not a sensors list: %s", perr);
            continue;
        }
        if (blueos_sensor_url(&s, host, url, cap, perr, sizeof perr) != HOST_OK) {
            snprintf(why, sizeof why, "%s", perr);
            continue;
        }
        return 1;
    }
    snprintf(url, cap, "udp:%s:%d", host, BLUEOS_BRIDGE_PORT);
    if (errf != NULL)
        fprintf(errf, "sonard: warning: the ping service at %s:%d named no Ping360 in %d tries (%s); using %s, "
                "the first Ping360 bridge\n", host, port, BLUEOS_TRIES, why, url);
    return 0;
}
