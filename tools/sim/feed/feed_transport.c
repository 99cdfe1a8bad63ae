/* feed_transport.c -- sonar-feed's clock, event log and link to sonard: TCP (one client), UDP (the last sender), or a pty behind a symlink; writes block at most 100 ms a poll. */
#define _GNU_SOURCE
#include "feed.h"

double feed_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + (double)t.tv_nsec * 1e-9;
}

void feed_log(struct feed *f, const char *fmt, const char *what, long v)
{
    if (f->log != NULL) {
        fprintf(f->log, fmt, what, v);
        fflush(f->log);
    }
}

int feed_send_bytes(struct feed *f, const uint8_t *b, size_t n)
{
    ssize_t w;
    if (f->cfd < 0)
        return -1;
    if (f->transport == T_UDP) {
        if (!f->have_peer)
            return -1;
        w = sendto(f->cfd, b, n, 0, (const struct sockaddr *)&f->peer, sizeof(f->peer));
    } else {
        size_t off = 0;
        while (off < n) {
            w = write(f->cfd, b + off, n - off);
            if (w < 0 && (errno == EAGAIN || errno == EINTR)) {
                struct pollfd p = {f->cfd, POLLOUT, 0};
                poll(&p, 1, 100);
                continue;
            }
            if (w <= 0)
                return -1;
            off += (size_t)w;
        }
        return 0;
    }
    return w == (ssize_t)n ? 0 : -1;
}

void feed_close_client(struct feed *f)
{
    if (f->transport == T_UDP) {
        f->have_peer = 0; /* UDP "disconnect": forget the host, which must send again */
        return;
    }
    if (f->cfd >= 0)
        close(f->cfd);
    f->cfd = -1;
}

int feed_open_pty(struct feed *f)
{
    struct termios t;
    char *name;
    int m = posix_openpt(O_RDWR | O_NOCTTY | O_NONBLOCK);
    if (m < 0 || grantpt(m) != 0 || unlockpt(m) != 0 || (name = ptsname(m)) == NULL) {
        perror("sonar_feed: pty");
        return -1;
    }
    if (tcgetattr(m, &t) == 0) {
        cfmakeraw(&t);
        tcsetattr(m, TCSANOW, &t);
    }
    unlink(f->pty_link);
    if (symlink(name, f->pty_link) != 0) {
        perror(f->pty_link);
        close(m);
        return -1;
    }
    f->cfd = m;
    return 0;
}

int feed_setup(struct feed *f)
{
    struct sockaddr_in a;
    int one = 1;
    f->cfd = f->lfd = -1;
    if (f->transport == T_PTY)
        return feed_open_pty(f);
    memset(&a, 0, sizeof(a));
    a.sin_family = AF_INET;
    a.sin_port = htons((uint16_t)f->port);
    if (inet_pton(AF_INET, f->host, &a.sin_addr) != 1) {
        fprintf(stderr, "sonar_feed: '%s' is not an IPv4 address\n", f->host);
        return -1;
    }
    if (f->transport == T_UDP) {
        f->cfd = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK, 0);
        if (f->cfd < 0 || bind(f->cfd, (struct sockaddr *)&a, sizeof(a)) != 0) {
            perror("sonar_feed: udp");
            return -1;
        }
        return 0;
    }
    f->lfd = socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK, 0);
    setsockopt(f->lfd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
    if (f->lfd < 0 || bind(f->lfd, (struct sockaddr *)&a, sizeof(a)) != 0 || listen(f->lfd, 1) != 0) {
        perror("sonar_feed: tcp");
        return -1;
    }
    return 0;
}
