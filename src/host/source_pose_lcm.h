/* source_pose_lcm.h -- poses over LCM: sonar.pose_t on SONAR_POSE into the app, from sonard's own LCM or a URL of its own; a few bytes beside the lcm_t. */
#ifndef SONARD_SOURCE_POSE_LCM_H
#define SONARD_SOURCE_POSE_LCM_H

#include <stddef.h>
#include <stdint.h>

#include "app.h"
#include "live.h"

struct source_pose_lcm {
    void *lcm;        /* lcm_t */
    int owned;        /* opened here (a URL of its own), so closed here */
    struct app *app;
    char channel[64];
    uint32_t received, bad, refused; /* messages; ones that do not decode; poses the ring refused */
};

/*
 * Subscribes to prefix + "SONAR_POSE" on lcm (an lcm_t, e.g. the LCM sink's), or, when url is not
 * NULL, on an LCM of its own at url. Returns HOST_OK, or HOST_ERR_IO with err naming the URL.
 */
HOST_CHECK int source_pose_lcm_open(struct source_pose_lcm *s, void *lcm, const char *url, const char *prefix,
                                    struct app *a, char *err, size_t errlen);

/* Handles what is waiting, without blocking (also for tests). */
void source_pose_lcm_poll(struct source_pose_lcm *s);

/* The loop's view of it: LCM's descriptor. */
void source_pose_lcm_live(struct source_pose_lcm *s, struct live_aux *out);

void source_pose_lcm_close(struct source_pose_lcm *s);

#endif
