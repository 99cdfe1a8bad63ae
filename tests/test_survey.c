/* test_survey.c -- the site survey: recorded sums to levels and spread (the survey replayed against itself has no foreground), each refusal by name, a surveyed cell judged by its own spread, a misfit found (another setting, a turn estimated, lines it does not hold, another site, something wider than a person before its structure; a person there is not) and taken back, a learnt model learnt on. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "sonar/survey.h"

#define N 400
#define RANGE 10.0f
#define FROM 100 /* the sector, gradians */
#define TO 180
#define STEP 2

static struct sonar_survey_rec rec;
static struct sonar_detector det;
static struct sonar_background bg;
static struct sonar_survey sv;
static struct sonar_survey_spread spread;
static struct sonar_detection places[SONAR_MAX_CLUSTERS];
static uint8_t img[SONAR_BGFILE_MAX];
static struct sonar_tracker tk;

/* xorshift: the same looks on every machine. */
static uint32_t rng = 12345u;
static uint32_t next(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 17;
    rng ^= rng << 5;
    return rng;
}

/* The site: a wall whose range grows with the angle (sample 150 + angle - FROM), a float bobbing at sample 100 of
   angle 140 (now there, now not), speckled water elsewhere with a spike now and then (a heavy tail: a look seldom
   seen is far out, which no standard deviation of a few looks covers). */
static void site(uint16_t angle, uint8_t *out)
{
    uint16_t i, wall = (uint16_t)(150 + angle - FROM);
    for (i = 0; i < N; i++)
        out[i] = (uint8_t)(next() % 40 == 0 ? 40 + next() % 60 : 8 + next() % 12);
    for (i = wall; i < wall + 4 && i < N; i++)
        out[i] = (uint8_t)(150 + next() % 40);
    if (angle == 140 && (next() & 1u))
        for (i = 100; i < 106; i++)
            out[i] = 120;
}

static void record_sweeps(int sweeps)
{
    uint8_t beam[N];
    int s;
    uint16_t a;
    for (s = 0; s < sweeps; s++) {
        for (a = FROM; a <= TO; a += STEP) {
            site(a, beam);
            assert_int_equal(sonar_survey_rec_beam(&rec, a, beam, N, RANGE, 1, 1000000LL * (s + 1)), SONAR_OK);
        }
        assert_int_equal(sonar_survey_rec_sweep(&rec, NULL, 0), SONAR_OK);
    }
}

static struct sonar_detector_config detector_config(void)
{
    struct sonar_detector_config c;
    memset(&c, 0, sizeof(c));
    c.threshold_mode = SONAR_DET_CFAR;
    c.max_clusters = 8;
    c.iterations = 10;
    c.join_beams = 2;
    c.min_points = 12;
    c.join_m = 0.15f;
    c.max_extent_m = 3.5f;
    c.cfar.cut = 1;
    c.cfar.guard = 1;
    c.cfar.train = 4;
    c.cfar.rank16 = 8;
    c.cfar.scale = 2.5f;
    c.cfar.floor = 16;
    return c;
}

/* A recorded survey of `sweeps` sweeps as an image; returns its length. */
static size_t survey_image_of(int sweeps)
{
    struct sonar_bgfile_meta m;
    struct sonar_detector_config dc = detector_config();
    uint8_t np = 0;
    int32_t len;
    sonar_survey_rec_init(&rec);
    record_sweeps(sweeps);
    memset(&m, 0, sizeof(m));
    m.mode = SONAR_BACKGROUND_AUTO;
    m.median = 5;
    len = sonar_survey_rec_image(&rec, &m, &dc, &det, places, &np, img, sizeof(img));
    assert_true(len > 0);
    return (size_t)len;
}

static size_t survey_image(void)
{
    return survey_image_of(SONAR_SURVEY_MIN_LOOKS);
}

static void use(size_t len)
{
    struct sonar_background_config c = {SONAR_BACKGROUND_AUTO, 2, 1, 8};
    const char *why = NULL;
    assert_int_equal(sonar_background_init(&bg, &c), SONAR_OK);
    sonar_survey_init(&sv, &spread, places);
    assert_int_equal(sonar_survey_use(&sv, &bg, img, len, &why), SONAR_OK);
    assert_int_equal(sv.state, SONAR_SURVEY_IN_USE);
}

/*
 * Levels are the looks' means, the header says what was recorded, and every look the survey saw is under its gate:
 * with 16 looks a spike can stand more than 3 standard deviations out (by Samuelson's bound, at most sqrt(15)), and
 * does in the water's heavy tail; the spread covers it.
 */
static void test_record_and_replay_against_itself(void **state)
{
    struct sonar_bgfile_meta m;
    uint8_t beam[N], fg[N];
    size_t len = survey_image_of(2 * SONAR_SURVEY_MIN_LOOKS);
    uint32_t save = rng;
    int s, stood = 0;
    uint16_t a, i;
    (void)state;
    assert_int_equal(sonar_bgfile_check(img, len, &m, NULL), SONAR_OK);
    assert_int_equal(m.n, N);
    assert_int_equal(m.gain, 1);
    assert_int_equal(m.range_mm, 10000);
    assert_int_equal(m.sweeps, 2 * SONAR_SURVEY_MIN_LOOKS);
    assert_true((m.flags & SONAR_BGFILE_SPREAD) && (m.flags & SONAR_BGFILE_SURVEY));
    assert_int_equal(m.utime, 1000000LL * 2 * SONAR_SURVEY_MIN_LOOKS);
    use(len);
    assert_true(sv.fixed && sv.has_spread);
    /* The water's level is its mean, about 13.5; the wall's about 169. */
    assert_in_range(bg.cell[120][50], 11, 16);
    assert_in_range(bg.cell[120][170], 150, 190);
    /* The same looks again: nothing stands out anywhere. */
    rng = 12345u;
    for (s = 0; s < 2 * SONAR_SURVEY_MIN_LOOKS; s++)
        for (a = FROM; a <= TO; a += STEP) {
            site(a, beam);
            assert_int_equal(sonar_survey_apply(&sv, &bg, a, beam, fg, N), 1);
            for (i = 0; i < N; i++)
                stood += fg[i] != 0;
        }
    assert_int_equal(stood, 0);
    rng = save;
}

/* A cell is judged by its own spread: the bobbing float's place takes its own echo, open water does not. */
static void test_spread_gate(void **state)
{
    uint8_t beam[N], fg[N];
    uint16_t i;
    (void)state;
    use(survey_image());
    assert_true(spread.s[140][102] > 20); /* the float comes and goes */
    assert_true(spread.s[120][102] < 10); /* water */
    for (i = 0; i < N; i++)
        beam[i] = bg.cell[140][i];
    for (i = 100; i < 106; i++)
        beam[i] = 120; /* the float, as the survey saw it */
    for (i = 300; i < 320; i++)
        beam[i] = 90; /* a body in the water behind it */
    assert_int_equal(sonar_survey_apply(&sv, &bg, 140, beam, fg, N), 1);
    for (i = 100; i < 106; i++)
        assert_int_equal(fg[i], 0);
    /* The body keeps its contrast above the level, not above the gate. */
    assert_int_equal(fg[310], 90 - bg.cell[140][310]);
    /* An angle the survey never looked at, within 2 gradians of one it did, is judged by that one; farther, not. */
    assert_int_equal(sonar_survey_covers(&sv, 101), 1);
    assert_int_equal(sonar_survey_covers(&sv, 190), 0);
    assert_int_equal(sonar_survey_apply(&sv, &bg, 190, beam, fg, N), 0);
}

/*
 * A fresh recording of 2 x SONAR_SURVEY_PATH sweeps with one confirmed track (ID 7, of the existence
 * given) going 0.5 m a look in a line; returns the last sonar_survey_rec_sweep's result.
 */
static int moving_track(float existence)
{
    uint8_t beam[N];
    int i, r = SONAR_OK;
    sonar_survey_rec_init(&rec);
    assert_int_equal(sonar_tracker_init(&tk, &(struct sonar_tracker_config){0.05f, 0.5f, 0.15f, 1.0f, 2.5f, 9.21f, 2, 3, 2,
                                                                          60.0f, 1, 1, 0, 1}),
                     SONAR_OK);
    tk.n = 1;
    tk.t[0].id = 7;
    tk.t[0].state = SONAR_TRACK_CONFIRMED;
    tk.t[0].det = 0;
    tk.t[0].existence = existence;
    tk.t[0].exists = existence >= SONAR_TRK_EXIST_ALARM;
    for (i = 0; i < SONAR_SURVEY_PATH; i++) {
        uint16_t a;
        for (a = FROM; a <= TO; a += STEP) {
            memset(beam, 10, sizeof(beam));
            assert_true(sonar_survey_rec_apply(&rec, a, beam, beam, N, 8) == (i >= SONAR_SURVEY_REC_LOOKS));
            assert_int_equal(sonar_survey_rec_beam(&rec, a, beam, N, RANGE, 1, i + 1), SONAR_OK);
        }
        tk.t[0].px = -3.0f + 0.5f * (float)i;
        tk.t[0].py = 2.0f;
        assert_int_equal(sonar_survey_rec_sweep(&rec, &tk, 0), SONAR_OK); /* its rows not yet judged: no path kept */
    }
    for (i = 0; i < SONAR_SURVEY_PATH; i++) {
        uint16_t a;
        for (a = FROM; a <= TO; a += STEP) {
            memset(beam, 10, sizeof(beam));
            assert_int_equal(sonar_survey_rec_apply(&rec, a, beam, beam, N, 8), 1);
            assert_int_equal(sonar_survey_rec_beam(&rec, a, beam, N, RANGE, 1, i + 10), SONAR_OK);
        }
        tk.t[0].px = -3.0f + 0.5f * (float)i;
        r = sonar_survey_rec_sweep(&rec, &tk, 0);
        if (i + 1 < SONAR_SURVEY_PATH)
            assert_int_equal(r, SONAR_OK);
    }
    return r;
}

/* Each refusal of a recording, by name. */
static void test_refusals(void **state)
{
    uint8_t beam[N];
    uint16_t angle;
    uint8_t looks;
    (void)state;
    memset(beam, 10, sizeof(beam));
    sonar_survey_rec_init(&rec);
    assert_int_equal(sonar_survey_rec_beam(&rec, 100, beam, N, RANGE, 1, 1), SONAR_OK);
    assert_int_equal(sonar_survey_rec_beam(&rec, 102, beam, N - 1, RANGE, 1, 2), SONAR_ERR_STATE);
    assert_int_equal(rec.why, SONAR_SURVEY_GEOMETRY);
    assert_string_equal(sonar_survey_why_str(rec.why), "geometry");
    sonar_survey_rec_init(&rec);
    assert_int_equal(sonar_survey_rec_beam(&rec, 100, beam, N, RANGE, 1, 1), SONAR_OK);
    assert_int_equal(sonar_survey_rec_beam(&rec, 102, beam, N, RANGE * 1.01f, 1, 2), SONAR_ERR_STATE);
    assert_int_equal(rec.why, SONAR_SURVEY_GEOMETRY);
    sonar_survey_rec_init(&rec);
    assert_int_equal(sonar_survey_rec_beam(&rec, 100, beam, N, RANGE, 1, 1), SONAR_OK);
    assert_int_equal(sonar_survey_rec_beam(&rec, 102, beam, N, RANGE, 2, 2), SONAR_ERR_STATE);
    assert_int_equal(rec.why, SONAR_SURVEY_GAIN);
    /* Refused stays refused, and writes nothing. */
    assert_int_equal(sonar_survey_rec_beam(&rec, 104, beam, N, RANGE, 1, 3), SONAR_ERR_STATE);
    sonar_survey_rec_init(&rec);
    assert_int_equal(sonar_survey_rec_sweep(&rec, NULL, 1), SONAR_ERR_STATE);
    assert_int_equal(rec.why, SONAR_SURVEY_WORLD);
    /* Too few looks, then an angle of the sector never looked at. */
    sonar_survey_rec_init(&rec);
    record_sweeps(SONAR_SURVEY_MIN_LOOKS - 1);
    assert_int_equal(sonar_survey_rec_check(&rec, FROM, TO, STEP, &angle, &looks), SONAR_ERR_STATE);
    assert_int_equal(rec.why, SONAR_SURVEY_ANGLES);
    assert_int_equal(looks, SONAR_SURVEY_MIN_LOOKS - 1);
    sonar_survey_rec_init(&rec);
    record_sweeps(SONAR_SURVEY_MIN_LOOKS);
    assert_int_equal(sonar_survey_rec_check(&rec, FROM, TO, STEP, &angle, &looks), SONAR_OK);
    assert_int_equal(sonar_survey_rec_check(&rec, FROM, TO + 20, STEP, &angle, &looks), SONAR_ERR_STATE);
    assert_int_equal(looks, 0);
    assert_in_range(angle, TO + 3, TO + 20);
    /* Something that moves through the site: a track going 0.5 m a look in a line, established. */
    assert_int_equal(moving_track(1.0f), SONAR_ERR_STATE);
    assert_int_equal(rec.why, SONAR_SURVEY_MOVED);
    assert_int_equal(rec.moved_id, 7);
    assert_true(rec.moved_m > 1.4f && rec.moved_m < 1.6f);
    /* The same path by a track whose existence is not established (clutter hops joined): no refusal. */
    assert_int_equal(moving_track(SONAR_TRK_EXIST_ALARM - 0.1f), SONAR_OK);
    assert_int_equal(rec.why, SONAR_SURVEY_OK);
}

/* A track that jitters about one place (a float, a wall's piece) is no mover. */
static void test_jitter_is_not_moving(void **state)
{
    static const float jx[] = {0.0f, 0.6f, -0.3f, 0.5f, -0.4f, 0.3f, 0.0f, 0.6f, -0.2f, 0.4f};
    uint8_t beam[N];
    unsigned i;
    (void)state;
    sonar_survey_rec_init(&rec);
    tk.n = 1;
    tk.t[0].id = 9;
    tk.t[0].state = SONAR_TRACK_CONFIRMED;
    tk.t[0].det = 0;
    for (i = 0; i < SONAR_SURVEY_REC_LOOKS + sizeof(jx) / sizeof(jx[0]); i++) {
        uint16_t a;
        for (a = FROM; a <= TO; a += STEP) {
            memset(beam, 10, sizeof(beam));
            assert_true(sonar_survey_rec_apply(&rec, a, beam, beam, N, 8) >= 0);
            assert_int_equal(sonar_survey_rec_beam(&rec, a, beam, N, RANGE, 1, i + 1), SONAR_OK);
        }
        tk.t[0].px = -3.0f + (i >= SONAR_SURVEY_REC_LOOKS ? jx[i - SONAR_SURVEY_REC_LOOKS] : 0.0f);
        tk.t[0].py = 2.0f;
        assert_int_equal(sonar_survey_rec_sweep(&rec, &tk, 0), SONAR_OK);
    }
    assert_int_equal(rec.why, SONAR_SURVEY_OK);
}

/* Another setting than the survey's gives it up at once; beams of its own again take it back. */
static void test_setting_misfit_and_refit(void **state)
{
    (void)state;
    use(survey_image());
    assert_int_equal(sonar_survey_fits_beam(&sv, N, RANGE, 1), SONAR_SURVEY_OK);
    assert_int_equal(sonar_survey_fits_beam(&sv, N, RANGE, -1), SONAR_SURVEY_OK); /* unknown gain: the geometry alone */
    assert_int_equal(sonar_survey_fits_beam(&sv, N, RANGE, 0), SONAR_SURVEY_GAIN);
    assert_int_equal(sonar_survey_fits_beam(&sv, N + 1, RANGE, 1), SONAR_SURVEY_GEOMETRY);
    assert_int_equal(sonar_survey_fits_beam(&sv, N, 12.0f, 1), SONAR_SURVEY_GEOMETRY);
    sonar_survey_lost(&sv, SONAR_SURVEY_GAIN);
    assert_int_equal(sv.state, SONAR_SURVEY_UNFIT);
    assert_int_equal(sv.unfits, 1);
    assert_int_equal(sonar_survey_fits_beam(&sv, N, RANGE, 0), SONAR_SURVEY_OK); /* unfit: nothing more to say */
    assert_int_equal(sv.refit, 0);
    assert_int_equal(sonar_survey_fits_beam(&sv, N, RANGE, 1), SONAR_SURVEY_OK);
    assert_int_equal(sv.refit, 1);
    assert_int_equal(sonar_survey_covers(&sv, 120), 0);
}

/*
 * Sweeps of the site turned by `turn` gradians (each head angle a looks where the survey's a + turn did), with
 * something (an echo of 230 over 4 samples from sample `at`) before the wall at angles from..to (none when from > to).
 */
static int sweeps_of(int turn, uint16_t from, uint16_t to, uint16_t at, int sweeps)
{
    uint8_t beam[N], fg[N];
    int s, gave_up = 0;
    uint16_t a, i;
    for (s = 0; s < sweeps && !gave_up; s++) {
        for (a = FROM + 20; a <= TO - 20; a += STEP) {
            site((uint16_t)(a + turn), beam);
            if (a >= from && a <= to)
                for (i = at; i < at + 4u; i++)
                    beam[i] = 230;
            sonar_survey_look(&sv, &bg, a, beam, N);
            (void)sonar_survey_apply(&sv, &bg, a, beam, fg, N);
        }
        gave_up = sonar_survey_sweep(&sv, 0);
    }
    return gave_up;
}

static int turned_sweeps(int turn, int sweeps)
{
    return sweeps_of(turn, 1, 0, 0, sweeps);
}

/* The site as surveyed fits; turned, it is given up within two sweeps with the turn estimated to the gradian. */
static void test_turned_mount(void **state)
{
    (void)state;
    use(survey_image());
    assert_int_equal(turned_sweeps(0, 6), 0);
    assert_int_equal(sv.state, SONAR_SURVEY_IN_USE);
    assert_int_equal(turned_sweeps(6, 2), 1);
    assert_int_equal(sv.state, SONAR_SURVEY_UNFIT);
    assert_int_equal(sv.why, SONAR_SURVEY_TURNED);
    assert_int_equal(sv.turn_grad, 6);
    /* Turned back: it fits again after SONAR_SURVEY_REFIT_SWEEPS sweeps. */
    use(survey_image());
    assert_int_equal(turned_sweeps(-10, 2), 1);
    assert_int_equal(sv.turn_grad, -10);
    assert_int_equal(turned_sweeps(0, SONAR_SURVEY_REFIT_SWEEPS - 1), 0);
    assert_int_equal(sv.refit, 0);
    assert_int_equal(turned_sweeps(0, 1), 0);
    assert_int_equal(sv.refit, 1);
}

/*
 * A person 1 m out hides most of the wall (14 of 21 angles, 0.4 m across): that says nothing of the survey's fit.
 * A barge's side 3.5 m out across all of it (2.2 m, wider than SONAR_SURVEY_PERSON_M) is the site changed.
 */
static void test_hidden_structure(void **state)
{
    (void)state;
    use(survey_image());
    assert_int_equal(sweeps_of(0, 120, 146, 40, 6), 0);
    assert_int_equal(sv.state, SONAR_SURVEY_IN_USE);
    assert_int_equal(sweeps_of(0, 120, 160, 140, 2), 1);
    assert_int_equal(sv.state, SONAR_SURVEY_UNFIT);
    assert_int_equal(sv.why, SONAR_SURVEY_CHANGED);
}

/* Lines wider than any object in 2 of 3 sweeps: structure the survey does not hold. */
static void test_new_structure(void **state)
{
    (void)state;
    use(survey_image());
    assert_int_equal(sonar_survey_sweep(&sv, 1), 0);
    assert_int_equal(sonar_survey_sweep(&sv, 0), 0);
    assert_int_equal(sonar_survey_sweep(&sv, 0), 0);
    assert_int_equal(sonar_survey_sweep(&sv, 1), 0); /* 1 of the last 3 */
    assert_int_equal(sonar_survey_sweep(&sv, 2), 1);
    assert_int_equal(sv.why, SONAR_SURVEY_NEW);
}

/* A learnt model (no survey flag) is learnt on: not judged against, its structure not checked, its setting checked. */
static void test_learnt_model(void **state)
{
    struct sonar_background_config c = {SONAR_BACKGROUND_AUTO, 2, 1, 8};
    struct sonar_bgfile_meta m;
    uint8_t beam[N], fg[N];
    const char *why = NULL;
    int32_t len;
    int s;
    uint16_t a;
    (void)state;
    assert_int_equal(sonar_background_init(&bg, &c), SONAR_OK);
    for (s = 0; s < 4; s++)
        for (a = FROM; a <= TO; a += STEP) {
            site(a, beam);
            assert_int_equal(sonar_background_apply(&bg, a, beam, fg, N), SONAR_OK);
        }
    memset(&m, 0, sizeof(m));
    m.n = N;
    m.mode = SONAR_BACKGROUND_AUTO;
    m.median = 5;
    m.gain = 1;
    m.range_mm = 10000;
    len = sonar_bgfile_write(&bg, &m, img, sizeof(img));
    assert_true(len > 0);
    sonar_survey_init(&sv, &spread, places);
    assert_int_equal(sonar_survey_use(&sv, &bg, img, (size_t)len, &why), SONAR_OK);
    assert_int_equal(sv.fixed, 0);
    assert_int_equal(sonar_survey_apply(&sv, &bg, 120, beam, fg, N), 0);
    assert_int_equal(sonar_survey_covers(&sv, 120), 0);
    assert_int_equal(turned_sweeps(20, 4), 0);
    assert_int_equal(sonar_survey_fits_beam(&sv, N, RANGE, 0), SONAR_SURVEY_GAIN);
}

/* Bad input: a damaged image is refused with the survey and background unchanged. */
static void test_damaged_image(void **state)
{
    size_t len = survey_image();
    const char *why = NULL;
    struct sonar_background_config c = {SONAR_BACKGROUND_AUTO, 2, 1, 8};
    (void)state;
    assert_int_equal(sonar_background_init(&bg, &c), SONAR_OK);
    sonar_survey_init(&sv, &spread, places);
    img[len / 2] ^= 1u;
    assert_true(sonar_survey_use(&sv, &bg, img, len, &why) < 0);
    assert_non_null(strstr(why, "checksum"));
    assert_int_equal(sv.state, SONAR_SURVEY_NONE);
    assert_int_equal(bg.n, 0);
    assert_true(sonar_survey_use(&sv, &bg, img, len - 10, &why) < 0);
    assert_non_null(strstr(why, "truncated"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_record_and_replay_against_itself),
        cmocka_unit_test(test_spread_gate),
        cmocka_unit_test(test_refusals),
        cmocka_unit_test(test_jitter_is_not_moving),
        cmocka_unit_test(test_setting_misfit_and_refit),
        cmocka_unit_test(test_turned_mount),
        cmocka_unit_test(test_hidden_structure),
        cmocka_unit_test(test_new_structure),
        cmocka_unit_test(test_learnt_model),
        cmocka_unit_test(test_damaged_image),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
