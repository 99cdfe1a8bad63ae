/* pvbin.c -- Ping Viewer sensor logs (.bin) to the study's CSV: QDataStream records, one continuous resyncing Ping parser across them; reads a buffer, O(bytes), ~2 KB of parser state. */
#include "pvbin.h"

#include <stdarg.h>
#include <string.h>

#include "sonar/geometry.h"
#include "sonar/ping.h"

struct reader {
    const uint8_t *b;
    size_t n, off;
    const char *path;
};

static int u32(struct reader *r, uint32_t *v)
{
    if (r->n - r->off < 4)
        return -1;
    *v = (uint32_t)r->b[r->off] << 24 | (uint32_t)r->b[r->off + 1] << 16 | (uint32_t)r->b[r->off + 2] << 8 | r->b[r->off + 3];
    r->off += 4;
    return 0;
}

/* A QString as ASCII into out: UTF-16BE (Qt's default) or UTF-8 (some writers); 0xFFFFFFFF is null. */
static int qstring(struct reader *r, char *out, size_t cap)
{
    uint32_t len, i, k = 0;
    int utf16 = 1;
    if (u32(r, &len) != 0)
        return -1;
    out[0] = '\0';
    if (len == 0xFFFFFFFFu)
        return 0;
    if (len > r->n - r->off || len > 4096)
        return -1;
    /* UTF-16BE text of ASCII has a NUL before every character; UTF-8 has none */
    if (len % 2 != 0)
        utf16 = 0;
    for (i = 0; utf16 && i < len; i += 2)
        if (r->b[r->off + i] != 0)
            utf16 = 0;
    for (i = utf16 ? 1 : 0; i < len && k + 1 < cap; i += utf16 ? 2 : 1)
        out[k++] = (char)r->b[r->off + i];
    out[k] = '\0';
    r->off += len;
    return 0;
}

static void say(FILE *errf, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

static void say(FILE *errf, const char *fmt, ...)
{
    va_list ap;
    if (errf == NULL)
        return;
    va_start(ap, fmt);
    vfprintf(errf, fmt, ap);
    va_end(ap);
}

/* Long: one pass over the log's records (header, time, Ping frames, rows out), each step naming its byte for a clear
   error; they share the reader's position, so they stay in one function. */
int pvbin_convert(const uint8_t *buf, size_t size, const char *name, double start, double c, FILE *out, FILE *errf,
                  struct pvbin_stats *st)
{
    struct sonar_ping_parser parser;
    struct reader r;
    char s[4096], prev[16] = "";
    /*
     * Times in whole microseconds: the start rounded once, the record's milliseconds added exactly
     * (3.186 s in doubles, truncated to nanoseconds, was 3.185999999).
     */
    int64_t day_s = 0, start_us = (int64_t)(start * 1e6 + 0.5);
    uint32_t v, family = 0, type = 0;
    uint16_t n0 = 0;
    int i;
    memset(st, 0, sizeof(*st));
    r.b = buf;
    r.n = size;
    r.off = 0;
    r.path = name;
    if (qstring(&r, s, sizeof(s)) != 0 || strcmp(s, "PingViewer sensor log file") != 0) {
        say(errf, "sonar-pvbin2csv: %s: not a Ping Viewer sensor log (header '%.40s')\n", name, s);
        return HOST_ERR_CONFIG;
    }
    if (u32(&r, &v) != 0 || v == 0 || v > 1) {
        say(errf, "sonar-pvbin2csv: %s: log version %u is not 1\n", name, v);
        return HOST_ERR_CONFIG;
    }
    for (i = 0; i < 5; i++)
        if (qstring(&r, s, sizeof(s)) != 0) {
            say(errf, "sonar-pvbin2csv: %s: truncated header at byte %zu\n", name, r.off);
            return HOST_ERR_CONFIG;
        }
    if (u32(&r, &family) != 0 || u32(&r, &type) != 0) {
        say(errf, "sonar-pvbin2csv: %s: truncated header at byte %zu\n", name, r.off);
        return HOST_ERR_CONFIG;
    }
    if (type != 2)
        say(errf, "sonar-pvbin2csv: %s: sensor type %u is not a Ping360 (2); converting its 2300/2301 frames anyway\n", name,
            type);
    if (sonar_ping_parser_init(&parser, 0) != SONAR_OK)
        return HOST_ERR_CONFIG;
    while (r.off < r.n) {
        size_t at = r.off;
        uint32_t len;
        int h, m, sec, ms;
        int64_t t_us;
        const uint8_t *p;
        size_t left;
        struct sonar_ping_frame f;
        if (qstring(&r, s, sizeof(s)) != 0 || u32(&r, &len) != 0 || (len != 0xFFFFFFFFu && len > r.n - r.off)) {
            say(errf, "sonar-pvbin2csv: %s: record %u truncated at byte %zu; stopping there\n", name, st->records + 1, at);
            break;
        }
        /* A QTime: every field bounded before it reaches arithmetic and the timestamp's cast. */
        if (sscanf(s, "%d:%d:%d.%d", &h, &m, &sec, &ms) != 4 || h < 0 || h > 23 || m < 0 || m > 59 || sec < 0 ||
            sec > 59 || ms < 0 || ms > 999) {
            say(errf, "sonar-pvbin2csv: %s: record %u at byte %zu: time '%.40s' is not hh:mm:ss.zzz\n", name, st->records + 1,
                at, s);
            break;
        }
        /* the elapsed time wraps at 24 h (QTime) */
        if (strcmp(s, prev) < 0 && prev[0] != '\0')
            day_s += 86400;
        snprintf(prev, sizeof(prev), "%.15s", s);
        t_us = start_us + (day_s + h * 3600 + m * 60 + sec) * 1000000 + (int64_t)ms * 1000;
        st->records++;
        if (len == 0xFFFFFFFFu)
            continue;
        p = r.b + r.off;
        left = len;
        r.off += len;
        while (sonar_ping_parser_next(&parser, &p, &left, &f) == 1) {
            struct sonar_ping360_data d;
            struct csv_meta meta = csv_meta_none();
            if (sonar_ping_decode_data(&f, &d) != SONAR_OK || d.data_length == 0)
                continue;
            if (n0 == 0)
                n0 = d.data_length;
            if (d.data_length != n0 || d.data_length > SONAR_MAX_SAMPLES) {
                say(errf, "sonar-pvbin2csv: %s: record %u: a beam of %u samples among beams of %u; skipped\n", name,
                    st->records, d.data_length, n0);
                st->skipped++;
                continue;
            }
            meta.range_m = sonar_geometry_range_m(d.sample_period, d.data_length, c);
            meta.gain = d.gain;
            meta.sample_period = d.sample_period;
            meta.transmit_duration = d.transmit_duration;
            meta.transmit_frequency = d.transmit_frequency;
            meta.speed_of_sound = c;
            if (csv_write(out, t_us / 1000000, (uint32_t)(t_us % 1000000) * 1000u, d.angle, d.data, d.data_length,
                          &meta) != 0) {
                say(errf, "sonar-pvbin2csv: write error\n");
                return HOST_ERR_IO;
            }
            st->beams++;
        }
    }
    st->parser = parser.counters;
    return HOST_OK;
}
