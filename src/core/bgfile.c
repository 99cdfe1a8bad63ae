/* bgfile.c -- a per-angle background to and from a checked byte image (bgfile.h); one pass over the model and one CRC-32, no heap. */
#include "sonar/bgfile.h"

#include <math.h>
#include <string.h>

#include "le_internal.h"
#include "sonar/cpframe.h"

static const uint8_t magic[8] = {'S', 'O', 'N', 'A', 'R', 'B', 'G', '\n'};

int sonar_bgfile_layout(uint16_t n, uint8_t flags, uint8_t places, struct sonar_bgfile_layout *l)
{
    size_t rows;
    if (l == NULL || n == 0 || n > SONAR_MAX_SAMPLES || places > SONAR_MAX_CLUSTERS)
        return SONAR_ERR_ARG;
    rows = (size_t)SONAR_MAX_ANGLES * n;
    l->looks = SONAR_BGFILE_HEADER;
    l->across = l->looks + SONAR_MAX_ANGLES + 1u;
    l->levels = l->across + n;
    l->spread = l->levels + rows;
    l->places = l->spread + ((flags & SONAR_BGFILE_SPREAD) ? rows : 0u);
    l->crc = l->places + (size_t)places * SONAR_BGFILE_PLACE;
    l->size = l->crc + 4u;
    return SONAR_OK;
}

size_t sonar_bgfile_size(uint16_t n)
{
    struct sonar_bgfile_layout l;
    return sonar_bgfile_layout(n, 0, 0, &l) == SONAR_OK ? l.size : 0;
}

static int per_angle(uint8_t mode)
{
    return mode == SONAR_BACKGROUND_PER_ANGLE || mode == SONAR_BACKGROUND_AUTO;
}

static void put_le64(uint8_t *p, int64_t v)
{
    uint64_t u = (uint64_t)v;
    sonar_put_le32(p, (uint32_t)(u & 0xffffffffu));
    sonar_put_le32(p + 4, (uint32_t)(u >> 32));
}

static int64_t le64(const uint8_t *p)
{
    uint64_t u = (uint64_t)sonar_le32(p) | (uint64_t)sonar_le32(p + 4) << 32;
    return u <= (uint64_t)INT64_MAX ? (int64_t)u : -(int64_t)(~u) - 1;
}

static int32_t le32s(const uint8_t *p)
{
    uint32_t u = sonar_le32(p);
    return u <= (uint32_t)INT32_MAX ? (int32_t)u : -(int32_t)(~u) - 1;
}

/* Metres to signed millimetres as two's complement, clamped to +-2 000 km. */
static uint32_t mm_of(float m)
{
    double v = (double)m * 1000.0;
    int32_t i = !(v == v) ? 0 : v > 2e9 ? 2000000000 : v < -2e9 ? -2000000000 : (int32_t)lround(v);
    return (uint32_t)i;
}

void sonar_bgfile_put_header(uint8_t *out, const struct sonar_bgfile_meta *m)
{
    memset(out, 0, SONAR_BGFILE_HEADER);
    memcpy(out, magic, sizeof(magic));
    sonar_put_le16(out + 8, SONAR_BGFILE_VERSION);
    sonar_put_le16(out + 10, SONAR_MAX_ANGLES);
    sonar_put_le16(out + 12, m->n);
    out[14] = m->mode;
    out[15] = m->median;
    out[16] = m->median2d;
    out[17] = m->gain;
    out[18] = m->flags;
    out[19] = m->places;
    sonar_put_le32(out + 20, m->range_mm);
    sonar_put_le32(out + 24, m->sound_mm_s);
    sonar_put_le32(out + 28, m->sweeps);
    put_le64(out + 32, m->utime);
    sonar_put_le32(out + 40, (uint32_t)m->offset_mgrad);
}

void sonar_bgfile_put_place(uint8_t *out, const struct sonar_detection *d)
{
    uint8_t v, nv = d->hull_count <= SONAR_MAX_HULL ? d->hull_count : SONAR_MAX_HULL;
    memset(out, 0, SONAR_BGFILE_PLACE);
    out[0] = d->kind;
    out[1] = nv;
    sonar_put_le32(out + 4, mm_of(d->x_m));
    sonar_put_le32(out + 8, mm_of(d->y_m));
    for (v = 0; v < nv; v++) {
        sonar_put_le32(out + 12 + 8 * v, mm_of(d->hull_x[v]));
        sonar_put_le32(out + 16 + 8 * v, mm_of(d->hull_y[v]));
    }
}

void sonar_bgfile_get_place(const uint8_t *at, struct sonar_detection *d)
{
    uint8_t v;
    memset(d, 0, sizeof(*d));
    d->kind = at[0];
    d->hull_count = at[1] <= SONAR_MAX_HULL ? at[1] : SONAR_MAX_HULL;
    d->x_m = (float)le32s(at + 4) * 1e-3f;
    d->y_m = (float)le32s(at + 8) * 1e-3f;
    d->range_m = sqrtf(d->x_m * d->x_m + d->y_m * d->y_m);
    for (v = 0; v < d->hull_count; v++) {
        d->hull_x[v] = (float)le32s(at + 12 + 8 * v) * 1e-3f;
        d->hull_y[v] = (float)le32s(at + 16 + 8 * v) * 1e-3f;
    }
}

void sonar_bgfile_seal(uint8_t *out, const struct sonar_bgfile_layout *l)
{
    sonar_put_le32(out + l->crc, sonar_cpf_crc32(0, out, l->crc));
}

int32_t sonar_bgfile_write(const struct sonar_background *bg, const struct sonar_bgfile_meta *m, uint8_t *out, size_t cap)
{
    struct sonar_bgfile_meta h;
    struct sonar_bgfile_layout l;
    uint16_t a;
    if (bg == NULL || m == NULL || out == NULL)
        return SONAR_ERR_ARG;
    if (bg->n == 0 || bg->world || !per_angle(bg->mode))
        return SONAR_ERR_STATE;
    if (m->n != bg->n || m->mode != bg->mode || m->range_mm == 0 || sonar_bgfile_layout(bg->n, 0, 0, &l) != SONAR_OK)
        return SONAR_ERR_ARG;
    if (cap < l.size)
        return SONAR_ERR_SPACE;
    h = *m;
    h.flags = 0; /* a learnt model: no spread, not a checked survey, no places */
    h.places = 0;
    sonar_bgfile_put_header(out, &h);
    memcpy(out + l.looks, bg->visits, SONAR_MAX_ANGLES);
    out[l.looks + SONAR_MAX_ANGLES] = bg->across_visits;
    memcpy(out + l.across, bg->across, bg->n);
    for (a = 0; a < SONAR_MAX_ANGLES; a++)
        memcpy(out + l.levels + (size_t)a * bg->n, bg->cell[a], bg->n);
    sonar_bgfile_seal(out, &l);
    return (int32_t)l.size;
}

size_t sonar_bgfile_declared(const uint8_t *in, size_t len)
{
    struct sonar_bgfile_layout l;
    if (in == NULL || len < SONAR_BGFILE_HEADER || memcmp(in, magic, sizeof(magic)) != 0 ||
        sonar_le16(in + 8) != SONAR_BGFILE_VERSION || sonar_le16(in + 12) == 0 || sonar_le16(in + 12) > SONAR_MAX_SAMPLES ||
        in[19] > SONAR_MAX_CLUSTERS || sonar_bgfile_layout(sonar_le16(in + 12), in[18], in[19], &l) != SONAR_OK ||
        l.size > len)
        return len;
    return l.size;
}

int sonar_bgfile_check(const uint8_t *in, size_t len, struct sonar_bgfile_meta *m, const char **why)
{
    struct sonar_bgfile_layout l;
    const char *dummy;
    uint16_t angles, n;
    if (why == NULL)
        why = &dummy;
    *why = "bad argument";
    if (in == NULL || m == NULL)
        return SONAR_ERR_ARG;
    if (len < sizeof(magic) || memcmp(in, magic, sizeof(magic)) != 0) {
        *why = "not a sonard background file (no SONARBG header)";
        return SONAR_ERR_ID;
    }
    if (len < 10u) {
        *why = "truncated: shorter than its header";
        return SONAR_ERR_LENGTH;
    }
    if (sonar_le16(in + 8) != SONAR_BGFILE_VERSION) {
        *why = "version: not " SONAR_STR(SONAR_BGFILE_VERSION) ", the one this build reads (record the survey again)";
        return SONAR_ERR_RANGE;
    }
    if (len < SONAR_BGFILE_HEADER) {
        *why = "truncated: shorter than its header";
        return SONAR_ERR_LENGTH;
    }
    angles = sonar_le16(in + 10);
    n = sonar_le16(in + 12);
    if (angles != SONAR_MAX_ANGLES || n == 0 || n > SONAR_MAX_SAMPLES) {
        *why = "geometry: its angles or samples are not what this build holds (" SONAR_STR(SONAR_MAX_ANGLES) " angles, 1.." SONAR_STR(SONAR_MAX_SAMPLES) " samples)";
        return SONAR_ERR_RANGE;
    }
    if (in[19] > SONAR_MAX_CLUSTERS || (in[18] & ~(SONAR_BGFILE_SPREAD | SONAR_BGFILE_SURVEY)) != 0 ||
        sonar_bgfile_layout(n, in[18], in[19], &l) != SONAR_OK) {
        *why = "header: unknown flags, or more structure places than this build holds";
        return SONAR_ERR_RANGE;
    }
    if (len < l.size) {
        *why = "truncated: shorter than its geometry says";
        return SONAR_ERR_LENGTH;
    }
    if (len > l.size) {
        *why = "longer than its geometry says (trailing bytes)";
        return SONAR_ERR_LENGTH;
    }
    if (sonar_le32(in + l.crc) != sonar_cpf_crc32(0, in, l.crc)) {
        *why = "checksum: the file is damaged";
        return SONAR_ERR_LENGTH;
    }
    m->n = n;
    m->mode = in[14];
    m->median = in[15];
    m->median2d = in[16];
    m->gain = in[17];
    m->flags = in[18];
    m->places = in[19];
    m->range_mm = sonar_le32(in + 20);
    m->sound_mm_s = sonar_le32(in + 24);
    m->sweeps = sonar_le32(in + 28);
    m->utime = le64(in + 32);
    m->offset_mgrad = le32s(in + 40);
    if (!per_angle(m->mode) || m->range_mm == 0 || m->range_mm > 1000000u ||
        (m->gain > 2 && m->gain != SONAR_BGFILE_GAIN_UNKNOWN)) {
        *why = "header: its mode, range or gain is out of range";
        return SONAR_ERR_RANGE;
    }
    *why = "ok";
    return SONAR_OK;
}

int sonar_bgfile_load(struct sonar_background *bg, const uint8_t *in, size_t len, const char **why)
{
    struct sonar_bgfile_meta m;
    struct sonar_bgfile_layout l;
    const char *dummy;
    uint16_t a;
    int r;
    if (why == NULL)
        why = &dummy;
    if (bg == NULL) {
        *why = "bad argument";
        return SONAR_ERR_ARG;
    }
    if ((r = sonar_bgfile_check(in, len, &m, why)) != SONAR_OK)
        return r;
    if (!per_angle(bg->mode)) {
        *why = "mode: a site's background is per angle (--background auto or per-angle)";
        return SONAR_ERR_STATE;
    }
    if (sonar_bgfile_layout(m.n, m.flags, m.places, &l) != SONAR_OK)
        return SONAR_ERR_ARG;
    sonar_background_reset(bg);
    memcpy(bg->visits, in + l.looks, SONAR_MAX_ANGLES);
    bg->across_visits = in[l.looks + SONAR_MAX_ANGLES];
    memcpy(bg->across, in + l.across, m.n);
    for (a = 0; a < SONAR_MAX_ANGLES; a++)
        memcpy(bg->cell[a], in + l.levels + (size_t)a * m.n, m.n);
    bg->n = m.n;
    *why = "ok";
    return SONAR_OK;
}
