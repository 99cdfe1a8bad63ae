/* link.c -- non-blocking serial, UDP, UDP-listener and TCP links and their lifecycle (open, connect, lose, reopen); line breaks without sleeping; O(1) per call. */
#define _DEFAULT_SOURCE
#include "link.h"

#include <errno.h>
#include <fcntl.h>
#include <netdb.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <termios.h>
#include <unistd.h>

/*
 * Rates tried by --baud auto, highest first: Ping Viewer's list less 570600, 257600 and 250000,
 * which termios cannot set without the Linux-only BOTHER ioctl.
 */
static const long rates[] = {2000000, 921600, 460800, 230400, 115200};
#define NRATES ((int)(sizeof(rates) / sizeof(rates[0])))

static speed_t speed_of(long baud)
{
    switch (baud) {
    case 9600: return B9600;
    case 19200: return B19200;
    case 38400: return B38400;
    case 57600: return B57600;
    case 115200: return B115200;
    case 230400: return B230400;
    case 460800: return B460800;
    case 921600: return B921600;
#ifdef B2000000
    case 2000000: return B2000000;
#endif
#ifdef B3000000
    case 3000000: return B3000000;
#endif
    default: return 0;
    }
}

/* The forms kinds allows, for a message: "serial:PATH[:BAUD], udp:HOST:PORT or tcp:HOST:PORT". */
static const char *forms(unsigned kinds, char *buf, size_t n)
{
    static const char *const name[] = {"serial:PATH[:BAUD]", "udp:HOST:PORT", "tcp:HOST:PORT", "udpin:ADDR:PORT"};
    size_t k = 0;
    unsigned i, left = 0;
    for (i = 0; i < 4; i++)
        left += (kinds >> i) & 1u;
    buf[0] = '\0';
    for (i = 0; i < 4; i++) {
        if (!(kinds & (1u << i)))
            continue;
        left--;
        k += (size_t)snprintf(buf + k, k < n ? n - k : 0, "%s%s", name[i], left == 0 ? "" : left == 1 ? " or " : ", ");
    }
    return buf;
}

/* "HOST:PORT" after a scheme, split at the last colon; the port 1..65535. Returns 0 or -1. */
static int host_port(struct link *l, const char *rest)
{
    const char *colon = strrchr(rest, ':');
    if (colon == NULL || colon == rest || colon[1] == '\0' || strlen(colon + 1) >= sizeof(l->port) ||
        (size_t)(colon - rest) >= sizeof(l->host) || strspn(colon + 1, "0123456789") != strlen(colon + 1) ||
        atoi(colon + 1) < 1 || atoi(colon + 1) > 65535)
        return -1;
    /* [v6]:PORT: the brackets only mark where the address ends */
    if (rest[0] == '[' && colon[-1] == ']')
        snprintf(l->host, sizeof(l->host), "%.*s", (int)(colon - rest) - 2, rest + 1);
    else
        snprintf(l->host, sizeof(l->host), "%.*s", (int)(colon - rest), rest);
    snprintf(l->port, sizeof(l->port), "%s", colon + 1);
    return 0;
}

int link_parse(struct link *l, const char *opt, const char *url, unsigned kinds, long baud_opt, char *err, size_t errlen)
{
    static const struct { const char *scheme; int kind; } net[] = {
        {"udp:", LINK_UDP}, {"udpout:", LINK_UDP}, {"tcp:", LINK_TCP}, {"udpin:", LINK_UDP_LISTEN}};
    char f[128];
    const char *rest;
    size_t i;
    memset(l, 0, sizeof(*l));
    l->fd = -1;
    l->break_clear_at = l->send_u_at = INT64_MAX;
    l->reopen_at = INT64_MIN; /* due at once */
    if (strncmp(url, "serial:", 7) == 0 && (kinds & LINK_ALLOW_SERIAL)) {
        const char *colon;
        rest = url + 7;
        colon = strrchr(rest, ':');
        l->kind = LINK_SERIAL;
        l->baud = 115200;
        if (colon != NULL) {
            char *end;
            long b = strtol(colon + 1, &end, 10);
            if (*end != '\0' || speed_of(b) == 0) {
                snprintf(err, errlen, "%s %s: baud '%s' is not one termios supports (9600..3000000)", opt, url, colon + 1);
                return HOST_ERR_CONFIG;
            }
            l->baud = b;
            snprintf(l->path, sizeof(l->path), "%.*s", (int)(colon - rest), rest);
        } else {
            snprintf(l->path, sizeof(l->path), "%s", rest);
        }
        if (l->path[0] == '\0') {
            snprintf(err, errlen, "%s %s: no device path", opt, url);
            return HOST_ERR_CONFIG;
        }
        if (baud_opt == -1) {
            l->autobaud = 1;
            l->baud = rates[0];
        } else if (baud_opt > 0) {
            if (speed_of(baud_opt) == 0) {
                snprintf(err, errlen, "--baud %ld: not a rate termios supports", baud_opt);
                return HOST_ERR_CONFIG;
            }
            l->baud = baud_opt;
        }
        return HOST_OK;
    }
    for (i = 0; i < sizeof(net) / sizeof(net[0]); i++) {
        size_t k = strlen(net[i].scheme);
        if (strncmp(url, net[i].scheme, k) != 0 || !(kinds & (1u << net[i].kind)))
            continue;
        l->kind = net[i].kind;
        if (host_port(l, url + k) != 0) {
            snprintf(err, errlen, "%s %s: expected %.*sHOST:PORT with a port 1..65535", opt, url, (int)k, net[i].scheme);
            return HOST_ERR_CONFIG;
        }
        return HOST_OK;
    }
    snprintf(err, errlen, "%s %s: not %s", opt, url, forms(kinds, f, sizeof(f)));
    return HOST_ERR_CONFIG;
}

static int open_serial(struct link *l, char *err, size_t errlen)
{
    struct termios t;
    int fd = open(l->path, O_RDWR | O_NOCTTY | O_NONBLOCK);
    if (fd < 0) {
        snprintf(err, errlen, "%s: %s", l->path, strerror(errno));
        return -1;
    }
    if (tcgetattr(fd, &t) != 0) {
        snprintf(err, errlen, "%s: not a serial port (%s)", l->path, strerror(errno));
        close(fd);
        return -1;
    }
    cfmakeraw(&t);
    t.c_cflag |= CLOCAL | CREAD;
    t.c_cc[VMIN] = 0;
    t.c_cc[VTIME] = 0;
    cfsetispeed(&t, speed_of(l->baud));
    cfsetospeed(&t, speed_of(l->baud));
    if (tcsetattr(fd, TCSANOW, &t) != 0) {
        snprintf(err, errlen, "%s: cannot set %ld baud (%s)", l->path, l->baud, strerror(errno));
        close(fd);
        return -1;
    }
    tcflush(fd, TCIOFLUSH);
    l->fd = fd;
    return 0;
}

static int open_socket(struct link *l, char *err, size_t errlen)
{
    struct addrinfo hints, *res = NULL;
    int fd, r;
    memset(&hints, 0, sizeof(hints));
    hints.ai_family = AF_UNSPEC;
    hints.ai_socktype = l->kind == LINK_TCP ? SOCK_STREAM : SOCK_DGRAM;
    hints.ai_flags = AI_NUMERICSERV | (l->kind == LINK_UDP_LISTEN ? AI_PASSIVE : 0);
    if ((r = getaddrinfo(l->host, l->port, &hints, &res)) != 0) {
        snprintf(err, errlen, "%s:%s: %s", l->host, l->port, gai_strerror(r));
        return -1;
    }
    fd = socket(res->ai_family, res->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (fd < 0) {
        snprintf(err, errlen, "socket: %s", strerror(errno));
        freeaddrinfo(res);
        return -1;
    }
    if (l->kind == LINK_UDP_LISTEN) {
        r = bind(fd, res->ai_addr, res->ai_addrlen);
        freeaddrinfo(res);
        if (r != 0) {
            snprintf(err, errlen, "%s:%s: cannot bind: %s", l->host, l->port, strerror(errno));
            close(fd);
            return -1;
        }
        l->fd = fd;
        return 0;
    }
    r = connect(fd, res->ai_addr, res->ai_addrlen);
    freeaddrinfo(res);
    if (r != 0 && errno != EINPROGRESS) {
        snprintf(err, errlen, "%s:%s: %s", l->host, l->port, strerror(errno));
        close(fd);
        return -1;
    }
    l->fd = fd;
    l->connecting = r != 0;
    return 0;
}

static int link_open(struct link *l, int64_t now_us, char *err, size_t errlen)
{
    int r;
    l->break_clear_at = l->send_u_at = INT64_MAX;
    if (l->kind == LINK_SERIAL) {
        if ((r = open_serial(l, err, errlen)) == 0)
            link_line_break(l, now_us); /* the device detects our baud rate from "U" after a break */
        return r;
    }
    return open_socket(l, err, errlen);
}

static int link_finish_connect(struct link *l, char *err, size_t errlen)
{
    int e = 0;
    socklen_t len = sizeof(e);
    if (getsockopt(l->fd, SOL_SOCKET, SO_ERROR, &e, &len) != 0 || e != 0) {
        snprintf(err, errlen, "%s:%s: %s", l->host, l->port, strerror(e ? e : errno));
        return HOST_ERR_IO;
    }
    l->connecting = 0;
    return HOST_OK;
}

ssize_t link_read(struct link *l, uint8_t *buf, size_t cap)
{
    ssize_t n;
    if (l->fd < 0)
        return HOST_ERR_CLOSED;
    if (l->kind == LINK_UDP_LISTEN) {
        l->from_len = sizeof(l->from);
        n = recvfrom(l->fd, buf, cap, MSG_DONTWAIT, (struct sockaddr *)&l->from, &l->from_len);
        return n >= 0 ? n : 0; /* a listener is never closed by its peers */
    }
    n = read(l->fd, buf, cap);
    if (n > 0)
        return n;
    if (n == 0) /* TCP: closed. Serial with VMIN = 0: just nothing yet (a hang-up shows as POLLHUP or EIO). */
        return l->kind == LINK_TCP ? HOST_ERR_CLOSED : 0;
    return errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR ? 0 : HOST_ERR_CLOSED;
}

int link_write(struct link *l, const uint8_t *buf, size_t n)
{
    ssize_t w;
    if (l->fd < 0 || l->connecting)
        return HOST_ERR_IO;
    w = write(l->fd, buf, n);
    /* A full kernel buffer for a 24-byte request means the link is stuck: the timeout will retry. */
    return w == (ssize_t)n ? HOST_OK : HOST_ERR_IO;
}

void link_line_break(struct link *l, int64_t now_us)
{
    if (l->fd < 0)
        return;
    if (l->kind == LINK_UDP) {
        /* Best effort, here and below: a lost break or "UUU" only costs a probe timeout, which retries. */
        (void)write(l->fd, "", 0);
    } else if (l->kind == LINK_SERIAL && l->break_clear_at == INT64_MAX) {
        if (ioctl(l->fd, TIOCSBRK) == 0)
            l->break_clear_at = now_us + 50000;
        else
            l->send_u_at = now_us; /* a pty cannot break: just send the U's */
    }
}

/* The line-break steps. Returns the next time it needs a call, or INT64_MAX. */
static int64_t link_timers(struct link *l, int64_t now_us)
{
    if (l->fd >= 0 && now_us >= l->break_clear_at) {
        (void)ioctl(l->fd, TIOCCBRK);
        l->break_clear_at = INT64_MAX;
        l->send_u_at = now_us + 11000; /* Ping Viewer waits 11 ms after the break */
    }
    if (l->fd >= 0 && now_us >= l->send_u_at) {
        (void)write(l->fd, "UUU", 3);
        l->send_u_at = INT64_MAX;
    }
    return l->break_clear_at < l->send_u_at ? l->break_clear_at : l->send_u_at;
}

int link_next_baud(struct link *l)
{
    if (!l->autobaud)
        return HOST_ERR_FULL;
    l->baud_index = (l->baud_index + 1) % NRATES;
    l->baud = rates[l->baud_index];
    return l->baud_index == 0 ? -1 : 0;
}

static void shut(struct link *l)
{
    if (l->fd >= 0)
        close(l->fd);
    l->fd = -1;
    l->connecting = 0;
    l->break_clear_at = l->send_u_at = INT64_MAX;
}

void link_close(struct link *l)
{
    shut(l);
    l->reopen_at = INT64_MAX;
}

void link_lost(struct link *l, int64_t now_us, uint32_t delay_us)
{
    shut(l);
    l->reopen_at = now_us + (int64_t)delay_us;
}

int link_service_timers(struct link *l, int64_t now_us, char *err, size_t errlen)
{
    int ev = LINK_EV_NONE;
    if (l->fd < 0 && now_us >= l->reopen_at) {
        l->reopen_at = INT64_MAX;
        if (link_open(l, now_us, err, errlen) != 0) {
            link_lost(l, now_us, LINK_RETRY_US);
            return LINK_EV_FAILED;
        }
        ev = l->connecting ? LINK_EV_NONE : LINK_EV_UP;
    }
    (void)link_timers(l, now_us);
    return ev;
}

int link_service_fd(struct link *l, short revents, int64_t now_us, char *err, size_t errlen)
{
    if (l->fd < 0)
        return LINK_EV_NONE;
    if (l->connecting) {
        if (!(revents & (POLLOUT | POLLERR | POLLHUP)))
            return LINK_EV_NONE;
        if (link_finish_connect(l, err, errlen) != HOST_OK) {
            link_lost(l, now_us, LINK_RETRY_US);
            return LINK_EV_FAILED;
        }
        return LINK_EV_UP;
    }
    if (revents & POLLIN)
        return LINK_EV_DATA;
    /* the serial adapter was unplugged, or the peer hung up, with nothing left to read */
    return revents & (POLLERR | POLLHUP | POLLNVAL) ? LINK_EV_HUNGUP : LINK_EV_NONE;
}

int link_poll_fd(const struct link *l, short *events)
{
    *events = (short)(l->connecting ? POLLOUT : POLLIN);
    return l->fd;
}

int64_t link_wake(const struct link *l)
{
    int64_t w = l->fd < 0 ? l->reopen_at : INT64_MAX;
    if (l->break_clear_at < w)
        w = l->break_clear_at;
    if (l->send_u_at < w)
        w = l->send_u_at;
    return w;
}

int link_send_to(struct link *l, const uint8_t *buf, size_t n, const struct sockaddr_storage *addr, socklen_t len)
{
    if (l->fd < 0)
        return HOST_ERR_IO;
    /* Non-blocking: a full socket drops this datagram, never the loop's time. */
    return sendto(l->fd, buf, n, MSG_DONTWAIT, (const struct sockaddr *)addr, len) == (ssize_t)n ? HOST_OK : HOST_ERR_IO;
}

const char *link_describe(const struct link *l, char *buf, size_t n)
{
    if (l->kind == LINK_SERIAL)
        snprintf(buf, n, "serial:%s@%ld", l->path, l->baud);
    else
        snprintf(buf, n, strchr(l->host, ':') ? "%s:[%s]:%s" : "%s:%s:%s", l->kind == LINK_UDP ? "udp" : l->kind == LINK_TCP ? "tcp" : "udpin",
                 l->host, l->port);
    return buf;
}

/* What the link reads goes to the owner; a read that says closed is a loss, unless it is a UDP socket's soft error. */
static void serve_read(struct link *l, int64_t now, const struct link_endpoint_ops *ops, void *owner)
{
    uint8_t buf[4096];
    int reads;
    for (reads = 0; reads < LINK_READS; reads++) {
        ssize_t n = link_read(l, buf, sizeof(buf));
        if (n < 0) {
            if (!(ops->udp_errors_soft && l->kind != LINK_SERIAL))
                ops->lost(owner, now, "closed");
            return;
        }
        if (n == 0 || !ops->bytes(owner, buf, (size_t)n, now))
            return;
    }
}

static void serve(struct link *l, int ev, const char *err, int64_t now, const struct link_endpoint_ops *ops, void *owner)
{
    switch (ev) {
    case LINK_EV_UP:
        ops->up(owner, now);
        break;
    case LINK_EV_FAILED:
        ops->failed(owner, err, now);
        break;
    case LINK_EV_DATA:
        serve_read(l, now, ops, owner);
        break;
    case LINK_EV_HUNGUP:
        if (ops->udp_errors_soft && l->kind != LINK_SERIAL)
            serve_read(l, now, ops, owner);
        else
            ops->lost(owner, now, "hung up");
        break;
    default:
        break;
    }
}

void link_serve_fd(struct link *l, short revents, int64_t now_us, const struct link_endpoint_ops *ops, void *owner)
{
    char err[256];
    serve(l, link_service_fd(l, revents, now_us, err, sizeof(err)), err, now_us, ops, owner);
}

int64_t link_serve_timers(struct link *l, int64_t now_us, const struct link_endpoint_ops *ops, void *owner)
{
    char err[256];
    serve(l, link_service_timers(l, now_us, err, sizeof(err)), err, now_us, ops, owner);
    return link_wake(l);
}
