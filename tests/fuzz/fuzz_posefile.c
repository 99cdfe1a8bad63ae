/* fuzz_posefile.c -- libFuzzer: any bytes as a --pose CSV; the header is taken or refused naming file:line, every row is taken or counted bad, and the poses in the app stay in time order. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "posefile.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static int64_t clock0(void *u)
{
    (void)u;
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static struct app_storage mem;
    static struct posefile p;
    struct app *a;
    struct sonar_pipeline_config c;
    struct app_clock clk = {clock0, clock0, NULL};
    const struct sonar_pose_ring *r;
    char err[512];
    FILE *f;
    uint16_t i;
    if (size == 0 || (f = fmemopen((void *)(uintptr_t)data, size, "r")) == NULL)
        return 0;
    sonar_pipeline_defaults(&c);
    if (app_init(&a, &mem, &c, NULL, NULL, &clk, 0, err, sizeof(err)) != HOST_OK)
        abort();
    err[0] = '\0';
    if (posefile_open_stream(&p, f, "fuzz.csv", err, sizeof(err)) != HOST_OK) {
        if (strncmp(err, "fuzz.csv:", 9) != 0)
            abort(); /* a refused header names the file and line */
        return 0;
    }
    posefile_feed(&p, a, INT64_MAX, NULL);
    if (p.good + p.bad > p.line)
        abort(); /* a row is taken or counted bad, once */
    r = app_poses(a);
    for (i = 1; i < r->n; i++)
        if (r->s[(r->head + i) % SONAR_MAX_POSES].utime <= r->s[(r->head + i - 1u) % SONAR_MAX_POSES].utime)
            abort(); /* the ring holds poses in time order */
    posefile_close(&p);
    return 0;
}
