/* csv.c -- tolerant, strict-about-values parser of the study's CSV; one fixed line buffer, no heap. */
#include "csv.h"

#include <ctype.h>
#include <errno.h>
#include <stdlib.h>
#include <string.h>

int csv_open(struct csv_reader *r, const char *path)
{
    memset(r, 0, sizeof(*r));
    r->path = path;
    if (strcmp(path, "-") == 0) {
        r->f = stdin;
        return 0;
    }
    r->f = fopen(path, "r");
    if (r->f == NULL)
        return -1;
    r->owned = 1;
    return 0;
}

void csv_close(struct csv_reader *r)
{
    if (r->owned && r->f != NULL)
        fclose(r->f);
    r->f = NULL;
}

/* Splits at commas outside double quotes, in place; returns the field count (max cap). */
static int split_fields(char *s, char **field, int cap)
{
    int n = 0, quoted = 0;
    char *w = s;
    field[n++] = w;
    for (; *s != '\0'; s++) {
        if (*s == '"') {
            quoted = !quoted;
            continue;
        }
        if (*s == ',' && !quoted) {
            *w++ = '\0';
            if (n == cap)
                return -1;
            field[n++] = w;
            continue;
        }
        *w++ = *s;
    }
    *w = '\0';
    return n;
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

static void meta(struct csv_row *row, const char *tok)
{
    static const char *const keys[] = {"range_m", "sample_period", "speed_of_sound", "gain",
                                       "transmit_duration", "transmit_frequency"};
    double *dst[6];
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
    klen = (size_t)(eq - tok);
    v = strtod(eq + 1, &end);
    if (*end != '\0')
        return;
    for (i = 0; i < 6; i++)
        if (strlen(keys[i]) == klen && strncmp(tok, keys[i], klen) == 0)
            *dst[i] = v;
}

/* Parses the timestamp and angle fields; returns the index of the first sample field or -1. */
static int parse_head(char **field, int nf, struct csv_row *row, char *err, size_t errlen)
{
    char *t = trim(field[0]);
    char *dot = strchr(t, '.');
    int64_t v;
    int a;
    if (dot != NULL) {
        char frac[10] = "000000000";
        size_t fl;
        *dot = '\0';
        fl = strlen(dot + 1);
        if (parse_i64(t, &row->sec) != 0 || fl == 0 || fl > 9 || strspn(dot + 1, "0123456789") != fl) {
            snprintf(err, errlen, "timestamp '%s.%s' is not sec.nsec", t, dot + 1);
            return -1;
        }
        memcpy(frac, dot + 1, fl);
        row->nsec = (uint32_t)strtoul(frac, NULL, 10);
        a = 1;
    } else {
        if (nf < 2 || parse_i64(t, &row->sec) != 0) {
            snprintf(err, errlen, "timestamp seconds '%s' is not an integer", t);
            return -1;
        }
        t = trim(field[1]);
        if (parse_i64(t, &v) != 0 || v < 0 || v > 999999999) {
            snprintf(err, errlen, "nanoseconds '%s' is not an integer 0..999999999", t);
            return -1;
        }
        row->nsec = (uint32_t)v;
        a = 2;
    }
    if (a >= nf) {
        snprintf(err, errlen, "no angle column");
        return -1;
    }
    t = trim(field[a]);
    if (parse_i64(t, &v) != 0 || v < 0 || v > 399) {
        snprintf(err, errlen, "angle '%s' is not an integer 0..399 gradians", t);
        return -1;
    }
    row->angle = (uint16_t)v;
    return a + 1;
}

static int parse_row(struct csv_reader *r, char *line, struct csv_row *row, char *err, size_t errlen)
{
    char **field = r->field;
    int nf, first, i;
    unsigned long count = 0;
    int in_meta = 0;
    nf = split_fields(line, field, CSV_MAX_FIELDS);
    if (nf < 0) {
        snprintf(err, errlen, "too many columns (more than %d)", CSV_MAX_FIELDS);
        return -1;
    }
    row->range_m = row->sample_period = row->speed_of_sound = -1.0;
    row->gain = row->transmit_duration = row->transmit_frequency = -1.0;
    if ((first = parse_head(field, nf, row, err, errlen)) < 0)
        return -1;
    for (i = first; i < nf; i++) {
        char *save = NULL, *tok;
        for (tok = strtok_r(field[i], " \t\r\n[]", &save); tok != NULL; tok = strtok_r(NULL, " \t\r\n[]", &save)) {
            int64_t v;
            if (strspn(tok, ".") == strlen(tok))
                continue; /* the study's stray '...' */
            if (strchr(tok, '=') != NULL) {
                in_meta = 1;
                meta(row, tok);
                continue;
            }
            if (in_meta) {
                snprintf(err, errlen, "sample '%s' after metadata", tok);
                return -1;
            }
            if (parse_i64(tok, &v) != 0) {
                snprintf(err, errlen, "sample %lu '%s' is not a number", count + 1, tok);
                return -1;
            }
            if (v < 0 || v > 255) {
                snprintf(err, errlen, "sample %lu is %lld, outside 0..255", count + 1, (long long)v);
                return -1;
            }
            if (count >= SONAR_MAX_SAMPLES) {
                snprintf(err, errlen, "more than %d samples", SONAR_MAX_SAMPLES);
                return -1;
            }
            row->samples[count++] = (uint8_t)v;
        }
    }
    if (count == 0) {
        snprintf(err, errlen, "no samples");
        return -1;
    }
    if (r->expect_n != 0 && count != r->expect_n) {
        snprintf(err, errlen, "%lu samples, but the file's first row had %u", count, r->expect_n);
        return -1;
    }
    r->expect_n = (uint16_t)count;
    row->n = (uint16_t)count;
    return 0;
}

int csv_next(struct csv_reader *r, struct csv_row *row, char *err, size_t errlen)
{
    for (;;) {
        size_t len;
        char *s;
        if (fgets(r->buf, sizeof(r->buf), r->f) == NULL)
            return 0;
        r->line++;
        len = strlen(r->buf);
        if (len == sizeof(r->buf) - 1 && r->buf[len - 1] != '\n') {
            int c;
            while ((c = fgetc(r->f)) != EOF && c != '\n')
                ;
            r->bad++;
            snprintf(err, errlen, "line longer than %d bytes", CSV_LINE_MAX - 2);
            return -1;
        }
        s = trim(r->buf);
        if (*s == '\0' || *s == '#')
            continue;
        /* A header: only before any data, and only if its first field is not numeric. */
        if (!r->seen_data && !isdigit((unsigned char)*s) && *s != '-') {
            r->seen_data = 1;
            continue;
        }
        r->seen_data = 1;
        if (parse_row(r, s, row, err, errlen) != 0) {
            r->bad++;
            return -1;
        }
        r->good++;
        return 1;
    }
}

int csv_write(FILE *f, int64_t sec, uint32_t nsec, uint16_t angle, const uint8_t *s, uint16_t n, double range_m)
{
    uint16_t i;
    if (fprintf(f, "%lld,%09u,%u,\"", (long long)sec, (unsigned)nsec, (unsigned)angle) < 0)
        return -1;
    for (i = 0; i < n; i++)
        if (fprintf(f, i ? " %u" : "%u", (unsigned)s[i]) < 0)
            return -1;
    if (fputc('"', f) == EOF)
        return -1;
    if (range_m > 0.0 && fprintf(f, ",range_m=%.4f", range_m) < 0)
        return -1;
    return fputc('\n', f) == EOF ? -1 : 0;
}
