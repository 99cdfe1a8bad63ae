/* posefile.h -- the offline pose source: a CSV of utime_us,north_m,east_m,yaw_deg read ahead of the beams into the app's poses; one line buffer (~1 KB). */
#ifndef SONARD_POSEFILE_H
#define SONARD_POSEFILE_H

#include <stdio.h>

#include "app.h"

#define POSEFILE_LINE_MAX 1024

struct posefile {
    FILE *f;
    const char *path;
    unsigned long line;       /* line of the last row read */
    unsigned long good, bad;  /* rows taken; rows malformed or refused by the poses */
    int col[4];               /* column of utime_us, north_m, east_m, yaw_deg */
    int ncol;
    int have_next, eof;
    struct sonar_pose next;   /* read, not yet given: later than what was asked for */
    unsigned long next_line;
    char buf[POSEFILE_LINE_MAX + 2];
};

/*
 * Opens path and reads its header: a line naming the columns, comma-separated, among them
 * utime_us (us since the epoch), north_m, east_m (local NED, metres) and yaw_deg (degrees
 * clockwise from north), in any order; other columns are ignored. Returns HOST_OK, HOST_ERR_IO
 * or HOST_ERR_CONFIG (no such header), with "PATH[:LINE]: reason" in err.
 */
HOST_CHECK int posefile_open(struct posefile *p, const char *path, char *err, size_t errlen);

/* The same over an open stream (kept, and closed by posefile_close or a failed open); path names it in messages. */
HOST_CHECK int posefile_open_stream(struct posefile *p, FILE *stream, const char *path, char *err, size_t errlen);

/*
 * Gives the app every sample up to and including until_us (us since the epoch). A malformed row
 * or one the poses refuse (out of order, a jump) is reported on errf as "PATH:LINE: reason; row
 * skipped" (errf NULL: only counted) and the file goes on.
 */
void posefile_feed(struct posefile *p, struct app *a, int64_t until_us, FILE *errf);

void posefile_close(struct posefile *p);

#endif
