/* gain.c -- automatic receiver gain: a histogram of each sweep's raw samples, a decision at its end; O(n) a beam, O(256) a sweep, no heap. */
#include "sonar/gain.h"

#include <string.h>

void sonar_gain_defaults(struct sonar_gain_config *c)
{
    c->start = 0;
    c->sat_level = 250;
    c->sat_max = 0.01f;
    c->floor_level = 2;
    c->hold_sweeps = 2;
    c->memory_sweeps = 30;
}

const char *sonar_gain_config_check(const struct sonar_gain_config *c)
{
    if (c->start > SONAR_GAIN_MAX)
        return "start: 0..2 (low, normal, high)";
    if (c->sat_level < 128)
        return "sat_level: 128..255";
    if (!(c->sat_max > 0.0f && c->sat_max <= 0.5f))
        return "sat_max: (0, 0.5]";
    if (c->floor_level > 64)
        return "floor_level: 0..64";
    if (c->hold_sweeps < 1 || c->hold_sweeps > 100)
        return "hold_sweeps: 1..100";
    return NULL;
}

int sonar_gain_init(struct sonar_gain *g, const struct sonar_gain_config *cfg)
{
    if (g == NULL || cfg == NULL || sonar_gain_config_check(cfg) != NULL)
        return SONAR_ERR_ARG;
    memset(g, 0, sizeof(*g));
    g->cfg = *cfg;
    g->gain = cfg->start;
    g->held = 255;
    g->barred = SONAR_GAIN_MAX + 1;
    return SONAR_OK;
}

void sonar_gain_beam(struct sonar_gain *g, const uint8_t *samples, uint16_t n, uint8_t at)
{
    uint16_t i;
    if (at != g->gain) {
        g->other++;
        return;
    }
    if (g->samples > 0xF0000000u)
        return;
    for (i = 0; i < n; i++)
        g->hist[samples[i]]++;
    g->samples += n;
}

int sonar_gain_sweep_end(struct sonar_gain *g)
{
    uint32_t sat = 0, half = g->samples / 2, seen = 0;
    unsigned v, median = 0;
    int next = -1;
    g->other = 0;
    if (g->samples == 0)
        return -1;
    for (v = g->cfg.sat_level; v < 256; v++)
        sat += g->hist[v];
    for (v = 0; v < 256; v++) {
        seen += g->hist[v];
        if (seen > half) {
            median = v;
            break;
        }
    }
    g->last_sat = (float)sat / (float)g->samples;
    g->last_median = (uint8_t)median;
    memset(g->hist, 0, sizeof(g->hist));
    g->samples = 0;
    if (g->barred_for > 0 && --g->barred_for == 0)
        g->barred = SONAR_GAIN_MAX + 1;
    if (g->held < 255)
        g->held++;
    if (g->held < g->cfg.hold_sweeps)
        return -1;
    if (g->last_sat > g->cfg.sat_max && g->gain > 0) {
        /* Saturating: lower, and keep off this setting for a while. */
        if (g->cfg.memory_sweeps > 0) {
            /* Saturating again right after going up to it: bar it twice as long as last time. */
            g->bar_len = g->raised && g->bar_len > 0 ? (uint16_t)(g->bar_len * 2u > 60000u ? 60000u : g->bar_len * 2u)
                                                     : g->cfg.memory_sweeps;
            g->barred = g->gain;
            g->barred_for = g->bar_len;
        }
        next = g->gain - 1;
    } else if (g->last_sat < g->cfg.sat_max / 10.0f && median <= g->cfg.floor_level && g->gain < SONAR_GAIN_MAX &&
               g->gain + 1 < g->barred) {
        next = g->gain + 1;
    }
    if (next < 0)
        return -1;
    g->raised = next > g->gain;
    g->gain = (uint8_t)next;
    g->held = 0;
    g->changes++;
    return next;
}
