/* fuzz_pvbin.c -- libFuzzer: any bytes as a Ping Viewer .bin log; the reader stays inside the buffer, writes only well-formed rows, and says where it stopped. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pvbin.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static char out[1 << 16];
    struct pvbin_stats st;
    FILE *f = fmemopen(out, sizeof(out), "w");
    int r;
    if (f == NULL)
        return 0;
    /* A copy, so reading past the end is past a heap block ASan guards, not into the fuzzer's buffer. */
    {
        uint8_t *copy = malloc(size ? size : 1);
        if (copy == NULL) {
            fclose(f);
            return 0;
        }
        memcpy(copy, data, size);
        r = pvbin_convert(copy, size, "fuzz.bin", 1.6e9, 1500.0, f, NULL, &st);
        free(copy);
    }
    fclose(f);
    if (r != HOST_OK && r != HOST_ERR_CONFIG && r != HOST_ERR_IO)
        abort();
    if (st.beams > st.parser.frames)
        abort();
    return 0;
}
