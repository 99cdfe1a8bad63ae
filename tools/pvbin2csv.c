/* pvbin2csv.c -- Ping Viewer sensor logs (.bin) to the study's CSV: QDataStream records, one continuous resyncing Ping parser across them. */
#define _POSIX_C_SOURCE 200809L
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "../src/host/csv.h"
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

int main(int argc, char **argv)
{
    static struct sonar_ping_parser parser;
    struct reader r;
    char s[4096], prev[16] = "";
    double c = 1500.0, start = 0.0, day = 0.0;
    uint32_t v, family = 0, type = 0, recs = 0, beams = 0, skipped = 0;
    uint16_t n0 = 0;
    FILE *in, *out;
    long size;
    uint8_t *buf;
    int i;
    if (argc < 3) {
        fprintf(stderr, "usage: pvbin2csv LOG.bin OUT.csv [--speed-of-sound C] [--start EPOCH_SECONDS]\n"
                        "The log's name YYYYMMDD-hhmmsszzz.bin gives the start time (as UTC) unless --start is given.\n");
        return 2;
    }
    for (i = 3; i + 1 < argc; i += 2) {
        if (strcmp(argv[i], "--speed-of-sound") == 0)
            c = atof(argv[i + 1]);
        else if (strcmp(argv[i], "--start") == 0)
            start = atof(argv[i + 1]);
    }
    if (start == 0.0) {
        const char *base = strrchr(argv[1], '/') ? strrchr(argv[1], '/') + 1 : argv[1];
        struct tm tm;
        int ms = 0;
        memset(&tm, 0, sizeof(tm));
        if (sscanf(base, "%4d%2d%2d-%2d%2d%2d%3d", &tm.tm_year, &tm.tm_mon, &tm.tm_mday, &tm.tm_hour, &tm.tm_min, &tm.tm_sec,
                   &ms) == 7) {
            tm.tm_year -= 1900;
            tm.tm_mon -= 1;
            start = (double)timegm(&tm) + ms / 1000.0;
        }
    }
    if ((in = fopen(argv[1], "rb")) == NULL) {
        perror(argv[1]);
        return 2;
    }
    fseek(in, 0, SEEK_END);
    size = ftell(in);
    rewind(in);
    buf = malloc(size > 0 ? (size_t)size : 1);
    if (buf == NULL || fread(buf, 1, (size_t)size, in) != (size_t)size) {
        fprintf(stderr, "pvbin2csv: %s: cannot read\n", argv[1]);
        return 2;
    }
    fclose(in);
    r.b = buf;
    r.n = (size_t)size;
    r.off = 0;
    r.path = argv[1];
    if (qstring(&r, s, sizeof(s)) != 0 || strcmp(s, "PingViewer sensor log file") != 0) {
        fprintf(stderr, "pvbin2csv: %s: not a Ping Viewer sensor log (header '%.40s')\n", argv[1], s);
        return 1;
    }
    if (u32(&r, &v) != 0 || v == 0 || v > 1) {
        fprintf(stderr, "pvbin2csv: %s: log version %u is not 1\n", argv[1], v);
        return 1;
    }
    for (i = 0; i < 5; i++)
        if (qstring(&r, s, sizeof(s)) != 0) {
            fprintf(stderr, "pvbin2csv: %s: truncated header at byte %zu\n", argv[1], r.off);
            return 1;
        }
    if (u32(&r, &family) != 0 || u32(&r, &type) != 0) {
        fprintf(stderr, "pvbin2csv: %s: truncated header at byte %zu\n", argv[1], r.off);
        return 1;
    }
    if (type != 2)
        fprintf(stderr, "pvbin2csv: %s: sensor type %u is not a Ping360 (2); converting its 2300/2301 frames anyway\n",
                argv[1], type);
    if ((out = fopen(argv[2], "w")) == NULL) {
        perror(argv[2]);
        return 2;
    }
    if (sonar_ping_parser_init(&parser, 0) != SONAR_OK)
        return 2;
    while (r.off < r.n) {
        size_t at = r.off;
        uint32_t len;
        int h, m, sec, ms;
        double t;
        const uint8_t *p;
        size_t left;
        struct sonar_ping_frame f;
        if (qstring(&r, s, sizeof(s)) != 0 || u32(&r, &len) != 0 || (len != 0xFFFFFFFFu && len > r.n - r.off)) {
            fprintf(stderr, "pvbin2csv: %s: record %u truncated at byte %zu; stopping there\n", argv[1], recs + 1, at);
            break;
        }
        if (sscanf(s, "%d:%d:%d.%d", &h, &m, &sec, &ms) != 4) {
            fprintf(stderr, "pvbin2csv: %s: record %u at byte %zu: time '%s' is not hh:mm:ss.zzz\n", argv[1], recs + 1, at, s);
            break;
        }
        /* the elapsed time wraps at 24 h (QTime) */
        if (strcmp(s, prev) < 0 && prev[0] != '\0')
            day += 86400.0;
        snprintf(prev, sizeof(prev), "%.15s", s);
        t = start + day + h * 3600.0 + m * 60.0 + sec + ms / 1000.0;
        recs++;
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
                fprintf(stderr, "pvbin2csv: %s: record %u: a beam of %u samples among beams of %u; skipped\n", argv[1],
                        recs, d.data_length, n0);
                skipped++;
                continue;
            }
            meta.range_m = sonar_geometry_range_m(d.sample_period, d.data_length, c);
            meta.gain = d.gain;
            meta.sample_period = d.sample_period;
            meta.transmit_duration = d.transmit_duration;
            meta.transmit_frequency = d.transmit_frequency;
            meta.speed_of_sound = c;
            if (csv_write(out, (int64_t)t, (uint32_t)((t - (double)(int64_t)t) * 1e9), d.angle, d.data, d.data_length, &meta) != 0) {
                fprintf(stderr, "pvbin2csv: %s: write error\n", argv[2]);
                return 1;
            }
            beams++;
        }
    }
    fclose(out);
    fprintf(stderr, "pvbin2csv: %s: %u records, %u beams written, %u skipped; frames %u, checksum errors %u, resyncs %u\n",
            argv[1], recs, beams, skipped, parser.counters.frames, parser.counters.checksum_errors, parser.counters.resyncs);
    free(buf);
    return beams > 0 ? 0 : 1;
}
