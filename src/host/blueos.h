/* blueos.h -- finds a Ping360 through BlueOS's ping service (GET :9110/v1.0/sensors) for --sonar blueos[:HOST[:PORT]]; ~64 KB of stack for one reply, no heap. */
#ifndef SONARD_BLUEOS_H
#define SONARD_BLUEOS_H

#include <stddef.h>
#include <stdio.h>

#include "herr.h"

#define BLUEOS_PING_PORT 9110        /* the ping service's REST port on BlueOS */
#define BLUEOS_BRIDGE_PORT 9092      /* the first serial Ping360's bridge (UDP); more count up from it */
#define BLUEOS_REPLY_MAX 65536       /* bytes of one reply read at most; a longer one is refused */
#define BLUEOS_TRIES 3               /* asks before falling back */

/* One device from the sensors list, as far as sonard needs it. Strings are cut to fit, NUL-terminated. */
struct blueos_sensor {
    char ping_type[16];   /* "Ping360", "Ping1D", ... */
    char port[64];        /* the serial device ("" for an Ethernet one) */
    char ethernet[64];    /* "IP:PORT" for a Ping360 found by Ethernet discovery, else "" */
    long udp_port;        /* driver_status.udp_port: the bridge's UDP port; -1 when absent */
};

/* What a sensors reply held. */
struct blueos_sensors {
    struct blueos_sensor ping360; /* the first Ping360 listed (valid when found) */
    int found;                    /* 1 when a Ping360 was listed */
    int others;                   /* devices of another type (Ping1D ...) passed over */
};

/*
 * Parses the JSON body of GET /v1.0/sensors (an array of device objects with ping_type, port,
 * ethernet_discovery_info and driver_status.udp_port; other keys skipped) of len bytes.
 * Returns HOST_OK with *out filled, or HOST_ERR_ROW with err naming the byte and what was
 * expected ("byte 17: expected ':' after a key").
 */
HOST_CHECK int blueos_parse_sensors(const char *body, size_t len, struct blueos_sensors *out, char *err, size_t errlen);

/*
 * The URL --sonar takes for a parsed list: "udp:IP:PORT" of an Ethernet Ping360, else
 * "udp:HOST:UDP_PORT" of its bridge. Returns HOST_OK, or HOST_ERR_ROW with err saying why
 * (no Ping360 listed, no udp_port).
 */
HOST_CHECK int blueos_sensor_url(const struct blueos_sensors *s, const char *host, char *url, size_t cap, char *err, size_t errlen);

/*
 * Splits "blueos", "blueos:HOST" or "blueos:HOST:PORT" (HOST an IPv4 address or name, default
 * 127.0.0.1; PORT the ping service's, default 9110). Returns 1 when spec is such a form, 0 when it
 * is another URL, HOST_ERR_CONFIG (err set) when it starts with "blueos" but is malformed.
 */
int blueos_spec(const char *spec, char *host, size_t hostcap, int *port, char *err, size_t errlen);

/*
 * Asks the ping service at host:port for its sensors, at most BLUEOS_TRIES times, each bounded by
 * timeout_ms (connect, request and reply together), waiting retry_ms between tries; writes the
 * Ping360's URL into url. When no answer names a Ping360 (service absent, slow, garbage, none
 * listed) it says so once on errf (when not NULL), with the last reason, and writes the fallback
 * "udp:HOST:9092". Returns 1 when the service named the sonar, 0 when it fell back.
 */
int blueos_resolve(const char *host, int port, int timeout_ms, int retry_ms, char *url, size_t cap, FILE *errf);

#endif
