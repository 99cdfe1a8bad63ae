/* sonar_sim.c -- writes a simulated scene in the study's CSV plus a ground-truth JSON (see scene.h). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "csv.h"
#include "scene.h"

int main(int argc, char **argv)
{
    const char *scene_name = "pool", *csv_path = NULL, *truth_path = NULL;
    struct scene s;
    struct scene_rng g = {0x9E3779B97F4A7C15ull};
    FILE *csv, *truth;
    uint8_t samples[1200];
    double t = 1728153122.0;
    int i, sweep, a, sweeps = -1;
    struct csv_meta meta;
    for (i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--scene") == 0 && i + 1 < argc)
            scene_name = argv[++i];
        else if (strcmp(argv[i], "--out") == 0 && i + 1 < argc)
            csv_path = argv[++i];
        else if (strcmp(argv[i], "--truth") == 0 && i + 1 < argc)
            truth_path = argv[++i];
        else if (strcmp(argv[i], "--sweeps") == 0 && i + 1 < argc)
            sweeps = atoi(argv[++i]);
        else if (strcmp(argv[i], "--seed") == 0 && i + 1 < argc)
            g.s ^= strtoull(argv[++i], NULL, 0) * 0xBF58476D1CE4E5B9ull;
        else {
            fprintf(stderr,
                    "usage: %s --scene pool|open --out FILE.csv --truth FILE.json [--sweeps N] [--seed S]\n"
                    "  pool: 20 x 12 m pool walls, two gate posts from sweep 2, a moving buoy from sweep 3 (7 sweeps)\n"
                    "  open: open water, a post, a moving buoy and a diver from sweep 0 (4 sweeps)\n"
                    "  12 m range, 1200 samples, 400 beams per sweep; timestamps follow the Ping360 timing model\n",
                    argv[0]);
            return 2;
        }
    }
    if (scene_make(&s, scene_name) != 0) {
        fprintf(stderr, "sonar_sim: --scene: '%s' is not pool or open\n", scene_name);
        return 2;
    }
    if (csv_path == NULL || truth_path == NULL) {
        fprintf(stderr, "sonar_sim: --out and --truth are required\n");
        return 2;
    }
    if (sweeps > 0)
        s.sweeps = sweeps;
    if ((csv = fopen(csv_path, "w")) == NULL || (truth = fopen(truth_path, "w")) == NULL) {
        perror("sonar_sim");
        return 2;
    }
    if (scene_write_truth(truth, &s, s.sweeps) != 0) {
        perror("sonar_sim: truth");
        return 1;
    }
    meta = csv_meta_none();
    meta.range_m = s.range_m;
    for (sweep = 0; sweep < s.sweeps; sweep++) {
        for (a = 0; a < 400; a += s.step) {
            double sec = floor(t);
            scene_beam(&s, sweep, a, s.range_m, s.samples, &g, samples);
            csv_write(csv, (int64_t)sec, (uint32_t)((t - sec) * 1e9), (uint16_t)a, samples, (uint16_t)s.samples, &meta);
            /* Device timing model (ping.md section 3): 19.4 ms + 6 ms per gradian + 2R/c. */
            t += 0.0194 + 0.006 * s.step + 2.0 * s.range_m / 1500.0;
        }
    }
    if (fclose(csv) != 0 || fclose(truth) != 0) {
        perror("sonar_sim");
        return 1;
    }
    return 0;
}
