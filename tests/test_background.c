/* test_background.c -- seeding, convergence to the median, clamping, contrast margin, range mode, resets, auto mode's across-beam start and kept objects, and the world grid of a moving sonar. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <math.h>
#include <string.h>

#include <cmocka.h>

#include "sonar/background.h"

static struct sonar_background bg;

static void test_config_validation(void **state)
{
    struct sonar_background_config c = {SONAR_BACKGROUND_PER_ANGLE, 2, 1, 0};
    (void)state;
    assert_int_equal(sonar_background_init(&bg, &c), SONAR_OK);
    c.warmup = 0;
    assert_int_equal(sonar_background_init(&bg, &c), SONAR_ERR_ARG);
    c.warmup = 2;
    c.step = 65;
    assert_int_equal(sonar_background_init(&bg, &c), SONAR_ERR_ARG);
    c.step = 1;
    c.mode = 4; /* 3 is auto */
    assert_int_equal(sonar_background_init(&bg, &c), SONAR_ERR_ARG);
    c.mode = 1;
    c.margin = 65;
    assert_int_equal(sonar_background_init(&bg, &c), SONAR_ERR_ARG);
}

/* The study's worked example (Fig. backgroundsubtraction): 60 - 55 = 5; below the background clamps to 0. */
static void test_subtract_and_clamp(void **state)
{
    struct sonar_background_config c = {SONAR_BACKGROUND_PER_ANGLE, 1, 1, 0};
    uint8_t b0[4] = {55, 55, 200, 0}, x[4] = {60, 50, 255, 0}, fg[4];
    (void)state;
    assert_int_equal(sonar_background_init(&bg, &c), SONAR_OK);
    assert_int_equal(sonar_background_apply(&bg, 10, b0, fg, 4), SONAR_OK);
    assert_memory_equal(fg, "\0\0\0\0", 4); /* seeding: no model yet, no foreground */
    assert_int_equal(sonar_background_apply(&bg, 10, x, fg, 4), SONAR_OK);
    assert_int_equal(fg[0], 5);
    assert_int_equal(fg[1], 0);
    assert_int_equal(fg[2], 55);
    assert_int_equal(fg[3], 0);
    /* the model moved one level toward the observation */
    assert_int_equal(bg.cell[10][0], 56);
    assert_int_equal(bg.cell[10][1], 54);
    /* another angle is a separate model */
    assert_int_equal(sonar_background_apply(&bg, 11, x, fg, 4), SONAR_OK);
    assert_memory_equal(fg, "\0\0\0\0", 4);
}

static void test_warmup_mean_then_median(void **state)
{
    struct sonar_background_config c = {SONAR_BACKGROUND_PER_ANGLE, 4, 1, 0};
    uint8_t x[1], fg[1];
    static const uint8_t seq[4] = {10, 20, 30, 41};
    int i;
    (void)state;
    assert_int_equal(sonar_background_init(&bg, &c), SONAR_OK);
    for (i = 0; i < 4; i++) {
        x[0] = seq[i];
        assert_int_equal(sonar_background_apply(&bg, 0, x, fg, 1), SONAR_OK);
        assert_int_equal(fg[0], 0);
    }
    assert_int_equal(bg.cell[0][0], 25); /* running mean of 10, 20, 30, 41, rounded */
    /* then a stream whose median is 100 with 30 % bright outliers: the tracker settles on ~100 */
    srand(3);
    for (i = 0; i < 2000; i++) {
        x[0] = (uint8_t)(rand() % 10 < 3 ? 250 : 90 + rand() % 21);
        assert_int_equal(sonar_background_apply(&bg, 0, x, fg, 1), SONAR_OK);
    }
    assert_in_range(bg.cell[0][0], 95, 108);
}

/* The vectorised seeding divides by a multiply-shift: it must equal the exact rounded mean update. */
static void test_seed_rounding_exhaustive(void **state)
{
    static uint8_t b[256], x[256], fg[256];
    unsigned v, c, i;
    (void)state;
    for (v = 2; v <= 64; v++) {
        struct sonar_background_config cfg = {SONAR_BACKGROUND_PER_ANGLE, 64, 1, 0};
        for (c = 0; c < 256; c++) {
            assert_int_equal(sonar_background_init(&bg, &cfg), SONAR_OK);
            memset(b, (int)c, sizeof(b));
            for (i = 0; i < 256; i++)
                x[i] = (uint8_t)i;
            /* visits 1..v-1 seed every cell with c, then visit v sees x */
            for (i = 1; i < v; i++)
                assert_int_equal(sonar_background_apply(&bg, 3, b, fg, 256), SONAR_OK);
            assert_int_equal(sonar_background_apply(&bg, 3, x, fg, 256), SONAR_OK);
            for (i = 0; i < 256; i++) {
                int d = (int)i - (int)c;
                int want = (int)c + (d >= 0 ? (d + (int)v / 2) / (int)v : -((-d + (int)v / 2) / (int)v));
                if (bg.cell[3][i] != want)
                    fail_msg("v=%u b=%u x=%u: got %u, want %d", v, c, i, bg.cell[3][i], want);
            }
        }
    }
}

/* Every (x, b) pair in steady state at several margins and steps against the rule written out cell by cell. */
static void test_track_exhaustive(void **state)
{
    static const uint8_t margins[] = {0, 1, 5, 8, 16, 24, 64}, steps[] = {1, 3, 64};
    uint8_t row[256], x[256], fg[256];
    unsigned mi, si, m, i;
    (void)state;
    for (i = 0; i < 256; i++)
        x[i] = (uint8_t)i;
    for (mi = 0; mi < sizeof(margins); mi++)
        for (si = 0; si < sizeof(steps); si++) {
            struct sonar_background_config c = {SONAR_BACKGROUND_PER_ANGLE, 1, steps[si], margins[mi]};
            assert_int_equal(sonar_background_init(&bg, &c), SONAR_OK);
            for (m = 0; m < 256; m++) {
                memset(row, (int)m, sizeof(row));
                assert_int_equal(sonar_background_apply(&bg, (uint16_t)m, row, fg, 256), SONAR_OK); /* seeds b = m */
                assert_int_equal(sonar_background_apply(&bg, (uint16_t)m, x, fg, 256), SONAR_OK);
                for (i = 0; i < 256; i++) {
                    unsigned up = i > m ? i - m : 0, dn = m > i ? m - i : 0, g = (m * margins[mi]) >> 4;
                    unsigned gate = g < 255 ? g : 255, want_fg = up > gate ? up - gate : 0;
                    unsigned want_b = m + (up < steps[si] ? up : steps[si]) - (dn < steps[si] ? dn : steps[si]);
                    if (fg[i] != want_fg || bg.cell[m * SONAR_MAX_ANGLES / 400][i] != want_b)
                        fail_msg("x %u b %u margin %u step %u: fg %u (want %u), b %u (want %u)", i, m, margins[mi],
                                 steps[si], fg[i], want_fg, bg.cell[m * SONAR_MAX_ANGLES / 400][i], want_b);
                }
            }
        }
}

/*
 * Auto mode past both warm-ups, at several margins and steps: the foreground is the smaller of the
 * two models' (fg against the larger model) and both models step towards x, for every x over a grid
 * of (row, across) levels, against the rule written out cell by cell.
 */
static unsigned fg_rule(unsigned x, unsigned m, unsigned margin)
{
    unsigned up = x > m ? x - m : 0, g = (m * margin) >> 4, gate = g < 255 ? g : 255;
    return up > gate ? up - gate : 0;
}

static unsigned step_rule(unsigned x, unsigned m, unsigned step)
{
    unsigned up = x > m ? x - m : 0, dn = m > x ? m - x : 0;
    return m + (up < step ? up : step) - (dn < step ? dn : step);
}

static void test_auto_pair_exhaustive(void **state)
{
    static const uint8_t margins[] = {0, 5, 8, 64}, steps[] = {1, 3};
    uint8_t x[256], fg[256];
    unsigned mi, si, m, c, i, row = 7u * SONAR_MAX_ANGLES / 400u;
    (void)state;
    for (i = 0; i < 256; i++)
        x[i] = (uint8_t)i;
    for (mi = 0; mi < sizeof(margins); mi++)
        for (si = 0; si < sizeof(steps); si++) {
            struct sonar_background_config cf = {SONAR_BACKGROUND_AUTO, 1, steps[si], margins[mi]};
            assert_int_equal(sonar_background_init(&bg, &cf), SONAR_OK);
            assert_int_equal(sonar_background_apply(&bg, 7, x, fg, 255), SONAR_OK); /* sets n */
            for (m = 0; m < 256; m += 15)
                for (c = 0; c < 256; c += 15) {
                    memset(bg.cell[row], (int)m, 255);
                    memset(bg.across, (int)c, 255);
                    bg.visits[row] = 1;
                    bg.across_visits = SONAR_BG_ACROSS_WARMUP;
                    assert_int_equal(sonar_background_apply(&bg, 7, x, fg, 255), SONAR_OK);
                    for (i = 0; i < 255; i++) {
                        unsigned fm = fg_rule(i, m, margins[mi]), fc = fg_rule(i, c, margins[mi]);
                        unsigned want = fm < fc ? fm : fc;
                        if (fg[i] != want || bg.cell[row][i] != step_rule(i, m, steps[si]) ||
                            bg.across[i] != step_rule(i, c, steps[si]))
                            fail_msg("x %u row %u across %u margin %u step %u: fg %u (want %u), row %u, across %u", i,
                                     m, c, margins[mi], steps[si], fg[i], want, bg.cell[row][i], bg.across[i]);
                    }
                }
        }
}

static void test_margin_scales_with_background(void **state)
{
    struct sonar_background_config c = {SONAR_BACKGROUND_PER_ANGLE, 1, 1, 8};
    uint8_t b0[2] = {100, 10}, x[2] = {160, 60}, fg[2];
    (void)state;
    assert_int_equal(sonar_background_init(&bg, &c), SONAR_OK);
    assert_int_equal(sonar_background_apply(&bg, 5, b0, fg, 2), SONAR_OK);
    assert_int_equal(sonar_background_apply(&bg, 5, x, fg, 2), SONAR_OK);
    assert_int_equal(fg[0], 60 - 50); /* margin 8/16 of 100 */
    assert_int_equal(fg[1], 50 - 5);  /* of 10 */
}

static void test_range_mode_shares_bins_across_angles(void **state)
{
    struct sonar_background_config c = {SONAR_BACKGROUND_RANGE, 1, 1, 0};
    uint8_t a[3] = {50, 50, 50}, b[3] = {50, 90, 50}, fg[3];
    (void)state;
    assert_int_equal(sonar_background_init(&bg, &c), SONAR_OK);
    assert_int_equal(sonar_background_apply(&bg, 0, a, fg, 3), SONAR_OK);
    assert_int_equal(sonar_background_apply(&bg, 200, b, fg, 3), SONAR_OK);
    assert_int_equal(fg[0], 0);
    assert_int_equal(fg[1], 40);
}

static void test_off_and_reset(void **state)
{
    struct sonar_background_config c = {SONAR_BACKGROUND_OFF, 1, 1, 0};
    uint8_t x[3] = {1, 2, 3}, fg[3];
    (void)state;
    assert_int_equal(sonar_background_init(&bg, &c), SONAR_OK);
    assert_int_equal(sonar_background_apply(&bg, 0, x, fg, 3), SONAR_OK);
    assert_memory_equal(fg, x, 3);
    c.mode = SONAR_BACKGROUND_PER_ANGLE;
    assert_int_equal(sonar_background_init(&bg, &c), SONAR_OK);
    assert_int_equal(sonar_background_apply(&bg, 0, x, fg, 3), SONAR_OK);
    assert_int_equal(sonar_background_apply(&bg, 0, x, fg, 3), SONAR_OK);
    assert_int_equal(bg.visits[0], 2);
    /* a new sample count invalidates every cell: the next beam seeds again */
    assert_int_equal(sonar_background_apply(&bg, 0, x, fg, 2), SONAR_OK);
    assert_int_equal(bg.visits[0], 1);
    assert_int_equal(bg.n, 2);
    assert_int_equal(sonar_background_apply(&bg, 400, x, fg, 2), SONAR_ERR_ARG);
    assert_int_equal(sonar_background_apply(&bg, 0, x, fg, SONAR_MAX_SAMPLES + 1), SONAR_ERR_ARG);
}

/* A 10 m beam of n samples from (north, east) along bearing: water 10, a wall 150 where the ray meets north = 8. */
static void wall_beam(double north, double east, double bearing, uint8_t *s, uint16_t n)
{
    double c = cos(bearing * 3.14159265358979323846 / 180.0);
    uint16_t i;
    (void)east;
    for (i = 0; i < n; i++)
        s[i] = 10;
    if (c > 0.1) {
        int k = (int)((8.0 - north) / c / 10.0 * n), j;
        for (j = k - 1; j <= k + 1; j++)
            if (j >= 0 && j < (int)n)
                s[j] = 150;
    }
}

static void test_world_grid(void **state)
{
    struct sonar_background_config c = {SONAR_BACKGROUND_PER_ANGLE, 2, 1, 8};
    struct sonar_bg_ray r = {0.0, 0.0, 0.0, 2.0, 10.0f, 0.5f};
    uint8_t s[200], fg[200];
    int k, i, sum;
    (void)state;
    assert_int_equal(sonar_background_init(&bg, &c), SONAR_OK);
    /* Bad rays change nothing. */
    r.north_m = NAN;
    assert_int_equal(sonar_background_apply_world(&bg, &r, s, fg, 200), SONAR_ERR_ARG);
    r.north_m = 2e6;
    assert_int_equal(sonar_background_apply_world(&bg, &r, s, fg, 200), SONAR_ERR_ARG);
    r.north_m = 0.0;
    r.range_m = 0.0f;
    assert_int_equal(sonar_background_apply_world(&bg, &r, s, fg, 200), SONAR_ERR_ARG);
    r.range_m = 10.0f;
    assert_int_equal(bg.world, 0);
    /* The sonar moves north 1 cm a beam and sweeps +-20 degrees: the wall at north = 8 comes nearer. */
    for (k = 0; k < 200; k++) {
        r.north_m = 0.01 * k;
        r.bearing_deg = -20.0 + (double)(k % 21) * 2.0;
        wall_beam(r.north_m, r.east_m, r.bearing_deg, s, 200);
        assert_int_equal(sonar_background_apply_world(&bg, &r, s, fg, 200), SONAR_OK);
        if (k == 0)
            for (i = 0; i < 200; i++)
                assert_int_equal(fg[i], 0); /* nothing seen yet */
    }
    assert_int_equal(bg.world, 1);
    assert_true(bg.cell_m > 0.06f && bg.cell_m < 0.07f); /* 3 x 10 m over 489 - 4 cells at 400 x 1200 */
    /* The wall, seen from where the sonar is now (6 m from it at 2 m north), is background. */
    r.north_m = 2.0;
    r.bearing_deg = 4.0;
    wall_beam(r.north_m, r.east_m, r.bearing_deg, s, 200);
    s[60] = s[61] = s[62] = 200; /* and something new at 3 m */
    assert_int_equal(sonar_background_apply_world(&bg, &r, s, fg, 200), SONAR_OK);
    for (sum = 0, i = 100; i < 140; i++)
        sum += fg[i];
    assert_int_equal(sum, 0);
    assert_true(fg[61] > 150);
    for (i = 0; i < 5; i++)
        assert_int_equal(fg[i], 0); /* inside near_m: never foreground */
    /* A jump beyond the window clears it: nothing there is known. */
    r.north_m = 500.0;
    assert_int_equal(sonar_background_apply_world(&bg, &r, s, fg, 200), SONAR_OK);
    for (sum = 0, i = 0; i < 200; i++)
        sum += fg[i];
    assert_int_equal(sum, 0);
    /* Back to the per-angle model: a fresh start, counted. */
    assert_int_equal(sonar_background_apply(&bg, 0, s, fg, 200), SONAR_OK);
    assert_int_equal(bg.world, 0);
    assert_int_equal(bg.reframes, 1);
    /* Other modes ignore the ray. */
    c.mode = SONAR_BACKGROUND_OFF;
    assert_int_equal(sonar_background_init(&bg, &c), SONAR_OK);
    assert_int_equal(sonar_background_apply_world(&bg, &r, s, fg, 200), SONAR_OK);
    assert_memory_equal(fg, s, 200);
}

/*
 * A sweep of 20 beams 10 gradians apart, 100 samples: water 10, a wall (150) at samples 70..74 on
 * every beam, and a person (120) at samples 30..39 on beams 4..6, there from the first ping.
 */
static void pool_beam(int beam, uint8_t *s)
{
    memset(s, 10, 100);
    memset(s + 70, 150, 5);
    if (beam >= 4 && beam <= 6)
        memset(s + 30, 120, 10);
}

static int sum_fg(const uint8_t *fg, int lo, int hi)
{
    int i, t = 0;
    for (i = lo; i < hi; i++)
        t += fg[i];
    return t;
}

static void test_auto_starts_from_the_across_beam_model(void **state)
{
    struct sonar_background_config c = {SONAR_BACKGROUND_AUTO, 2, 1, 8};
    uint8_t s[100], fg[100];
    int b;
    (void)state;
    assert_int_equal(sonar_background_init(&bg, &c), SONAR_OK);
    /*
     * First sweep: the rows are seeding, so each beam is compared with the across-beam model.
     * Its own first SONAR_BG_ACROSS_WARMUP beams seed that: nothing. Then the person, on 3 of
     * 20 beams, stands out against it; the wall, on every beam at one range, is in it.
     */
    for (b = 0; b < 20; b++) {
        pool_beam(b, s);
        assert_int_equal(sonar_background_apply(&bg, (uint16_t)(b * 10), s, fg, 100), SONAR_OK);
        if (b < SONAR_BG_ACROSS_WARMUP)
            assert_int_equal(sum_fg(fg, 0, 100), 0);
    }
    assert_int_equal(bg.across_visits, 20);
    /*
     * The person was in 3 of the across model's 8 seeding beams (a mean of 51 there, falling a level
     * a beam since): on the second sweep it still stands out until the rows are ready.
     */
    pool_beam(5, s);
    assert_int_equal(sonar_background_apply(&bg, 50, s, fg, 100), SONAR_OK);
    assert_true(sum_fg(fg, 30, 40) > 10 * 40);
    assert_int_equal(sum_fg(fg, 70, 75), 0);
    /* The per-angle model seeded meanwhile: with no track kept, the third visit learnt the person too. */
    assert_int_equal(sonar_background_apply(&bg, 50, s, fg, 100), SONAR_OK);
    assert_int_equal(sum_fg(fg, 0, 100), 0);
}

static void test_auto_keeps_tracked_objects_out_of_the_model(void **state)
{
    struct sonar_background_config c = {SONAR_BACKGROUND_AUTO, 2, 1, 8};
    struct sonar_bg_span keep = {28, 42};
    uint8_t s[100], fg[100], before[100];
    int sweep, b;
    (void)state;
    assert_int_equal(sonar_background_init(&bg, &c), SONAR_OK);
    for (sweep = 0; sweep < 40; sweep++)
        for (b = 0; b < 20; b++) {
            /* From the second sweep a tracker has the person: its span is kept on beams 4..6. */
            uint8_t kept = (uint8_t)(sweep >= 1 && b >= 4 && b <= 6);
            pool_beam(b, s);
            if (b == 5)
                memcpy(before, bg.cell[50], 100);
            assert_int_equal(sonar_background_apply_keep(&bg, (uint16_t)(b * 10), s, fg, 100, &keep, kept), SONAR_OK);
            if (b == 5 && sweep >= 2) {
                /* The person stays foreground sweep after sweep; the wall beside it does not. */
                assert_true(sum_fg(fg, 30, 40) > 10 * 80);
                assert_int_equal(sum_fg(fg, 70, 75), 0);
                /* Under the span the row holds the across-beam level it was given, and keeps it. */
                if (sweep >= 3)
                    assert_memory_equal(bg.cell[50] + 28, before + 28, 14);
            }
        }
    assert_true(bg.cell[50][35] < 60); /* the across-beam level, not the person's 120 */
    /* Released (the track ended), the person is learnt like anything else that stands still. */
    for (sweep = 0; sweep < 200; sweep++) {
        pool_beam(5, s);
        assert_int_equal(sonar_background_apply_keep(&bg, 50, s, fg, 100, NULL, 0), SONAR_OK);
    }
    assert_int_equal(sum_fg(fg, 30, 40), 0);
    /* Spans are checked: reversed ones are refused, long ones clipped. */
    keep.lo = 50;
    keep.hi = 40;
    assert_int_equal(sonar_background_apply_keep(&bg, 50, s, fg, 100, &keep, 1), SONAR_ERR_ARG);
    assert_int_equal(sonar_background_apply_keep(&bg, 50, s, fg, 100, NULL, 1), SONAR_ERR_ARG);
    keep.lo = 90;
    keep.hi = 5000;
    assert_int_equal(sonar_background_apply_keep(&bg, 50, s, fg, 100, &keep, 1), SONAR_OK);
}

/*
 * Structure learnt at once (sonar_background_apply_spans): a bright echo a seeded row did not learn
 * stands out; under a learn span the row rises to it first, so the look has no foreground there and
 * neither has the next, while the rest of the beam is as it was. learnt() after the warm-up only.
 */
static void test_learn_spans_raise_the_row(void **state)
{
    struct sonar_background_config c = {SONAR_BACKGROUND_PER_ANGLE, 2, 1, 8};
    struct sonar_bg_span learn = {10, 20}, bad = {5, 4};
    uint8_t x[64], fg[64], plain[64];
    int k;
    (void)state;
    assert_int_equal(sonar_background_init(&bg, &c), SONAR_OK);
    memset(x, 20, sizeof(x));
    for (k = 0; k < 2; k++) {
        assert_int_equal(sonar_background_learnt(&bg, 8), 0);
        assert_int_equal(sonar_background_apply(&bg, 8, x, fg, 64), SONAR_OK);
    }
    assert_int_equal(sonar_background_learnt(&bg, 8), 0); /* just seeded */
    assert_int_equal(sonar_background_apply(&bg, 8, x, fg, 64), SONAR_OK);
    assert_int_equal(sonar_background_learnt(&bg, 8), 1);
    assert_int_equal(sonar_background_learnt(&bg, 9), 0); /* another row */
    memset(x + 10, 150, 10);
    x[40] = 150; /* outside the span: stands out as before */
    memcpy(plain, x, sizeof(x));
    assert_int_equal(sonar_background_apply_spans(&bg, 8, x, fg, 64, NULL, 0, &learn, 1), SONAR_OK);
    assert_int_equal(sum_fg(fg, 10, 20), 0);
    assert_true(fg[40] > 0);
    for (k = 10; k < 20; k++)
        assert_true(bg.cell[8][k] >= 149);
    assert_int_equal(sonar_background_apply(&bg, 8, plain, fg, 64), SONAR_OK);
    assert_int_equal(sum_fg(fg, 10, 20), 0);
    assert_int_equal(sonar_background_apply_spans(&bg, 8, x, fg, 64, NULL, 0, &bad, 1), SONAR_ERR_ARG);
    assert_int_equal(sonar_background_apply_spans(&bg, 8, x, fg, 64, NULL, 0, NULL, 1), SONAR_ERR_ARG);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_config_validation),
        cmocka_unit_test(test_subtract_and_clamp),
        cmocka_unit_test(test_warmup_mean_then_median),
        cmocka_unit_test(test_seed_rounding_exhaustive),
        cmocka_unit_test(test_track_exhaustive),
        cmocka_unit_test(test_auto_pair_exhaustive),
        cmocka_unit_test(test_margin_scales_with_background),
        cmocka_unit_test(test_range_mode_shares_bins_across_angles),
        cmocka_unit_test(test_off_and_reset),
        cmocka_unit_test(test_auto_starts_from_the_across_beam_model),
        cmocka_unit_test(test_auto_keeps_tracked_objects_out_of_the_model),
        cmocka_unit_test(test_world_grid),
        cmocka_unit_test(test_learn_spans_raise_the_row),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
