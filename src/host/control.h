/* control.h -- sonard --control: commands on SONAR_CONTROL (record the site's survey while running, cancel it) taken from LCM, one a second, each answered on SONAR_STATUS; RAM: sizeof(struct control) = 784 B (the recording is the caller's survey_run). */
#ifndef SONARD_CONTROL_H
#define SONARD_CONTROL_H

#include <stddef.h>
#include <stdint.h>

#include "app.h"
#include "live.h"
#include "options.h"
#include "survey_run.h"

#define CONTROL_GAP_US 1000000     /* commands closer than this to the last one are refused, so a flood changes nothing */
#define CONTROL_SWEEPS_MIN 8       /* a survey's sweeps, as --survey N's */
#define CONTROL_SWEEPS_MAX 255

enum control_command { CONTROL_RECORD_SURVEY = 1, CONTROL_CANCEL_SURVEY = 2 };

struct control {
    void *lcm;                       /* lcm_t: sonard's own (the LCM sink's), borrowed */
    struct app *app;
    const struct sonard_options *opt; /* the survey's file, the sector, what makes the sonar move */
    struct survey_run *run;          /* the recording's storage, the caller's (sonard's --survey N uses it too) */
    char channel[64];
    struct app_sink sink;            /* adds the control part to every SONAR_STATUS */
    int64_t last_us;                 /* the last command's arrival (monotonic), 0 none */
    uint32_t seq;                    /* the last command handled, its answer and why */
    int result;
    char said[200];
    int rec;                         /* enum sonar_control_rec */
    uint32_t rec_of;                 /* sweeps asked for */
    char rec_said[360];
    uint32_t received, bad, refused; /* commands; ones that did not decode; ones refused */
};

/*
 * Subscribes to prefix + "SONAR_CONTROL" on lcm (sonard's, an lcm_t) and adds the control's part to
 * every status the app sends (a sink with only a fill). run is where a recording goes; o the running
 * options (kept, not copied). Returns HOST_OK, or HOST_ERR_IO / HOST_ERR_CONFIG with err saying why.
 */
HOST_CHECK int control_open(struct control *c, void *lcm, const char *prefix, struct app *a,
                            const struct sonard_options *o, struct survey_run *run, char *err, size_t errlen);

/*
 * One command (decoded: seq, command, sweeps) at now_us (monotonic): taken or refused, with why, into
 * the next status; a survey's recording started or cancelled. For the LCM handler and for tests.
 * Returns SONAR_CONTROL_TAKEN or SONAR_CONTROL_REFUSED.
 */
int control_command(struct control *c, int32_t seq, int command, int sweeps, int64_t now_us);

/* A recording that has its sweeps or was refused is finished: checked, written, loaded (said); call often. */
void control_tick(struct control *c);

/* At the end of the run: a recording still going is given up, nothing written (said). */
void control_close(struct control *c);

/* The loop's view of it: LCM's descriptor (shared with SONAR_POSE's subscription: either handles both). */
void control_live(struct control *c, struct live_aux *out);

#endif
