/* survey_run.h -- sonard --survey N: the empty site recorded while sonard runs as usual, then checked (nothing moved, every angle of the sector known), written atomically and summed up; RAM: sizeof(struct survey_run) = 4 358 200 B (the recording's sums, a detector, the image). */
#ifndef SONARD_SURVEY_RUN_H
#define SONARD_SURVEY_RUN_H

#include <stdio.h>

#include "app.h"
#include "options.h"
#include "sonar/bgfile.h"
#include "sonar/clutter.h"
#include "sonar/survey.h"

struct survey_run {
    struct sonar_survey_rec rec;
    struct sonar_detector det; /* finds the site's structure in the levels */
    struct sonar_detection places[SONAR_MAX_CLUSTERS];
    uint8_t image[SONAR_BGFILE_MAX + SONAR_CLUTTER_WIRE]; /* the survey's image, its clutter map after it */
};

/* Starts recording: every beam after the median and every sweep's tracks of a go into r (app_record_survey; ends_run:
   a refusal ends the run, as --survey N's does). */
void survey_run_start(struct survey_run *r, struct app *a, int ends_run);

/*
 * After the recording (sweeps asked for: --survey N's or a command's; or the source ended or was stopped): stops it, checks it
 * (nothing moved; the sweeps asked for; every angle of the sector, the live sonar's or --sector's,
 * else the replay's, looked at SONAR_SURVEY_MIN_LOOKS times), writes o->survey atomically and says
 * what it holds on out: sweeps, angles, structure places, the file. Returns HOST_OK; HOST_ERR_REFUSED
 * (nothing written, err says why and what to do); HOST_ERR_IO (the write failed, the old file whole).
 */
HOST_CHECK int survey_run_finish(struct survey_run *r, struct app *a, const struct sonard_options *o, long sweeps,
                                 FILE *out, char *err, size_t errlen);

#endif
