/* test_cfar.c -- the block OS-CFAR against a plain reference (every block, qsort, no lanes, no skipping), alone and with neighbouring beams, its edges, and what it is for: a faint extended echo passes, a spike and a one-beam speck do not, a neighbour in the training cells does not hide a target. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "sonar/cfar.h"

static uint8_t beam[SONAR_MAX_SAMPLES];

static struct sonar_cfar_config defaults(void)
{
    struct sonar_cfar_config c = {0, 1, 1, 4, 8, 2.5f, 16};
    return c;
}

static int cmp_int(const void *a, const void *b)
{
    return *(const int *)a - *(const int *)b;
}

/*
 * The definition in cfar.h, block by block: block means as sums of 8 (a short last block scaled
 * to 8, rounded down), the window's blocks that exist, the training blocks that exist, the
 * ceil(rank16 * m / 16)-th smallest of them, and the test mean > scale * noise + floor in integers
 * (scale in sixteenths, rounded).
 */
/* Block sums of a beam as the definition has them. */
static void ref_sums(const uint8_t *fg, int n, int *s)
{
    int b, i, nb = (n + 7) / 8;
    for (b = 0; b < nb; b++) {
        int len = n - 8 * b < 8 ? n - 8 * b : 8, t = 0;
        for (i = 0; i < len; i++)
            t += fg[8 * b + i];
        s[b] = t * 8 / len;
    }
}

/* The beam fg with neighbours prev and next (NULL: none), each n samples: their block sums added, everything over kb beams. */
static int reference3(const struct sonar_cfar_config *c, const uint8_t *prev, const uint8_t *fg, const uint8_t *next, int n,
                      uint8_t *on, uint8_t *thr)
{
    int s[SONAR_CFAR_MAX_BLOCKS], t3[SONAR_CFAR_MAX_BLOCKS], nb = (n + 7) / 8, b, passed = 0;
    long long kb = 1 + (prev != NULL) + (next != NULL);
    long long scale16 = (long long)(c->scale * 16.0f + 0.5f);
    ref_sums(fg, n, s);
    if (prev != NULL) {
        ref_sums(prev, n, t3);
        for (b = 0; b < nb; b++)
            s[b] += t3[b];
    }
    if (next != NULL) {
        ref_sums(next, n, t3);
        for (b = 0; b < nb; b++)
            s[b] += t3[b];
    }
    for (b = 0; b < nb; b++) {
        int train[2 * SONAR_CFAR_TRAIN_MAX], m = 0, j;
        long long sc = 0, kc = 0, noise = 0, lim;
        for (j = b - c->cut; j <= b + c->cut; j++)
            if (j >= 0 && j < nb) {
                sc += s[j];
                kc++;
            }
        for (j = b - c->cut - c->guard - c->train; j < b - c->cut - c->guard; j++)
            if (j >= 0 && j < nb)
                train[m++] = s[j];
        for (j = b + c->cut + c->guard + 1; j <= b + c->cut + c->guard + c->train; j++)
            if (j >= 0 && j < nb)
                train[m++] = s[j];
        if (m > 0) {
            int k = (c->rank16 * m + 15) / 16;
            qsort(train, (size_t)m, sizeof(int), cmp_int);
            noise = train[(k < 1 ? 1 : k) - 1];
        }
        lim = scale16 * noise * kc + 128LL * c->floor * kc * kb;
        on[b] = (uint8_t)(16 * sc > lim);
        passed += on[b];
        if (thr != NULL)
            thr[b] = (uint8_t)(lim / (128 * kc * kb) > 255 ? 255 : lim / (128 * kc * kb));
    }
    return passed;
}

static int reference(const struct sonar_cfar_config *c, const uint8_t *fg, int n, uint8_t *on, uint8_t *thr)
{
    return reference3(c, NULL, fg, NULL, n, on, thr);
}

/* xorshift: the same beams everywhere. */
static uint32_t rng = 2463534242u;
static uint32_t next(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 17;
    rng ^= rng << 5;
    return rng;
}

static void test_matches_reference(void **state)
{
    uint8_t on[SONAR_CFAR_MAX_BLOCKS], on_ref[SONAR_CFAR_MAX_BLOCKS], thr[SONAR_CFAR_MAX_BLOCKS],
        thr_ref[SONAR_CFAR_MAX_BLOCKS];
    int trial;
    (void)state;
    for (trial = 0; trial < 600; trial++) {
        struct sonar_cfar_config c;
        int n = trial < 20 ? trial + 1 : (int)(next() % SONAR_MAX_SAMPLES) + 1, i, kind = (int)(next() % 4), got;
        c.across = 0;
        c.cut = (uint8_t)(next() % (SONAR_CFAR_CUT_MAX + 1));
        c.guard = (uint8_t)(next() % (SONAR_CFAR_GUARD_MAX + 1));
        c.train = (uint8_t)(next() % SONAR_CFAR_TRAIN_MAX + 1);
        c.rank16 = (uint8_t)(next() % 16 + 1);
        c.scale = 0.5f + (float)(next() % 250) / 16.0f;
        c.floor = (uint8_t)(next() % 40);
        if (trial % 3 == 0)
            c = defaults();
        /* Silent water with speckle, dense speckle, echoes on speckle, and saturation. */
        for (i = 0; i < n; i++) {
            uint32_t r = next();
            beam[i] = (uint8_t)(kind == 0   ? (r % 10 == 0 ? r % 40 : 0)
                                : kind == 1 ? r % 64
                                : kind == 2 ? ((i / 40) % 5 == 2 ? 30 + r % 90 : r % 12)
                                            : (r % 7 == 0 ? 255 : r % 200));
        }
        got = sonar_cfar_blocks(&c, beam, (uint16_t)n, on, thr);
        assert_int_equal(got, reference(&c, beam, n, on_ref, thr_ref));
        assert_memory_equal(on, on_ref, (size_t)(n + 7) / 8);
        assert_memory_equal(thr, thr_ref, (size_t)(n + 7) / 8);
        /* Without thr the blocks that cannot pass are skipped: the same answer. */
        assert_int_equal(sonar_cfar_blocks(&c, beam, (uint16_t)n, on, NULL), got);
        assert_memory_equal(on, on_ref, (size_t)(n + 7) / 8);
    }
}

static uint8_t beam_prev[SONAR_MAX_SAMPLES], beam_next[SONAR_MAX_SAMPLES];

/* The block sums against a plain sum over every length: full-scale beams (2040 a block), random ones, a short last block. */
static void test_sums_match_plain(void **state)
{
    uint16_t sums[SONAR_CFAR_MAX_BLOCKS];
    int n, i, b;
    (void)state;
    for (n = 1; n <= SONAR_MAX_SAMPLES; n++) {
        for (i = 0; i < n; i++)
            beam[i] = (uint8_t)(n % 3 == 0 ? 255u : next() % 256u);
        assert_int_equal(sonar_cfar_sums(beam, (uint16_t)n, sums), (n + 7) / 8);
        for (b = 0; b < (n + 7) / 8; b++) {
            int t = 0, len = n - 8 * b < 8 ? n - 8 * b : 8;
            for (i = 0; i < len; i++)
                t += beam[8 * b + i];
            assert_int_equal(sums[b], t * 8 / len);
        }
    }
}

/* The same, with neighbouring beams in the window: every combination of neighbours present. */
static void test_across_matches_reference(void **state)
{
    uint8_t on[SONAR_CFAR_MAX_BLOCKS], on_ref[SONAR_CFAR_MAX_BLOCKS], thr[SONAR_CFAR_MAX_BLOCKS],
        thr_ref[SONAR_CFAR_MAX_BLOCKS];
    uint16_t sp[SONAR_CFAR_MAX_BLOCKS], sn[SONAR_CFAR_MAX_BLOCKS];
    int trial;
    (void)state;
    for (trial = 0; trial < 300; trial++) {
        struct sonar_cfar_config c = defaults();
        int n = (int)(next() % SONAR_MAX_SAMPLES) + 1, i, got, hp = trial & 1, hn = (trial >> 1) & 1;
        c.across = 1;
        c.scale = 0.5f + (float)(next() % 100) / 16.0f;
        c.floor = (uint8_t)(next() % 40);
        for (i = 0; i < n; i++) {
            uint32_t r = next();
            beam[i] = (uint8_t)(r % 3 == 0 ? r % 120 : 0);
            beam_prev[i] = (uint8_t)((r >> 8) % 4 == 0 ? (r >> 8) % 200 : 0);
            beam_next[i] = (uint8_t)((r >> 16) % 5 == 0 ? 255 : (r >> 16) % 30);
        }
        assert_int_equal(sonar_cfar_sums(beam_prev, (uint16_t)n, sp), (n + 7) / 8);
        assert_int_equal(sonar_cfar_sums(beam_next, (uint16_t)n, sn), (n + 7) / 8);
        got = sonar_cfar_blocks_across(&c, hp ? sp : NULL, beam, hn ? sn : NULL, (uint16_t)n, on, thr);
        assert_int_equal(got, reference3(&c, hp ? beam_prev : NULL, beam, hn ? beam_next : NULL, n, on_ref, thr_ref));
        assert_memory_equal(on, on_ref, (size_t)(n + 7) / 8);
        assert_memory_equal(thr, thr_ref, (size_t)(n + 7) / 8);
    }
    assert_int_equal(sonar_cfar_sums(NULL, 10, sp), SONAR_ERR_ARG);
    assert_int_equal(sonar_cfar_sums(beam, 0, sp), SONAR_ERR_ARG);
}

/*
 * What the window across beams is for: a speck of level 60 over two blocks of one beam passes on
 * its own (60 > 16), and with its two empty neighbours in the window it does not (60 / 3 = 20 < 26,
 * the floor over three beams being 16 and the speckle 4.5 a sample); an echo of level 40 in all
 * three beams keeps its level.
 */
static void test_across_dilutes_a_speck(void **state)
{
    struct sonar_cfar_config c = defaults();
    uint8_t on[SONAR_CFAR_MAX_BLOCKS];
    uint16_t sp[SONAR_CFAR_MAX_BLOCKS], sn[SONAR_CFAR_MAX_BLOCKS];
    int i;
    (void)state;
    c.across = 1;
    for (i = 0; i < 800; i++) {
        beam[i] = (uint8_t)(next() % 10);
        beam_prev[i] = (uint8_t)(next() % 10);
        beam_next[i] = (uint8_t)(next() % 10);
    }
    memset(beam + 400, 60, 16);
    assert_int_equal(sonar_cfar_sums(beam_prev, 800, sp), 100);
    assert_int_equal(sonar_cfar_sums(beam_next, 800, sn), 100);
    assert_true(sonar_cfar_blocks(&c, beam, 800, on, NULL) > 0);
    assert_int_equal(on[50], 1);
    assert_int_equal(sonar_cfar_blocks_across(&c, sp, beam, sn, 800, on, NULL), 0);
    memset(beam_prev + 400, 40, 32);
    memset(beam + 400, 40, 32);
    memset(beam_next + 400, 40, 32);
    assert_int_equal(sonar_cfar_sums(beam_prev, 800, sp), 100);
    assert_int_equal(sonar_cfar_sums(beam_next, 800, sn), 100);
    assert_true(sonar_cfar_blocks_across(&c, sp, beam, sn, 800, on, NULL) > 0);
    assert_int_equal(on[51], 1);
    assert_int_equal(on[52], 1);
}

static void test_edges(void **state)
{
    struct sonar_cfar_config c = defaults();
    uint8_t on[SONAR_CFAR_MAX_BLOCKS], thr[SONAR_CFAR_MAX_BLOCKS];
    int b;
    (void)state;
    /* All zeros: nothing; all 255: nothing either (the noise is the beam itself); no NaN, no overflow. */
    memset(beam, 0, sizeof(beam));
    assert_int_equal(sonar_cfar_blocks(&c, beam, SONAR_MAX_SAMPLES, on, thr), 0);
    for (b = 0; b < SONAR_CFAR_MAX_BLOCKS; b++)
        assert_int_equal(thr[b], c.floor);
    memset(beam, 255, sizeof(beam));
    assert_int_equal(sonar_cfar_blocks(&c, beam, SONAR_MAX_SAMPLES, on, thr), 0);
    assert_int_equal(thr[SONAR_CFAR_MAX_BLOCKS / 2], 255);
    /* A beam shorter than the window and its training cells: only the floor applies. */
    memset(beam, 40, 12);
    assert_int_equal(sonar_cfar_blocks(&c, beam, 12, on, thr), 2);
    assert_int_equal(thr[0], c.floor);
    assert_int_equal(thr[1], c.floor);
    assert_int_equal(sonar_cfar_blocks(&c, beam, 1, on, NULL), 1);
    /* Bad arguments write nothing. */
    on[0] = 7;
    assert_int_equal(sonar_cfar_blocks(&c, beam, 0, on, NULL), SONAR_ERR_ARG);
    assert_int_equal(sonar_cfar_blocks(&c, beam, SONAR_MAX_SAMPLES + 1, on, NULL), SONAR_ERR_ARG);
    assert_int_equal(sonar_cfar_blocks(NULL, beam, 10, on, NULL), SONAR_ERR_ARG);
    assert_int_equal(sonar_cfar_blocks(&c, NULL, 10, on, NULL), SONAR_ERR_ARG);
    assert_int_equal(sonar_cfar_blocks(&c, beam, 10, NULL, NULL), SONAR_ERR_ARG);
    c.scale = 0.0f;
    assert_int_equal(sonar_cfar_blocks(&c, beam, 10, on, NULL), SONAR_ERR_ARG);
    assert_int_equal(on[0], 7);
}

static void test_config_check(void **state)
{
    struct sonar_cfar_config c = defaults();
    (void)state;
    assert_null(sonar_cfar_config_check(&c));
    c.cut = SONAR_CFAR_CUT_MAX + 1;
    assert_string_equal(sonar_cfar_config_check(&c), "cfar.cut: 0..4 blocks");
    c = defaults();
    c.guard = SONAR_CFAR_GUARD_MAX + 1;
    assert_string_equal(sonar_cfar_config_check(&c), "cfar.guard: 0..8 blocks");
    c = defaults();
    c.train = 0;
    assert_string_equal(sonar_cfar_config_check(&c), "cfar.train: 1..8 blocks");
    c = defaults();
    c.rank16 = 17;
    assert_string_equal(sonar_cfar_config_check(&c), "cfar.rank16: 1..16 sixteenths");
    c = defaults();
    c.scale = 16.5f;
    assert_string_equal(sonar_cfar_config_check(&c), "cfar.scale: 0.5..16");
    c = defaults();
    c.floor = 255;
    assert_string_equal(sonar_cfar_config_check(&c), "cfar.floor: 0..254 grey levels");
    c = defaults();
    c.across = 2;
    assert_string_equal(sonar_cfar_config_check(&c), "cfar.across: 0 or 1 beam each side");
}

/* Speckle at 0..9 with a 32-sample echo of level at samples 400..431 (blocks 50..53), optionally another of level2 at 448..471. */
static void scene(uint8_t level, uint8_t level2)
{
    int i;
    for (i = 0; i < 800; i++)
        beam[i] = (uint8_t)(next() % 10);
    for (i = 400; i < 432 && level > 0; i++)
        beam[i] = level;
    for (i = 448; i < 472 && level2 > 0; i++)
        beam[i] = level2;
}

static void test_what_it_is_for(void **state)
{
    struct sonar_cfar_config c = defaults();
    uint8_t on[SONAR_CFAR_MAX_BLOCKS];
    (void)state;
    /*
     * An extended echo of level 32 over speckle of mean 4.5: the threshold on a window's mean is
     * 2.5 * 4.5 + 16 = 27.3, so the windows inside it pass, the ones half on it (32 + 32 + 4.5) / 3
     * do not, nor does the speckle.
     */
    scene(32, 0);
    assert_int_equal(sonar_cfar_blocks(&c, beam, 800, on, NULL), 2);
    assert_int_equal(on[51], 1);
    assert_int_equal(on[52], 1);
    assert_int_equal(on[50], 0);
    assert_int_equal(on[10], 0);
    /* A one-sample spike of 200 is an eighth of its window: it does not. */
    scene(0, 0);
    beam[300] = 200;
    assert_int_equal(sonar_cfar_blocks(&c, beam, 800, on, NULL), 0);
    /* A strong echo behind it fills two of block 51's eight training blocks: the median ignores it ... */
    scene(32, 250);
    assert_int_equal(sonar_cfar_blocks(&c, beam, 800, on, NULL) > 0, 1);
    assert_int_equal(on[51], 1);
    /* ... the largest of them (rank 16/16, a greatest-of CFAR) would not. */
    c.rank16 = 16;
    assert_int_equal(sonar_cfar_blocks(&c, beam, 800, on, NULL) > 0, 1);
    assert_int_equal(on[51], 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_matches_reference),
        cmocka_unit_test(test_sums_match_plain),
        cmocka_unit_test(test_across_matches_reference),
        cmocka_unit_test(test_across_dilutes_a_speck),
        cmocka_unit_test(test_edges),
        cmocka_unit_test(test_config_check),
        cmocka_unit_test(test_what_it_is_for),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
