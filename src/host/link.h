/* link.h -- every live source's transport and its lifecycle, once: serial (raw termios), UDP, a UDP listener or TCP, non-blocking, opened from a URL; open, connect, bounded reads, loss, reopen after a delay; sizeof(struct link) = 592 B. */
#ifndef SONARD_LINK_H
#define SONARD_LINK_H

#include <stddef.h>
#include <stdint.h>
#include <sys/socket.h>
#include <sys/types.h>

#include "herr.h"

enum link_kind { LINK_SERIAL = 0, LINK_UDP = 1, LINK_TCP = 2, LINK_UDP_LISTEN = 3 };

/* The URL forms a caller takes (link_parse's kinds): serial:, udp: (also udpout:), tcp:, udpin:. */
#define LINK_ALLOW_SERIAL (1u << LINK_SERIAL)
#define LINK_ALLOW_UDP (1u << LINK_UDP)
#define LINK_ALLOW_TCP (1u << LINK_TCP)
#define LINK_ALLOW_LISTEN (1u << LINK_UDP_LISTEN)

#define LINK_RETRY_US 1000000 /* reopen after an open or connect that failed, or a loss with no delay of its own */
#define LINK_READS 16         /* reads per wake: a fast peer cannot starve the loop */

/* What a link did (link_service_timers, link_service_fd). */
enum link_event {
    LINK_EV_NONE = 0,
    LINK_EV_UP = 1,     /* opened (or connected): usable now */
    LINK_EV_DATA = 2,   /* readable: read at most LINK_READS times */
    LINK_EV_FAILED = 3, /* an open or connect failed: err says why; closed, reopened LINK_RETRY_US later */
    LINK_EV_HUNGUP = 4  /* the peer hung up or the device went away: the caller calls link_lost */
};

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
    int64_t reopen_at;      /* closed: open it then; INT64_MAX while open or when it stays closed */
    struct sockaddr_storage from; /* listener: the last datagram's sender */
    socklen_t from_len;
};

/*
 * Parses serial:PATH[:BAUD], udp:HOST:PORT (or udpout:), tcp:HOST:PORT or udpin:ADDR:PORT, of the
 * forms kinds allows (LINK_ALLOW_*). opt: the option it came from, for messages ("--sonar").
 * baud_opt: > 0 overrides the URL's, -1 means auto. Returns HOST_OK, or HOST_ERR_CONFIG with a
 * message naming the option and the URL part in err. The link is closed, due to open at once.
 */
HOST_CHECK int link_parse(struct link *l, const char *opt, const char *url, unsigned kinds, long baud_opt, char *err,
                          size_t errlen);

/*
 * The lifecycle. Closed and due (now >= reopen_at): opens it. Returns LINK_EV_UP (usable now),
 * LINK_EV_FAILED (err set; retried LINK_RETRY_US later) or LINK_EV_NONE (not due, open already,
 * or a TCP connect under way: link_service_fd finishes it). Also runs the line-break timers.
 */
int link_service_timers(struct link *l, int64_t now_us, char *err, size_t errlen);

/*
 * poll() said revents on the link's descriptor: LINK_EV_UP (a TCP connect finished), LINK_EV_FAILED
 * (it failed: err set, retried LINK_RETRY_US later), LINK_EV_DATA, LINK_EV_HUNGUP or LINK_EV_NONE.
 */
int link_service_fd(struct link *l, short revents, int64_t now_us, char *err, size_t errlen);

/* For poll(): the descriptor (-1 when closed) and the events wanted (POLLOUT while connecting). */
int link_poll_fd(const struct link *l, short *events);

/* The link is gone (a read said closed, the peer hung up, the device stopped answering): closed, reopened after delay_us. */
void link_lost(struct link *l, int64_t now_us, uint32_t delay_us);

/* When link_service_timers is next due: the reopen or a line-break step; INT64_MAX when neither. */
int64_t link_wake(const struct link *l);

/* Listener: sends a datagram to addr (non-blocking). Returns HOST_OK or HOST_ERR_IO. */
HOST_CHECK int link_send_to(struct link *l, const uint8_t *buf, size_t n, const struct sockaddr_storage *addr,
                            socklen_t len);

/* Reads what is there: > 0 bytes, 0 nothing now, HOST_ERR_CLOSED the link is gone (closed, unplugged, refused). A listener keeps the sender in from. */
ssize_t link_read(struct link *l, uint8_t *buf, size_t cap);

/* Writes a whole request (small: <= 40 bytes). Returns HOST_OK or HOST_ERR_IO. */
HOST_CHECK int link_write(struct link *l, const uint8_t *buf, size_t n);

/*
 * Serial: starts a 50 ms line break, then "UUU" (the device's baud detection) without blocking;
 * link_service_timers finishes it. UDP: an empty datagram, which a BlueOS bridge turns into a break. TCP: nothing.
 */
void link_line_break(struct link *l, int64_t now_us);

/* Serial auto-baud: moves to the next rate. Returns HOST_OK, or HOST_ERR_FULL when every rate was tried (it wraps). */
HOST_CHECK int link_next_baud(struct link *l);

/*
 * A link's owner (the sonar's source, the co-processor's, the autopilot's endpoint), as
 * mavlink-router's Endpoint: the lifecycle and the bounded read loop are link_serve_*'s; the owner
 * keeps only what is its own, in four callbacks.
 */
struct link_endpoint_ops {
    void (*up)(void *owner, int64_t now_us);                    /* opened or connected: usable now */
    void (*failed)(void *owner, const char *err, int64_t now_us); /* an open or connect failed; reopened LINK_RETRY_US later */
    /* n > 0 bytes read (a listener: the sender in the link's from). Returns 1 to read on, 0 to leave the rest for the next wake. */
    int (*bytes)(void *owner, const uint8_t *buf, size_t n, int64_t now_us);
    /* Gone (why: "closed", "hung up"): the owner calls link_lost with its own delay, or link_close. */
    void (*lost)(void *owner, int64_t now_us, const char *why);
    /* 1: on UDP, an error the socket reports (ICMP: nobody listening there yet) is read and forgotten, not a loss. */
    uint8_t udp_errors_soft;
};

/* poll() said revents on l's descriptor: what it means goes to the owner's callbacks (at most LINK_READS reads). */
void link_serve_fd(struct link *l, short revents, int64_t now_us, const struct link_endpoint_ops *ops, void *owner);

/* l's timers (a reopen when due, a line break's steps), their events to the owner. Returns link_wake afterwards. */
int64_t link_serve_timers(struct link *l, int64_t now_us, const struct link_endpoint_ops *ops, void *owner);

/* Closes it for good (stopping, exit): it is not reopened. */
void link_close(struct link *l);

/* Human-readable description, e.g. "udp:127.0.0.1:12345" or "serial:/dev/ttyUSB0@115200". */
const char *link_describe(const struct link *l, char *buf, size_t n);

#endif
