/* bgstore.h -- --background-load and --background-save: a recorded background read whole and checked, written atomically (temporary file, fsync, rename); RAM: one image buffer, static (sonar_bgfile_size at SONAR_MAX_SAMPLES). */
#ifndef SONARD_BGSTORE_H
#define SONARD_BGSTORE_H

#include <stddef.h>

#include "app.h"

/*
 * Reads path and hands the model to the app (app_background_load): the file's header, size,
 * version, geometry and checksum are checked first, its range, samples and gain against the first
 * beam. Returns HOST_OK; HOST_ERR_IO (unreadable: err says why, with errno's text); or
 * HOST_ERR_CONFIG (refused: err names the file and what is wrong). On an error nothing changed and
 * the background learns from scratch.
 */
HOST_CHECK int bgstore_load(struct app *a, const char *path, char *err, size_t errlen);

/*
 * Writes the app's learnt model to path: into path.tmp.PID beside it, fsync'd, then renamed over
 * path (and the folder fsync'd), so a reader sees the old file or the new one, never a part. On any
 * failure the temporary file is removed and path is as it was. Returns HOST_OK, HOST_ERR_IO (err
 * with errno's text) or HOST_ERR_STATE (nothing learnt yet, or a world-frame model: err says so).
 */
HOST_CHECK int bgstore_save(const struct app *a, const char *path, char *err, size_t errlen);

#endif
