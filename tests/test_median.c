/* test_median.c -- selection networks proved by the 0-1 principle; 1-D and K x K medians against brute force. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "sonar/median.h"
#include "tables_internal.h"

/*
 * 0-1 principle: a comparator network selects the median of every input iff it does for every
 * 0/1 input. Bit-sliced: 64 inputs per word, min = AND, max = OR.
 */
static int network_selects_median(const uint8_t (*ce)[2], unsigned count, unsigned n)
{
    uint64_t v[25];
    uint64_t base;
    uint64_t total = (uint64_t)1 << n;
    for (base = 0; base < total; base += 64) {
        unsigned i, c, lanes = total - base < 64 ? (unsigned)(total - base) : 64;
        uint64_t want = 0;
        for (i = 0; i < n; i++) {
            uint64_t w = 0;
            unsigned l;
            for (l = 0; l < lanes; l++)
                w |= (((base + l) >> i) & 1u) << l;
            v[i] = w;
        }
        for (c = 0; c < count; c++) {
            uint64_t a = v[ce[c][0]], b = v[ce[c][1]];
            v[ce[c][0]] = a & b;
            v[ce[c][1]] = a | b;
        }
        for (i = 0; i < lanes; i++)
            if ((unsigned)__builtin_popcountll(base + i) > n / 2)
                want |= (uint64_t)1 << i;
        if ((v[n / 2] ^ want) & (lanes == 64 ? ~(uint64_t)0 : (((uint64_t)1 << lanes) - 1)))
            return 0;
    }
    return 1;
}

static void test_networks_zero_one(void **state)
{
    (void)state;
    assert_true(network_selects_median(sonar_net3, sizeof(sonar_net3) / 2, 3));
    assert_true(network_selects_median(sonar_net5, sizeof(sonar_net5) / 2, 5));
    assert_true(network_selects_median(sonar_net7, sizeof(sonar_net7) / 2, 7));
    assert_true(network_selects_median(sonar_net9, sizeof(sonar_net9) / 2, 9));
    /* 2^25 inputs, 64 at a time: about a second */
    assert_true(network_selects_median(sonar_net25, sizeof(sonar_net25) / 2, 25));
}

static void test_broken_network_is_caught(void **state)
{
    uint8_t bad[8][2];
    (void)state;
    memcpy(bad, sonar_net5, sizeof(bad));
    bad[3][0] = bad[3][1]; /* a self-comparison: a no-op that loses one exchange */
    assert_false(network_selects_median((const uint8_t (*)[2])bad, 8, 5));
}

static int cmp_u8(const void *a, const void *b)
{
    return (int)*(const uint8_t *)a - (int)*(const uint8_t *)b;
}

static uint8_t brute_1d(const uint8_t *in, int n, int j, int w)
{
    uint8_t win[9];
    int k, h = w / 2;
    for (k = 0; k < w; k++) {
        int i = j - h + k;
        win[k] = in[i < 0 ? 0 : i >= n ? n - 1 : i];
    }
    qsort(win, (size_t)w, 1, cmp_u8);
    return win[h];
}

static void test_1d_against_brute_force(void **state)
{
    static uint8_t in[1300], out[1300];
    static const uint16_t sizes[] = {1, 2, 3, 5, 63, 64, 65, 200, 1199, 1200};
    unsigned s, w, trial;
    (void)state;
    srand(7);
    for (trial = 0; trial < 4; trial++)
        for (s = 0; s < sizeof(sizes) / sizeof(sizes[0]); s++)
            for (w = 3; w <= SONAR_MAX_MEDIAN; w += 2) {
                int j, n = sizes[s];
                for (j = 0; j < n; j++)
                    in[j] = (uint8_t)(trial == 0 ? rand() : trial == 1 ? (rand() % 3) * 100 : j * 7 + rand() % 5);
                assert_int_equal(sonar_median_1d(in, out, (uint16_t)n, (uint8_t)w), SONAR_OK);
                for (j = 0; j < n; j++)
                    assert_int_equal(out[j], brute_1d(in, n, j, (int)w));
            }
}

static void test_1d_rejects_bad_windows(void **state)
{
    uint8_t in[8] = {0}, out[8];
    (void)state;
    assert_int_equal(sonar_median_1d(in, out, 8, 4), SONAR_ERR_ARG);
    assert_int_equal(sonar_median_1d(in, out, 8, 11), SONAR_ERR_ARG);
    assert_int_equal(sonar_median_1d(in, out, 0, 5), SONAR_ERR_ARG);
    assert_int_equal(sonar_median_1d(NULL, out, 8, 5), SONAR_ERR_ARG);
}

static uint8_t brute_2d(uint8_t m[][300], int rows, int cols, int r, int c, int k)
{
    uint8_t win[25];
    int a, b, n = 0, h = k / 2;
    for (a = -h; a <= h; a++)
        for (b = -h; b <= h; b++) {
            int rr = r + a, cc = c + b;
            rr = rr < 0 ? 0 : rr >= rows ? rows - 1 : rr;
            cc = cc < 0 ? 0 : cc >= cols ? cols - 1 : cc;
            win[n++] = m[rr][cc];
        }
    qsort(win, (size_t)n, 1, cmp_u8);
    return win[n / 2];
}

static void test_2d_streaming_against_brute_force(void **state)
{
    static uint8_t m[40][300];
    static struct sonar_median2d f;
    static const int rows_list[] = {1, 2, 3, 4, 7, 40};
    uint8_t out[300];
    unsigned k, t;
    (void)state;
    srand(11);
    for (k = 3; k <= 5; k += 2)
        for (t = 0; t < sizeof(rows_list) / sizeof(rows_list[0]); t++) {
            int rows = rows_list[t], cols = 37 + 50 * (int)t, r, c, emitted = 0, got;
            struct sonar_median_row meta, om;
            for (r = 0; r < rows; r++)
                for (c = 0; c < cols; c++)
                    m[r][c] = (uint8_t)(rand() % 4 == 0 ? 255 : rand() % 60);
            assert_int_equal(sonar_median2d_init(&f, (uint8_t)k), SONAR_OK);
            for (r = 0; r <= rows; r++) {
                if (r < rows) {
                    meta.utime = r * 1000;
                    meta.angle = (uint16_t)r;
                    meta.tag = 0;
                    got = sonar_median2d_push(&f, m[r], (uint16_t)cols, &meta, out, &om);
                    /* row i leaves when row i + K/2 arrives */
                    assert_int_equal(got, r >= (int)k / 2 ? 1 : 0);
                } else {
                    got = sonar_median2d_flush(&f, out, &om);
                }
                while (got == 1) {
                    assert_int_equal(om.angle, emitted);
                    assert_int_equal(om.utime, emitted * 1000);
                    for (c = 0; c < cols; c++)
                        assert_int_equal(out[c], brute_2d(m, rows, cols, emitted, c, (int)k));
                    emitted++;
                    got = r < rows ? 0 : sonar_median2d_flush(&f, out, &om);
                }
            }
            assert_int_equal(emitted, rows);
            /* the flush emptied the sweep: the next row starts a new one */
            assert_int_equal(f.pushed, 0);
        }
}

static void test_2d_rejects_mixed_lengths(void **state)
{
    static struct sonar_median2d f;
    uint8_t row[10] = {0}, out[10];
    struct sonar_median_row meta = {0, 0, 0}, om;
    (void)state;
    assert_int_equal(sonar_median2d_init(&f, 4), SONAR_ERR_ARG);
    assert_int_equal(sonar_median2d_init(&f, 3), SONAR_OK);
    assert_int_equal(sonar_median2d_push(&f, row, 10, &meta, out, &om), 0);
    assert_int_equal(sonar_median2d_push(&f, row, 9, &meta, out, &om), SONAR_ERR_ARG);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_networks_zero_one),
        cmocka_unit_test(test_broken_network_is_caught),
        cmocka_unit_test(test_1d_against_brute_force),
        cmocka_unit_test(test_1d_rejects_bad_windows),
        cmocka_unit_test(test_2d_streaming_against_brute_force),
        cmocka_unit_test(test_2d_rejects_mixed_lengths),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
