/* report.h -- writes a sweep's detections as one JSON line or as readable text; stdio only. */
#ifndef SONARD_REPORT_H
#define SONARD_REPORT_H

#include <stdio.h>

#include "sonar/detector.h"

/* {"sweep":k,"utime":us,"beams":n,"detections":[{"x_m",...,"hull":[[x,y],...]}]} and a newline. */
int report_json(FILE *f, const struct sonar_detections *d);

/* One line per sweep and one per detection. */
int report_text(FILE *f, const struct sonar_detections *d);

#endif
