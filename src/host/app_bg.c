/* app_bg.c -- the app's site survey (or recorded background) and the clutter map after it: loaded and checked against the configuration, its fate said beam by beam (given up, taken back), the learnt model as an image; no RAM beyond struct app. */
#include "app_internal.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "sonar/bgfile.h"

/* "2026-12-05 10:31 UTC" for us since the epoch. */
static void date_of(int64_t utime, char *out, size_t len)
{
    time_t t = (time_t)(utime / 1000000);
    struct tm tm;
    if (utime <= 0 || gmtime_r(&t, &tm) == NULL || strftime(out, len, "%Y-%m-%d %H:%M UTC", &tm) == 0)
        snprintf(out, len, "an unknown date");
}

static const char *gain_str(uint8_t g)
{
    return g == 0 ? "0" : g == 1 ? "1" : g == 2 ? "2" : "unknown";
}

/*
 * The clutter map after a site file's image (tail bytes of it; none in a file written before sonard
 * kept one): loaded, or learnt afresh, and said either way. A damaged map never costs the survey.
 */
static void clutter_load(struct app *a, const uint8_t *tail, size_t len)
{
    struct sonar_clutter_summary s;
    int r;
    if (len == 0) {
        app_say(a, "clutter map: none in the file (written before sonard kept one): learnt as sonard runs");
        return;
    }
    if ((r = sonar_clutter_decode(&a->clutter, tail, len)) != SONAR_OK) {
        sonar_clutter_init(&a->clutter);
        app_warn(a, "clutter map: refused, %s: learnt afresh as sonard runs",
                 r == SONAR_ERR_ID       ? "another grid than this build's (bands x sectors)"
                 : r == SONAR_ERR_LENGTH ? "truncated or too long"
                                         : "damaged (its checksum or a value is wrong)");
        return;
    }
    sonar_clutter_summarise(&a->clutter, &s);
    app_say(a, "clutter map: loaded, learnt over %u looks: %.2f false detections a look expected, densest %.3f a m^2 at "
               "%.1f m, %.0f gradians",
            (unsigned)s.looks, (double)s.per_look, (double)s.peak, (double)s.peak_range_m, (double)s.peak_bearing_g);
}

int32_t app_clutter_image(const struct app *a, uint8_t *out, size_t cap)
{
    struct sonar_clutter_summary s;
    sonar_clutter_summarise(&a->clutter, &s);
    if (s.looks == 0)
        return 0;
    return sonar_clutter_encode(&a->clutter, out, cap);
}

int app_background_load(struct app *a, const uint8_t *img, size_t len, char *err, size_t errlen)
{
    const struct sonar_pipeline_config *c = sonar_pipeline_running(&a->pipe);
    struct sonar_bgfile_meta m;
    const char *why;
    char date[40];
    /* The image, then a clutter map if the file has one (a tail that is not one: refused as trailing bytes). */
    size_t head = sonar_bgfile_declared(img, len);
    if (len - head < 4 || memcmp(img + head, "SCM1", 4) != 0)
        head = len;
    if (sonar_bgfile_check(img, head, &m, &why) != SONAR_OK) {
        snprintf(err, errlen, "%s", why);
        return HOST_ERR_CONFIG;
    }
    if (m.median != (c->median2d ? 1 : c->median) || m.median2d != c->median2d) {
        snprintf(err, errlen, "filter: learnt after median %u / median2d %u, running median %u / median2d %u", m.median,
                 m.median2d, c->median2d ? 1u : c->median, c->median2d);
        return HOST_ERR_CONFIG;
    }
    if (sonar_pipeline_load_background(&a->pipe, img, head, &why) != SONAR_OK) {
        snprintf(err, errlen, "%s", why);
        return HOST_ERR_CONFIG;
    }
    a->survey_img = img;
    a->survey_len = head;
    a->survey_state = SONAR_SURVEY_IN_USE;
    a->survey_why = SONAR_SURVEY_OK;
    date_of(m.utime, date, sizeof(date));
    if (m.flags & SONAR_BGFILE_SURVEY)
        app_say(a, "survey: of %s, %u sweeps, %u samples over %.3f m at gain %s, %u structure place%s: in use (what it "
                   "holds is never an object; what it does not, always is)",
                date, m.sweeps, m.n, (double)m.range_mm * 1e-3, gain_str(m.gain), m.places, m.places == 1 ? "" : "s");
    else
        app_say(a, "background: loaded, %u samples over %.3f m at gain %s, learnt over %u sweeps (%s): learnt on from "
                   "(a learnt model, not a survey: what stands in it from the start may be learnt)",
                m.n, (double)m.range_mm * 1e-3, gain_str(m.gain), m.sweeps, date);
    clutter_load(a, img + head, len - head);
    return HOST_OK;
}

/* Why the survey was given up, for people. */
static void say_unfit(const struct app *a, const struct sonar_survey *sv)
{
    const char *then = "not used; the background learns afresh";
    uint16_t n;
    float range_m;
    sonar_pipeline_geometry(&a->pipe, &n, &range_m);
    switch (sv->why) {
    case SONAR_SURVEY_GEOMETRY:
    case SONAR_SURVEY_GAIN:
        app_warn(a, "survey: at sweep %u: recorded at %u samples over %.3f m, gain %s; the sonar gives %u over %.3f m, gain %d: %s (it is "
                    "taken back when the beams are of its setting again)",
                 (unsigned)a->sweeps, sv->meta.n, (double)sv->meta.range_mm * 1e-3, gain_str(sv->meta.gain), n, (double)range_m,
                 sonar_pipeline_gain(&a->pipe), then);
        break;
    case SONAR_SURVEY_TURNED:
        app_warn(a, "survey: at sweep %u: the site's structure is where the survey has it turned by about %+d gradians "
                    "(%+.0f degrees): the mount turned? %s; turn it back, or record the survey again",
                 (unsigned)a->sweeps, sv->turn_grad, sv->turn_grad * 0.9, then);
        break;
    case SONAR_SURVEY_CHANGED:
        app_warn(a, "survey: at sweep %u: the site's structure is not where the survey has it (%u of 16 parts agree): the "
                    "sonar moved or the site changed? %s; record the survey again",
                 (unsigned)a->sweeps, sv->agree16, then);
        break;
    case SONAR_SURVEY_STANDOUT:
        app_warn(a, "survey: at sweep %u: %.1f %% of the sweep stands out against it (the water level, or the site "
                    "changed?): %s", (unsigned)a->sweeps, sv->standout1000 * 0.1, then);
        break;
    case SONAR_SURVEY_NEW:
        app_warn(a, "survey: at sweep %u: lines wider than any object stand out against it in %d of the last 3 sweeps "
                    "(walls, a dock, ropes it does not hold): the site changed or the sonar moved? %s; record the survey "
                    "again", (unsigned)a->sweeps, SONAR_SURVEY_NEW_SWEEPS, then);
        break;
    case SONAR_SURVEY_WORLD:
        app_warn(a, "survey: the vehicle's pose is known (the world frame): a survey is of a fixed site: not used");
        break;
    default:
        app_warn(a, "survey: the background restarted (a new filter or background mode, or a co-processor's): not used");
        break;
    }
}

void app_survey_watch(struct app *a)
{
    const struct sonar_survey *sv = &a->survey;
    const char *why;
    if (sv->state == SONAR_SURVEY_UNFIT && sv->refit && a->survey_img != NULL) {
        /* Fits again: taken back from the image it was loaded from (the same checks pass: they did). */
        if (sonar_pipeline_load_background(&a->pipe, a->survey_img, a->survey_len, &why) == SONAR_OK)
            app_say(a, "survey: the beams fit it again: in use from sweep %u", (unsigned)a->sweeps + 1u);
        else
            app_warn(a, "survey: fits again, but could not be taken back: %s", why);
    }
    if (sv->state == a->survey_state && sv->unfits == a->survey_unfits)
        return;
    if (sv->state == SONAR_SURVEY_UNFIT)
        say_unfit(a, sv);
    a->survey_state = sv->state;
    a->survey_why = sv->why;
    a->survey_unfits = sv->unfits;
}

const struct sonar_survey *app_survey(const struct app *a)
{
    return &a->survey;
}

const uint8_t *app_survey_image(const struct app *a)
{
    return a->survey_img;
}

void app_record_survey(struct app *a, struct sonar_survey_rec *rec, int ends_run)
{
    a->rec = rec;
    a->rec_ends_run = rec != NULL && ends_run;
    sonar_pipeline_set_recording(&a->pipe, rec);
}

int32_t app_background_image(const struct app *a, uint8_t *out, size_t cap, char *err, size_t errlen)
{
    const struct sonar_pipeline_config *c = sonar_pipeline_running(&a->pipe);
    struct sonar_bgfile_meta m;
    float range_m;
    int32_t r;
    memset(&m, 0, sizeof(m));
    sonar_pipeline_geometry(&a->pipe, &m.n, &range_m);
    m.mode = c->background.mode;
    m.median = c->median2d ? 1 : c->median;
    m.median2d = c->median2d;
    m.gain = a->last_gain >= 0 && a->last_gain <= 2 ? (uint8_t)a->last_gain : SONAR_BGFILE_GAIN_UNKNOWN;
    m.range_mm = (uint32_t)lrint((double)range_m * 1e3);
    m.sweeps = a->sweeps;
    m.utime = a->cur.utime;
    if (m.n == 0 || m.range_mm == 0) {
        snprintf(err, errlen, "background: no beam yet, nothing learnt to save");
        return HOST_ERR_STATE;
    }
    if (a->survey.state == SONAR_SURVEY_IN_USE) {
        snprintf(err, errlen, "background: the site's survey is in use, nothing was learnt over it: not saved (record a "
                              "survey with --survey N)");
        return HOST_ERR_STATE;
    }
    r = sonar_pipeline_save_background(&a->pipe, &m, out, cap);
    if (r >= 0) { /* the clutter map after it, loaded with it */
        int32_t k = app_clutter_image(a, out + r, cap - (size_t)r);
        r = k < 0 ? k : r + k;
    }
    if (r == SONAR_ERR_STATE)
        snprintf(err, errlen, "background: nothing to save (a world-frame model, tied to where the vehicle was, or a "
                              "mode without per-angle rows)");
    else if (r < 0)
        snprintf(err, errlen, "background: %s", sonar_err_str(r));
    return r < 0 ? host_err_of(r) : r;
}
