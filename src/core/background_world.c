/* background_world.c -- the background in a world-fixed grid for a sonar on a moving vehicle: a torus of two-byte cells that scrolls with the sonar, each beam learning its footprint and compared with what static structure can return there; O(cells in the wedge + rings) a beam, no heap. */
#include "sonar/background.h"

#include <math.h>
#include <string.h>

#include "sonar/frame.h"

/* Cells a side: the largest square of two-byte cells that the per-angle bytes hold beside the range profile. */
static uint16_t grid_side(void)
{
    uint32_t g = 1;
    while (2u * (g + 1u) * (g + 1u) <= SONAR_BG_GRID_CELLS - SONAR_MAX_SAMPLES)
        g++;
    return (uint16_t)g;
}

/* a modulo m, 0..m-1, for any sign. */
static uint32_t mod(int32_t a, uint16_t m)
{
    int32_t r = a % (int32_t)m;
    return (uint32_t)(r < 0 ? r + (int32_t)m : r);
}

/* A cell: its model (0 = never seen) and, next to it, its observations so far (saturating). */
static uint8_t *grid_at(struct sonar_background *bg, int32_t i, int32_t j)
{
    return &bg->cell[0][0] + 2u * (mod(i, bg->grid) * bg->grid + mod(j, bg->grid));
}

/* The world cell index holding coordinate v (metres). */
static int32_t cell_index(const struct sonar_background *bg, double v)
{
    return (int32_t)floor(v / (double)bg->cell_m);
}

/* The range profile: the last SONAR_MAX_SAMPLES bytes, after the grid. */
static uint8_t *profile(struct sonar_background *bg)
{
    return &bg->cell[0][0] + SONAR_BG_GRID_CELLS - SONAR_MAX_SAMPLES;
}

/*
 * Keeps the window [wi0, wi0 + grid) x [wj0, wj0 + grid) centred on cell (ci, cj): rows and
 * columns that scroll in were last used for cells that scrolled out, so they are cleared.
 */
static void scroll(struct sonar_background *bg, int32_t ci, int32_t cj)
{
    const int32_t g = (int32_t)bg->grid;
    int32_t ni = ci - g / 2, nj = cj - g / 2, k, r;
    if (ni - bg->wi0 >= g || bg->wi0 - ni >= g || nj - bg->wj0 >= g || bg->wj0 - nj >= g) {
        memset(&bg->cell[0][0], 0, 2u * (size_t)g * (size_t)g);
    } else {
        /* Entering rows: [wi0 + g, ni + g) moving north, [ni, wi0) moving south; columns alike. */
        for (k = ni > bg->wi0 ? bg->wi0 + g : ni; k < (ni > bg->wi0 ? ni + g : bg->wi0); k++)
            memset(grid_at(bg, k, 0), 0, 2u * (size_t)g);
        for (k = nj > bg->wj0 ? bg->wj0 + g : nj; k < (nj > bg->wj0 ? nj + g : bg->wj0); k++)
            for (r = 0; r < g; r++) {
                uint8_t *c = grid_at(bg, r, k);
                c[0] = c[1] = 0;
            }
    }
    bg->wi0 = ni;
    bg->wj0 = nj;
}

/* One step of the running median toward x, 0 being "never seen" (seeded by x). */
static uint8_t follow(uint8_t b, uint8_t x, unsigned st)
{
    unsigned m = b, up, dn;
    if (b == 0)
        return x > 0 ? x : 1u;
    up = x > m ? x - m : 0u;
    dn = x < m ? m - x : 0u;
    m = m + (up < st ? up : st) - (dn < st ? dn : st);
    return (uint8_t)(m > 0u ? m : 1u);
}

/* One observation of a grid cell: averaged in over the first warmup ones, then the step rule. */
static void learn(uint8_t *c, uint8_t x, unsigned warmup, unsigned st)
{
    unsigned v = c[1] < 255u ? c[1] + 1u : 255u;
    c[1] = (uint8_t)v;
    if (v <= warmup) {
        /* b += (x - b) / v, rounded; kept >= 1 since 0 means never seen */
        int b = v == 1u ? (int)x : (int)c[0] + ((int)x - (int)c[0] + (x >= c[0] ? (int)v / 2 : -(int)v / 2)) / (int)v;
        c[0] = (uint8_t)(b < 1 ? 1 : b > 255 ? 255 : b);
    } else {
        c[0] = follow(c[0], x, st);
    }
}

static int ray_ok(const struct sonar_bg_ray *r)
{
    return isfinite(r->north_m) && isfinite(r->east_m) && fabs(r->north_m) <= 1e6 && fabs(r->east_m) <= 1e6 &&
           isfinite(r->bearing_deg) && fabs(r->bearing_deg) <= 1e6 && isfinite(r->width_deg) &&
           r->range_m > 0.0f && r->range_m <= 1000.0f && r->near_m >= 0.0f && isfinite(r->near_m);
}

/*
 * Rings of cells a beam crosses at most: it reaches a third of the grid's side, which is at most
 * 905 cells (400 x 4096 bytes of two-byte cells). Stack: 2 bytes a ring.
 */
#define RINGS_MAX 310
SONAR_STATIC_ASSERT(SONAR_MAX_ANGLES * SONAR_MAX_SAMPLES <= SONAR_GRAD_TURN * 4096u, rings_max_holds_the_grid);

/*
 * A rotation by a fixed angle, the points of an arc stepped by it: the beams' arcs have a few dozen
 * distinct point counts, so each count's step is computed once a beam, not once a ring.
 */
#define ARC_CACHE 64
struct arc_steps {
    double c[ARC_CACHE], s[ARC_CACHE]; /* cos, sin of span / pts for pts < ARC_CACHE */
    uint8_t have[ARC_CACHE];
    double span;
};

static void arc_step(struct arc_steps *a, int32_t pts, double *c, double *s)
{
    if (pts >= ARC_CACHE) {
        *c = cos(a->span / (double)pts);
        *s = sin(a->span / (double)pts);
        return;
    }
    if (!a->have[pts]) {
        a->c[pts] = cos(a->span / (double)pts);
        a->s[pts] = sin(a->span / (double)pts);
        a->have[pts] = 1;
    }
    *c = a->c[pts];
    *s = a->s[pts];
}

/*
 * What static structure can return at each range along the beam: for every ring of cells the beam
 * reaches, the largest model on the arc of SONAR_BG_LOOK_DEG about the beam (ringmax), then the
 * largest over +- slack rings (out). A wall's echo depends on where it is seen from (strong head-on,
 * weak and spread out in range at a glance), and the pose and the beam's width place it only so
 * well; comparing with the cell under the sample alone made walls the detections on the simulated
 * vehicle scene. 0 where none was ever seen. One pass over the arc's cells, about 1 000 reads at
 * 15 m, instead of the arc again for every sample (the first form of this cost 500 us a beam).
 */
static void look_rings(struct sonar_background *bg, const struct sonar_bg_ray *ray, double th, int32_t rings,
                       int32_t slack, uint8_t *out)
{
    static const double deg = SONAR_RAD_PER_DEG;
    struct arc_steps a;
    uint8_t ringmax[RINGS_MAX];
    double cs = (double)bg->cell_m, c0 = cos(th - SONAR_BG_LOOK_DEG * deg / 2.0), s0 = sin(th - SONAR_BG_LOOK_DEG * deg / 2.0);
    int32_t k, j;
    memset(a.have, 0, sizeof(a.have));
    a.span = SONAR_BG_LOOK_DEG * deg;
    for (k = 0; k < rings; k++) {
        double r = ((double)k + 0.5) * cs, cu = c0, su = s0, cd, sd;
        int32_t pts = (int32_t)ceil(r * a.span / cs);
        uint8_t m = 0;
        pts = pts < 1 ? 1 : pts;
        arc_step(&a, pts, &cd, &sd);
        for (j = 0; j <= pts; j++) {
            double t = cu * cd - su * sd;
            uint8_t v = *grid_at(bg, cell_index(bg, ray->north_m + r * cu), cell_index(bg, ray->east_m + r * su));
            m = v > m ? v : m;
            su = su * cd + cu * sd;
            cu = t;
        }
        ringmax[k] = m;
    }
    for (k = 0; k < rings; k++) {
        uint8_t m = 0;
        for (j = k - slack; j <= k + slack; j++)
            if (j >= 0 && j < rings && ringmax[j] > m)
                m = ringmax[j];
        out[k] = m;
    }
}

/* Is (north, east) inside one of the discs? */
static int kept(const struct sonar_bg_disc *keep, uint8_t nkeep, double north, double east)
{
    uint8_t k;
    for (k = 0; k < nkeep; k++) {
        double dn = north - (double)keep[k].north_m, de = east - (double)keep[k].east_m;
        if (dn * dn + de * de <= (double)keep[k].radius_m * (double)keep[k].radius_m)
            return 1;
    }
    return 0;
}

int sonar_background_apply_world(struct sonar_background *bg, const struct sonar_bg_ray *ray, const uint8_t *in,
                                 uint8_t *fg, uint16_t n)
{
    return sonar_background_apply_world_keep(bg, ray, in, fg, n, NULL, 0);
}

/* Long: one screen and a half, because the footprint, the comparison and the update read and write the same grid cells in one
   pass per beam, the hot path of a moving vehicle; split, each part would walk the footprint again. */
int sonar_background_apply_world_keep(struct sonar_background *bg, const struct sonar_bg_ray *ray, const uint8_t *in,
                                      uint8_t *fg, uint16_t n, const struct sonar_bg_disc *keep, uint8_t nkeep)
{
    static const double deg = SONAR_RAD_PER_DEG;
    uint8_t src[SONAR_MAX_SAMPLES], near[RINGS_MAX];
    struct sonar_bg_disc here[SONAR_BG_DISCS_MAX];
    struct arc_steps arc;
    double th, w, c0, s0, cs, rmax, cw, sw;
    int32_t k, k0, kmax, slack, rings;
    uint16_t i;
    uint8_t nhere = 0, d;
    if (bg == NULL || ray == NULL || in == NULL || fg == NULL || n == 0 || n > SONAR_MAX_SAMPLES || !ray_ok(ray) ||
        (nkeep > 0 && keep == NULL))
        return SONAR_ERR_ARG;
    if (bg->mode != SONAR_BACKGROUND_PER_ANGLE && bg->mode != SONAR_BACKGROUND_AUTO)
        return sonar_background_apply(bg, 0, in, fg, n);
    /* The beam is learnt from after fg is written, and they may be the same buffer. */
    memcpy(src, in, n);
    in = src;
    if (!bg->world || n != bg->n || ray->range_m != bg->grid_range_m) {
        if (!bg->world && bg->n != 0)
            bg->reframes++;
        sonar_background_reset(bg);
        bg->world = 1;
        bg->n = n;
        bg->grid = grid_side();
        bg->grid_range_m = ray->range_m;
        bg->cell_m = (float)SONAR_BG_WINDOW * ray->range_m / (float)(bg->grid - 4u);
        bg->wi0 = cell_index(bg, ray->north_m) - (int32_t)bg->grid / 2;
        bg->wj0 = cell_index(bg, ray->east_m) - (int32_t)bg->grid / 2;
        memset(&bg->cell[0][0], 0, 2u * (size_t)bg->grid * bg->grid);
        memset(profile(bg), 0, SONAR_MAX_SAMPLES);
    }
    cs = (double)bg->cell_m;
    slack = (int32_t)ceil((double)SONAR_BG_SLACK_M / cs);
    scroll(bg, cell_index(bg, ray->north_m), cell_index(bg, ray->east_m));
    th = ray->bearing_deg * deg;
    c0 = cos(th);
    s0 = sin(th);
    rmax = (double)ray->range_m;
    rings = (int32_t)ceil(rmax / cs) + 1;
    rings = rings > RINGS_MAX ? RINGS_MAX : rings;
    look_rings(bg, ray, th, rings, slack, near);
    /* The foreground against the model before this beam. */
    for (i = 0; i < n; i++) {
        double r = ((double)i + 0.5) * rmax / (double)n;
        const uint8_t *under;
        int32_t ring = (int32_t)(r / cs);
        uint8_t x = in[i], m, pr = profile(bg)[i];
        fg[i] = 0;
        if (r < (double)ray->near_m)
            continue;
        /* A cell seen fewer than SONAR_BG_MIN_SEEN times (the edge of what the vehicle has explored) says nothing yet. */
        under = grid_at(bg, cell_index(bg, ray->north_m + r * c0), cell_index(bg, ray->east_m + r * s0));
        if (under[1] < SONAR_BG_MIN_SEEN)
            continue;
        m = near[ring < rings ? ring : rings - 1];
        /* The level every beam sees at this range (the ring-down's tail, the gain's curve) moves with the sonar. */
        m = pr > m ? pr : m;
        if (m != 0) {
            unsigned gate = ((unsigned)m * bg->margin) >> 4, up = x > m ? (unsigned)(x - m) : 0u;
            fg[i] = (uint8_t)(up > gate ? up - gate : 0u);
        }
    }
    for (i = 0; i < n; i++)
        profile(bg)[i] = follow(profile(bg)[i], in[i], bg->step);
    /*
     * The footprint: rings one cell apart, each crossed by points at most a cell apart along its
     * arc (so every cell of the wedge is visited about once), turned by a rotation each step
     * rather than a sine per point. Each point takes the sample at its ring's range. Cells within
     * a kept disc (a tracked object) are not learnt: of those discs, only the ones this wedge can
     * reach are looked at.
     */
    w = ray->width_deg < 0.5 ? 0.5 : ray->width_deg > 90.0 ? 90.0 : ray->width_deg;
    w *= deg;
    for (d = 0; d < nkeep && nhere < SONAR_BG_DISCS_MAX; d++) {
        double dn = (double)keep[d].north_m - ray->north_m, de = (double)keep[d].east_m - ray->east_m;
        double dist = sqrt(dn * dn + de * de), rad = (double)keep[d].radius_m;
        double off = fabs(remainder(atan2(de, dn) - th, 2.0 * SONAR_PI));
        if (dist - rad < rmax && (dist <= rad || off <= w / 2.0 + asin(rad / dist)))
            here[nhere++] = keep[d];
    }
    k0 = (int32_t)floor((double)ray->near_m / cs);
    kmax = (int32_t)floor(rmax / cs);
    cw = cos(th - w / 2.0);
    sw = sin(th - w / 2.0);
    memset(arc.have, 0, sizeof(arc.have));
    arc.span = w / 2.0; /* the half step from the wedge's edge to its first point, by points */
    for (k = k0; k < kmax; k++) {
        double r = ((double)k + 0.5) * cs, ca, sa, ch, sh, cd, sd;
        int32_t pts = (int32_t)ceil(r * w / cs), j;
        uint8_t x;
        if (r < (double)ray->near_m)
            continue;
        i = (uint16_t)(r / rmax * (double)n);
        if (i >= n)
            break;
        x = in[i];
        pts = pts < 1 ? 1 : pts;
        /* Points at the middles of pts equal parts of the wedge: half a part in, then whole parts. */
        arc_step(&arc, pts, &ch, &sh);
        cd = ch * ch - sh * sh;
        sd = 2.0 * sh * ch;
        ca = cw * ch - sw * sh;
        sa = sw * ch + cw * sh;
        for (j = 0; j < pts; j++) {
            double t = ca * cd - sa * sd, pn = ray->north_m + r * ca, pe = ray->east_m + r * sa;
            if (nhere == 0 || !kept(here, nhere, pn, pe))
                learn(grid_at(bg, cell_index(bg, pn), cell_index(bg, pe)), x, bg->warmup, bg->step);
            sa = sa * cd + ca * sd;
            ca = t;
        }
    }
    return SONAR_OK;
}

int sonar_background_world_at(const struct sonar_background *bg, double north_m, double east_m, uint8_t *model,
                              uint8_t *seen)
{
    int32_t i, j;
    const uint8_t *c;
    *model = *seen = 0;
    if (bg == NULL || !bg->world || !isfinite(north_m) || !isfinite(east_m) || fabs(north_m) > 1e6 || fabs(east_m) > 1e6)
        return 0;
    i = cell_index(bg, north_m);
    j = cell_index(bg, east_m);
    if (i < bg->wi0 || i >= bg->wi0 + (int32_t)bg->grid || j < bg->wj0 || j >= bg->wj0 + (int32_t)bg->grid)
        return 0;
    c = &bg->cell[0][0] + 2u * (mod(i, bg->grid) * bg->grid + mod(j, bg->grid));
    *model = c[0];
    *seen = c[1];
    return 1;
}
