/* csv.c -- tolerant, strict-about-values parser of the study's CSV; one fixed line buffer, no heap. */
#include "csv.h"

#include <ctype.h>
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#ifdef __SSE2__
#include <emmintrin.h>
#endif

#include "csv_internal.h"

/* Next comma-separated field of *p (quotes and blanks around it stripped), NUL-terminated in place; NULL at the end. */
static char *next_field(char **p)
{
    char *f = *p, *e;
    int quoted = 0;
    if (f == NULL)
        return NULL;
    for (e = f; *e != '\0' && (quoted || *e != ','); e++)
        if (*e == '"')
            quoted = !quoted;
    *p = *e == ',' ? e + 1 : NULL;
    *e = '\0';
    while (isspace((unsigned char)*f) || *f == '"')
        f++;
    while (e > f && (isspace((unsigned char)e[-1]) || e[-1] == '"'))
        *--e = '\0';
    return f;
}

static int parse_i64(const char *s, int64_t *v)
{
    char *end;
    long long x;
    if (*s == '\0')
        return -1;
    errno = 0;
    x = strtoll(s, &end, 10);
    if (errno != 0 || *end != '\0')
        return -1;
    *v = (int64_t)x;
    return 0;
}

/* key=value metadata: unknown keys are ignored; a known key must carry a number in its range. */
static int meta(struct csv_row *row, const char *tok, unsigned *pose_keys, char *err, size_t errlen)
{
    static const char *const keys[] = {"range_m", "sample_period", "speed_of_sound", "gain", "transmit_duration",
                                       "transmit_frequency", "north_m", "east_m", "yaw_deg"};
    static const double lo[] = {0.0, 0.0, CSV_META_SOS_MIN, 0.0, 0.0, 0.0, -CSV_META_NE_MAX, -CSV_META_NE_MAX,
                                -CSV_META_YAW_MAX};
    static const double hi[] = {CSV_META_RANGE_MAX, CSV_META_U16_MAX, CSV_META_SOS_MAX, 255.0, CSV_META_U16_MAX,
                                CSV_META_U16_MAX, CSV_META_NE_MAX, CSV_META_NE_MAX, CSV_META_YAW_MAX};
    double *dst[9];
    const char *eq = strchr(tok, '=');
    size_t i, klen;
    char *end;
    double v;
    dst[0] = &row->range_m;
    dst[1] = &row->sample_period;
    dst[2] = &row->speed_of_sound;
    dst[3] = &row->gain;
    dst[4] = &row->transmit_duration;
    dst[5] = &row->transmit_frequency;
    dst[6] = &row->north_m;
    dst[7] = &row->east_m;
    dst[8] = &row->yaw_deg;
    klen = (size_t)(eq - tok);
    for (i = 0; i < 9; i++)
        if (strlen(keys[i]) == klen && strncmp(tok, keys[i], klen) == 0)
            break;
    if (i == 9)
        return 0;
    v = strtod(eq + 1, &end);
    /* range_m must be > 0; the rest may be 0. NaN fails both comparisons. */
    if (eq[1] == '\0' || *end != '\0' || !(v >= lo[i] && v <= hi[i]) || (i == 0 && !(v > 0.0))) {
        snprintf(err, errlen, "metadata %s is not a number in %g..%g", tok, lo[i], hi[i]);
        return -1;
    }
    *dst[i] = v;
    if (i >= 6)
        *pose_keys |= 1u << (i - 6);
    return 0;
}

/* Parses the timestamp and angle fields off *p. Returns 0, or -1 with err set. */
static int parse_head(char **p, struct csv_row *row, char *err, size_t errlen)
{
    char *t = next_field(p), *a, *dot;
    int64_t v;
    if (t == NULL || (dot = strchr(t, '.')) != NULL) {
        char frac[10] = "000000000";
        size_t fl;
        if (t == NULL) {
            snprintf(err, errlen, "empty row");
            return -1;
        }
        *dot = '\0';
        fl = strlen(dot + 1);
        if (parse_i64(t, &row->sec) != 0 || row->sec > CSV_MAX_SEC || row->sec < -CSV_MAX_SEC || fl == 0 || fl > 9 || strspn(dot + 1, "0123456789") != fl) {
            snprintf(err, errlen, "timestamp '%s.%s' is not sec.nsec", t, dot + 1);
            return -1;
        }
        memcpy(frac, dot + 1, fl);
        row->nsec = (uint32_t)strtoul(frac, NULL, 10);
    } else {
        if (parse_i64(t, &row->sec) != 0 || row->sec > CSV_MAX_SEC || row->sec < -CSV_MAX_SEC) {
            snprintf(err, errlen, "timestamp seconds '%s' is not an integer within +-%lld", t, (long long)CSV_MAX_SEC);
            return -1;
        }
        t = next_field(p);
        if (t == NULL || parse_i64(t, &v) != 0 || v < 0 || v > 999999999) {
            snprintf(err, errlen, "nanoseconds '%s' is not an integer 0..999999999", t ? t : "");
            return -1;
        }
        row->nsec = (uint32_t)v;
    }
    a = next_field(p);
    if (a == NULL) {
        snprintf(err, errlen, "no angle column");
        return -1;
    }
    if (parse_i64(a, &v) != 0 || v < 0 || v > 399) {
        snprintf(err, errlen, "angle '%s' is not an integer 0..399 gradians", a);
        return -1;
    }
    row->angle = (uint16_t)v;
    return 0;
}

/* Character classes of the sample tokenizer: separators (commas, quotes, blanks, the brackets of a
 * printed array), digits, the terminating NUL, and anything else. */
enum { C_OTHER = 0, C_SEP = 1, C_DIGIT = 2, C_END = 3 };

static const unsigned char char_class[256] = {
    [0] = C_END, [' '] = C_SEP, [','] = C_SEP, ['"'] = C_SEP, ['\t'] = C_SEP, ['\r'] = C_SEP, ['\n'] = C_SEP,
    ['['] = C_SEP, [']'] = C_SEP, ['0'] = C_DIGIT, ['1'] = C_DIGIT, ['2'] = C_DIGIT, ['3'] = C_DIGIT,
    ['4'] = C_DIGIT, ['5'] = C_DIGIT, ['6'] = C_DIGIT, ['7'] = C_DIGIT, ['8'] = C_DIGIT, ['9'] = C_DIGIT};

/* A token that is not a plain number: a stray '...' (skipped), key=value metadata, or an error. */
static int odd_token(struct csv_row *row, const char *tok, size_t len, unsigned long count, int *in_meta,
                     unsigned *pose_keys, char *err, size_t errlen)
{
    size_t k;
    for (k = 0; k < len && tok[k] == '.'; k++)
        ;
    if (k == len)
        return 0; /* the study's stray '...' */
    if (memchr(tok, '=', len) != NULL && len < 64) {
        char kv[64];
        memcpy(kv, tok, len);
        kv[len] = '\0';
        *in_meta = 1;
        return meta(row, kv, pose_keys, err, errlen);
    }
    snprintf(err, errlen, "sample %lu '%.*s' is not a number", count + 1, (int)(len > 20 ? 20 : len), tok);
    return -1;
}

/*
 * Fast path for plain "12 7 255 ..." text, which is where a replay spends its time: 64 bytes are
 * classified at once into a digit bitmask, then every number in them is decoded independently
 * (no chain through the previous token's length). It stops before the first byte that is neither
 * a digit nor a blank/comma, at a token boundary, and returns there; the general path continues.
 */
static const char *fast_samples(const char *p, struct csv_row *row, unsigned long *count)
{
    static const unsigned m0[3] = {1, 10, 100}, m1[3] = {0, 1, 10}, m2[3] = {0, 0, 1};
    unsigned long n = *count;
    for (;;) {
        uint64_t dig = 0, sep = 0, ok, starts, ends;
        unsigned i, stop = 64;
        int more;
#ifdef __SSE2__
        for (i = 0; i < 64; i += 16) {
            __m128i c = _mm_loadu_si128((const __m128i *)(const void *)(p + i));
            /* digits: '0' <= c <= '9' as signed bytes (all ASCII digits are positive) */
            __m128i d = _mm_and_si128(_mm_cmpgt_epi8(c, _mm_set1_epi8('0' - 1)), _mm_cmplt_epi8(c, _mm_set1_epi8('9' + 1)));
            __m128i b = _mm_or_si128(_mm_or_si128(_mm_cmpeq_epi8(c, _mm_set1_epi8(' ')), _mm_cmpeq_epi8(c, _mm_set1_epi8(','))),
                                     _mm_or_si128(_mm_cmpeq_epi8(c, _mm_set1_epi8('"')), _mm_cmpeq_epi8(c, _mm_set1_epi8('\t'))));
            dig |= (uint64_t)(unsigned)_mm_movemask_epi8(d) << i;
            sep |= (uint64_t)(unsigned)_mm_movemask_epi8(b) << i;
        }
#else
        for (i = 0; i < 64; i++) {
            unsigned char c = (unsigned char)p[i];
            dig |= (uint64_t)((unsigned)(c - '0') < 10u) << i;
            sep |= (uint64_t)(c == ' ' || c == ',' || c == '"' || c == '\t') << i;
        }
#endif
        ok = dig | sep;
        more = ~ok == 0; /* the whole block is digits and separators: go on after it */
        if (!more)
            stop = (unsigned)__builtin_ctzll(~ok); /* first byte to leave to the general path */
        /* Only whole tokens: back up to the blank before a token the stop byte (or byte 64) cuts. */
        if (stop > 0 && ((dig >> (stop - 1)) & 1u))
            while (stop > 0 && ((dig >> (stop - 1)) & 1u))
                stop--;
        if (stop == 0)
            break;
        dig &= stop == 64 ? ~(uint64_t)0 : (((uint64_t)1 << stop) - 1u);
        starts = dig & ~(dig << 1);
        ends = dig & ~(dig >> 1);
        /* Byte 0 cannot continue a token: the previous block ended on a blank or at the start. */
        while (starts != 0) {
            unsigned a = (unsigned)__builtin_ctzll(starts), b = (unsigned)__builtin_ctzll(ends), v;
            const unsigned char *t = (const unsigned char *)p + a;
            unsigned c0, c1, c2;
            if (b - a > 2 || n >= SONAR_MAX_SAMPLES)
                goto done_at; /* 4+ digits or too many samples: the general path reports it */
            c0 = (unsigned)t[0] - '0';
            c1 = (unsigned)t[1] - '0';
            c2 = (unsigned)t[2] - '0';
            /* branch-free: the multipliers of a 1-, 2- or 3-digit number (bytes past it count 0) */
            v = c0 * m0[b - a] + c1 * m1[b - a] + c2 * m2[b - a];
            if (v > 255u) {
            done_at:
                *count = n;
                return p + a;
            }
            row->samples[n++] = (uint8_t)v;
            starts &= starts - 1u;
            ends &= ends - 1u;
        }
        p += stop;
        if (!more)
            break;
    }
    *count = n;
    return p;
}

/* The untimed form's head: the angle alone. */
static int parse_angle(char **p, struct csv_row *row, char *err, size_t errlen)
{
    char *a = next_field(p);
    int64_t v;
    row->sec = 0;
    row->nsec = 0;
    if (a == NULL || parse_i64(a, &v) != 0 || v < 0 || v > 399) {
        snprintf(err, errlen, "angle '%s' is not an integer 0..399 gradians", a ? a : "");
        return -1;
    }
    row->angle = (uint16_t)v;
    return 0;
}

/* Long: every field of a row is checked where it is read, so each error names its column and value. */
static int parse_row(struct csv_reader *r, char *line, struct csv_row *row, char *err, size_t errlen)
{
    const char *p;
    char *rest = line;
    unsigned long count = 0;
    int in_meta = 0;
    unsigned pose_keys = 0;
    row->range_m = row->sample_period = row->speed_of_sound = -1.0;
    row->gain = row->transmit_duration = row->transmit_frequency = -1.0;
    row->has_pose = 0;
    row->north_m = row->east_m = row->yaw_deg = 0.0;
    row->timed = r->format != CSV_FORMAT_UNTIMED;
    if ((row->timed ? parse_head(&rest, row, err, errlen) : parse_angle(&rest, row, err, errlen)) != 0)
        return -1;
    if (rest != NULL)
        rest = (char *)(uintptr_t)fast_samples(rest, row, &count);
    /* The general path, from the first byte the fast path did not take; the common token
     * (1-3 digits, then a blank or a comma) takes a short path and anything else the general one. */
    for (p = rest; p != NULL;) {
        const char *tok = p;
        const unsigned char *u = (const unsigned char *)p;
        unsigned char cls;
        unsigned v;
        /* Four bytes at once (the buffer is padded): y holds each byte XOR '0', so a digit byte is
         * < 10; bit 7 of ((y + 0x76) | y) flags the others (a carry only disturbs bytes after the
         * first non-digit, which are not used). n = leading digits. */
        uint32_t w = (uint32_t)u[0] | (uint32_t)u[1] << 8 | (uint32_t)u[2] << 16 | (uint32_t)u[3] << 24;
        uint32_t y = w ^ 0x30303030u;
        uint32_t nd = ((y + 0x76767676u) | y) & 0x80808080u;
        if (nd != 0 && (nd & 0x80u) == 0 && !in_meta && count < SONAR_MAX_SAMPLES) {
            unsigned n = (unsigned)__builtin_ctz(nd) >> 3; /* 1..3 */
            unsigned d0 = y & 0xffu, d1 = (y >> 8) & 0xffu, d2 = (y >> 16) & 0xffu;
            unsigned after = (w >> (8u * n)) & 0xffu;
            v = n == 1 ? d0 : n == 2 ? d0 * 10u + d1 : d0 * 100u + d1 * 10u + d2;
            cls = char_class[after];
            if ((cls == C_SEP || cls == C_END) && v <= 255u) {
                row->samples[count++] = (uint8_t)v;
                /* consume one blank or comma with the number */
                p += n + (after == ' ' || after == ',');
                continue;
            }
        }
        cls = char_class[(unsigned char)*p];
        if (cls == C_SEP) {
            p++;
            continue;
        }
        if (cls == C_END)
            break;
        v = 0;
        while ((cls = char_class[(unsigned char)*p]) == C_DIGIT) {
            if (v < 100000u)
                v = v * 10u + (unsigned)(*p - '0');
            p++;
        }
        if (cls == C_OTHER) {
            while ((cls = char_class[(unsigned char)*p]) != C_SEP && cls != C_END)
                p++;
            if (odd_token(row, tok, (size_t)(p - tok), count, &in_meta, &pose_keys, err, errlen) != 0)
                return -1;
            continue;
        }
        if (in_meta) {
            snprintf(err, errlen, "sample '%.*s' after metadata", (int)(p - tok > 20 ? 20 : p - tok), tok);
            return -1;
        }
        if (v > 255u) {
            snprintf(err, errlen, "sample %lu is %.*s, outside 0..255", count + 1, (int)(p - tok > 20 ? 20 : p - tok), tok);
            return -1;
        }
        if (count >= SONAR_MAX_SAMPLES) {
            snprintf(err, errlen, "more than %d samples", SONAR_MAX_SAMPLES);
            return -1;
        }
        row->samples[count++] = (uint8_t)v;
    }
    if (count == 0) {
        snprintf(err, errlen, "no samples");
        return -1;
    }
    /* Half a pose would put the beam somewhere invented. */
    if (pose_keys != 0 && pose_keys != 7u) {
        static const char *const names[3] = {"north_m", "east_m", "yaw_deg"};
        const char *miss[3];
        unsigned k, nm = 0;
        for (k = 0; k < 3; k++)
            if (!(pose_keys & (1u << k)))
                miss[nm++] = names[k];
        snprintf(err, errlen, "metadata north_m, east_m and yaw_deg come together (%s%s%s missing)", miss[0],
                 nm > 1 ? " and " : "", nm > 1 ? miss[1] : "");
        return -1;
    }
    row->has_pose = pose_keys == 7u;
    if (r->expect_n != 0 && count != r->expect_n) {
        snprintf(err, errlen, "%lu samples, but the file's first row had %u", count, r->expect_n);
        return -1;
    }
    r->expect_n = (uint16_t)count;
    row->n = (uint16_t)count;
    return 0;
}

static char *trim(char *s)
{
    char *e;
    while (isspace((unsigned char)*s))
        s++;
    e = s + strlen(s);
    while (e > s && isspace((unsigned char)e[-1]))
        *--e = '\0';
    return s;
}

int csv_next(struct csv_reader *r, struct csv_row *row, char *err, size_t errlen)
{
    for (;;) {
        size_t len;
        char *s;
        if (r->stop || fgets(r->buf, CSV_LINE_MAX, r->f) == NULL)
            return r->stop ? 0 : csv_file_end(r, err, errlen);
        r->line++;
        len = strlen(r->buf);
        if (r->line == 1 && (unsigned char)r->buf[0] == 0x1f && (unsigned char)r->buf[1] == 0x8b) {
            /* Only a stream gets here (a file is decompressed by csv_open): its rows would all be garbage. */
            r->stop = 1;
            r->bad++;
            snprintf(err, errlen, "gzip-compressed data, not CSV rows: decompress it first (gzip -dc FILE.gz | ...), "
                     "or give the file's path");
            return HOST_ERR_ROW;
        }
        /* The tokenizers read up to 63 bytes past the NUL; make them this line's zeros, not an older line's text. */
        memset(r->buf + len, 0, 64);
        if (len == CSV_LINE_MAX - 1 && r->buf[len - 1] != '\n') {
            int c;
            while ((c = fgetc(r->f)) != EOF && c != '\n')
                ;
            r->bad++;
            snprintf(err, errlen, "line longer than %d bytes", CSV_LINE_MAX - 2);
            return HOST_ERR_ROW;
        }
        s = trim(r->buf);
        if (*s == '\0' || *s == '#')
            continue;
        if (r->format == CSV_FORMAT_UNKNOWN)
            r->format = strchr(s, ';') != NULL ? CSV_FORMAT_UNTIMED : CSV_FORMAT_STUDY;
        if (r->format == CSV_FORMAT_UNTIMED) {
            /* ';' is that form's comma; a comma inside it would be a decimal point, which no field may hold */
            char *q;
            for (q = s; (q = strpbrk(q, ";,")) != NULL; q++)
                *q = *q == ';' ? ',' : ';';
        }
        /* A header: only before any data, and only if its first field is not numeric. */
        if (!r->seen_data && !isdigit((unsigned char)*s) && *s != '-') {
            r->seen_data = 1;
            continue;
        }
        r->seen_data = 1;
        if (parse_row(r, s, row, err, errlen) != 0) {
            r->bad++;
            return HOST_ERR_ROW;
        }
        r->good++;
        return 1;
    }
}

const char *csv_format_name(const struct csv_reader *r)
{
    switch (r->format) {
    case CSV_FORMAT_STUDY: return "study CSV (sec,nsec,angle,samples)";
    case CSV_FORMAT_UNTIMED: return "brping rows (angle;samples, ';'-separated, no timestamps)";
    default: return "empty (no rows)";
    }
}

struct csv_meta csv_meta_none(void)
{
    struct csv_meta m;
    m.range_m = m.gain = m.sample_period = m.transmit_duration = m.transmit_frequency = m.speed_of_sound = -1.0;
    m.has_pose = 0;
    m.north_m = m.east_m = m.yaw_deg = 0.0;
    return m;
}

int csv_write(FILE *f, int64_t sec, uint32_t nsec, uint16_t angle, const uint8_t *s, uint16_t n, const struct csv_meta *meta)
{
    char line[5 * SONAR_MAX_SAMPLES + 256];
    size_t k = 0;
    uint16_t i;
    k += (size_t)snprintf(line, sizeof(line), "%lld,%09u,%u,\"", (long long)sec, (unsigned)nsec, (unsigned)angle);
    for (i = 0; i < n && i < SONAR_MAX_SAMPLES; i++) {
        unsigned v = s[i];
        /* hand-formatted: this runs for every sample of a recording */
        if (i)
            line[k++] = ' ';
        if (v >= 100)
            line[k++] = (char)('0' + v / 100);
        if (v >= 10)
            line[k++] = (char)('0' + v / 10 % 10);
        line[k++] = (char)('0' + v % 10);
    }
    line[k++] = '"';
    if (meta != NULL) {
        if (meta->range_m > 0)
            k += (size_t)snprintf(line + k, sizeof(line) - k, ",range_m=%.4f", meta->range_m);
        if (meta->gain >= 0)
            k += (size_t)snprintf(line + k, sizeof(line) - k, ",gain=%.0f", meta->gain);
        if (meta->sample_period >= 0)
            k += (size_t)snprintf(line + k, sizeof(line) - k, ",sample_period=%.0f", meta->sample_period);
        if (meta->transmit_duration >= 0)
            k += (size_t)snprintf(line + k, sizeof(line) - k, ",transmit_duration=%.0f", meta->transmit_duration);
        if (meta->transmit_frequency >= 0)
            k += (size_t)snprintf(line + k, sizeof(line) - k, ",transmit_frequency=%.0f", meta->transmit_frequency);
        if (meta->speed_of_sound > 0)
            k += (size_t)snprintf(line + k, sizeof(line) - k, ",speed_of_sound=%.1f", meta->speed_of_sound);
        if (meta->has_pose)
            k += (size_t)snprintf(line + k, sizeof(line) - k, ",north_m=%.3f,east_m=%.3f,yaw_deg=%.3f", meta->north_m,
                                  meta->east_m, meta->yaw_deg);
    }
    line[k++] = '\n';
    return fwrite(line, 1, k, f) == k ? HOST_OK : HOST_ERR_IO;
}
