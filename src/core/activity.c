/* activity.c -- each track's activity and alarms from its motion and its raw echo's look-to-look correlation; per beam O(slots), per look O(slots x 256 + tracks x slots), no heap. */
#include "sonar/activity.h"

#include <math.h>
#include <string.h>

#include "sonar/frame.h"
#include "sonar/geometry.h"

int sonar_activity_init(struct sonar_activity *a)
{
    if (a == NULL)
        return SONAR_ERR_ARG;
    memset(a, 0, sizeof(*a));
    a->gain = -1;
    return SONAR_OK;
}

/* Every window restarts: the looks before were taken at another setting. */
static void restart(struct sonar_activity *a)
{
    unsigned k;
    for (k = 0; k < SONAR_ACT_SLOTS; k++) {
        a->s[k].have_prev = 0;
        a->s[k].w[a->s[k].cur].rows = 0;
        a->s[k].idx_state = 0;
    }
}

void sonar_activity_beam(struct sonar_activity *a, uint16_t angle, const uint8_t *samples, uint16_t n,
                         float range_m, int gain)
{
    unsigned k, c;
    if (a == NULL || samples == NULL || n == 0 || !(range_m > 0.0f) || angle >= SONAR_GRAD_TURN)
        return;
    if (a->n != n || a->range_m != range_m || a->gain != gain) {
        if (a->n != 0)
            restart(a);
        a->n = n;
        a->range_m = range_m;
        a->gain = (int16_t)gain;
    }
    if (!(a->cover[angle / 8] & (1u << (angle % 8))))
        return;
    for (k = 0; k < SONAR_ACT_SLOTS; k++) {
        struct sonar_act_slot *s = &a->s[k];
        int d = sonar_frame_delta(s->centre_a, angle);
        uint8_t *row;
        if (s->id == 0 || d < -(SONAR_ACT_ROWS / 2 - 1) || d > SONAR_ACT_ROWS / 2)
            continue;
        if (s->idx_state == 0) {
            /* Once a window: a beam's part of it whole, or not at all (past the range end, or before 0). */
            s->idx_state = 1;
            for (c = 0; c < SONAR_ACT_COLS && s->idx_state == 1; c++) {
                double r = (double)s->centre_r + ((double)c + 0.5 - SONAR_ACT_COLS / 2.0) * (2.0 * SONAR_ACT_HALF_M / SONAR_ACT_COLS);
                int32_t i = sonar_geometry_sample_index(r, n, (double)range_m);
                s->idx[c] = (uint16_t)(i < 0 ? 0 : i);
                if (i < 0)
                    s->idx_state = 2;
            }
        }
        if (s->idx_state != 1)
            continue;
        row = s->w[s->cur].v[d + SONAR_ACT_ROWS / 2 - 1];
        for (c = 0; c < SONAR_ACT_COLS; c++)
            row[c] = samples[s->idx[c]];
        s->w[s->cur].rows |= (uint16_t)(1u << (d + SONAR_ACT_ROWS / 2 - 1));
    }
}

/*
 * Pairs each filled row of q (this look) with the nearest filled row of p (the look before), at
 * most SONAR_ACT_PAIR_GRAD gradians away: a back-and-forth sector visits other gradians each way
 * (AquaScan's passes at 3-gradian steps are 1 and 2 gradians apart), and the nearest beams share
 * the most of a 2-degree beam's footprint. Returns the pairs, p's rows in ip and q's in iq.
 */
static unsigned pairs(const struct sonar_act_patch *p, const struct sonar_act_patch *q, uint8_t *ip, uint8_t *iq)
{
    unsigned r, m = 0;
    int d;
    for (r = 0; r < SONAR_ACT_ROWS; r++) {
        if (!(q->rows & (1u << r)))
            continue;
        for (d = 0; d <= SONAR_ACT_PAIR_GRAD; d++) {
            int lo = (int)r - d, hi = (int)r + d;
            if (lo >= 0 && (p->rows & (1u << lo))) {
                ip[m] = (uint8_t)lo;
                break;
            }
            if (hi < SONAR_ACT_ROWS && (p->rows & (1u << hi))) {
                ip[m] = (uint8_t)hi;
                break;
            }
        }
        if (d <= SONAR_ACT_PAIR_GRAD)
            iq[m++] = (uint8_t)r;
    }
    return m;
}

/*
 * Pearson's correlation of two looks' windows over their paired rows (pairs()); 0 when either is
 * flat. Returns 0 and sets *ok = 0 when fewer than SONAR_ACT_MIN_ROWS pairs.
 */
static float correlate(const struct sonar_act_patch *p, const struct sonar_act_patch *q, int *ok)
{
    uint8_t ip[SONAR_ACT_ROWS], iq[SONAR_ACT_ROWS];
    unsigned m = pairs(p, q, ip, iq), r, c;
    /* Whole sums: 256 cells of 0..255 keep every sum of products under 2^24 (exact in 32 bits). */
    uint32_t su = 0, sv = 0, suu = 0, svv = 0, suv = 0;
    int64_t cnt, du, dv;
    *ok = m >= SONAR_ACT_MIN_ROWS;
    if (!*ok)
        return 0.0f;
    for (r = 0; r < m; r++) {
        const uint8_t *u = p->v[ip[r]], *v = q->v[iq[r]];
        for (c = 0; c < SONAR_ACT_COLS; c++) {
            su += u[c];
            sv += v[c];
            suu += (uint32_t)u[c] * u[c];
            svv += (uint32_t)v[c] * v[c];
            suv += (uint32_t)u[c] * v[c];
        }
    }
    /* n^2 var and n^2 cov in whole numbers (exact in 64 bits); one float division at the end (no doubles: the M4F has
       a single-precision unit only). */
    cnt = (int64_t)m * SONAR_ACT_COLS;
    du = cnt * suu - (int64_t)su * su;
    dv = cnt * svv - (int64_t)sv * sv;
    if (du <= 0 || dv <= 0)
        return 0.0f;
    return (float)(cnt * suv - (int64_t)su * sv) / (sqrtf((float)du) * sqrtf((float)dv));
}

static struct sonar_act_slot *slot_of(struct sonar_activity *a, uint32_t id)
{
    unsigned k;
    for (k = 0; k < SONAR_ACT_SLOTS; k++)
        if (a->s[k].id == id)
            return &a->s[k];
    return NULL;
}

/* Records an alarm change (room for two a slot: a track gone, another come, in one look). */
static void event(struct sonar_activity *a, const struct sonar_act_slot *s, uint8_t alarms, int gone)
{
    struct sonar_alarm_event *e;
    if (a->nev >= 2 * SONAR_ACT_SLOTS)
        return;
    e = &a->ev[a->nev++];
    e->id = s->id;
    e->alarms = alarms;
    e->was = s->said;
    e->gone = (uint8_t)gone;
    e->x_m = s->x[0];
    e->y_m = s->y[0];
}

/* Frees the slots whose tracks are gone (IDs are never reused, so a slot never meets another track); their alarms clear. */
static void free_gone(struct sonar_activity *a, const struct sonar_tracker *tk)
{
    unsigned k, j;
    for (k = 0; k < SONAR_ACT_SLOTS; k++) {
        if (a->s[k].id == 0)
            continue;
        for (j = 0; j < tk->n && tk->t[j].id != a->s[k].id; j++)
            ;
        if (j < tk->n)
            continue;
        if (a->s[k].said != 0)
            event(a, &a->s[k], 0, 1);
        a->s[k].id = 0;
    }
}

/*
 * The window for the next look where the track is now; kept while it stays within
 * SONAR_ACT_REANCHOR_M. Its correlations so far stay with it through a struggler's jitter, and
 * are forgotten when it is a window's depth or more from where they were taken: another place,
 * or another body (a track that swapped onto someone).
 */
static void place(struct sonar_act_slot *s, const struct sonar_track *t, float angle_offset_grad)
{
    double g;
    float d = hypotf(t->px - s->centre_x, t->py - s->centre_y);
    if (s->looks > 0 && s->have_prev && d <= SONAR_ACT_REANCHOR_M)
        return;
    if (d > 2.0f * SONAR_ACT_HALF_M)
        s->ncorr = 0;
    g = sonar_frame_bearing_deg((double)t->px, (double)t->py) / SONAR_DEG_PER_GRAD - (double)angle_offset_grad;
    s->centre_a = (uint16_t)sonar_frame_wrap((int)floor(g + 0.5));
    s->centre_r = hypotf(t->px, t->py);
    s->centre_x = t->px;
    s->centre_y = t->py;
    s->have_prev = 0;
    s->idx_state = 0;
}

/*
 * The mean of the known correlations (0 if none), and the verdict: moving on travel, else on the
 * echo. A track moving at its last look stays moving down to half the travel: a swimmer slowing at a
 * wall or turning is still swimming, while one that stood or struggled must cover the whole of it.
 */
static uint8_t classify(const struct sonar_act_slot *s, uint8_t was, float *mean)
{
    float m = 0.0f;
    unsigned k;
    for (k = 0; k < s->ncorr; k++)
        m += s->corr[k];
    *mean = s->ncorr > 0 ? m / (float)s->ncorr : 0.0f;
    if (s->looks < 3)
        return SONAR_ACT_UNKNOWN;
    if (hypotf(s->x[0] - s->x[1], s->y[0] - s->y[1]) + hypotf(s->x[1] - s->x[2], s->y[1] - s->y[2]) >
        (was == SONAR_ACT_MOVING ? 0.5f : 1.0f) * SONAR_ACT_MOVE_M)
        return SONAR_ACT_MOVING;
    if (s->ncorr < SONAR_ACT_MIN_LOOKS)
        return SONAR_ACT_UNKNOWN;
    return *mean < SONAR_ACT_CORR_MIN ? SONAR_ACT_STRUGGLING : SONAR_ACT_STANDING;
}

static unsigned bits(unsigned v)
{
    unsigned n = 0;
    for (; v != 0; v &= v - 1)
        n++;
    return n;
}

/*
 * Whether t may raise an alarm: confirmed, and its existence established (tracker.h: it reached
 * SONAR_TRK_EXIST_ALARM and has not fallen below SONAR_TRK_EXIST_DOUBT since). The water's own
 * echoes hop from place to place and seldom get there; a person seen look after look does.
 */
static int alarmable(const struct sonar_track *t)
{
    return t->state != SONAR_TRACK_TENTATIVE && t->exists;
}

/* One track's look: its windows compared, its positions and verdict moved on, its alarms set. */
static void look(struct sonar_act_slot *s, struct sonar_track *t, int64_t utime, float still_alarm_s, int world)
{
    float mean;
    int ok = 0;
    float c = !world && s->have_prev && s->hit && t->det >= 0 ? correlate(&s->w[s->cur ^ 1], &s->w[s->cur], &ok) : 0.0f;
    memmove(&s->x[1], &s->x[0], 2 * sizeof(s->x[0]));
    memmove(&s->y[1], &s->y[0], 2 * sizeof(s->y[0]));
    s->x[0] = t->px;
    s->y[0] = t->py;
    if (s->looks < 255)
        s->looks++;
    if (ok) {
        memmove(&s->corr[1], &s->corr[0], 2 * sizeof(s->corr[0]));
        s->corr[0] = c;
        if (s->ncorr < 3)
            s->ncorr++;
    }
    t->activity = classify(s, t->activity, &mean);
    t->echo_corr = (int8_t)(s->ncorr > 0 ? floorf(100.0f * mean + 0.5f) : SONAR_ACT_NO_CORR);
    s->struggled = (uint8_t)((s->struggled << 1) | (t->activity == SONAR_ACT_STRUGGLING));
    t->alarms = 0;
    if (alarmable(t) && bits(s->struggled & 7u) >= 2)
        t->alarms |= SONAR_ALARM_STRUGGLE;
    if (alarmable(t) && still_alarm_s > 0.0f && t->activity != SONAR_ACT_MOVING &&
        sonar_track_still_s(t, utime) >= still_alarm_s)
        t->alarms |= SONAR_ALARM_STILL;
    s->hit = t->det >= 0;
    s->have_prev = s->w[s->cur].rows != 0;
    s->cur ^= 1u;
    s->w[s->cur].rows = 0;
}

void sonar_activity_look(struct sonar_activity *a, struct sonar_tracker *tk, int64_t utime, float angle_offset_grad,
                         float still_alarm_s, int world)
{
    unsigned j, k;
    if (a == NULL || tk == NULL)
        return;
    a->nev = 0;
    free_gone(a, tk);
    for (j = 0; j < tk->n; j++) {
        struct sonar_track *t = &tk->t[j];
        struct sonar_act_slot *s = slot_of(a, t->id);
        if (s == NULL) {
            for (k = 0; k < SONAR_ACT_SLOTS && a->s[k].id != 0; k++)
                ;
            if (k == SONAR_ACT_SLOTS) {
                t->activity = SONAR_ACT_UNKNOWN;
                t->echo_corr = SONAR_ACT_NO_CORR;
                t->alarms = 0;
                a->unplaced++;
                continue;
            }
            s = &a->s[k];
            memset(s, 0, sizeof(*s));
            s->id = t->id;
        }
        look(s, t, utime, still_alarm_s, world);
        if (t->alarms != s->said) {
            event(a, s, t->alarms, 0);
            s->said = t->alarms;
        }
        if (world)
            s->have_prev = 0;
        else
            place(s, t, angle_offset_grad);
    }
    memset(a->cover, 0, sizeof(a->cover));
    for (k = 0; k < SONAR_ACT_SLOTS && !world; k++)
        if (a->s[k].id != 0)
            sonar_frame_mark_arc(a->cover, (int)a->s[k].centre_a - (SONAR_ACT_ROWS / 2 - 1), (int)a->s[k].centre_a + SONAR_ACT_ROWS / 2);
}

const struct sonar_alarm_event *sonar_activity_events(const struct sonar_activity *a, unsigned *n)
{
    *n = a != NULL ? a->nev : 0u;
    return a != NULL ? a->ev : NULL;
}

const char *sonar_activity_str(uint8_t activity)
{
    static const char *const names[] = {"unknown", "moving", "standing", "struggling"};
    return activity < sizeof(names) / sizeof(names[0]) ? names[activity] : "?";
}
