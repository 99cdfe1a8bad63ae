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

int sonar_survey_rec_apply(struct sonar_survey_rec *rec, uint16_t angle, const uint8_t *in, uint8_t *fg, uint16_t n,
                           uint8_t margin)
{
    unsigned row, v;
    uint16_t i;
    if (rec == NULL || in == NULL || fg == NULL || angle > SONAR_GRAD_MAX || n != rec->n || n == 0)
        return 0;
    row = row_of(angle);
    if ((v = rec->looks[row]) < SONAR_SURVEY_REC_LOOKS)
        return 0;
    for (i = 0; i < n; i++) {
        double mean = (double)rec->sum[row][i] / v, var = (double)rec->sq[row][i] / v - mean * mean;
        double gate = 3.0 * (var > 0.0 ? sqrt(var) : 0.0), floor16 = mean * margin / 16.0;
        double x = in[i];
        gate = gate > floor16 ? gate : floor16;
        fg[i] = (uint8_t)(x > mean + gate ? x - mean + 0.5 : 0.0);
    }
    rec->judged++;
    return 1;
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
    rec->sweep_beams++;
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

/* The path slot of track id (a free one, or the slot of a track that is gone, when it has none); NULL when full. */
static int path_slot(struct sonar_survey_rec *rec, const struct sonar_tracker *tk, uint32_t id)
{
    int k, free_at = -1;
    uint8_t i;
    for (k = 0; k < SONAR_MAX_TRACKS; k++) {
        int live = 0;
        if (rec->path[k].id == id)
            return k;
        for (i = 0; i < tk->n && !live; i++)
            live = tk->t[i].id == rec->path[k].id;
        if (free_at < 0 && (rec->path[k].id == 0 || !live))
            free_at = k;
    }
    if (free_at >= 0) {
        memset(&rec->path[free_at], 0, sizeof(rec->path[free_at]));
        rec->path[free_at].id = id;
    }
    return free_at;
}

/* Whether a path of SONAR_SURVEY_PATH hits went more than SONAR_SURVEY_MOVED_M, and in a line; *d the distance. */
static int went(const float *x, const float *y, float *d)
{
    float len = 0.0f, dx, dy;
    int k;
    for (k = 1; k < SONAR_SURVEY_PATH; k++) {
        dx = x[k] - x[k - 1];
        dy = y[k] - y[k - 1];
        len += sqrtf(dx * dx + dy * dy);
    }
    dx = x[SONAR_SURVEY_PATH - 1] - x[0];
    dy = y[SONAR_SURVEY_PATH - 1] - y[0];
    *d = sqrtf(dx * dx + dy * dy);
    return *d > SONAR_SURVEY_MOVED_M && *d >= SONAR_SURVEY_STRAIGHT * len;
}

/* The mean of a path's kept hits. */
static void mean_of(const struct sonar_survey_path *p, float *x, float *y)
{
    float sx = 0.0f, sy = 0.0f;
    uint8_t k;
    for (k = 0; k < p->n; k++) {
        sx += p->x[k];
        sy += p->y[k];
    }
    *x = p->n ? sx / (float)p->n : 0.0f;
    *y = p->n ? sy / (float)p->n : 0.0f;
}

/* Whether the mean of a path's last hits is more than SONAR_SURVEY_MOVED_M from the mean of its first: a slow drift. */
static int drifted(const struct sonar_survey_path *p, float *d)
{
    float x, y;
    mean_of(p, &x, &y);
    *d = sqrtf((x - p->x0) * (x - p->x0) + (y - p->y0) * (y - p->y0));
    return *d > SONAR_SURVEY_MOVED_M;
}

int sonar_survey_rec_sweep(struct sonar_survey_rec *rec, const struct sonar_tracker *tk, int world)
{
    uint8_t i;
    int judged;
    if (rec == NULL)
        return SONAR_ERR_ARG;
    if (rec->why != SONAR_SURVEY_OK)
        return SONAR_ERR_STATE;
    rec->sweeps++;
    if (world)
        return refuse(rec, SONAR_SURVEY_WORLD);
    judged = 2u * rec->judged >= rec->sweep_beams && rec->sweep_beams > 0;
    rec->judged = rec->sweep_beams = 0;
    if (!judged) {
        /* Learnt per angle, not yet against the sums: the site's own clutter stands out; paths start afresh. */
        memset(rec->path, 0, sizeof(rec->path));
        return SONAR_OK;
    }
    for (i = 0; tk != NULL && i < tk->n; i++) {
        const struct sonar_track *t = &tk->t[i];
        int k, m;
        float d;
        if (t->state == SONAR_TRACK_TENTATIVE || t->det < 0 || (k = path_slot(rec, tk, t->id)) < 0)
            continue;
        if (rec->path[k].n == SONAR_SURVEY_PATH) {
            for (m = 1; m < SONAR_SURVEY_PATH; m++) {
                rec->path[k].sweep[m - 1] = rec->path[k].sweep[m];
                rec->path[k].x[m - 1] = rec->path[k].x[m];
                rec->path[k].y[m - 1] = rec->path[k].y[m];
            }
            rec->path[k].n--;
        }
        m = rec->path[k].n++;
        rec->path[k].sweep[m] = rec->sweeps;
        rec->path[k].x[m] = t->px;
        rec->path[k].y[m] = t->py;
        if (rec->path[k].hits < 0xFFFFu)
            rec->path[k].hits++;
        if (rec->path[k].hits == SONAR_SURVEY_PATH)
            mean_of(&rec->path[k], &rec->path[k].x0, &rec->path[k].y0);
        /* Only what exists is judged: clutter hops joined into a track wander metres a look but seldom hold their
           existence (tracker.h); a swimmer's track does, and only the swimmer must refuse the survey. */
        if (rec->path[k].n == SONAR_SURVEY_PATH && t->existence >= SONAR_TRK_EXIST_ALARM &&
            ((rec->sweeps - rec->path[k].sweep[0] <= SONAR_SURVEY_PATH + 1u && went(rec->path[k].x, rec->path[k].y, &d)) ||
             (rec->path[k].hits >= 2 * SONAR_SURVEY_PATH && drifted(&rec->path[k], &d)))) {
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
