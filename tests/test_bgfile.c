/* test_bgfile.c -- a site's background as an image: it round-trips bit for bit and learning goes on from it; every damage (magic, version, geometry, length, checksum, header, flags, places, mode) is refused by name with the model unchanged; places round-trip; a world-frame or empty model is not written. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "sonar/bgfile.h"
#include "sonar/cpframe.h"

#define N 300
static struct sonar_background bg, bg2;
static uint8_t img[SONAR_BGFILE_MAX];

/* A model learnt over a few sweeps of a pattern that differs by angle and range. */
static void learn(struct sonar_background *b, uint8_t mode)
{
    struct sonar_background_config c = {0, 2, 1, 8};
    uint8_t in[N], fg[N];
    int s, a, i;
    c.mode = mode;
    assert_int_equal(sonar_background_init(b, &c), SONAR_OK);
    for (s = 0; s < 4; s++)
        for (a = 0; a < SONAR_MAX_ANGLES; a += 2) {
            for (i = 0; i < N; i++)
                in[i] = (uint8_t)((a * 7 + i * 3 + s) & 0x7f);
            assert_int_equal(sonar_background_apply(b, (uint16_t)a, in, fg, N), SONAR_OK);
        }
}

static struct sonar_bgfile_meta meta(uint8_t mode)
{
    struct sonar_bgfile_meta m;
    memset(&m, 0, sizeof(m));
    m.n = N;
    m.mode = mode;
    m.median = 5;
    m.gain = 1;
    m.range_mm = 15000;
    m.sweeps = 4;
    return m;
}

static int32_t write_auto(void)
{
    struct sonar_bgfile_meta m = meta(SONAR_BACKGROUND_AUTO);
    learn(&bg, SONAR_BACKGROUND_AUTO);
    return sonar_bgfile_write(&bg, &m, img, sizeof(img));
}

static void test_round_trip(void **state)
{
    struct sonar_bgfile_meta m;
    uint8_t in[N], fg1[N], fg2[N];
    const char *why;
    int32_t len = write_auto();
    int i;
    (void)state;
    assert_int_equal(len, (int32_t)sonar_bgfile_size(N));
    assert_int_equal(sonar_bgfile_check(img, (size_t)len, &m, &why), SONAR_OK);
    assert_int_equal(m.n, N);
    assert_int_equal(m.range_mm, 15000);
    assert_int_equal(m.gain, 1);
    assert_int_equal(m.median, 5);
    assert_int_equal(m.sweeps, 4);
    learn(&bg2, SONAR_BACKGROUND_AUTO);
    assert_int_equal(sonar_background_init(&bg2, &(struct sonar_background_config){SONAR_BACKGROUND_AUTO, 2, 1, 8}), SONAR_OK);
    assert_int_equal(sonar_bgfile_load(&bg2, img, (size_t)len, &why), SONAR_OK);
    /* Learning goes on from the loaded model exactly as it would have from the one saved. */
    for (i = 0; i < N; i++)
        in[i] = (uint8_t)(i & 0xff);
    assert_int_equal(sonar_background_apply(&bg, 20, in, fg1, N), SONAR_OK);
    assert_int_equal(sonar_background_apply(&bg2, 20, in, fg2, N), SONAR_OK);
    assert_memory_equal(fg1, fg2, N);
    assert_memory_equal(bg.cell[20], bg2.cell[20], N);
    assert_memory_equal(bg.visits, bg2.visits, sizeof(bg.visits));
    assert_memory_equal(bg.across, bg2.across, N);
}

/* Each damage is refused with a reason naming it, and the model it would have loaded into is unchanged. */
static void refused(size_t len, const char *word)
{
    const char *why = NULL;
    struct sonar_bgfile_meta m;
    static struct sonar_background before;
    learn(&bg2, SONAR_BACKGROUND_AUTO);
    before = bg2;
    assert_true(sonar_bgfile_check(img, len, &m, &why) < 0);
    assert_non_null(strstr(why, word));
    why = NULL;
    assert_true(sonar_bgfile_load(&bg2, img, len, &why) < 0);
    assert_non_null(strstr(why, word));
    assert_memory_equal(&before, &bg2, sizeof(bg2));
}

/* Rewrites the CRC after a header edit, so that the header check itself is what refuses it. */
static void recrc(size_t len)
{
    uint32_t c = sonar_cpf_crc32(0, img, len - 4);
    img[len - 4] = (uint8_t)c;
    img[len - 3] = (uint8_t)(c >> 8);
    img[len - 2] = (uint8_t)(c >> 16);
    img[len - 1] = (uint8_t)(c >> 24);
}

static void test_damage_refused_by_name(void **state)
{
    size_t len = (size_t)write_auto();
    (void)state;
    refused(len - 1, "truncated");
    refused(20, "truncated");
    refused(0, "not a sonard background file");
    img[len] = 0;
    refused(len + 1, "longer");
    img[SONAR_BGFILE_HEADER + 1000] ^= 0x10; /* one bit in a row */
    refused(len, "checksum");
    len = (size_t)write_auto();
    img[0] = 'X';
    refused(len, "not a sonard background file");
    len = (size_t)write_auto();
    img[8] = 1; /* the version before */
    recrc(len);
    refused(len, "version");
    len = (size_t)write_auto();
    img[18] = 0x80; /* a flag this build does not know */
    recrc(len);
    refused(len, "flags");
    len = (size_t)write_auto();
    img[19] = SONAR_MAX_CLUSTERS + 1; /* more places than this build holds */
    recrc(len);
    refused(len, "places");
    len = (size_t)write_auto();
    img[10] = (uint8_t)((SONAR_MAX_ANGLES - 1) & 0xff); /* another build's angles */
    img[11] = (uint8_t)((SONAR_MAX_ANGLES - 1) >> 8);
    recrc(len);
    refused(len, "geometry");
    len = (size_t)write_auto();
    img[14] = SONAR_BACKGROUND_RANGE; /* no per-angle rows */
    recrc(len);
    refused(len, "header");
    len = (size_t)write_auto();
    img[17] = 7; /* no such gain */
    recrc(len);
    refused(len, "header");
}

/* A site's model is per angle: one learnt in auto mode loads into a per-angle background, never into a range one. */
static void test_mode(void **state)
{
    size_t len = (size_t)write_auto();
    const char *why = NULL;
    struct sonar_background_config c = {SONAR_BACKGROUND_RANGE, 8, 1, 8};
    (void)state;
    learn(&bg2, SONAR_BACKGROUND_PER_ANGLE);
    assert_int_equal(sonar_bgfile_load(&bg2, img, len, &why), SONAR_OK);
    assert_memory_equal(bg.cell[20], bg2.cell[20], N);
    assert_int_equal(sonar_background_init(&bg2, &c), SONAR_OK);
    assert_int_equal(sonar_bgfile_load(&bg2, img, len, &why), SONAR_ERR_STATE);
    assert_non_null(strstr(why, "mode"));
}

/* A place's kind, centroid and hull come back to the millimetre; a hull longer than SONAR_MAX_HULL is not read past. */
static void test_place_round_trip(void **state)
{
    struct sonar_detection d, back;
    uint8_t buf[SONAR_BGFILE_PLACE];
    uint8_t v;
    (void)state;
    memset(&d, 0, sizeof(d));
    d.kind = SONAR_DET_STRUCTURE;
    d.x_m = -12.3456f;
    d.y_m = 7.0f;
    d.hull_count = 5;
    for (v = 0; v < d.hull_count; v++) {
        d.hull_x[v] = -12.0f - 0.1f * v;
        d.hull_y[v] = 6.5f + 0.25f * v;
    }
    sonar_bgfile_put_place(buf, &d);
    sonar_bgfile_get_place(buf, &back);
    assert_int_equal(back.kind, SONAR_DET_STRUCTURE);
    assert_int_equal(back.hull_count, 5);
    assert_true(back.x_m > -12.3465f && back.x_m < -12.3445f);
    assert_true(back.y_m > 6.9995f && back.y_m < 7.0005f);
    for (v = 0; v < 5; v++) {
        assert_true(back.hull_x[v] > d.hull_x[v] - 0.001f && back.hull_x[v] < d.hull_x[v] + 0.001f);
        assert_true(back.hull_y[v] > d.hull_y[v] - 0.001f && back.hull_y[v] < d.hull_y[v] + 0.001f);
    }
    buf[1] = 200; /* more vertices than a place holds */
    sonar_bgfile_get_place(buf, &back);
    assert_int_equal(back.hull_count, SONAR_MAX_HULL);
}

/* The layout: levels, then the spread when flagged, then the places, then the CRC. */
static void test_layout(void **state)
{
    struct sonar_bgfile_layout a, b;
    (void)state;
    assert_int_equal(sonar_bgfile_layout(N, 0, 0, &a), SONAR_OK);
    assert_int_equal(sonar_bgfile_layout(N, SONAR_BGFILE_SPREAD, 3, &b), SONAR_OK);
    assert_int_equal(a.levels, b.levels);
    assert_int_equal(b.places - b.spread, (size_t)SONAR_MAX_ANGLES * N);
    assert_int_equal(b.crc - b.places, 3u * SONAR_BGFILE_PLACE);
    assert_int_equal(a.size, sonar_bgfile_size(N));
    assert_true(b.size <= SONAR_BGFILE_MAX);
    assert_int_equal(sonar_bgfile_layout(N, 0, SONAR_MAX_CLUSTERS + 1, &a), SONAR_ERR_ARG);
    assert_int_equal(sonar_bgfile_layout(0, 0, 0, &a), SONAR_ERR_ARG);
}

static void test_nothing_to_write(void **state)
{
    struct sonar_bgfile_meta m = meta(SONAR_BACKGROUND_AUTO);
    struct sonar_background_config c = {SONAR_BACKGROUND_AUTO, 2, 1, 8};
    (void)state;
    assert_int_equal(sonar_background_init(&bg, &c), SONAR_OK);
    assert_int_equal(sonar_bgfile_write(&bg, &m, img, sizeof(img)), SONAR_ERR_STATE); /* empty */
    learn(&bg, SONAR_BACKGROUND_AUTO);
    assert_int_equal(sonar_bgfile_write(&bg, &m, img, 100), SONAR_ERR_SPACE);
    m.n = N + 1;
    assert_int_equal(sonar_bgfile_write(&bg, &m, img, sizeof(img)), SONAR_ERR_ARG); /* not the model's */
    m = meta(SONAR_BACKGROUND_AUTO);
    bg.world = 1; /* a world-frame model is tied to where the vehicle was */
    assert_int_equal(sonar_bgfile_write(&bg, &m, img, sizeof(img)), SONAR_ERR_STATE);
    c.mode = SONAR_BACKGROUND_RANGE;
    assert_int_equal(sonar_background_init(&bg, &c), SONAR_OK);
    assert_int_equal(sonar_bgfile_size(0), 0);
    assert_int_equal(sonar_bgfile_size(SONAR_MAX_SAMPLES + 1), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_round_trip),
        cmocka_unit_test(test_damage_refused_by_name),
        cmocka_unit_test(test_mode),
        cmocka_unit_test(test_place_round_trip),
        cmocka_unit_test(test_layout),
        cmocka_unit_test(test_nothing_to_write),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
