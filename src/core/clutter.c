/* clutter.c -- the site's clutter map: teaching, a look's moving average, the density a track is judged against, its bytes; a look O(cells), a query O(1), no heap. */
#include "sonar/clutter.h"

#include <math.h>
#include <string.h>

#include "le_internal.h"
#include "sonar/cpframe.h"
#include "sonar/frame.h"

#define CELLS (SONAR_CLUTTER_BANDS * SONAR_CLUTTER_SECTORS)
#define GRAD_PER_SECTOR ((int)SONAR_GRAD_TURN / SONAR_CLUTTER_SECTORS)
#define PI_F 3.14159265f

SONAR_STATIC_ASSERT(SONAR_CLUTTER_MEMORY >= 1 && SONAR_CLUTTER_MEMORY <= 255, memory_fits_looks);

void sonar_clutter_init(struct sonar_clutter *m)
{
    if (m != NULL)
        memset(m, 0, sizeof(*m));
}

static float band_m(const struct sonar_clutter *m)
{
    return m->range_m / (float)SONAR_CLUTTER_BANDS;
}

/* A cell's area, m^2: its band's annulus cut to one sector. */
static float area(const struct sonar_clutter *m, int b)
{
    float w = band_m(m);
    return PI_F / (float)SONAR_CLUTTER_SECTORS * w * w * (float)(2 * b + 1);
}

/* The cell at x, y (*b band, *s sector); 0 when outside the bands (no range yet, or beyond it). */
static int cell_at(const struct sonar_clutter *m, float x, float y, int *b, int *s)
{
    float r = sqrtf(x * x + y * y);
    double g;
    if (!(m->range_m > 0.0f) || !(r < m->range_m))
        return 0;
    *b = (int)(r / band_m(m));
    if (*b >= SONAR_CLUTTER_BANDS)
        *b = SONAR_CLUTTER_BANDS - 1;
    g = sonar_frame_bearing_deg((double)x, (double)y) / SONAR_DEG_PER_GRAD;
    *s = sonar_frame_wrap((int)floor(g)) / GRAD_PER_SECTOR;
    return 1;
}

void sonar_clutter_teach(struct sonar_clutter *m, float x, float y, float n)
{
    int b, s;
    unsigned q;
    struct sonar_clutter_cell *c;
    if (m == NULL || !(n > 0.0f) || !cell_at(m, x, y, &b, &s))
        return;
    q = (unsigned)((n < 16.0f ? n : 16.0f) * (float)SONAR_CLUTTER_PEND_ONE + 0.5f);
    c = &m->c[b][s];
    c->pend = (uint8_t)(c->pend + q > 255u ? 255u : c->pend + q);
    m->taught += (float)q / (float)SONAR_CLUTTER_PEND_ONE;
}

/* The mean density of the cells looked at, each weighted by its area: detections per m^2 a look. */
static float site_mean(const struct sonar_clutter *m)
{
    float sum = 0.0f, seen = 0.0f;
    int b, s;
    for (b = 0; b < SONAR_CLUTTER_BANDS; b++)
        for (s = 0; s < SONAR_CLUTTER_SECTORS; s++)
            if (m->c[b][s].looks > 0) {
                sum += (float)m->c[b][s].rate / (float)SONAR_CLUTTER_RATE_ONE;
                seen += area(m, b);
            }
    return seen > 0.0f ? sum / seen : 0.0f;
}

static int sector_in_view(const uint8_t *cover, int s)
{
    int a;
    if (cover == NULL)
        return 1;
    for (a = s * GRAD_PER_SECTOR; a < (s + 1) * GRAD_PER_SECTOR; a++)
        if ((cover[a / 8] >> (a % 8)) & 1)
            return 1;
    return 0;
}

int sonar_clutter_look(struct sonar_clutter *m, const uint8_t *cover, float min_r, float max_r)
{
    float w;
    int b, s;
    if (m == NULL || !(max_r >= 0.1f && max_r <= SONAR_CLUTTER_MAX_RANGE))
        return SONAR_ERR_ARG;
    if (fabsf(max_r - m->range_m) > 0.01f * max_r) {
        if (m->range_m > 0.0f)
            m->resets++;
        memset(m->c, 0, sizeof(m->c));
        m->range_m = max_r;
    }
    w = band_m(m);
    m->looks++;
    for (s = 0; s < SONAR_CLUTTER_SECTORS; s++) {
        int view = sector_in_view(cover, s);
        for (b = 0; b < SONAR_CLUTTER_BANDS; b++) {
            struct sonar_clutter_cell *c = &m->c[b][s];
            int in = view && (float)(b + 1) * w > min_r;
            if (in || c->pend > 0) {
                /* A running mean over the first looks, then a moving average: 1 / min(looks, MEMORY). */
                unsigned n = c->looks < 255u ? c->looks + 1u : 255u;
                float pend = (float)c->pend / (float)SONAR_CLUTTER_PEND_ONE;
                float taught = pend > (float)SONAR_CLUTTER_BURST ? (float)SONAR_CLUTTER_BURST : pend;
                float rate = (float)c->rate / (float)SONAR_CLUTTER_RATE_ONE;
                float alpha = 1.0f / (float)(n < SONAR_CLUTTER_MEMORY ? n : SONAR_CLUTTER_MEMORY);
                m->capped += pend - taught;
                rate += alpha * (taught - rate);
                /* Truncated, not rounded: rounding stalls the decay at 32 / 4096 a look, and a wake would stay for good. */
                c->rate = (uint16_t)(rate * (float)SONAR_CLUTTER_RATE_ONE);
                c->looks = (uint8_t)n;
                c->pend = 0;
            }
        }
    }
    m->site = site_mean(m);
    return SONAR_OK;
}

static float cell_density(const struct sonar_clutter *m, int b, int s)
{
    const struct sonar_clutter_cell *c = &m->c[b][s];
    float a = area(m, b);
    float n = (float)(c->looks < SONAR_CLUTTER_MEMORY ? c->looks : SONAR_CLUTTER_MEMORY);
    float rate = (float)c->rate / (float)SONAR_CLUTTER_RATE_ONE;
    float d = (n * rate + (float)SONAR_CLUTTER_PRIOR_LOOKS * m->site * a) / ((n + (float)SONAR_CLUTTER_PRIOR_LOOKS) * a);
    return d > SONAR_CLUTTER_FLOOR ? d : SONAR_CLUTTER_FLOOR;
}

float sonar_clutter_density(const struct sonar_clutter *m, float x, float y)
{
    int b, s;
    if (m == NULL || !cell_at(m, x, y, &b, &s))
        return SONAR_CLUTTER_FLOOR;
    return cell_density(m, b, s);
}

float sonar_clutter_cell(const struct sonar_clutter *m, int band, int sector)
{
    if (m == NULL || band < 0 || band >= SONAR_CLUTTER_BANDS || sector < 0 || sector >= SONAR_CLUTTER_SECTORS ||
        m->c[band][sector].looks == 0)
        return 0.0f;
    return cell_density(m, band, sector);
}

void sonar_clutter_summarise(const struct sonar_clutter *m, struct sonar_clutter_summary *out)
{
    int b, s;
    memset(out, 0, sizeof(*out));
    if (m == NULL)
        return;
    out->looks = m->looks;
    out->site = m->site;
    for (b = 0; b < SONAR_CLUTTER_BANDS; b++) {
        for (s = 0; s < SONAR_CLUTTER_SECTORS; s++) {
            float d;
            if (m->c[b][s].looks == 0)
                continue;
            out->cells_seen++;
            out->per_look += (float)m->c[b][s].rate / (float)SONAR_CLUTTER_RATE_ONE;
            d = cell_density(m, b, s);
            if (d > out->peak) {
                out->peak = d;
                out->peak_range_m = ((float)b + 0.5f) * band_m(m);
                out->peak_bearing_g = ((float)s + 0.5f) * (float)GRAD_PER_SECTOR;
            }
        }
    }
}

int sonar_clutter_encode(const struct sonar_clutter *m, uint8_t *buf, size_t cap)
{
    uint8_t *p;
    int b, s;
    if (m == NULL || buf == NULL)
        return SONAR_ERR_ARG;
    if (cap < SONAR_CLUTTER_WIRE)
        return SONAR_ERR_SPACE;
    memcpy(buf, "SCM1", 4);
    sonar_put_le16(buf + 4, SONAR_CLUTTER_BANDS);
    sonar_put_le16(buf + 6, SONAR_CLUTTER_SECTORS);
    sonar_put_le32(buf + 8, (uint32_t)(m->range_m * 1000.0f + 0.5f));
    sonar_put_le32(buf + 12, m->looks);
    sonar_put_le32(buf + 16, (uint32_t)(m->taught + 0.5f));
    sonar_put_le32(buf + 20, 0u);
    p = buf + 28;
    for (b = 0; b < SONAR_CLUTTER_BANDS; b++) {
        for (s = 0; s < SONAR_CLUTTER_SECTORS; s++, p += 4) {
            sonar_put_le16(p, m->c[b][s].rate);
            p[2] = m->c[b][s].looks;
            p[3] = 0;
        }
    }
    sonar_put_le32(buf + 24, sonar_cpf_crc32(0, buf + 28, 4u * CELLS));
    return (int)SONAR_CLUTTER_WIRE;
}

int sonar_clutter_decode(struct sonar_clutter *m, const uint8_t *buf, size_t len)
{
    const uint8_t *p;
    uint32_t range_mm;
    int b, s;
    if (m == NULL || buf == NULL)
        return SONAR_ERR_ARG;
    if (len < 8 || memcmp(buf, "SCM1", 4) != 0 || sonar_le16(buf + 4) != SONAR_CLUTTER_BANDS ||
        sonar_le16(buf + 6) != SONAR_CLUTTER_SECTORS)
        return SONAR_ERR_ID;
    if (len != SONAR_CLUTTER_WIRE)
        return SONAR_ERR_LENGTH;
    range_mm = sonar_le32(buf + 8);
    if (sonar_le32(buf + 24) != sonar_cpf_crc32(0, buf + 28, 4u * CELLS) || range_mm < 100u ||
        (float)range_mm > SONAR_CLUTTER_MAX_RANGE * 1000.0f)
        return SONAR_ERR_RANGE;
    for (p = buf + 28; p < buf + SONAR_CLUTTER_WIRE; p += 4)
        if (p[3] != 0)
            return SONAR_ERR_RANGE;
    sonar_clutter_init(m);
    m->range_m = (float)range_mm * 1e-3f;
    m->looks = sonar_le32(buf + 12);
    m->taught = (float)sonar_le32(buf + 16);
    p = buf + 28;
    for (b = 0; b < SONAR_CLUTTER_BANDS; b++) {
        for (s = 0; s < SONAR_CLUTTER_SECTORS; s++, p += 4) {
            m->c[b][s].rate = sonar_le16(p);
            m->c[b][s].looks = p[2];
        }
    }
    m->site = site_mean(m);
    return SONAR_OK;
}
