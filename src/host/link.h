/* link.h -- the sonar's transport: serial (raw termios), UDP or TCP, all non-blocking, opened from a URL. */
#ifndef SONARD_LINK_H
#define SONARD_LINK_H

#include <stddef.h>
#include <stdint.h>
#include <sys/types.h>

#include "herr.h"

enum link_kind { LINK_SERIAL = 0, LINK_UDP = 1, LINK_TCP = 2 };

struct link {
    int kind;
    int fd;          /* -1 when closed */
    int connecting;  /* TCP connect in progress: wait for POLLOUT */
    char path[256];  /* serial device */
    char host[128];
    char port[16];
    long baud;       /* serial bits/s */
    int autobaud;    /* cycle through link_baud_rates on failed probes */
    int baud_index;
    int64_t break_clear_at; /* serial line break in progress: clear it then */
    int64_t send_u_at;      /* then send "UUU" for the device's baud detection */
};

/*
 * Parses serial:PATH[:BAUD], udp:HOST:PORT or tcp:HOST:PORT. baud_opt: > 0 overrides the URL's,
 * -1 means auto. Returns HOST_OK, or HOST_ERR_CONFIG with a message naming the URL part in err.
 */
HOST_CHECK int link_parse(struct link *l, const char *url, long baud_opt, char *err, size_t errlen);

/* Opens (TCP: starts connecting). Returns HOST_OK, or HOST_ERR_IO with err set (errno kept). */
HOST_CHECK int link_open(struct link *l, int64_t now_us, char *err, size_t errlen);

/* TCP: after POLLOUT, HOST_OK if connected, HOST_ERR_IO (err set) if the connect failed. */
HOST_CHECK int link_finish_connect(struct link *l, char *err, size_t errlen);

/* Reads what is there: > 0 bytes, 0 nothing now, HOST_ERR_CLOSED the link is gone (closed, unplugged, refused). */
ssize_t link_read(struct link *l, uint8_t *buf, size_t cap);

/* Writes a whole request (small: <= 40 bytes). Returns HOST_OK or HOST_ERR_IO. */
HOST_CHECK int link_write(struct link *l, const uint8_t *buf, size_t n);

/*
 * Serial: starts a 50 ms line break, then "UUU" (the device's baud detection) without blocking;
 * link_timers finishes it. UDP: an empty datagram, which a BlueOS bridge turns into a break. TCP: nothing.
 */
void link_line_break(struct link *l, int64_t now_us);

/* Runs the line-break timers. Returns the next time it needs a call, or INT64_MAX. */
int64_t link_timers(struct link *l, int64_t now_us);

/* Serial auto-baud: moves to the next rate. Returns HOST_OK, or SONAR_ERR_RANGE when every rate was tried (it wraps). */
HOST_CHECK int link_next_baud(struct link *l);

void link_close(struct link *l);

/* Human-readable description, e.g. "udp:127.0.0.1:12345" or "serial:/dev/ttyUSB0@115200". */
const char *link_describe(const struct link *l, char *buf, size_t n);

#endif
