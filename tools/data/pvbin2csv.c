/* pvbin2csv.c -- Ping Viewer sensor logs (.bin) to the study's CSV (the reader is src/host/pvbin.c); reads the whole file into memory. */
#define _POSIX_C_SOURCE 200809L
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "pvbin.h"

int main(int argc, char **argv)
{
    struct pvbin_stats st;
    double c = 1500.0, start = 0.0;
    FILE *in, *out;
    long size;
    uint8_t *buf;
    int i, r;
    if (argc < 3) {
        fprintf(stderr, "usage: sonar-pvbin2csv LOG.bin OUT.csv [--speed-of-sound C] [--start EPOCH_SECONDS]\n"
                        "The log's name YYYYMMDD-hhmmsszzz.bin gives the start time (as UTC) unless --start is given.\n");
        return 2;
    }
    for (i = 3; i < argc; i += 2) {
        char *end;
        double *dst = strcmp(argv[i], "--speed-of-sound") == 0 ? &c : strcmp(argv[i], "--start") == 0 ? &start : NULL;
        if (dst == NULL || i + 1 >= argc) {
            fprintf(stderr, "sonar-pvbin2csv: %s: unknown option or no value (see usage)\n", argv[i]);
            return 2;
        }
        *dst = strtod(argv[i + 1], &end);
        if (*end != '\0' || (dst == &c && !(c >= 1300.0 && c <= 1700.0)) || (dst == &start && !(start >= 0.0 && start < 1e11))) {
            fprintf(stderr, "sonar-pvbin2csv: %s: '%s' is not %s\n", argv[i], argv[i + 1],
                    dst == &c ? "a number in 1300..1700 m/s" : "epoch seconds in 0..1e11");
            return 2;
        }
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
        fprintf(stderr, "sonar-pvbin2csv: %s: cannot read\n", argv[1]);
        return 2;
    }
    fclose(in);
    if ((out = fopen(argv[2], "w")) == NULL) {
        perror(argv[2]);
        return 2;
    }
    r = pvbin_convert(buf, (size_t)size, argv[1], start, c, out, stderr, &st);
    if (fclose(out) != 0 && r == HOST_OK)
        r = HOST_ERR_IO;
    free(buf);
    if (r != HOST_OK)
        return r == HOST_ERR_IO ? 2 : 1;
    fprintf(stderr, "sonar-pvbin2csv: %s: %u records, %u beams written, %u skipped; frames %u, checksum errors %u, resyncs %u\n",
            argv[1], st.records, st.beams, st.skipped, st.parser.frames, st.parser.checksum_errors, st.parser.resyncs);
    return st.beams > 0 ? 0 : 1;
}
