/* bgstore.h -- a site's survey and --background-load / --background-save: the file read whole and checked, written atomically (temporary file, fsync, rename); RAM: two image buffers, static (SONAR_BGFILE_MAX + SONAR_CLUTTER_WIRE + 1: 965 522 B each at the default limits, a clutter map after the image; the second touched only by a survey loaded while running). */
#ifndef SONARD_BGSTORE_H
#define SONARD_BGSTORE_H

#include <stddef.h>
#include <stdint.h>

#include "app.h"

/*
 * Reads path into the buffer the app does not hold and hands it to the app (app_background_load),
 * which keeps it to take the survey back after a misfit (so it may be called while running): the file's header, size, version, geometry and checksum are checked
 * first, its filters against the configuration; its range, samples and gain against every beam.
 * what names the setting in messages ("survey", "--background-load"). Returns HOST_OK; HOST_ERR_IO
 * (unreadable: err says why, with errno's text); or HOST_ERR_CONFIG (refused: err names the file and
 * what is wrong). On an error the app keeps what it had (at start: the background learns from scratch).
 */
HOST_CHECK int bgstore_load(struct app *a, const char *what, const char *path, char *err, size_t errlen);

/*
 * Writes len bytes of img to path: into path.tmp.PID beside it, fsync'd, then renamed over path
 * (and the folder fsync'd), so a reader sees the old file or the new one, never a part. On any
 * failure the temporary file is removed and path is as it was. Returns HOST_OK or HOST_ERR_IO (err
 * with what, the path and errno's text).
 */
HOST_CHECK int bgstore_write(const char *what, const char *path, const uint8_t *img, size_t len, char *err, size_t errlen);

/*
 * --background-save: the app's learnt model written to path (bgstore_write). Returns HOST_OK,
 * HOST_ERR_IO or HOST_ERR_STATE (nothing learnt yet, a world-frame model, or a survey in use: err
 * says so).
 */
HOST_CHECK int bgstore_save(const struct app *a, const char *path, char *err, size_t errlen);

#endif
