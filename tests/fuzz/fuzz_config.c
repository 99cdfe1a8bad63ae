/* fuzz_config.c -- libFuzzer: any bytes as a --config file; the reader accepts it or names file:line, and an accepted file leaves every numeric option inside its table range. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "options.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static struct sonard_options o;
    const struct opt_schema *s = options_schema();
    char err[512];
    size_t used = 0, i;
    FILE *f;
    int r;
    if (size == 0)
        return 0;
    f = fmemopen((void *)(uintptr_t)data, size, "r");
    if (f == NULL)
        return 0;
    memset(&o, 0, sizeof(o));
    sonar_pipeline_defaults(&o.pipeline);
    err[0] = '\0';
    r = opt_read_stream(s, f, "fuzz.conf", &o, &o.given, o.pool, sizeof(o.pool), &used, err, sizeof(err));
    fclose(f);
    if (r != HOST_OK) {
        if (strncmp(err, "fuzz.conf:", 10) != 0 && strncmp(err, "--config fuzz.conf", 18) != 0)
            abort(); /* every error names the file (and line) */
        return 0;
    }
    if (used > sizeof(o.pool))
        abort();
    for (i = 0; i < s->count; i++) {
        const struct opt_spec *p = &s->spec[i];
        const char *field = (const char *)&o + p->offset;
        double v;
        if (!opt_was_given(&o.given, i) || p->type < OPT_LONG || p->type > OPT_F64)
            continue;
        v = p->type == OPT_LONG ? (double)*(const long *)(const void *)field
          : p->type == OPT_U8 ? (double)*(const uint8_t *)field
          : p->type == OPT_U16 ? (double)*(const uint16_t *)(const void *)field
          : p->type == OPT_F32 ? (double)*(const float *)(const void *)field : *(const double *)(const void *)field;
        if (!(v >= p->lo && v <= p->hi))
            abort();
    }
    return 0;
}
