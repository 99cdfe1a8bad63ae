/* discover.h -- finds Ethernet Ping360s the way Blue Robotics' software does ("Discovery" to UDP 30303, the device's text reply), then asks each for its firmware; ~8 KB of stack (one Ping Protocol parser), no heap. */
#ifndef SONARD_DISCOVER_H
#define SONARD_DISCOVER_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "herr.h"

#define DISCOVER_PORT 30303        /* the device's discovery port */
#define DISCOVER_DATA_PORT 12345   /* the device's Ping Protocol port */
#define DISCOVER_MAX_DEVICES 16    /* devices listed by one run; more are counted, not listed */

/* One device, as its reply describes it. */
struct discover_device {
    char name[32];      /* the reply's first line, trimmed: "SONAR PING360" */
    uint8_t mac[6];
    uint32_t ip;        /* the address the device says it has, host byte order */
    uint32_t from;      /* the address the reply came from, host byte order */
    int fw_known;       /* device_information answered on the data port */
    uint8_t fw[3];
    uint8_t device_type;
};

/*
 * Parses a discovery reply: lines separated by CR LF (or LF), the first naming a PING360, then
 * "MAC Address:- 54-10-EC-79-7D-C5" and "IP Address:- 192.168.000.111" (zero-padded octets) in
 * any order. Returns HOST_OK with *d filled (from, fw_known left 0), or HOST_ERR_ROW with the
 * reason in err ("no 'MAC Address:-' line", "not text: byte 3 is 0x00", ...).
 */
HOST_CHECK int discover_parse_reply(const uint8_t *buf, size_t len, struct discover_device *d, char *err, size_t errlen);

/* "54-10-EC-79-7D-C5" (hex pairs, either case, then the end or a blank) into mac. Returns 0, or -1 with mac unspecified. */
int discover_parse_mac(const char *s, uint8_t mac[6]);

/* The reply a Ping360 sends (sonar-feed answers with it): "SONAR PING360  \r\nBlue Robotics\r\n...". Returns its length. */
size_t discover_format_reply(char *buf, size_t cap, const uint8_t mac[6], uint32_t ip);

struct discover_config {
    const char *to;     /* "HOST:PORT" to send the probe to; NULL: 255.255.255.255:30303, broadcast */
    double seconds;     /* how long to listen, 0.2..60; the probe is sent again each second */
    int data_port;      /* where to ask for device_information, 1..65535 (DISCOVER_DATA_PORT) */
};

/*
 * Sends "Discovery", listens for c->seconds, asks each device found for its firmware, and prints
 * one line per device on out (address, MAC, firmware, the URL to give --sonar). Malformed replies
 * are named on errf and ignored; a device whose address is on no local interface's subnet is
 * warned about on errf. Returns the number of devices found, or HOST_ERR_IO / HOST_ERR_CONFIG
 * with the reason on errf.
 */
HOST_CHECK int discover_run(const struct discover_config *c, FILE *out, FILE *errf);

/* 1 when ip (host byte order) shares a subnet with an IPv4 interface that is up, else 0; the
 * interfaces are listed into ifs ("lo 127.0.0.1/8, eth0 192.168.2.1/24") for the warning. */
int discover_on_local_subnet(uint32_t ip, char *ifs, size_t ifslen);

#endif
