/* survey.c -- a site's survey in use (survey.h): one compare pass and one strongest-echo search a beam, a check of its fit each sweep; no heap. Recording is survey_rec.c. */
#include "sonar/survey.h"

#include <string.h>

#include "sonar/edge.h"
#include "survey_internal.h"

#define NONE 0xFFFFu

const char *sonar_survey_why_str(int why)
{
    switch (why) {
    case SONAR_SURVEY_OK: return "ok";
    case SONAR_SURVEY_MOVED: return "moved";
    case SONAR_SURVEY_GEOMETRY: return "geometry";
    case SONAR_SURVEY_GAIN: return "gain";
    case SONAR_SURVEY_ANGLES: return "angles";
    case SONAR_SURVEY_TURNED: return "turned";
    case SONAR_SURVEY_CHANGED: return "changed";
    case SONAR_SURVEY_STANDOUT: return "standout";
    case SONAR_SURVEY_WORLD: return "world";
    case SONAR_SURVEY_RESTART: return "restart";
    case SONAR_SURVEY_NEW: return "new structure";
    default: return "?";
    }
}

void sonar_survey_init(struct sonar_survey *sv, struct sonar_survey_spread *spread, struct sonar_detection *places)
{
    memset(sv, 0, sizeof(*sv));
    sv->spread = spread;
    sv->places = places;
}

/*
 * A cell's gate over its level L (survey.h): the larger of SONAR_SURVEY_SPREADS16 spreads and the
 * margin's share of L, at most 255 (where L + gate passes 255 nothing can stand out either way).
 */
static uint8_t gate_above(unsigned l, unsigned spread, int has_spread, uint8_t margin)
{
    unsigned g = (l * margin) >> 4, gs = (spread * SONAR_SURVEY_SPREADS16) >> 4, v = has_spread && gs > g ? gs : g;
    return (uint8_t)(v < 255u ? v : 255u);
}

/*
 * Each row's structure: the sample of its strongest level beyond the ring-down, when that level is
 * SONAR_SURVEY_SIG_LEVEL or more and SONAR_SURVEY_SIG_TIMES its median there (a wall, a ladder,
 * not the water's speckle); with the level there, for a look that only sees it behind something.
 */
static void signature(struct sonar_survey *sv, const struct sonar_background *bg, unsigned row, uint8_t *sig_level)
{
    uint16_t hist[256], i, at = 0;
    const uint8_t *lv = bg->cell[row];
    uint8_t top = 0, med;
    sv->sig[row] = NONE;
    if (sv->near >= sv->meta.n)
        return;
    memset(hist, 0, sizeof(hist));
    for (i = sv->near; i < sv->meta.n; i++) {
        hist[lv[i]]++;
        if (lv[i] > top) {
            top = lv[i];
            at = i;
        }
    }
    med = hist_median(hist, (unsigned)(sv->meta.n - sv->near));
    if (top >= SONAR_SURVEY_SIG_LEVEL && (unsigned)top >= SONAR_SURVEY_SIG_TIMES * (unsigned)med) {
        sv->sig[row] = at;
        sig_level[row] = top;
    }
}

/* Forgets the sweep's looks: rows looked at, their agreement and their stand-out. */
static void new_sweep(struct sonar_survey *sv)
{
    memset(sv->looked, 0, sizeof(sv->looked));
    memset(sv->hid, 0, sizeof(sv->hid));
    sv->checked = sv->agreed = sv->occluded = 0;
    sv->cells = sv->standout = 0;
}

int sonar_survey_use(struct sonar_survey *sv, struct sonar_background *bg, const uint8_t *img, size_t len, const char **why)
{
    struct sonar_bgfile_meta m;
    struct sonar_bgfile_layout l;
    const char *dummy;
    unsigned row, known, fill = SONAR_SURVEY_FILL * SONAR_MAX_ANGLES / SONAR_GRAD_TURN;
    uint8_t k;
    int r;
    if (why == NULL)
        why = &dummy;
    *why = "bad argument";
    if (sv == NULL || bg == NULL)
        return SONAR_ERR_ARG;
    if ((r = sonar_bgfile_check(img, len, &m, why)) != SONAR_OK)
        return r;
    if (sonar_bgfile_layout(m.n, m.flags, m.places, &l) != SONAR_OK)
        return SONAR_ERR_ARG;
    if ((r = sonar_bgfile_load(bg, img, len, why)) != SONAR_OK)
        return r;
    sv->meta = m;
    sv->fixed = (uint8_t)((m.flags & SONAR_BGFILE_SURVEY) != 0);
    sv->has_spread = (uint8_t)(sv->spread != NULL && (m.flags & SONAR_BGFILE_SPREAD));
    if (sv->has_spread)
        for (row = 0; row < SONAR_MAX_ANGLES; row++)
            memcpy(sv->spread->s[row], img + l.spread + (size_t)row * m.n, m.n);
    /* A checked survey knows a row it looked at SONAR_SURVEY_MIN_LOOKS times; a learnt model one past its warm-up. */
    known = (m.flags & SONAR_BGFILE_SURVEY) ? SONAR_SURVEY_MIN_LOOKS : (unsigned)bg->warmup + 1u;
    sv->near = near_samples(m.n, (double)m.range_mm * 1e-3);
    /*
     * A row is judged with its own levels when the survey looked at it at all; one it looked at fewer times than it
     * knows (a sector's end, looked along once a turn-around) takes the larger spread of the nearest row it knows. A
     * row it never looked at takes the nearest known row within SONAR_SURVEY_FILL gradians (the beam's width).
     */
    for (row = 0; row < SONAR_MAX_ANGLES; row++) {
        unsigned d, near_known = NONE, i;
        for (d = 0; d <= fill && near_known == NONE; d++) {
            unsigned lo = (row + SONAR_MAX_ANGLES - d) % SONAR_MAX_ANGLES, hi = (row + d) % SONAR_MAX_ANGLES;
            near_known = bg->visits[lo] >= known ? lo : bg->visits[hi] >= known ? hi : NONE;
        }
        sv->src[row] = (uint16_t)(bg->visits[row] > 0 ? row : near_known);
        if (sv->has_spread && bg->visits[row] > 0 && bg->visits[row] < known && near_known != NONE)
            for (i = 0; i < m.n; i++)
                if (sv->spread->s[near_known][i] > sv->spread->s[row][i])
                    sv->spread->s[row][i] = sv->spread->s[near_known][i];
    }
    /* The spreads become the gates, once (the margin is the background's until it restarts, which gives the survey up):
       the per-beam pass is then a subtraction and a compare a cell. */
    for (row = 0; sv->has_spread && row < SONAR_MAX_ANGLES; row++) {
        unsigned i;
        for (i = 0; i < m.n; i++)
            sv->spread->s[row][i] = gate_above(bg->cell[row][i], sv->spread->s[row][i], 1, bg->margin);
    }
    {
        uint8_t sig_level[SONAR_MAX_ANGLES];
        for (row = 0; row < SONAR_MAX_ANGLES; row++) {
            sv->sig[row] = NONE;
            if (bg->visits[row] >= known)
                signature(sv, bg, row, sig_level);
            sv->sig_level[row] = sv->sig[row] == NONE ? 0 : sig_level[row];
        }
    }
    sv->nplaces = 0;
    for (k = 0; sv->places != NULL && k < m.places; k++)
        sonar_bgfile_get_place(img + l.places + (size_t)k * SONAR_BGFILE_PLACE, &sv->places[sv->nplaces++]);
    sv->state = SONAR_SURVEY_IN_USE;
    sv->why = SONAR_SURVEY_OK;
    sv->turn_grad = 0;
    sv->bad_run = sv->good_run = 0;
    sv->refit = 0;
    sv->sweeps_in_use = 0;
    new_sweep(sv);
    *why = "ok";
    return SONAR_OK;
}

void sonar_survey_lost(struct sonar_survey *sv, int why)
{
    if (sv == NULL || sv->state != SONAR_SURVEY_IN_USE)
        return;
    sv->state = SONAR_SURVEY_UNFIT;
    sv->why = (uint8_t)why;
    sv->unfits++;
    sv->good_run = sv->bad_run = 0;
    sv->lines = 0;
    sv->refit = 0;
}

int sonar_survey_fits_beam(struct sonar_survey *sv, uint16_t n, float range_m, int16_t gain)
{
    int geometry, fits;
    if (sv == NULL || sv->state == SONAR_SURVEY_NONE)
        return SONAR_SURVEY_OK;
    geometry = n == sv->meta.n && same_range(range_m, (double)sv->meta.range_mm);
    fits = geometry && (gain < 0 || sv->meta.gain == SONAR_BGFILE_GAIN_UNKNOWN || gain == (int16_t)sv->meta.gain);
    if (sv->state == SONAR_SURVEY_UNFIT) {
        /* Given up for its geometry or gain: beams of its own again are the survey's site again. */
        if (fits && (sv->why == SONAR_SURVEY_GEOMETRY || sv->why == SONAR_SURVEY_GAIN))
            sv->refit = 1;
        return SONAR_SURVEY_OK;
    }
    return fits ? SONAR_SURVEY_OK : geometry ? SONAR_SURVEY_GAIN : SONAR_SURVEY_GEOMETRY;
}

/* Samples that make SONAR_SURVEY_SIG_M at the survey's range (at least 2). */
static uint16_t sig_tolerance(const struct sonar_survey *sv)
{
    double t = (double)SONAR_SURVEY_SIG_M * (double)sv->meta.n / ((double)sv->meta.range_mm * 1e-3);
    return (uint16_t)(t < 2.0 ? 2.0 : t);
}

/* The gate of cell i of surveyed row src, as a level: its level plus the gate over it. */
static unsigned gate_at(const struct sonar_survey *sv, const struct sonar_background *bg, unsigned src, uint16_t i)
{
    unsigned l = bg->cell[src][i];
    return l + (sv->has_spread ? sv->spread->s[src][i] : gate_above(l, 0u, 0, bg->margin));
}

static int has_bit(const uint8_t *map, unsigned r)
{
    return (int)(((unsigned)map[r / 8] >> (r % 8)) & 1u);
}

/* Samples that make SONAR_SURVEY_OCCLUDE_M at the survey's range. */
static unsigned occlude_samples(const struct sonar_survey *sv)
{
    return (unsigned)((double)SONAR_SURVEY_OCCLUDE_M * (double)sv->meta.n / ((double)sv->meta.range_mm * 1e-3));
}

void sonar_survey_look(struct sonar_survey *sv, const struct sonar_background *bg, uint16_t angle, const uint8_t *in,
                       uint16_t n)
{
    unsigned row = row_of(angle), src;
    uint16_t at, sig, tol, lo, hi, i;
    uint8_t top = 0;
    if (sv == NULL || sv->state == SONAR_SURVEY_NONE || n != sv->meta.n || sv->near >= n)
        return;
    at = sonar_edge_strongest(in, sv->near, n);
    sv->obs[row] = at;
    sv->looked[row / 8] = (uint8_t)(sv->looked[row / 8] | 1u << (row % 8));
    src = sv->src[row];
    if (src == NONE || (sig = sv->sig[src]) == NONE)
        return;
    /* It agrees where its strongest echo is the survey's, or the survey's still echoes behind something brighter. */
    tol = sig_tolerance(sv);
    lo = sig > tol ? (uint16_t)(sig - tol) : 0;
    hi = (uint16_t)(sig + tol < n ? sig + tol : n - 1u);
    for (i = lo; i <= hi; i++)
        top = in[i] > top ? in[i] : top;
    /*
     * Occluded: something a body's depth nearer (SONAR_SURVEY_OCCLUDE_M) that stands out against the survey there (an
     * object: above the gate, which the water's spikes seldom pass) hides the structure: a person in front of the wall
     * says nothing of the survey's fit.
     */
    if (sv->state == SONAR_SURVEY_IN_USE && sv->fixed && (unsigned)at + occlude_samples(sv) < sig &&
        in[at] > gate_at(sv, bg, src, at)) {
        sv->occluded++;
        sv->hid[row / 8] = (uint8_t)(sv->hid[row / 8] | 1u << (row % 8));
        return;
    }
    sv->checked++;
    sv->agreed = (uint16_t)(sv->agreed + ((at >= lo && at <= hi) || 2u * top >= sv->sig_level[src]));
}

/*
 * SV_BLOCK cells judged, in byte arithmetic with no branches, so that with the constant length -O2
 * vectorises it (as the background's steady state, background.c): up = max(x, L) - L. With the gates
 * (gt: the spread block, made gates at load) the echo above the level where it passes its gate (a
 * faint body keeps its whole contrast); by the level alone, what exceeds the margin, as a learnt
 * background's foreground is. Returns the cells that stood out.
 */
#define SV_BLOCK 64
static unsigned judge_block(const uint8_t *restrict x, const uint8_t *restrict lv, const uint8_t *restrict gt,
                            uint8_t *restrict fg, uint8_t margin)
{
    unsigned i;
    uint8_t cnt = 0;
    if (gt != NULL)
        for (i = 0; i < SV_BLOCK; i++) {
            uint8_t xi = x[i], l = lv[i], hi = xi > l ? xi : l, up = (uint8_t)(hi - l);
            fg[i] = up > gt[i] ? up : 0u;
        }
    else
        for (i = 0; i < SV_BLOCK; i++) {
            uint8_t xi = x[i], l = lv[i], hi = xi > l ? xi : l, up = (uint8_t)(hi - l);
            uint16_t g16 = (uint16_t)((l * margin) >> 4);
            uint8_t gate = (uint8_t)(g16 < 255u ? g16 : 255u), over = up > gate ? up : gate;
            fg[i] = (uint8_t)(over - gate);
        }
    /* A foreground cell is never 0 (it passed a gate of 0 or more); a byte holds a block's count. */
    for (i = 0; i < SV_BLOCK; i++)
        cnt = (uint8_t)(cnt + (fg[i] != 0u));
    return cnt;
}

int sonar_survey_apply(struct sonar_survey *sv, const struct sonar_background *bg, uint16_t angle, const uint8_t *in,
                       uint8_t *fg, uint16_t n)
{
    unsigned src, i0;
    const uint8_t *lv, *gt;
    uint32_t out = 0;
    uint8_t blk[SV_BLOCK];
    if (sv == NULL || sv->state != SONAR_SURVEY_IN_USE || !sv->fixed || n != sv->meta.n ||
        (src = sv->src[row_of(angle)]) == NONE)
        return 0;
    lv = bg->cell[src];
    gt = sv->has_spread ? sv->spread->s[src] : NULL;
    /* Each block of in copied first: in and fg may be one buffer. */
    for (i0 = 0; i0 + SV_BLOCK <= n; i0 += SV_BLOCK) {
        memcpy(blk, in + i0, SV_BLOCK);
        out += judge_block(blk, lv + i0, gt != NULL ? gt + i0 : NULL, fg + i0, bg->margin);
    }
    if (i0 < n) {
        /* The ragged end as one more block through copies, padded with silence (which never stands out). */
        uint8_t tl[SV_BLOCK], tg[SV_BLOCK], tf[SV_BLOCK];
        size_t len = n - i0;
        memset(blk, 0, sizeof(blk));
        memset(tl, 0, sizeof(tl));
        memset(tg, 0, sizeof(tg));
        memcpy(blk, in + i0, len);
        memcpy(tl, lv + i0, len);
        if (gt != NULL)
            memcpy(tg, gt + i0, len);
        out += judge_block(blk, tl, gt != NULL ? tg : NULL, tf, bg->margin);
        memcpy(fg + i0, tf, len);
    }
    sv->cells += n;
    sv->standout += out;
    return 1;
}

/* Rows looked at this sweep whose row r + s (shift s in rows) has structure, and those of them that agree with it. */
static void shifted(const struct sonar_survey *sv, int s, uint16_t tol, unsigned *cnt, unsigned *agree)
{
    unsigned r;
    *cnt = *agree = 0;
    for (r = 0; r < SONAR_MAX_ANGLES; r++) {
        unsigned q = (unsigned)(((int)r + s + SONAR_MAX_ANGLES) % SONAR_MAX_ANGLES);
        uint16_t sig = sv->sig[q];
        if (!has_bit(sv->looked, r) || sig == NONE)
            continue;
        (*cnt)++;
        *agree += (sv->obs[r] > sig ? sv->obs[r] - sig : sig - sv->obs[r]) <= tol;
    }
}

/*
 * The turn that puts this sweep's strongest echoes where the survey has its structure: among the
 * shifts s (rows) with SONAR_SURVEY_MIN_SIG rows to compare, the best agreeing one when a quarter of
 * its rows and three times the unturned share agree (a strongest echo is noisy along a wall's
 * return, but no other shift comes near the right one), reported as the middle of the shifts within
 * a sixteenth of the best (a wall agrees over a few shifts). Returns 1 and *best, or 0 when none does.
 */
static int find_turn(const struct sonar_survey *sv, int *best)
{
    const int max = SONAR_SURVEY_MAX_TURN * SONAR_MAX_ANGLES / SONAR_GRAD_TURN;
    uint16_t tol = sig_tolerance(sv);
    unsigned top256 = 0, at0 = 0, cnt, agree;
    int s, lo = 1, hi = 0;
    for (s = -max; s <= max; s++) {
        shifted(sv, s, tol, &cnt, &agree);
        if (cnt >= SONAR_SURVEY_MIN_SIG && 256u * agree / cnt > top256)
            top256 = 256u * agree / cnt;
        if (s == 0 && cnt > 0)
            at0 = 256u * agree / cnt;
    }
    if (top256 < 64u || top256 < 3u * at0)
        return 0;
    for (s = -max; s <= max; s++) {
        shifted(sv, s, tol, &cnt, &agree);
        if (cnt >= SONAR_SURVEY_MIN_SIG && 256u * agree / cnt + 16u >= top256) {
            lo = lo > hi ? s : lo;
            hi = s;
        }
    }
    *best = (lo + hi) / 2;
    return 1;
}

/* Metres end to end between the strongest echoes at samples a0 of row r0 and a1 of row r1. */
static float chord_m(const struct sonar_survey *sv, unsigned r0, uint16_t a0, unsigned r1, uint16_t a1)
{
    float m = (float)sv->meta.range_mm * 1e-3f / (float)sv->meta.n, p = (float)a0 * m, q = (float)a1 * m;
    float th = (float)((r1 + SONAR_MAX_ANGLES - r0) % SONAR_MAX_ANGLES) * (float)(2.0 * SONAR_PI / SONAR_MAX_ANGLES);
    float c2 = p * p + q * q - 2.0f * p * q * cosf(th);
    return c2 > 0.0f ? sqrtf(c2) : 0.0f;
}

/*
 * Rows hidden this sweep behind something wider than SONAR_SURVEY_PERSON_M end to end. A hider is a run of rows
 * looked at whose strongest echoes are each within a body's depth of the last (a person, a barge's side seen
 * aslant); its hidden rows are those it holds. People each hide a few gradians however many of them stand before a
 * wall; a moored boat or a new pontoon hides wider than any of them.
 */
static unsigned hidden_by_wide(const struct sonar_survey *sv)
{
    unsigned k, r, start, first = 0, last = 0, nrun = 0, wide = 0, depth = occlude_samples(sv);
    uint16_t a_first = 0, a_last = 0;
    if (sv->occluded == 0)
        return 0;
    /* Walked from a row not hidden, so that a hider across the turn's 0 is one. */
    for (start = 0; start < SONAR_MAX_ANGLES && !(has_bit(sv->looked, start) && !has_bit(sv->hid, start)); start++)
        ;
    if (start == SONAR_MAX_ANGLES)
        return sv->occluded; /* all of it hidden */
    for (k = 1; k <= SONAR_MAX_ANGLES; k++) {
        r = (start + k) % SONAR_MAX_ANGLES;
        if (!has_bit(sv->looked, r))
            continue;
        if (nrun > 0 && (sv->obs[r] > a_last ? (unsigned)sv->obs[r] - a_last : (unsigned)a_last - sv->obs[r]) <= depth) {
            last = r;
            a_last = sv->obs[r];
            nrun += (unsigned)has_bit(sv->hid, r);
            continue;
        }
        if (nrun > 0 && chord_m(sv, first, a_first, last, a_last) > SONAR_SURVEY_PERSON_M)
            wide += nrun;
        nrun = 0;
        if (has_bit(sv->hid, r)) {
            first = last = r;
            a_first = a_last = sv->obs[r];
            nrun = 1;
        }
    }
    if (nrun > 0 && chord_m(sv, first, a_first, last, a_last) > SONAR_SURVEY_PERSON_M)
        wide += nrun;
    return wide < sv->occluded ? wide : sv->occluded;
}

/* Bits set in the low three of b: sweeps of the last three with structure the survey does not hold. */
static unsigned last3(uint8_t b)
{
    return (b & 1u) + ((b >> 1) & 1u) + ((b >> 2) & 1u);
}

int sonar_survey_sweep(struct sonar_survey *sv, unsigned structures)
{
    int agree_known, agrees, quiet, turn = 0, gave_up = 0, lines;
    if (sv == NULL || sv->state == SONAR_SURVEY_NONE)
        return 0;
    if (!sv->fixed) {
        /* A learnt model is learnt on: it follows the site as it is (only its setting is checked, beam by beam). */
        new_sweep(sv);
        return 0;
    }
    /* Structure hidden by something wider than a person is no person in front of a wall: the site changed there. */
    {
        unsigned wide = hidden_by_wide(sv);
        sv->checked = (uint16_t)(sv->checked + wide);
        sv->occluded = (uint16_t)(sv->occluded - wide);
    }
    /* People hiding most of it say nothing: what is left in view says whether it fits, when a few rows are. */
    agree_known = sv->checked >= SONAR_SURVEY_MIN_SIG ||
                  (sv->checked + sv->occluded >= SONAR_SURVEY_MIN_SIG && sv->checked >= SONAR_SURVEY_MIN_VIEW);
    agrees = !agree_known || 16u * sv->agreed >= (unsigned)SONAR_SURVEY_AGREE16 * sv->checked;
    /* Only a spread says how much of the water stands out by chance: by the level alone a fifth of a speckled cell's looks do. */
    quiet = !sv->has_spread || sv->cells == 0 ||
            1000u * (uint64_t)sv->standout <= (uint64_t)SONAR_SURVEY_STANDOUT1000 * sv->cells;
    sv->agree16 = (uint8_t)(agree_known ? 16u * sv->agreed / sv->checked : 16u);
    sv->standout1000 = (uint8_t)(sv->cells ? (1000u * (uint64_t)sv->standout / sv->cells > 255u
                                                  ? 255u : 1000u * (uint64_t)sv->standout / sv->cells) : 0u);
    sv->lines = (uint8_t)(sv->lines << 1 | (sv->state == SONAR_SURVEY_IN_USE && sv->fixed && structures > 0));
    lines = last3(sv->lines) >= SONAR_SURVEY_NEW_SWEEPS;
    if (sv->state == SONAR_SURVEY_IN_USE) {
        sv->sweeps_in_use++;
        sv->bad_run = (uint8_t)(agrees && quiet ? 0u : sv->bad_run + 1u);
        if (sv->bad_run >= SONAR_SURVEY_UNFIT_SWEEPS || lines) {
            sonar_survey_lost(sv, !agrees ? SONAR_SURVEY_CHANGED : !quiet ? SONAR_SURVEY_STANDOUT : SONAR_SURVEY_NEW);
            /* Whatever said it, a turn that puts the structure back where the survey has it is what happened. */
            if (find_turn(sv, &turn) && turn != 0) {
                sv->why = SONAR_SURVEY_TURNED;
                sv->turn_grad = (int16_t)(turn * (int)SONAR_GRAD_TURN / SONAR_MAX_ANGLES);
            }
            gave_up = 1;
        }
    } else if (sv->why == SONAR_SURVEY_TURNED || sv->why == SONAR_SURVEY_CHANGED || sv->why == SONAR_SURVEY_STANDOUT ||
               sv->why == SONAR_SURVEY_NEW) {
        /* Its structure back where it was, three quarters of the rows agreeing, sweeps in a row: it may be taken back. */
        int back = agree_known && 4u * sv->agreed >= 3u * sv->checked;
        sv->good_run = (uint8_t)(back ? (sv->good_run < 255u ? sv->good_run + 1u : 255u) : 0u);
        if (sv->good_run >= SONAR_SURVEY_REFIT_SWEEPS)
            sv->refit = 1;
    }
    new_sweep(sv);
    return gave_up;
}

int sonar_survey_covers(const struct sonar_survey *sv, uint16_t angle)
{
    return sv != NULL && sv->state == SONAR_SURVEY_IN_USE && sv->fixed && sv->src[row_of(angle)] != NONE;
}
