/* image.c -- a minimal bare-metal image that owns one pipeline statically, so `make size` measures the core's real flash and RAM. */
#include <stdint.h>

#include "sonar/pipeline.h"

/* The caller's allocation, as firmware would do it: static, sized by config.h. */
static struct sonar_pipeline pipeline;
static struct sonar_background background;
static struct sonar_pipeline_config config;
static uint8_t beam[SONAR_MAX_SAMPLES];
static volatile uint32_t detections;

static void on_sweep(void *user, const struct sonar_detections *d)
{
    (void)user;
    detections += d->count;
}

int main(void)
{
    struct sonar_beam b;
    uint16_t a;
    sonar_pipeline_defaults(&config);
    config.on_sweep = on_sweep;
    if (sonar_pipeline_init(&pipeline, &background, &config) != SONAR_OK)
        return 1;
    b.utime = 0;
    b.n = SONAR_MAX_SAMPLES;
    b.range_m = 20.0f;
    b.samples = beam;
    b.gain = 0;
    for (a = 0; a < 400; a++) {
        b.angle = a;
        beam[a % SONAR_MAX_SAMPLES] = (uint8_t)a;
        if (sonar_pipeline_push(&pipeline, &b) != SONAR_OK)
            return 2;
    }
    return sonar_pipeline_finish(&pipeline) == SONAR_OK ? 0 : 3;
}
