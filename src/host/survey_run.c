/* survey_run.c -- sonard --survey N (survey_run.h): the recording fed by the app, its refusals said, the image written atomically, a summary; O(cells) once at the end. */
#include "survey_run.h"

#include <string.h>

#include "bgstore.h"

void survey_run_start(struct survey_run *r, struct app *a, int ends_run)
{
    sonar_survey_rec_init(&r->rec);
    app_record_survey(a, &r->rec, ends_run);
}

/* Why the recording was refused, and what to do, into err. */
static void refused(const struct sonar_survey_rec *rec, char *err, size_t errlen)
{
    switch (rec->why) {
    case SONAR_SURVEY_MOVED:
        snprintf(err, errlen, "track %u went %.1f m over its last %d looks (to %.1f, %.1f m) by sweep %u: someone or "
                              "something was in the water; record the survey again when the site is empty and still",
                 (unsigned)rec->moved_id, (double)rec->moved_m, SONAR_SURVEY_PATH, (double)rec->moved_x, (double)rec->moved_y,
                 (unsigned)rec->sweeps);
        break;
    case SONAR_SURVEY_GEOMETRY:
        snprintf(err, errlen, "the samples or the range changed during the survey (it began at %u samples over %.3f m): "
                              "record it at one setting", rec->n, (double)rec->range_m);
        break;
    case SONAR_SURVEY_GAIN:
        snprintf(err, errlen, "the gain changed during the survey (it began at gain %d): record it at one gain (not "
                              "--gain auto)", rec->gain);
        break;
    case SONAR_SURVEY_WORLD:
        snprintf(err, errlen, "the vehicle's pose came during the survey (the world frame): a survey is of a fixed site");
        break;
    default:
        snprintf(err, errlen, "%s", sonar_survey_why_str(rec->why));
        break;
    }
}

/* Rows looked at often enough to be known, and the fewest and most looks among them. */
static unsigned known_rows(const struct sonar_survey_rec *rec, unsigned *lo, unsigned *hi)
{
    unsigned k, n = 0;
    *lo = 255;
    *hi = 0;
    for (k = 0; k < SONAR_MAX_ANGLES; k++) {
        if (rec->looks[k] < SONAR_SURVEY_MIN_LOOKS)
            continue;
        n++;
        *lo = rec->looks[k] < *lo ? rec->looks[k] : *lo;
        *hi = rec->looks[k] > *hi ? rec->looks[k] : *hi;
    }
    return n;
}

int survey_run_finish(struct survey_run *r, struct app *a, const struct sonard_options *o, long sweeps, FILE *out,
                      char *err, size_t errlen)
{
    const struct sonar_pipeline_config *c = sonar_pipeline_running(app_pipeline(a));
    const struct sonar_ping360_config *d = &o->device;
    /* The sector: the live sonar's, or the one given for a replay; else whatever the recording looked at. */
    int sector = o->sonar != NULL || options_given(o, "sector");
    uint16_t from = sector ? d->start_angle : 0, to = sector && !d->full_circle ? d->stop_angle : from;
    uint16_t step = sector ? d->step : 0, angle = 0;
    struct sonar_bgfile_meta m;
    unsigned rows, lo, hi, walls = 0;
    uint8_t looks = 0, np = 0, k;
    char why[320];
    int32_t len;
    app_record_survey(a, NULL, 0);
    if (r->rec.why != SONAR_SURVEY_OK) {
        refused(&r->rec, why, sizeof(why));
        snprintf(err, errlen, "survey: refused, nothing written: %s", why);
        return HOST_ERR_REFUSED;
    }
    if (r->rec.sweeps < (uint32_t)sweeps) {
        snprintf(err, errlen, "survey: refused, nothing written: the run ended after %u of the %ld sweeps asked for",
                 (unsigned)r->rec.sweeps, sweeps);
        return HOST_ERR_REFUSED;
    }
    if (sonar_survey_rec_check(&r->rec, from, to, step, &angle, &looks) != SONAR_OK) {
        if (looks == 0)
            snprintf(err, errlen, "survey: refused, nothing written: gradian %u of the sector %u..%u was never looked at: "
                                  "the angles covered are fewer than the sector's", angle, from, to);
        else
            snprintf(err, errlen, "survey: refused, nothing written: gradian %u was looked at %u times, fewer than the %d "
                                  "that know a cell's level and spread: record more sweeps",
                     angle, looks, SONAR_SURVEY_MIN_LOOKS);
        return HOST_ERR_REFUSED;
    }
    memset(&m, 0, sizeof(m));
    m.mode = c->background.mode;
    m.median = c->median2d ? 1 : c->median;
    m.median2d = c->median2d;
    m.sound_mm_s = (uint32_t)(o->speed_of_sound * 1e3 + 0.5);
    len = sonar_survey_rec_image(&r->rec, &m, &c->detector, &r->det, r->places, &np, r->image, sizeof(r->image));
    if (len < 0) {
        snprintf(err, errlen, "survey: refused, nothing written: %s", sonar_err_str(len));
        return HOST_ERR_REFUSED;
    }
    {
        /* The clutter map learnt over the same sweeps, after the image: a site's false echoes come with its survey. */
        int32_t map = app_clutter_image(a, r->image + len, sizeof(r->image) - (size_t)len);
        if (map < 0) {
            snprintf(err, errlen, "survey: refused, nothing written: the clutter map: %s", sonar_err_str(map));
            return HOST_ERR_REFUSED;
        }
        len += map;
    }
    if (bgstore_write("survey", o->survey, r->image, (size_t)len, err, errlen) != HOST_OK)
        return HOST_ERR_IO;
    for (k = 0; k < np; k++)
        walls += r->places[k].kind == SONAR_DET_STRUCTURE;
    rows = known_rows(&r->rec, &lo, &hi);
    fprintf(out, "sonard: survey: written to %s: %u sweeps, %u angles known (%u..%u looks each), %u samples over %.3f m at "
                 "gain %d; %u structure place%s (%u wall%s or rope%s, %u compact)\n",
            o->survey, (unsigned)r->rec.sweeps, rows, lo, hi, r->rec.n, (double)r->rec.range_m, r->rec.gain, np,
            np == 1 ? "" : "s", walls, walls == 1 ? "" : "s", walls == 1 ? "" : "s", np - walls);
    return HOST_OK;
}
