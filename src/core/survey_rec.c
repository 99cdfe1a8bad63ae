/* survey_rec.c -- recording a site's survey (survey.h): each look summed into its cells, refusals, then the levels, spread and structure written as a bgfile.h image; O(n) a beam, no heap. */
#include "sonar/survey.h"

#include <string.h>

#include "survey_internal.h"

void sonar_survey_rec_init(struct sonar_survey_rec *rec)
{
    memset(rec, 0, sizeof(*rec));
    rec->gain = -1;
}

static int refuse(struct sonar_survey_rec *rec, int why)
{
    if (rec->why == SONAR_SURVEY_OK)
        rec->why = (uint8_t)why;
    return SONAR_ERR_STATE;
}

int sonar_survey_rec_beam(struct sonar_survey_rec *rec, uint16_t angle, const uint8_t *samples, uint16_t n, float range_m,
                          int16_t gain, int64_t utime)
{
    uint16_t *sum;
    uint32_t *sq;
    uint8_t *top;
    unsigned row;
    uint16_t i;
    if (rec == NULL || samples == NULL || angle > SONAR_GRAD_MAX || n == 0 || n > SONAR_MAX_SAMPLES || !(range_m > 0.0f))
        return SONAR_ERR_ARG;
    if (rec->why != SONAR_SURVEY_OK)
        return SONAR_ERR_STATE;
    if (rec->n == 0) {
        rec->n = n;
        rec->range_m = range_m;
        rec->gain = gain;
        rec->first_utime = utime;
    } else if (n != rec->n || !same_range(range_m, (double)rec->range_m * 1e3)) {
        return refuse(rec, SONAR_SURVEY_GEOMETRY);
    } else if (gain != rec->gain) {
        return refuse(rec, SONAR_SURVEY_GAIN);
    }
    rec->last_utime = utime;
    rec->beams++;
    row = row_of(angle);
    if (rec->looks[row] >= SONAR_SURVEY_MAX_LOOKS)
        return SONAR_OK; /* enough is known of it: the sums would overflow */
    rec->looks[row]++;
    sum = rec->sum[row];
    sq = rec->sq[row];
    top = rec->top[row];
    for (i = 0; i < n; i++) {
        sum[i] = (uint16_t)(sum[i] + samples[i]);
        sq[i] += (uint32_t)samples[i] * samples[i];
        top[i] = samples[i] > top[i] ? samples[i] : top[i];
    }
    return SONAR_OK;
}

int sonar_survey_rec_sweep(struct sonar_survey_rec *rec, const struct sonar_tracker *tk, int world)
{
    uint8_t i, j;
    if (rec == NULL)
        return SONAR_ERR_ARG;
    if (rec->why != SONAR_SURVEY_OK)
        return SONAR_ERR_STATE;
    rec->sweeps++;
    if (world)
        return refuse(rec, SONAR_SURVEY_WORLD);
    for (i = 0; tk != NULL && i < tk->n; i++) {
        const struct sonar_track *t = &tk->t[i];
        float dx, dy, d;
        if (t->state == SONAR_TRACK_TENTATIVE)
            continue;
        for (j = 0; j < rec->nfirst && rec->first[j].id != t->id; j++)
            ;
        if (j == rec->nfirst) {
            /* Where it was when first confirmed; a full table keeps the first ones (more than
               SONAR_MAX_TRACKS things in an empty site is itself a refusal to come). */
            if (rec->nfirst < SONAR_MAX_TRACKS) {
                rec->first[rec->nfirst].id = t->id;
                rec->first[rec->nfirst].x = t->px;
                rec->first[rec->nfirst].y = t->py;
                rec->nfirst++;
            }
            continue;
        }
        dx = t->px - rec->first[j].x;
        dy = t->py - rec->first[j].y;
        d = sqrtf(dx * dx + dy * dy);
        /* Moving by its models, over enough hits that it is something (two flukes joined make a young track jump). */
        if (d > SONAR_SURVEY_MOVED_M && t->hits >= SONAR_TRK_KIND_HITS && t->kind == SONAR_TRACK_KIND_MOVING) {
            rec->moved_id = t->id;
            rec->moved_m = d;
            rec->moved_x = t->px;
            rec->moved_y = t->py;
            return refuse(rec, SONAR_SURVEY_MOVED);
        }
    }
    return SONAR_OK;
}

int sonar_survey_rec_check(struct sonar_survey_rec *rec, uint16_t from, uint16_t to, uint16_t step, uint16_t *angle_out,
                           uint8_t *looks_out)
{
    /* An angle is known from a row looked at this close: half the step, and never less than the beam's reach. */
    int reach = step / 2 > SONAR_SURVEY_FILL ? step / 2 : SONAR_SURVEY_FILL, span, k;
    if (rec == NULL || from > SONAR_GRAD_MAX || to > SONAR_GRAD_MAX || step > 200)
        return SONAR_ERR_ARG;
    if (rec->why != SONAR_SURVEY_OK)
        return SONAR_ERR_STATE;
    span = from == to || (to + 1) % (int)SONAR_GRAD_TURN == from ? (int)SONAR_GRAD_TURN - 1
                                                                : sonar_frame_wrap((int)to - (int)from);
    for (k = 0; k <= span; k++) {
        int a = sonar_frame_wrap((int)from + k), d, best = -1;
        unsigned row;
        if (step == 0 && rec->looks[row_of((uint16_t)a)] == 0)
            continue; /* the sector is what the recording looked at */
        /* The row that knows the angle best within reach (a sector's end is looked at once a turn-around). */
        for (d = 0; d <= reach; d++) {
            unsigned lo = row_of((uint16_t)sonar_frame_wrap(a - d)), hi = row_of((uint16_t)sonar_frame_wrap(a + d));
            row = rec->looks[lo] >= rec->looks[hi] ? lo : hi;
            if (rec->looks[row] > 0 && (best < 0 || rec->looks[row] > rec->looks[best]))
                best = (int)row;
        }
        if (best < 0 || rec->looks[best] < SONAR_SURVEY_MIN_LOOKS) {
            *angle_out = (uint16_t)a;
            *looks_out = best < 0 ? 0 : rec->looks[best];
            return refuse(rec, SONAR_SURVEY_ANGLES);
        }
    }
    for (k = 0; k < SONAR_MAX_ANGLES; k++)
        if (rec->looks[k] > 0)
            return SONAR_OK;
    *angle_out = from;
    *looks_out = 0;
    return refuse(rec, SONAR_SURVEY_ANGLES);
}

/*
 * The site's structure: where the levels stand out from the level across the angles at their
 * range (twice it, and SONAR_SURVEY_SIG_LEVEL / 2 above it), as a detector of config dc finds them
 * over every row looked at: walls (wider than any object: kind structure), ladders and posts.
 */
static int find_places(const struct sonar_survey_rec *rec, const uint8_t *out, const struct sonar_bgfile_layout *l,
                       const struct sonar_detector_config *dc, struct sonar_detector *det, struct sonar_detections *found)
{
    struct sonar_detector_config c = *dc;
    uint8_t fg[SONAR_MAX_SAMPLES], on[SONAR_MAX_SAMPLES / 8 + 1];
    const uint8_t *across = out + l->across;
    unsigned row;
    uint16_t i;
    int r;
    c.track_m = 0.0f; /* nothing is expected anywhere */
    c.max_clusters = SONAR_MAX_CLUSTERS;
    if ((r = sonar_detector_init(det, &c)) != SONAR_OK)
        return r;
    memset(on, 1, sizeof(on));
    for (row = 0; row < SONAR_MAX_ANGLES; row++) {
        const uint8_t *lv = out + l->levels + (size_t)row * rec->n;
        if (rec->looks[row] == 0)
            continue;
        for (i = 0; i < rec->n; i++) {
            unsigned need = 2u * across[i] > across[i] + SONAR_SURVEY_SIG_LEVEL / 2u ? 2u * across[i]
                                                                                  : across[i] + SONAR_SURVEY_SIG_LEVEL / 2u;
            fg[i] = (uint8_t)(lv[i] >= need ? (unsigned)lv[i] - across[i] : 0u);
        }
        r = sonar_detector_add_blocks(det, angle_of(row), fg, on, rec->n, rec->range_m, rec->last_utime);
        if (r != SONAR_OK && r != SONAR_ERR_FULL)
            return r;
    }
    r = sonar_detector_end(det, found);
    return r < 0 ? r : SONAR_OK;
}

int32_t sonar_survey_rec_image(struct sonar_survey_rec *rec, const struct sonar_bgfile_meta *m,
                               const struct sonar_detector_config *dc, struct sonar_detector *det,
                               struct sonar_detection *places, uint8_t *nplaces, uint8_t *out, size_t cap)
{
    static const uint8_t flags = SONAR_BGFILE_SPREAD | SONAR_BGFILE_SURVEY;
    struct sonar_bgfile_meta h;
    struct sonar_bgfile_layout l;
    struct sonar_detections found;
    uint16_t hist[256];
    unsigned row, used = 0;
    uint16_t i;
    uint8_t k, np;
    int r;
    if (rec == NULL || m == NULL || dc == NULL || det == NULL || out == NULL)
        return SONAR_ERR_ARG;
    if (rec->why != SONAR_SURVEY_OK || rec->n == 0)
        return SONAR_ERR_STATE;
    if (sonar_bgfile_layout(rec->n, flags, SONAR_MAX_CLUSTERS, &l) != SONAR_OK)
        return SONAR_ERR_ARG;
    if (cap < l.size)
        return SONAR_ERR_SPACE;
    /*
     * Each cell's level (the mean of its looks, rounded) and spread: their standard deviation, or what puts the
     * largest look under the gate when that is more (spreads are gated in 16ths: rounded up).
     */
    for (row = 0; row < SONAR_MAX_ANGLES; row++) {
        uint8_t *lv = out + l.levels + (size_t)row * rec->n, *sp = out + l.spread + (size_t)row * rec->n;
        unsigned v = rec->looks[row];
        used += v > 0;
        for (i = 0; i < rec->n; i++) {
            double mean = v ? (double)rec->sum[row][i] / v : 0.0, var = v ? (double)rec->sq[row][i] / v - mean * mean : 0.0;
            unsigned sd, over, need;
            lv[i] = (uint8_t)(v ? (rec->sum[row][i] + v / 2u) / v : 0u);
            over = v && rec->top[row][i] > lv[i] ? (unsigned)rec->top[row][i] - lv[i] : 0u;
            need = (over * 16u + SONAR_SURVEY_SPREADS16 - 1u) / SONAR_SURVEY_SPREADS16;
            sd = var > 0.0 ? (unsigned)(sqrt(var) + 0.5) : 0u;
            sd = sd > need ? sd : need;
            sp[i] = (uint8_t)(sd > 255u ? 255u : sd);
        }
    }
    if (used == 0)
        return SONAR_ERR_STATE;
    memcpy(out + l.looks, rec->looks, SONAR_MAX_ANGLES);
    out[l.looks + SONAR_MAX_ANGLES] = 255; /* the level across the angles is known from every row */
    /* The level across the angles: the median of the rows' levels at each range. */
    for (i = 0; i < rec->n; i++) {
        memset(hist, 0, sizeof(hist));
        for (row = 0; row < SONAR_MAX_ANGLES; row++)
            if (rec->looks[row] > 0)
                hist[out[l.levels + (size_t)row * rec->n + i]]++;
        out[l.across + i] = hist_median(hist, used);
    }
    if ((r = find_places(rec, out, &l, dc, det, &found)) != SONAR_OK)
        return r;
    np = found.count;
    if (sonar_bgfile_layout(rec->n, flags, np, &l) != SONAR_OK)
        return SONAR_ERR_ARG;
    for (k = 0; k < np; k++) {
        sonar_bgfile_put_place(out + l.places + (size_t)k * SONAR_BGFILE_PLACE, &found.det[k]);
        if (places != NULL)
            places[k] = found.det[k];
    }
    if (nplaces != NULL)
        *nplaces = np;
    h = *m;
    h.n = rec->n;
    h.gain = rec->gain >= 0 && rec->gain <= 2 ? (uint8_t)rec->gain : SONAR_BGFILE_GAIN_UNKNOWN;
    h.range_mm = (uint32_t)lround((double)rec->range_m * 1e3);
    h.sweeps = rec->sweeps;
    h.utime = rec->last_utime;
    h.flags = flags;
    h.places = np;
    h.offset_mgrad = (int32_t)lround((double)dc->angle_offset * 1e3);
    sonar_bgfile_put_header(out, &h);
    sonar_bgfile_seal(out, &l);
    return (int32_t)l.size;
}
