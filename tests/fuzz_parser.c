/* fuzz_parser.c -- checks the parser contract (docs/parser-security.md) on random or given streams; standalone, or libFuzzer with -DSONAR_LIBFUZZER. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sonar/ping.h"

static struct sonar_ping_parser parser;

static void die(const char *what)
{
    fprintf(stderr, "fuzz_parser: contract broken: %s\n", what);
    abort();
}

/* Feeds data in chunks of the given sizes and checks every frame and every return. */
static unsigned long run(const uint8_t *data, size_t size, unsigned chunk_seed, uint16_t max_payload)
{
    unsigned long frames = 0;
    size_t off = 0;
    if (sonar_ping_parser_init(&parser, max_payload) != SONAR_OK)
        die("init");
    while (off < size) {
        size_t len = 1 + (chunk_seed = chunk_seed * 1103515245u + 12345u) % 300;
        const uint8_t *in = data + off;
        struct sonar_ping_frame f;
        int r;
        len = len < size - off ? len : size - off;
        off += len;
        for (;;) {
            const uint8_t *before = in;
            memset(&f, 0xA5, sizeof(f));
            r = sonar_ping_parser_next(&parser, &in, &len, &f);
            if (in < before || in > data + size)
                die("input pointer moved outside the data");
            if (r == 0) {
                const uint8_t *p = (const uint8_t *)&f;
                size_t i;
                if (len != 0)
                    die("returned 0 with input left");
                for (i = 0; i < sizeof(f); i++)
                    if (p[i] != 0xA5)
                        die("frame written on 0");
                break;
            }
            if (r != 1)
                die("unexpected return");
            {
                const uint8_t *b = parser.buf, *e = parser.buf + sizeof(parser.buf);
                uint32_t sum = 0;
                size_t i;
                if (f.payload_len > parser.max_payload)
                    die("payload over the limit");
                if (f.payload < b + SONAR_PING_HEADER_LEN || f.payload + f.payload_len + 2 > e)
                    die("payload outside the buffer");
                for (i = 0; i < SONAR_PING_HEADER_LEN + f.payload_len; i++)
                    sum += f.payload[(ptrdiff_t)i - (ptrdiff_t)SONAR_PING_HEADER_LEN];
                if ((uint16_t)sum != (uint16_t)(f.payload[f.payload_len] | f.payload[f.payload_len + 1] << 8))
                    die("bad checksum accepted");
                frames++;
            }
        }
    }
    return frames;
}

#ifdef SONAR_LIBFUZZER
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    run(data, size, (unsigned)size, (uint16_t)(size % 3 == 0 ? 0 : 200 + size % 1800));
    return 0;
}
#else
/* Random streams: noise biased towards 'B' and 'R', valid frames, and frames with one flipped byte. */
int main(int argc, char **argv)
{
    static uint8_t s[1 << 20];
    unsigned long rounds = argc > 1 ? strtoul(argv[1], NULL, 10) : 200, r, frames = 0, planted = 0;
    srand(argc > 2 ? (unsigned)atoi(argv[2]) : 1);
    for (r = 0; r < rounds; r++) {
        size_t n = 0;
        unsigned long planted_here = 0, got;
        /* even rounds: the default limit, where every intact frame must come out; odd: a random smaller one */
        uint16_t limit = (uint16_t)(r % 2 == 0 ? 0 : 200 + rand() % 1800);
        while (n < sizeof(s) - 4096) {
            int kind = rand() % 4;
            if (kind == 0) {
                int k = rand() % 200;
                while (k-- > 0)
                    s[n++] = (uint8_t)(rand() % 3 == 0 ? 'B' : rand() % 3 == 0 ? 'R' : rand());
            } else {
                uint8_t pl[1300];
                uint16_t pn = (uint16_t)(rand() % 1300);
                int i, w;
                for (i = 0; i < pn; i++)
                    pl[i] = (uint8_t)rand();
                w = sonar_ping_encode(s + n, sizeof(s) - n, (uint16_t)(rand() % 3000), pl, pn);
                if (w < 0)
                    die("encode");
                if (kind == 3)
                    s[n + (size_t)(rand() % w)] ^= (uint8_t)(1 + rand() % 255);
                else
                    planted_here++;
                n += (size_t)w;
            }
        }
        got = run(s, n, (unsigned)r, limit);
        /* A corrupted frame or noise could pass the checksum by chance (2^-16), so >=, not ==. */
        if (limit == 0 && got < planted_here) {
            fprintf(stderr, "fuzz_parser: round %lu lost frames: %lu of %lu intact frames found\n", r, got, planted_here);
            return 1;
        }
        if (limit == 0)
            planted += planted_here;
        frames += got;
    }
    printf("fuzz_parser: %lu rounds, %lu frames accepted; every one of the %lu intact frames planted under the default limit recovered; contract held\n",
           rounds, frames, planted);
    return 0;
}
#endif
