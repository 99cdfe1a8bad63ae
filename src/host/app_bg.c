/* app_bg.c -- the app's recorded background: a loaded model checked against the configuration and the first beam, and the learnt model as an image; no RAM beyond struct app. */
#include "app_internal.h"

#include <math.h>
#include <stdio.h>

#include "sonar/bgfile.h"

int app_background_load(struct app *a, const uint8_t *img, size_t len, char *err, size_t errlen)
{
    const struct sonar_pipeline_config *c = sonar_pipeline_running(&a->pipe);
    struct sonar_bgfile_meta m;
    const char *why;
    if (sonar_bgfile_check(img, len, &m, &why) != SONAR_OK) {
        snprintf(err, errlen, "%s", why);
        return HOST_ERR_CONFIG;
    }
    if (m.median != (c->median2d ? 1 : c->median) || m.median2d != c->median2d) {
        snprintf(err, errlen, "filter: learnt after median %u / median2d %u, running median %u / median2d %u", m.median,
                 m.median2d, c->median2d ? 1u : c->median, c->median2d);
        return HOST_ERR_CONFIG;
    }
    if (sonar_pipeline_load_background(&a->pipe, img, len, &why) != SONAR_OK) {
        snprintf(err, errlen, "%s", why);
        return HOST_ERR_CONFIG;
    }
    a->bg_file = m;
    a->bg_pending = 1;
    app_say(a, "background: loaded, %u samples over %.3f m at gain %s, learnt over %u sweeps", m.n,
            (double)m.range_mm * 1e-3, m.gain == SONAR_BGFILE_GAIN_UNKNOWN ? "unknown" : (m.gain == 0 ? "0" : m.gain == 1 ? "1" : "2"),
            m.sweeps);
    return HOST_OK;
}

void app_background_first_beam(struct app *a, const struct sonar_record *b)
{
    const struct sonar_bgfile_meta *m = &a->bg_file;
    double range_mm = (double)b->range_m * 1e3;
    int gain_off = b->gain >= 0 && m->gain != SONAR_BGFILE_GAIN_UNKNOWN && b->gain != (int)m->gain;
    if (!a->bg_pending)
        return;
    a->bg_pending = 0;
    /* The range is the sample period times the speed of sound: 1 mm covers rounding, not another setting. */
    if (b->n == m->n && fabs(range_mm - (double)m->range_mm) <= 1.0 && !gain_off)
        return;
    sonar_pipeline_restart_background(&a->pipe);
    a->bg_restarts++;
    app_warn(a, "background: the loaded file was recorded at %u samples over %.3f m, gain %d; the sonar gives %u over "
               "%.3f m, gain %d: refused, the background learns afresh",
            m->n, (double)m->range_mm * 1e-3, m->gain == SONAR_BGFILE_GAIN_UNKNOWN ? -1 : (int)m->gain, b->n,
            (double)b->range_m, (int)b->gain);
}

int32_t app_background_image(const struct app *a, uint8_t *out, size_t cap, char *err, size_t errlen)
{
    const struct sonar_pipeline_config *c = sonar_pipeline_running(&a->pipe);
    struct sonar_bgfile_meta m;
    float range_m;
    int32_t r;
    sonar_pipeline_geometry(&a->pipe, &m.n, &range_m);
    m.mode = c->background.mode;
    m.median = c->median2d ? 1 : c->median;
    m.median2d = c->median2d;
    m.gain = a->last_gain >= 0 && a->last_gain <= 2 ? (uint8_t)a->last_gain : SONAR_BGFILE_GAIN_UNKNOWN;
    m.range_mm = (uint32_t)lrint((double)range_m * 1e3);
    m.sound_mm_s = 0;
    m.sweeps = a->sweeps;
    if (m.n == 0 || m.range_mm == 0) {
        snprintf(err, errlen, "background: no beam yet, nothing learnt to save");
        return HOST_ERR_STATE;
    }
    r = sonar_pipeline_save_background(&a->pipe, &m, out, cap);
    if (r == SONAR_ERR_STATE)
        snprintf(err, errlen, "background: nothing to save (a world-frame model, tied to where the vehicle was, or a "
                              "mode without per-angle rows)");
    else if (r < 0)
        snprintf(err, errlen, "background: %s", sonar_err_str(r));
    return r < 0 ? host_err_of(r) : r;
}
