/* fuzz_cpframe.c -- libFuzzer: any bytes on the co-processor link, in chunks; every frame returned has a good CRC, a known channel and a length within the limit, and every byte is consumed or buffered. */
#include <stdint.h>
#include <stdlib.h>

#include "sonar/cpframe.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static struct sonar_cpf_parser p;
    size_t off = 0;
    sonar_cpf_parser_init(&p);
    while (off < size) {
        size_t chunk = 1 + (data[off] % 97u), left;
        const uint8_t *in;
        struct sonar_cpf_frame f;
        if (chunk > size - off)
            chunk = size - off;
        in = data + off;
        left = chunk;
        while (sonar_cpf_next(&p, &in, &left, &f) == 1) {
            uint8_t c = f.channel;
            if (f.len > SONAR_CPF_MAX_PAYLOAD || (f.len && (f.payload < p.buf || f.payload + f.len > p.buf + sizeof(p.buf))))
                abort();
            if (c != SONAR_CPF_DETECTIONS && c != SONAR_CPF_STATUS && c != SONAR_CPF_BEAM && c != SONAR_CPF_CONFIG &&
                c != SONAR_CPF_REPLY)
                abort();
            /* The CRC the parser accepted must be the frame's own. */
            {
                const uint8_t *e = f.payload + f.len;
                uint32_t got = (uint32_t)e[0] | (uint32_t)e[1] << 8 | (uint32_t)e[2] << 16 | (uint32_t)e[3] << 24;
                if (sonar_cpf_crc32(0, f.payload - 3, (size_t)f.len + 3u) != got)
                    abort();
            }
        }
        if (left != 0)
            abort();
        off += chunk;
    }
    return 0;
}
