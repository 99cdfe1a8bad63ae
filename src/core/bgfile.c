/* bgfile.c -- the per-angle background to and from a checked byte image (bgfile.h); one pass over the model and one CRC-32, no heap. */
#include "sonar/bgfile.h"

#include <string.h>

#include "le_internal.h"
#include "sonar/cpframe.h"

static const uint8_t magic[8] = {'S', 'O', 'N', 'A', 'R', 'B', 'G', '\n'};

size_t sonar_bgfile_size(uint16_t n)
{
    if (n == 0 || n > SONAR_MAX_SAMPLES)
        return 0;
    return (size_t)SONAR_BGFILE_HEADER + SONAR_MAX_ANGLES + 1u + n + (size_t)SONAR_MAX_ANGLES * n + 4u;
}

static int per_angle(uint8_t mode)
{
    return mode == SONAR_BACKGROUND_PER_ANGLE || mode == SONAR_BACKGROUND_AUTO;
}

int32_t sonar_bgfile_write(const struct sonar_background *bg, const struct sonar_bgfile_meta *m, uint8_t *out, size_t cap)
{
    size_t size, at;
    uint16_t a;
    if (bg == NULL || m == NULL || out == NULL)
        return SONAR_ERR_ARG;
    if (bg->n == 0 || bg->world || !per_angle(bg->mode))
        return SONAR_ERR_STATE;
    if (m->n != bg->n || m->mode != bg->mode || m->range_mm == 0)
        return SONAR_ERR_ARG;
    size = sonar_bgfile_size(bg->n);
    if (cap < size)
        return SONAR_ERR_SPACE;
    memset(out, 0, SONAR_BGFILE_HEADER);
    memcpy(out, magic, sizeof(magic));
    sonar_put_le16(out + 8, SONAR_BGFILE_VERSION);
    sonar_put_le16(out + 10, SONAR_MAX_ANGLES);
    sonar_put_le16(out + 12, bg->n);
    out[14] = bg->mode;
    out[15] = m->median;
    out[16] = m->median2d;
    out[17] = m->gain;
    sonar_put_le32(out + 20, m->range_mm);
    sonar_put_le32(out + 24, m->sound_mm_s);
    sonar_put_le32(out + 28, m->sweeps);
    at = SONAR_BGFILE_HEADER;
    memcpy(out + at, bg->visits, SONAR_MAX_ANGLES);
    at += SONAR_MAX_ANGLES;
    out[at++] = bg->across_visits;
    memcpy(out + at, bg->across, bg->n);
    at += bg->n;
    for (a = 0; a < SONAR_MAX_ANGLES; a++, at += bg->n)
        memcpy(out + at, bg->cell[a], bg->n);
    sonar_put_le32(out + at, sonar_cpf_crc32(0, out, at));
    return (int32_t)(at + 4u);
}

int sonar_bgfile_check(const uint8_t *in, size_t len, struct sonar_bgfile_meta *m, const char **why)
{
    const char *dummy;
    uint16_t angles, n;
    size_t size;
    if (why == NULL)
        why = &dummy;
    *why = "bad argument";
    if (in == NULL || m == NULL)
        return SONAR_ERR_ARG;
    if (len < sizeof(magic) || memcmp(in, magic, sizeof(magic)) != 0) {
        *why = "not a sonard background file (no SONARBG header)";
        return SONAR_ERR_ID;
    }
    if (len < SONAR_BGFILE_HEADER) {
        *why = "truncated: shorter than its header";
        return SONAR_ERR_LENGTH;
    }
    if (sonar_le16(in + 8) != SONAR_BGFILE_VERSION) {
        *why = "version: not " SONAR_STR(SONAR_BGFILE_VERSION) ", the one this build reads";
        return SONAR_ERR_RANGE;
    }
    angles = sonar_le16(in + 10);
    n = sonar_le16(in + 12);
    if (angles != SONAR_MAX_ANGLES || n == 0 || n > SONAR_MAX_SAMPLES) {
        *why = "geometry: its angles or samples are not what this build holds (" SONAR_STR(SONAR_MAX_ANGLES) " angles, 1.." SONAR_STR(SONAR_MAX_SAMPLES) " samples)";
        return SONAR_ERR_RANGE;
    }
    size = sonar_bgfile_size(n);
    if (len < size) {
        *why = "truncated: shorter than its geometry says";
        return SONAR_ERR_LENGTH;
    }
    if (len > size) {
        *why = "longer than its geometry says (trailing bytes)";
        return SONAR_ERR_LENGTH;
    }
    if (sonar_le32(in + size - 4u) != sonar_cpf_crc32(0, in, size - 4u)) {
        *why = "checksum: the file is damaged";
        return SONAR_ERR_LENGTH;
    }
    m->n = n;
    m->mode = in[14];
    m->median = in[15];
    m->median2d = in[16];
    m->gain = in[17];
    m->range_mm = sonar_le32(in + 20);
    m->sound_mm_s = sonar_le32(in + 24);
    m->sweeps = sonar_le32(in + 28);
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
    const char *dummy;
    size_t at;
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
    if (m.mode != bg->mode) {
        *why = "mode: the file holds another background mode than the one configured";
        return SONAR_ERR_STATE;
    }
    sonar_background_reset(bg);
    at = SONAR_BGFILE_HEADER;
    memcpy(bg->visits, in + at, SONAR_MAX_ANGLES);
    at += SONAR_MAX_ANGLES;
    bg->across_visits = in[at++];
    memcpy(bg->across, in + at, m.n);
    at += m.n;
    for (a = 0; a < SONAR_MAX_ANGLES; a++, at += m.n)
        memcpy(bg->cell[a], in + at, m.n);
    bg->n = m.n;
    *why = "ok";
    return SONAR_OK;
}
