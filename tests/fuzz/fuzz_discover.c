/* fuzz_discover.c -- libFuzzer: any datagram as a Ping360's discovery reply; it is taken with a terminated name and a MAC, or refused with the reason said. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "discover.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    struct discover_device d;
    char err[256], again[512];
    memset(&d, 0xA5, sizeof(d));
    err[0] = '\0';
    if (discover_parse_reply(data, size, &d, err, sizeof(err)) != HOST_OK) {
        if (err[0] == '\0')
            abort(); /* a refusal says why */
        return 0;
    }
    if (memchr(d.name, '\0', sizeof(d.name)) == NULL)
        abort();
    /* What was taken formats back into a reply that parses to the same MAC and address. */
    {
        struct discover_device e;
        size_t n = discover_format_reply(again, sizeof(again), d.mac, d.ip);
        if (n >= sizeof(again) || discover_parse_reply((const uint8_t *)again, n, &e, err, sizeof(err)) != HOST_OK ||
            memcmp(e.mac, d.mac, 6) != 0 || e.ip != d.ip)
            abort();
    }
    return 0;
}
