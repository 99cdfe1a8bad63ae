/* feed_discovery.c -- sonar-feed's discovery responder: "Discovery" on its UDP port answered with the device's text reply. */
#define _GNU_SOURCE
#include "feed.h"

/* A datagram on the discovery port: "Discovery" gets the device's text reply; anything else is ignored, as the device does. */
void feed_answer_discovery(struct feed *f)
{
    char buf[256], reply[256];
    struct sockaddr_in from;
    socklen_t fl = sizeof(from);
    struct in_addr ip;
    ssize_t got = recvfrom(f->dfd, buf, sizeof(buf) - 1, 0, (struct sockaddr *)&from, &fl);
    size_t n;
    if (got < 0)
        return;
    buf[got] = '\0';
    if (strncmp(buf, "Discovery", 9) != 0)
        return;
    if (inet_pton(AF_INET, f->claim_ip != NULL ? f->claim_ip : f->host, &ip) != 1)
        ip.s_addr = htonl(INADDR_LOOPBACK);
    n = discover_format_reply(reply, sizeof(reply), f->mac, ntohl(ip.s_addr));
    if (sendto(f->dfd, reply, n, 0, (struct sockaddr *)&from, fl) == (ssize_t)n)
        f->discoveries++;
}
