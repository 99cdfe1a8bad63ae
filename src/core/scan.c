/* scan.c -- the scan planner: sweep order, or passes that ping the targets' windows each time and the grid in turns; O(targets x window + the walk to the next ping) a call, 400 B of stack, no heap. */
#include "sonar/scan.h"

#include <string.h>

#define NEVER_US ((int64_t)86400000000) /* a day: the age of an angle never looked at */

/* us to ms for the per-beam loops: in 32 bits when it fits (a Cortex-M has no 64-bit divide), up to 2^31 ms. */
static int32_t ms(int64_t us)
{
    if (us >= 0 && us <= (int64_t)UINT32_MAX)
        return (int32_t)((uint32_t)us / 1000u);
    us /= 1000;
    return us > INT32_MAX ? INT32_MAX : us < INT32_MIN ? INT32_MIN : (int32_t)us;
}

const char *sonar_scan_config_check(const struct sonar_scan_config *c)
{
    if (c->mode > SONAR_SCAN_FOLLOW)
        return "mode: sweep or follow";
    if (c->start_angle >= SONAR_GRAD_TURN || c->stop_angle >= SONAR_GRAD_TURN)
        return "start_angle, stop_angle: 0..399 gradians";
    if (!c->full_circle && c->start_angle == c->stop_angle)
        return "stop_angle: a sector needs start != stop";
    if (c->step < 1 || c->step > 50)
        return "step: 1..50 gradians";
    if (c->ping_us < 1 || c->ping_us > 10000000)
        return "ping_us: 1..10^7 us";
    if (c->mode == SONAR_SCAN_FOLLOW) {
        if (!(c->revisit_s >= 0.2f && c->revisit_s <= (float)SONAR_SCAN_REVISIT_MAX_S))
            return "revisit_s: 0.2.." SONAR_STR(SONAR_SCAN_REVISIT_MAX_S) " s";
        if (!(c->surveil_s == 0.0f || (c->surveil_s > 0.0f && c->surveil_s <= (float)SONAR_SCAN_REVISIT_MAX_S)))
            return "surveil_s: 0 (twice a plain sweep) or up to " SONAR_STR(SONAR_SCAN_REVISIT_MAX_S) " s";
    }
    return NULL;
}

/* Gradians from start_angle (0..399). */
static int offset(const struct sonar_scan *s, int a)
{
    return (sonar_frame_wrap(a) + (int)SONAR_GRAD_TURN - (int)s->cfg.start_angle) % (int)SONAR_GRAD_TURN;
}

static int in_sector(const struct sonar_scan *s, int a)
{
    return s->cfg.full_circle || offset(s, a) <= (int)s->span;
}

/* Gradians the head travels from a to b: the shorter way round a full circle, inside a sector otherwise. */
static int travel(const struct sonar_scan *s, int a, int b)
{
    if (s->cfg.full_circle)
        return sonar_frame_gap((uint16_t)sonar_frame_wrap(a), (uint16_t)sonar_frame_wrap(b));
    return offset(s, a) > offset(s, b) ? offset(s, a) - offset(s, b) : offset(s, b) - offset(s, a);
}

uint32_t sonar_scan_cost_us(const struct sonar_scan *s, uint16_t from, uint16_t to)
{
    return s->cfg.ping_us + SONAR_SCAN_GRAD_US * (uint32_t)travel(s, from, to);
}

static int grid_beams(const struct sonar_scan *s);
static int interleave(const struct sonar_scan *s, int64_t w);
static int64_t window_reserve_us(const struct sonar_scan *s);

int sonar_scan_init(struct sonar_scan *s, const struct sonar_scan_config *cfg)
{
    if (s == NULL || cfg == NULL || sonar_scan_config_check(cfg) != NULL)
        return SONAR_ERR_ARG;
    memset(s, 0, sizeof(*s));
    s->cfg = *cfg;
    s->span = cfg->full_circle ? SONAR_GRAD_TURN
                               : (uint16_t)((cfg->stop_angle + SONAR_GRAD_TURN - cfg->start_angle) % SONAR_GRAD_TURN);
    s->dir = 1;
    s->head = cfg->start_angle;
    /* A plain sweep: one beam a step over the sector, each a ping and the step's travel. */
    s->sweep_us = (uint32_t)grid_beams(s) * (cfg->ping_us + SONAR_SCAN_GRAD_US * cfg->step);
    s->surveil_us = cfg->surveil_s > 0.0f ? (uint32_t)(cfg->surveil_s * 1e6f) : 2u * s->sweep_us;
    if (s->surveil_us < s->sweep_us)
        s->surveil_us = s->sweep_us; /* a bound tighter than a plain sweep cannot be kept */
    s->slow_q8 = 256;
    s->k = (uint16_t)interleave(s, window_reserve_us(s));
    s->window_left = (uint16_t)(window_reserve_us(s) / s->cfg.ping_us);
    return SONAR_OK;
}

/* us since gradian g was last pinged (NEVER_US when never). */
static int64_t age_us(const struct sonar_scan *s, int g, int64_t now)
{
    uint32_t t = s->seen_ms[sonar_frame_wrap(g)];
    return t == 0 ? NEVER_US : (now - s->t0) - (int64_t)t * 1000;
}

/* Grid angles of the sector: a plain sweep's beams. */
static int grid_beams(const struct sonar_scan *s)
{
    return s->cfg.full_circle ? ((int)SONAR_GRAD_TURN + s->cfg.step - 1) / s->cfg.step : (int)s->span / s->cfg.step + 1;
}

/* The windows' pings a pass may take: a quarter of the grid's, and at least one a target (SONAR_SCAN_MAX_TARGETS). */
static int window_budget(const struct sonar_scan *s)
{
    int b = grid_beams(s) / 4;
    return b > SONAR_SCAN_MAX_TARGETS ? b : SONAR_SCAN_MAX_TARGETS;
}

/* Steps either side of a target's bearing its window may span: two, or 8 gradians, at most SONAR_SCAN_MAX_HALF. */
static int window_steps(const struct sonar_scan *s)
{
    int g = 2 * s->cfg.step > 8 ? 2 * s->cfg.step : 8;
    return (g > SONAR_SCAN_MAX_HALF ? SONAR_SCAN_MAX_HALF : g) / s->cfg.step;
}

/* The windows' pings the passes to come are planned with: the targets' now and two more, each at its widest, within the budget. */
static int64_t window_reserve_us(const struct sonar_scan *s)
{
    int beams = ((int)s->ntargets + 2) * (2 * window_steps(s) + 1);
    return (int64_t)(beams < window_budget(s) ? beams : window_budget(s)) * s->cfg.ping_us;
}

/* Modelled time of one pass (a turn, or a sector one way) pinging 1/k of the grid and w us of windows. */
static int64_t model_pass_us(const struct sonar_scan *s, int k, int64_t w)
{
    int travel_g = s->cfg.full_circle ? (int)SONAR_GRAD_TURN : (int)s->span;
    /* The grid's pings fit 32 bits (400 x 10^7 us): a Cortex-M divides those in hardware. */
    return (int64_t)SONAR_SCAN_GRAD_US * travel_g + w + ((uint32_t)grid_beams(s) * s->cfg.ping_us + (uint32_t)k - 1u) / (uint32_t)k;
}

/* The same, scaled by how much slower than the model the beams have come (slow_q8: the link, the host; never faster). */
static int64_t pass_us(const struct sonar_scan *s, int k, int64_t w)
{
    return model_pass_us(s, k, w) * s->slow_q8 >> 8;
}

/*
 * The interleave for the next pass: the most passes k between pings of a grid angle that keep it
 * within the bound less a sixteenth (so that a longer pass is caught up without a cascade): k
 * passes round a circle, k + 1 in a sector (whose ends see uneven returns), with w us of target
 * windows a pass; 1 (every angle every pass, a plain sweep) at the least.
 */
static int interleave(const struct sonar_scan *s, int64_t w)
{
    int k, extra = s->cfg.full_circle ? 0 : 1;
    for (k = grid_beams(s); k > 1; k--)
        if ((k + extra) * pass_us(s, k, w) <= (int64_t)s->surveil_us - (int64_t)s->surveil_us / 16)
            break;
    return k;
}

/* What deciding a grid beam needs, worked out once a call: ms and 32 bits (a Cortex-M has no 64-bit divide). */
struct grid_plan {
    int32_t pass, bound, budget, ping, grad; /* ms: a pass to come (windows at their reserve), the bound, ... */
    uint32_t now_ms, phase, share_q8;        /* ms since t0; this pass mod k; a pass's ms a gradian, 1/256 */
    int hoff;                                /* the head's gradians from start_angle */
};

static void grid_plan(const struct sonar_scan *s, struct grid_plan *c, int64_t now)
{
    int travel_g = s->cfg.full_circle ? (int)SONAR_GRAD_TURN : (int)s->span;
    int64_t budget_us = window_reserve_us(s);
    c->pass = ms(pass_us(s, s->k, budget_us));
    c->bound = (int32_t)(s->surveil_us / 1000u);
    c->budget = ms(budget_us);
    c->ping = (int32_t)(s->cfg.ping_us / 1000u);
    c->grad = (int32_t)(SONAR_SCAN_GRAD_US / 1000u);
    c->now_ms = (uint32_t)ms(now - s->t0);
    c->phase = s->pass % (uint32_t)s->k;
    c->share_q8 = (uint32_t)c->pass * 256u / (uint32_t)(travel_g > 0 ? travel_g : 1);
    c->hoff = offset(s, s->head);
}

/*
 * Whether grid gradian g (p gradians from start_angle, on the grid) is pinged this pass: grid beam
 * j on the passes q with q = j mod k, and any that, skipped now, would pass the bound before its
 * next such pass (when the interleave changes, or the passes grow with the targets). tw: the
 * head's travel to it the way it goes.
 */
static int grid_needed(const struct sonar_scan *s, const struct grid_plan *c, int g, int p, int tw)
{
    uint32_t k = s->k, j = (uint32_t)(p + s->cfg.step - 1) / s->cfg.step, d = (j + k - c->phase) % k;
    int32_t age, at, share, back;
    if (d == 0)
        return 1;
    if (s->seen_ms[g] == 0)
        return 0; /* not yet in its first turn: its turn decides */
    age = (int32_t)(c->now_ms - s->seen_ms[g]);
    /* Getting there: the travel and a ping, or its share of a pass (pings on the way included). */
    at = c->ping + c->grad * tw;
    share = (int32_t)((c->share_q8 * (uint32_t)tw) >> 8);
    at = share > at ? share : at;
    back = (int32_t)d * c->pass;
    if (!s->cfg.full_circle) {
        /* In a sector the next pass is back after the far end: twice the rest of the way, and its pings. */
        int e = s->dir > 0 ? (int)s->span - p : p;
        back = c->grad * 2 * e + (2 * e / s->cfg.step) * c->ping / (int32_t)k + c->budget + ((int32_t)d - 1) * c->pass;
    }
    return age + at + back > c->bound;
}

/*
 * Marks the windows of the targets (step-spaced angles within +-half_width of the predicted
 * bearing, clipped to the sector, each at most an equal share of window_budget): each angle not
 * pinged within the last half pass.
 */
static void mark_targets(struct sonar_scan *s, uint8_t *need, const struct sonar_scan_target *t, unsigned n, int64_t now)
{
    int64_t half = pass_us(s, s->k, s->window_us) / 2;
    unsigned i, beams = 0;
    int share;
    if (n > SONAR_SCAN_MAX_TARGETS) {
        s->counters.targets_dropped += n - SONAR_SCAN_MAX_TARGETS;
        n = SONAR_SCAN_MAX_TARGETS;
    }
    share = n > 0 ? (window_budget(s) / (int)n - 1) / 2 : 0; /* steps either side */
    if (share > window_steps(s))
        share = window_steps(s);
    s->ntargets = (uint8_t)n;
    if (s->window_left == 0)
        n = 0; /* this pass's windows are spent: the plan's passes stay as long as it counted */
    for (i = 0; i < n; i++) {
        float hw = t[i].half_width > (float)SONAR_SCAN_MAX_HALF ? (float)SONAR_SCAN_MAX_HALF
                   : t[i].half_width > 0.0f                   ? t[i].half_width
                                                              : 0.0f;
        int c, k, h = (int)hw / s->cfg.step;
        if (h > share)
            h = share;
        if (!(t[i].angle >= 0.0f && t[i].angle < (float)SONAR_GRAD_TURN) || !in_sector(s, c = sonar_frame_wrap((int)(t[i].angle + 0.5f)))) {
            s->counters.targets_dropped++;
            continue;
        }
        for (k = -h; k <= h; k++) {
            int a = c + k * s->cfg.step;
            if (!in_sector(s, a))
                continue;
            beams++;
            if (age_us(s, a, now) > half)
                need[sonar_frame_wrap(a)] = (uint8_t)(need[sonar_frame_wrap(a)] | 2u);
        }
    }
    s->window_us = (int64_t)beams * s->cfg.ping_us;
}

/*
 * The first angle from the head going way d (+1/-1), inside the sector, that needs a ping: in a
 * window (need[] bit 2) or a grid beam due (grid_needed, then marked bit 1); -1 when none. Only the
 * first matters, so the grid is decided lazily, walking out from the head.
 */
static int first_needed(const struct sonar_scan *s, uint8_t *need, const struct grid_plan *c, int d)
{
    int k, a = s->head, p = c->hoff, left = s->cfg.full_circle ? (int)SONAR_GRAD_TURN - 1 : d > 0 ? (int)s->span - c->hoff : c->hoff;
    for (k = 1; k <= left; k++) {
        a += d;
        a = a < 0 ? a + (int)SONAR_GRAD_TURN : a >= (int)SONAR_GRAD_TURN ? a - (int)SONAR_GRAD_TURN : a;
        p += d;
        p = p < 0 ? p + (int)SONAR_GRAD_TURN : p >= (int)SONAR_GRAD_TURN ? p - (int)SONAR_GRAD_TURN : p;
        if (need[a])
            return a;
        if ((p % s->cfg.step == 0 || (!s->cfg.full_circle && p == (int)s->span)) && grid_needed(s, c, a, p, k)) {
            need[a] = 1;
            return a;
        }
    }
    return -1;
}

/* Follow mode: the head keeps its way (round a circle, to a sector's end and back), pinging only what needs it. */
static uint16_t follow(struct sonar_scan *s, const struct sonar_scan_target *t, unsigned n, int64_t now)
{
    uint8_t need[SONAR_GRAD_TURN];
    struct grid_plan c;
    int a;
    memset(need, 0, sizeof(need));
    grid_plan(s, &c, now);
    mark_targets(s, need, t, t == NULL ? 0u : n, now);
    need[s->head] = 0; /* just pinged */
    a = first_needed(s, need, &c, s->dir);
    if (a < 0 && !s->cfg.full_circle) {
        s->dir = (int8_t)-s->dir;
        a = first_needed(s, need, &c, s->dir);
    }
    if (a < 0) {
        /* Nothing needs a ping: the plain sweep's next angle from here. */
        s->pos = sonar_frame_sweep_advance((uint16_t)offset(s, s->head), &s->dir, s->span, s->cfg.step, s->cfg.full_circle);
        a = sonar_frame_wrap((int)s->cfg.start_angle + (int)s->pos);
    }
    if (need[a] & 2u) {
        if (!(need[a] & 1u) && s->window_left > 0)
            s->window_left--;
        s->counters.target_pings++;
        if (age_us(s, a, now) > (int64_t)(s->cfg.revisit_s * 1e6f))
            s->counters.late_looks++;
    } else {
        s->counters.surveil_pings++;
    }
    return (uint16_t)a;
}

/*
 * Measures the beam just done (the call before to this one) against the model: a moving average
 * of their ratio, at least 1, at most 4, which scales every pass the plan counts on.
 */
static void measure(struct sonar_scan *s, int64_t now)
{
    uint32_t model = sonar_scan_cost_us(s, s->prev, s->head), took, q;
    if (model == 0 || now <= s->last_call)
        return;
    took = now - s->last_call > 16000000 ? 16000000u : (uint32_t)(now - s->last_call); /* x 256 fits 32 bits */
    q = took * 256u / model;
    q = q < 256u ? 256u : q > 1024u ? 1024u : q;
    s->slow_q8 = (uint16_t)((s->slow_q8 * 7u + q) / 8u);
}

/* Counts passes (a turn of travel round a circle, a turn of the head's way in a sector) and sets each pass's interleave. */
static void account(struct sonar_scan *s, uint16_t a, int8_t was)
{
    int done;
    if (s->cfg.full_circle) {
        s->travelled = (uint16_t)(s->travelled + (uint16_t)travel(s, s->head, a));
        done = s->travelled >= SONAR_GRAD_TURN;
        if (done)
            s->travelled = (uint16_t)(s->travelled - SONAR_GRAD_TURN);
    } else {
        done = s->dir != was;
    }
    if (done) {
        s->pass++;
        s->k = (uint16_t)interleave(s, window_reserve_us(s));
        s->window_left = (uint16_t)(window_reserve_us(s) / s->cfg.ping_us);
    }
}

uint16_t sonar_scan_next(struct sonar_scan *s, const struct sonar_scan_target *targets, unsigned n, int64_t now)
{
    uint16_t a;
    int64_t ms;
    if (!s->started) {
        s->started = 1;
        s->t0 = now - 1000; /* seen_ms 0 means never: the first ping is 1 ms in */
        a = s->cfg.start_angle;
    } else {
        if (now < s->t0 + 1000)
            now = s->t0 + 1000;
        if (s->cfg.mode == SONAR_SCAN_FOLLOW) {
            int8_t was = s->dir;
            measure(s, now);
            a = follow(s, targets, n, now);
            account(s, a, was);
        } else {
            s->pos = sonar_frame_sweep_advance(s->pos, &s->dir, s->span, s->cfg.step, s->cfg.full_circle);
            a = (uint16_t)sonar_frame_wrap((int)s->cfg.start_angle + (int)s->pos);
        }
    }
    s->last_call = now;
    s->prev = s->head;
    ms = (now - s->t0) / 1000;
    s->seen_ms[a] = ms < 1 ? 1u : ms > 4000000000 ? 4000000000u : (uint32_t)ms;
    s->head = a;
    return a;
}
