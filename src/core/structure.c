/* structure.c -- places where detections stand, promoted to structure (structure.h); O(detections x places) a sweep, no heap. */
#include "sonar/structure.h"

#include <math.h>
#include <string.h>

#include "sonar/pose.h"

static int valid_s(float structure_s)
{
    return structure_s == 0.0f || (structure_s >= 1.0f && structure_s <= (float)SONAR_STRUCTURE_S_MAX);
}

int sonar_structure_init(struct sonar_structure *s, float structure_s)
{
    if (s == NULL || !valid_s(structure_s))
        return SONAR_ERR_ARG;
    memset(s, 0, sizeof(*s));
    s->structure_s = structure_s;
    return SONAR_OK;
}

int sonar_structure_tune(struct sonar_structure *s, float structure_s)
{
    if (s == NULL || !valid_s(structure_s))
        return SONAR_ERR_ARG;
    s->structure_s = structure_s;
    return SONAR_OK;
}

void sonar_structure_restart(struct sonar_structure *s)
{
    s->n = 0;
    s->restarts++;
}

void sonar_structure_turn(struct sonar_structure *s, float deg)
{
    unsigned k;
    for (k = 0; k < s->n; k++) {
        float x = s->p[k].x, y = s->p[k].y;
        sonar_pose_rotate(deg, x, y, &s->p[k].x, &s->p[k].y);
    }
}

unsigned sonar_structure_count(const struct sonar_structure *s)
{
    unsigned k, c = 0;
    for (k = 0; k < s->n; k++)
        c += s->p[k].structure;
    return c;
}

/* The nearest place within SONAR_PLACE_M of (x, y), or -1. */
static int nearest(const struct sonar_structure *s, float x, float y)
{
    float best = SONAR_PLACE_M * SONAR_PLACE_M;
    int k, at = -1;
    for (k = 0; k < (int)s->n; k++) {
        float dx = s->p[k].x - x, dy = s->p[k].y - y, d = dx * dx + dy * dy;
        if (d <= best) {
            best = d;
            at = k;
        }
    }
    return at;
}

/* When place q was last seen, us since the epoch. */
static int64_t last_us(const struct sonar_place *q)
{
    return q->first_us + (int64_t)q->last_ms * 1000;
}

/* A slot for a new place: a free one, else the one seen longest ago that is not structure (evicted), else -1. */
static int slot(struct sonar_structure *s)
{
    int k, old = -1;
    if (s->n < SONAR_MAX_PLACES)
        return s->n++;
    for (k = 0; k < SONAR_MAX_PLACES; k++)
        if (!s->p[k].structure && (old < 0 || last_us(&s->p[k]) < last_us(&s->p[old])))
            old = k;
    s->evicted++;
    return old;
}

int sonar_structure_sweep(struct sonar_structure *s, const struct sonar_structure_obs *obs, uint8_t n, int64_t utime,
                          uint8_t *kind)
{
    uint32_t hit = 0; /* places seen this sweep: each counts once, however many detections are there */
    uint8_t i, k, j;
    int count = 0;
    if (s == NULL || kind == NULL || n > SONAR_MAX_CLUSTERS || (n > 0 && obs == NULL))
        return SONAR_ERR_ARG;
    for (i = 0; i < n; i++)
        if (!isfinite(obs[i].x_m) || !isfinite(obs[i].y_m) || !isfinite(obs[i].radius_m))
            return SONAR_ERR_ARG;
    for (i = 0; i < n; i++) {
        const struct sonar_structure_obs *o = &obs[i];
        float rad = o->radius_m < SONAR_PLACE_MAX_RADIUS_M ? o->radius_m : SONAR_PLACE_MAX_RADIUS_M;
        int at = nearest(s, o->x_m, o->y_m);
        struct sonar_place *q;
        int64_t ms;
        int stood;
        kind[i] = SONAR_DET_OBJECT;
        /* Only what was there at the first look starts a place: nothing else can become structure. */
        if (at < 0 && o->first_look && (at = slot(s)) >= 0) {
            q = &s->p[at];
            memset(q, 0, sizeof(*q));
            q->x = o->x_m;
            q->y = o->y_m;
            q->first_us = o->utime;
            q->first_sweep = s->sweeps + 1u;
            hit &= ~(1u << at); /* a slot taken over this sweep starts unseen */
        }
        if (at < 0)
            continue;
        q = &s->p[at];
        ms = (o->utime - q->first_us) / 1000;
        if (ms > (int64_t)q->last_ms)
            q->last_ms = ms > (int64_t)UINT32_MAX ? UINT32_MAX : (uint32_t)ms;
        q->radius = rad > q->radius ? rad : q->radius;
        if (!(hit & (1u << at)) && q->seen < UINT16_MAX)
            q->seen++;
        hit |= 1u << at;
        /* Stood there since the first look: seen often enough, and in 3 of every 4 sweeps since. */
        stood = q->seen >= SONAR_PLACE_MIN_SEEN && 4u * (uint32_t)q->seen >= 3u * (s->sweeps + 2u - q->first_sweep);
        if (!q->structure && stood && s->structure_s > 0.0f &&
            (double)(o->utime - q->first_us) >= (double)s->structure_s * 1e6) {
            q->structure = 1;
            s->promoted++;
        }
        kind[i] = q->structure ? SONAR_DET_STRUCTURE : stood ? SONAR_DET_STATIC_START : SONAR_DET_OBJECT;
        count += q->structure;
    }
    /* Forget what has not been seen for a while (not structure: its echo is learnt, so it is seldom seen). */
    for (k = 0, j = 0; k < s->n; k++) {
        if (!s->p[k].structure && utime - last_us(&s->p[k]) > (int64_t)SONAR_PLACE_FORGET_S * 1000000)
            continue;
        if (j != k)
            s->p[j] = s->p[k];
        j++;
    }
    s->n = j;
    s->sweeps++;
    s->detections += (uint32_t)count;
    return count;
}
