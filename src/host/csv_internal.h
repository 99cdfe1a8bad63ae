/* csv_internal.h -- what the CSV reader (csv.c) asks of its file source (csv_file.c); not for other modules; no RAM. */
#ifndef SONARD_CSV_INTERNAL_H
#define SONARD_CSV_INTERNAL_H

#include <stddef.h>

#include "csv.h"

/*
 * At the end of the rows: for a compressed file, did gzip -dc read it all? Reaps the child.
 * Returns 0 (a plain file, or gzip ended well), or HOST_ERR_ROW with err naming the failure.
 */
int csv_file_end(struct csv_reader *r, char *err, size_t errlen);

#endif
