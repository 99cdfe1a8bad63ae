/* source_replay.h -- the replay source: rows of a CSV recording become beam records pushed into the app core; ~1.1 MB (the CSV reader's buffers). */
#ifndef SONARD_SOURCE_REPLAY_H
#define SONARD_SOURCE_REPLAY_H

#include <stdio.h>

#include "app.h"
#include "csv.h"
#include "posefile.h"

struct source_replay {
    struct csv_reader csv;
    struct csv_row row;
    double range_m;        /* > 0: overrides the rows' metadata */
    double speed_of_sound; /* m/s, when a row does not say */
    struct posefile *pose; /* --pose FILE, read ahead of each beam, or NULL: the rows' own poses */
    double beam_ms;        /* > 0: the time between untimed rows; else the Ping360 model */
    double speed;          /* > 0: push rows at this multiple of their recorded pace (1 = as recorded); 0: at once */
    int progress;          /* 1: a progress line on errf (the caller checks errf is a terminal) */
    int quiet;             /* 1: do not say which form the file is in */
    int64_t clock_us;      /* the untimed rows' clock */
    int prev_angle;        /* the previous untimed row's angle, -1 before the first */
};


/* path: a file or "-". Returns HOST_OK or HOST_ERR_IO with "PATH: reason" in err. */
HOST_CHECK int source_replay_open(struct source_replay *r, const char *path, double range_m, double speed_of_sound,
                                  char *err, size_t errlen);

/* The same over an open stream (fuzzing, tests); name is used in messages. */
void source_replay_stream(struct source_replay *r, FILE *f, const char *name, double range_m, double speed_of_sound);

/*
 * Pushes every row into a, ending the last sweep. A malformed or refused row is reported on
 * errf as "PATH:LINE: reason; row skipped" (errf NULL: only counted in a->rows_bad) and the run
 * goes on. Returns the rows used.
 */
unsigned long source_replay_run(struct source_replay *r, struct app *a, FILE *errf);

void source_replay_close(struct source_replay *r);

#endif
