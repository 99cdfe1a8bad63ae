/* report.h -- writes a sweep's detections and tracks as one JSON line or as readable text; stdio only. */
#ifndef SONARD_REPORT_H
#define SONARD_REPORT_H

#include <stdio.h>

#include "sonar/detector.h"
#include "sonar/pipeline.h"
#include "sonar/tracker.h"
#include "view.h"

/*
 * {"sweep":k,"utime":us,"beams":n,"detections":[{"utime","x_m",...,"hull":[[x,y],...]}],
 * "tracks":[{"id","state","x_m","y_m","vx_mps","vy_mps","age","hits","detection"}]} and a newline;
 * "tracks" only when tk is not NULL.
 */
int report_json(FILE *f, const struct sonar_detections *d, const struct sonar_tracker *tk, const struct msg_view *v);

/* One line per sweep, one per detection and one per track (tk may be NULL). */
int report_text(FILE *f, const struct sonar_detections *d, const struct sonar_tracker *tk, const struct msg_view *v);

#endif
