/* tracker_read.c -- the tracker as its readers see it: its tracks, their frame, the names of their states, modes and kinds, the revisions of the last look and a late reader's relabelled copy; O(tracks), no RAM. */
#include "sonar/tracker.h"

unsigned sonar_tracker_count(const struct sonar_tracker *tk)
{
    return tk->n;
}

const struct sonar_track *sonar_tracker_track(const struct sonar_tracker *tk, unsigned i)
{
    return &tk->t[i];
}

int sonar_tracker_world(const struct sonar_tracker *tk)
{
    return tk->world;
}

const char *sonar_track_state_str(int state)
{
    switch (state) {
    case SONAR_TRACK_TENTATIVE: return "tentative";
    case SONAR_TRACK_CONFIRMED: return "confirmed";
    case SONAR_TRACK_COASTING: return "coasting";
    default: return "?";
    }
}

const char *sonar_track_mode_str(int mode)
{
    switch (mode) {
    case SONAR_TRACK_MOVING: return "moving";
    case SONAR_TRACK_TURNING: return "turning";
    case SONAR_TRACK_RESTING: return "resting";
    default: return "?";
    }
}

const char *sonar_track_kind_str(int kind)
{
    switch (kind) {
    case SONAR_TRACK_KIND_NEW: return "new";
    case SONAR_TRACK_KIND_MOVING: return "moving";
    case SONAR_TRACK_KIND_RESTING: return "resting";
    case SONAR_TRACK_KIND_STILL: return "still";
    case SONAR_TRACK_KIND_STATIC_START: return "static since start";
    default: return "?";
    }
}

const struct sonar_track_revision *sonar_tracker_revisions(const struct sonar_tracker *tk, unsigned *n)
{
    *n = tk->nrev;
    return tk->rev;
}

unsigned sonar_tracker_relabel(struct sonar_tracker *copy, const struct sonar_tracker *next, uint8_t *kept)
{
    uint8_t k, j, r;
    for (k = 0, j = 0; k < copy->n; k++) {
        struct sonar_track t = copy->t[k];
        int gone = 0;
        for (r = 0; r < next->nrev; r++)
            if (next->rev[r].from == t.id) {
                gone = next->rev[r].to == 0;
                t.id = next->rev[r].to;
                break;
            }
        if (gone)
            continue;
        kept[j] = k;
        copy->t[j++] = t;
    }
    copy->n = j;
    copy->nrev = 0;
    return j;
}
