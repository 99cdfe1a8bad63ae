/* discover.c -- Ping360 discovery over UDP: the probe, the reply's text, a firmware question per device, the subnet check; O(replies) per run, no heap. */
#define _GNU_SOURCE
#include "discover.h"

#include <arpa/inet.h>
#include <errno.h>
#include <ifaddrs.h>
#include <net/if.h>
#include <netinet/in.h>
#include <poll.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include "sonar/ping.h"

static const char probe_text[] = "Discovery";

/* Skips blanks; returns the rest of the line after "key" (case-sensitive, as the device writes it), or NULL. */
static const char *after_key(const char *line, const char *key)
{
    size_t k = strlen(key);
    while (*line == ' ' || *line == '\t')
        line++;
    if (strncmp(line, key, k) != 0)
        return NULL;
    line += k;
    while (*line == ' ' || *line == '\t')
        line++;
    return line;
}

int discover_parse_mac(const char *s, uint8_t mac[6])
{
    unsigned v[6];
    int used = 0, i;
    if (sscanf(s, "%2x-%2x-%2x-%2x-%2x-%2x%n", &v[0], &v[1], &v[2], &v[3], &v[4], &v[5], &used) != 6 || used != 17)
        return -1;
    for (i = 0; i < 6; i++)
        mac[i] = (uint8_t)v[i];
    return s[used] == '\0' || s[used] == ' ' ? 0 : -1;
}

static int parse_ip(const char *s, uint32_t *ip)
{
    unsigned v[4];
    int used = 0, i;
    if (sscanf(s, "%3u.%3u.%3u.%3u%n", &v[0], &v[1], &v[2], &v[3], &used) != 4 || (s[used] != '\0' && s[used] != ' '))
        return -1;
    *ip = 0;
    for (i = 0; i < 4; i++) {
        if (v[i] > 255u)
            return -1;
        *ip = *ip << 8 | v[i];
    }
    return 0;
}

int discover_parse_reply(const uint8_t *buf, size_t len, struct discover_device *d, char *err, size_t errlen)
{
    char text[512], *line, *save = NULL;
    size_t i;
    int have_mac = 0, have_ip = 0, first = 1;
    memset(d, 0, sizeof(*d));
    if (len == 0 || len >= sizeof(text)) {
        snprintf(err, errlen, "%zu bytes, not a reply (1..%zu)", len, sizeof(text) - 1);
        return HOST_ERR_ROW;
    }
    for (i = 0; i < len; i++)
        if ((buf[i] < 0x20 && buf[i] != '\r' && buf[i] != '\n' && buf[i] != '\t') || buf[i] > 0x7e) {
            snprintf(err, errlen, "not text: byte %zu is 0x%02x", i, buf[i]);
            return HOST_ERR_ROW;
        }
    memcpy(text, buf, len);
    text[len] = '\0';
    for (line = strtok_r(text, "\r\n", &save); line != NULL; line = strtok_r(NULL, "\r\n", &save)) {
        const char *v;
        if (first) {
            size_t n;
            first = 0;
            while (*line == ' ')
                line++;
            n = strlen(line);
            while (n > 0 && line[n - 1] == ' ')
                line[--n] = '\0';
            if (strstr(line, "PING360") == NULL) {
                snprintf(err, errlen, "not a Ping360: first line '%.40s'", line);
                return HOST_ERR_ROW;
            }
            snprintf(d->name, sizeof(d->name), "%s", line);
        } else if ((v = after_key(line, "MAC Address:-")) != NULL) {
            if (discover_parse_mac(v, d->mac) != 0) {
                snprintf(err, errlen, "MAC '%.30s' is not six hex pairs like 54-10-EC-79-7D-C5", v);
                return HOST_ERR_ROW;
            }
            have_mac = 1;
        } else if ((v = after_key(line, "IP Address:-")) != NULL) {
            if (parse_ip(v, &d->ip) != 0) {
                snprintf(err, errlen, "IP '%.30s' is not a dotted quad like 192.168.002.002", v);
                return HOST_ERR_ROW;
            }
            have_ip = 1;
        }
    }
    if (first || !have_mac || !have_ip) {
        snprintf(err, errlen, "no '%s' line", first ? "SONAR PING360" : !have_mac ? "MAC Address:-" : "IP Address:-");
        return HOST_ERR_ROW;
    }
    return HOST_OK;
}

size_t discover_format_reply(char *buf, size_t cap, const uint8_t mac[6], uint32_t ip)
{
    int n = snprintf(buf, cap,
                     "SONAR PING360  \r\nBlue Robotics\r\nMAC Address:- %02X-%02X-%02X-%02X-%02X-%02X\r\n"
                     "IP Address:- %03u.%03u.%03u.%03u\r\n",
                     mac[0], mac[1], mac[2], mac[3], mac[4], mac[5], (unsigned)(ip >> 24), (unsigned)(ip >> 16 & 255u),
                     (unsigned)(ip >> 8 & 255u), (unsigned)(ip & 255u));
    return n < 0 ? 0 : (size_t)n < cap ? (size_t)n : cap - 1;
}

int discover_on_local_subnet(uint32_t ip, char *ifs, size_t ifslen)
{
    struct ifaddrs *all, *i;
    size_t k = 0;
    int found = 0;
    if (ifslen > 0)
        ifs[0] = '\0';
    if (getifaddrs(&all) != 0)
        return 0;
    for (i = all; i != NULL; i = i->ifa_next) {
        uint32_t a, m;
        int bits = 0;
        char dot[INET_ADDRSTRLEN];
        if (i->ifa_addr == NULL || i->ifa_addr->sa_family != AF_INET || i->ifa_netmask == NULL || !(i->ifa_flags & IFF_UP))
            continue;
        a = ntohl(((const struct sockaddr_in *)(const void *)i->ifa_addr)->sin_addr.s_addr);
        m = ntohl(((const struct sockaddr_in *)(const void *)i->ifa_netmask)->sin_addr.s_addr);
        if ((a & m) == (ip & m))
            found = 1;
        for (; bits < 32 && (m << bits & 0x80000000u); bits++)
            ;
        inet_ntop(AF_INET, &((const struct sockaddr_in *)(const void *)i->ifa_addr)->sin_addr, dot, sizeof(dot));
        if (k < ifslen) {
            int n = snprintf(ifs + k, ifslen - k, "%s%s %s/%d", k ? ", " : "", i->ifa_name, dot, bits);
            k += n > 0 ? (size_t)n : 0;
        }
    }
    freeifaddrs(all);
    return found;
}

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + (double)t.tv_nsec * 1e-9;
}

static void dotted(uint32_t ip, char *s, size_t n)
{
    snprintf(s, n, "%u.%u.%u.%u", (unsigned)(ip >> 24), (unsigned)(ip >> 16 & 255u), (unsigned)(ip >> 8 & 255u),
             (unsigned)(ip & 255u));
}

static int parse_to(const char *to, struct sockaddr_in *a, char *err, size_t errlen)
{
    char host[64];
    int port = 0;
    char tail;
    memset(a, 0, sizeof(*a));
    a->sin_family = AF_INET;
    if (sscanf(to, "%63[^:]:%d%c", host, &port, &tail) != 2 || port < 1 || port > 65535 ||
        inet_pton(AF_INET, host, &a->sin_addr) != 1) {
        snprintf(err, errlen, "--discover-to: '%s' is not IPV4:PORT (port 1..65535)", to);
        return HOST_ERR_CONFIG;
    }
    a->sin_port = htons((uint16_t)port);
    return HOST_OK;
}

/* device_information, asked of one device on its data port. */
static void ask_firmware(int fd, uint32_t from, int port)
{
    uint8_t req[16];
    struct sockaddr_in a;
    int n = sonar_ping_encode_general_request(req, sizeof(req), SONAR_PING_DEVICE_INFORMATION);
    if (n <= 0)
        return;
    memset(&a, 0, sizeof(a));
    a.sin_family = AF_INET;
    a.sin_port = htons((uint16_t)port);
    a.sin_addr.s_addr = htonl(from);
    (void)sendto(fd, req, (size_t)n, 0, (const struct sockaddr *)&a, sizeof(a));
}

/* A datagram on the data socket: device_information from a device already found. */
static void take_firmware(struct sonar_ping_parser *p, struct discover_device *dev, int ndev, const uint8_t *buf,
                          size_t len, uint32_t from)
{
    struct sonar_ping_frame f;
    int i;
    /* reset for each datagram: one device's bytes never complete another's frame */
    if (sonar_ping_parser_init(p, 0) != SONAR_OK)
        return;
    while (sonar_ping_parser_next(p, &buf, &len, &f) == 1) {
        struct sonar_ping_device_info info;
        if (f.id != SONAR_PING_DEVICE_INFORMATION || sonar_ping_decode_device_info(&f, &info) != SONAR_OK)
            continue;
        for (i = 0; i < ndev; i++)
            if (dev[i].from == from) {
                dev[i].fw_known = 1;
                dev[i].fw[0] = info.fw_major;
                dev[i].fw[1] = info.fw_minor;
                dev[i].fw[2] = info.fw_patch;
                dev[i].device_type = info.device_type;
            }
    }
}

/* Long: one bounded listen loop (send, receive, ask each device its firmware, report), its state on the stack. */
int discover_run(const struct discover_config *c, FILE *out, FILE *errf)
{
    struct discover_device dev[DISCOVER_MAX_DEVICES];
    struct sonar_ping_parser parser;
    struct sockaddr_in to;
    char err[160];
    int fd, dfd, one = 1, ndev = 0, more = 0, bad = 0, i;
    double t0 = now_s(), next_probe = t0, end = t0 + c->seconds, first = -1.0;
    if (c->to != NULL) {
        if (parse_to(c->to, &to, err, sizeof(err)) != HOST_OK) {
            fprintf(errf, "sonard: %s\n", err);
            return HOST_ERR_CONFIG;
        }
    } else {
        memset(&to, 0, sizeof(to));
        to.sin_family = AF_INET;
        to.sin_port = htons(DISCOVER_PORT);
        to.sin_addr.s_addr = htonl(INADDR_BROADCAST);
    }
    fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    dfd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    if (fd < 0 || dfd < 0 || setsockopt(fd, SOL_SOCKET, SO_BROADCAST, &one, sizeof(one)) != 0) {
        fprintf(errf, "sonard: --discover: socket: %s\n", strerror(errno));
        if (fd >= 0)
            close(fd);
        if (dfd >= 0)
            close(dfd);
        return HOST_ERR_IO;
    }
    for (;;) {
        struct pollfd p[2];
        double now = now_s();
        int wait_ms;
        if (now >= end)
            break;
        if (now >= next_probe) {
            /* Ping Viewer repeats it each second: a datagram can be lost, a device can be booting */
            if (sendto(fd, probe_text, sizeof(probe_text) - 1, 0, (const struct sockaddr *)&to, sizeof(to)) < 0)
                fprintf(errf, "sonard: --discover: sending to %s:%u: %s\n", inet_ntoa(to.sin_addr),
                        (unsigned)ntohs(to.sin_port), strerror(errno));
            for (i = 0; i < ndev; i++)
                if (!dev[i].fw_known)
                    ask_firmware(dfd, dev[i].from, c->data_port);
            next_probe += 1.0;
        }
        wait_ms = (int)(((next_probe < end ? next_probe : end) - now) * 1000.0) + 1;
        p[0].fd = fd;
        p[1].fd = dfd;
        p[0].events = p[1].events = POLLIN;
        if (poll(p, 2, wait_ms) < 0 && errno != EINTR)
            break;
        for (i = 0; i < 2; i++) {
            uint8_t buf[1024];
            struct sockaddr_in from;
            socklen_t fl = sizeof(from);
            ssize_t got;
            if (!(p[i].revents & POLLIN))
                continue;
            got = recvfrom(p[i].fd, buf, sizeof(buf), MSG_DONTWAIT, (struct sockaddr *)&from, &fl);
            if (got < 0)
                continue;
            if (i == 1) {
                take_firmware(&parser, dev, ndev, buf, (size_t)got, ntohl(from.sin_addr.s_addr));
            } else {
                struct discover_device d;
                int k;
                if (discover_parse_reply(buf, (size_t)got, &d, err, sizeof(err)) != HOST_OK) {
                    bad++;
                    fprintf(errf, "sonard: --discover: reply from %s:%u ignored: %s\n", inet_ntoa(from.sin_addr),
                            (unsigned)ntohs(from.sin_port), err);
                    continue;
                }
                d.from = ntohl(from.sin_addr.s_addr);
                for (k = 0; k < ndev && memcmp(dev[k].mac, d.mac, 6) != 0; k++)
                    ;
                if (k < ndev)
                    continue; /* the same device answering the repeated probe */
                if (ndev == DISCOVER_MAX_DEVICES) {
                    more++;
                    continue;
                }
                if (first < 0.0)
                    first = now_s() - t0;
                dev[ndev++] = d;
                ask_firmware(dfd, d.from, c->data_port);
            }
        }
    }
    close(fd);
    close(dfd);
    if (ndev > 0)
        fprintf(out, "%-16s %-18s %-9s %s\n", "address", "mac", "firmware", "sonar");
    for (i = 0; i < ndev; i++) {
        char ip[20], from[20], fw[16], ifs[512], note[48];
        dotted(dev[i].ip, ip, sizeof(ip));
        dotted(dev[i].from, from, sizeof(from));
        if (dev[i].fw_known)
            snprintf(fw, sizeof(fw), "%u.%u.%u", dev[i].fw[0], dev[i].fw[1], dev[i].fw[2]);
        else
            snprintf(fw, sizeof(fw), "?");
        note[0] = '\0';
        if (dev[i].ip != dev[i].from)
            snprintf(note, sizeof(note), "  (it answered from %s)", from);
        fprintf(out, "%-16s %02X-%02X-%02X-%02X-%02X-%02X  %-9s udp:%s:%d%s\n", ip, dev[i].mac[0], dev[i].mac[1],
                dev[i].mac[2], dev[i].mac[3], dev[i].mac[4], dev[i].mac[5], fw, from, c->data_port, note);
        if (!dev[i].fw_known)
            fprintf(errf, "sonard: --discover: %s did not answer device_information on UDP %d within %.1f s\n", from,
                    c->data_port, c->seconds);
        if (!discover_on_local_subnet(dev[i].ip, ifs, sizeof(ifs)))
            fprintf(errf,
                    "sonard: --discover: warning: the sonar at %s is on no local interface's subnet (%s): give this "
                    "computer an address in its subnet, or set the sonar's (Ping Viewer, or SetSS1IP to UDP 30303)\n",
                    ip, ifs[0] ? ifs : "no IPv4 interface is up");
    }
    if (more)
        fprintf(errf, "sonard: --discover: %d more devices answered; only %d are listed\n", more, DISCOVER_MAX_DEVICES);
    fprintf(errf, "sonard: --discover: %d Ping360%s found in %.1f s", ndev + more, ndev + more == 1 ? "" : "s", c->seconds);
    if (first >= 0.0)
        fprintf(errf, ", the first after %.1f ms", first * 1e3);
    fprintf(errf, "%s\n", bad ? "; malformed replies ignored, named above" : "");
    fflush(out);
    return ndev + more;
}
