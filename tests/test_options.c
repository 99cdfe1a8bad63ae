/* test_options.c -- sonard's option table: every numeric row accepts its ends and names itself past them; files, order, bad files, whole-config checks, --help and the docs from the same rows. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "options.h"

static struct sonard_options o;
static char err[512];

static int parse(int argc, const char **argv)
{
    return options_parse(argc, (char **)(uintptr_t)argv, &o, err, sizeof(err));
}

static void test_defaults(void **state)
{
    const char *argv[] = {"sonard", "--replay", "x.csv"};
    (void)state;
    assert_int_equal(parse(3, argv), 0);
    assert_string_equal(o.replay, "x.csv");
    assert_int_equal(o.pipeline.median, 5);
    assert_int_equal(o.pipeline.background.warmup, 2);
    assert_int_equal(o.pipeline.detector.join_beams, 2);
    assert_true(o.range_m < 0.0);
    assert_string_equal(o.channel_prefix, "");
    assert_int_equal(o.stage, SONAR_STAGE_FOREGROUND);
}

/* --background range brings the study's rules (sonard's before the CFAR) unless they are given. */
static void test_range_background_brings_the_study_rules(void **state)
{
    const char *def[] = {"sonard", "--replay", "x.csv"};
    const char *rng[] = {"sonard", "--replay", "x.csv", "--background", "range"};
    const char *mixed[] = {"sonard", "--replay", "x.csv", "--background", "range", "--threshold-mode", "cfar",
                           "--min-points", "30"};
    (void)state;
    assert_int_equal(parse(3, def), 0);
    assert_int_equal(o.pipeline.detector.threshold_mode, SONAR_DET_CFAR);
    assert_int_equal(o.pipeline.detector.min_points, 12);
    assert_true(o.pipeline.detector.max_extent_m > 3.4f && o.pipeline.detector.max_aspect > 1.9f);
    assert_int_equal(parse(5, rng), 0);
    assert_int_equal(o.pipeline.detector.threshold_mode, SONAR_DET_GLOBAL);
    assert_int_equal(o.pipeline.detector.min_points, 20);
    assert_true(o.pipeline.detector.max_extent_m == 0.0f && o.pipeline.detector.max_aspect == 0.0f);
    assert_int_equal(parse(9, mixed), 0);
    assert_int_equal(o.pipeline.detector.threshold_mode, SONAR_DET_CFAR);
    assert_int_equal(o.pipeline.detector.min_points, 30);
    assert_true(o.pipeline.detector.max_extent_m == 0.0f);
}

/* The value of numeric row r in o. */
static double field(const struct opt_spec *r)
{
    const char *at = (const char *)&o + r->offset;
    switch (r->type) {
    case OPT_LONG: return (double)*(const long *)(const void *)at;
    case OPT_U8: return (double)*(const uint8_t *)(const void *)at;
    case OPT_U16: return (double)*(const uint16_t *)(const void *)at;
    case OPT_F32: return (double)*(const float *)(const void *)at;
    default: return *(const double *)(const void *)at;
    }
}

/* Every numeric row whose documented default is a number: that is what sonard uses with no options. */
static void test_documented_defaults_are_the_defaults(void **state)
{
    const struct opt_schema *s = options_schema();
    const char *argv[] = {"sonard", "--replay", "x.csv"};
    size_t i;
    int rows = 0;
    (void)state;
    assert_int_equal(parse(3, argv), 0);
    for (i = 0; i < s->count; i++) {
        const struct opt_spec *r = &s->spec[i];
        char *end;
        double want;
        if (r->type < OPT_LONG || r->type > OPT_F64 || r->def == NULL)
            continue;
        want = strtod(r->def, &end);
        if (end == r->def || (*end != '\0' && *end != ';' && *end != ' '))
            continue; /* "auto", "2 per-angle, 8 range": not one number */
        rows++;
        if (!(fabs(field(r) - want) <= 1e-6 * (fabs(want) + 1.0)))
            fail_msg("--%s: documented default %s, but sonard uses %g", r->name, r->def, field(r));
    }
    assert_true(rows > 30);
}

static void fmt(char *buf, size_t n, double v, int whole)
{
    if (whole)
        snprintf(buf, n, "%.0f", v);
    else
        snprintf(buf, n, "%.17g", v);
}

/* Every numeric row of the table: lo and hi parse and land in the field; lo - 1 and hi + 1 are named. */
static void test_every_numeric_row_bounds(void **state)
{
    const struct opt_schema *s = options_schema();
    size_t i;
    int rows = 0;
    (void)state;
    for (i = 0; i < s->count; i++) {
        const struct opt_spec *r = &s->spec[i];
        char opt[80], v[64];
        /* --track-confirm may not exceed --track-window: give both room first; the row under test comes last */
        const char *argv[9] = {"sonard", "--replay", "x.csv", "--track-confirm", "1", "--track-window", "8", opt, v};
        int whole = r->type == OPT_LONG || r->type == OPT_U8 || r->type == OPT_U16, k;
        double ends[2];
        if (r->type < OPT_LONG || r->type > OPT_F64)
            continue;
        rows++;
        ends[0] = r->lo;
        ends[1] = r->hi;
        snprintf(opt, sizeof(opt), "--%s", r->name);
        for (k = 0; k < 2; k++) {
            char *field;
            double got;
            fmt(v, sizeof(v), ends[k], whole);
            /* --step 50 is valid only when stepping; --max-aspect's low end 0 means off */
            assert_int_equal(parse(9, argv), 0);
            field = (char *)&o + r->offset;
            got = r->type == OPT_LONG ? (double)*(long *)(void *)field
                : r->type == OPT_U8 ? (double)*(uint8_t *)field
                : r->type == OPT_U16 ? (double)*(uint16_t *)(void *)field
                : r->type == OPT_F32 ? (double)*(float *)(void *)field : *(double *)(void *)field;
            /* a float field holds the nearest float to the end, not the double itself */
            if (r->type == OPT_F32 ? (float)got != (float)ends[k] : got != ends[k])
                fail_msg("%s %s stored %g", opt, v, got);
            fmt(v, sizeof(v), k == 0 ? ends[0] - 1.0 : ends[1] + 1.0, whole);
            if (parse(9, argv) >= 0)
                fail_msg("%s %s accepted", opt, v);
            if (strstr(err, opt) == NULL || strstr(err, r->unit) == NULL)
                fail_msg("%s %s: message '%s' names neither option nor unit", opt, v, err);
        }
        snprintf(v, sizeof(v), "12abc");
        assert_true(parse(9, argv) < 0);
    }
    assert_true(rows >= 25);
}

static void test_names_unique_and_help_lists_all(void **state)
{
    const struct opt_schema *s = options_schema();
    char buf[32768];
    FILE *f = fmemopen(buf, sizeof(buf), "w");
    size_t i, j;
    (void)state;
    opt_usage(s, f);
    fclose(f);
    for (i = 0; i < s->count; i++) {
        char want[80];
        if (s->spec[i].type == OPT_SECTION)
            continue;
        for (j = i + 1; j < s->count; j++)
            if (s->spec[j].type != OPT_SECTION)
                assert_string_not_equal(s->spec[i].name, s->spec[j].name);
        snprintf(want, sizeof(want), "--%s", s->spec[i].name);
        if (strstr(buf, want) == NULL)
            fail_msg("--help lacks %s", want);
    }
    assert_non_null(strstr(buf, "--join-beams N"));
    assert_non_null(strstr(buf, "1..8 beams (default 2) [SIGHUP]"));
}

static char tmpdir[64];

static const char *write_file(const char *name, const char *text)
{
    static char path[8][128];
    static int k;
    char *p = path[k++ % 8];
    FILE *f;
    snprintf(p, 128, "%s/%s", tmpdir, name);
    f = fopen(p, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
    return p;
}

static void test_config_files(void **state)
{
    const char *a, *b, *bad, *flag;
    (void)state;
    snprintf(tmpdir, sizeof(tmpdir), "/tmp/sonard-opt.XXXXXX");
    assert_non_null(mkdtemp(tmpdir));
    a = write_file("a.conf", "# device\nlcm = memq://\nmin-points = 7\njson = true\n");
    b = write_file("b.conf", "min-points = 60000\n  median = 3x3  \n");
    {
        const char *argv[] = {"sonard", "--replay", "x", "--config", a, "--config", b};
        assert_int_equal(parse(7, argv), 0);
        assert_int_equal(o.pipeline.detector.min_points, 60000);
        assert_string_equal(o.lcm_url, "memq://"); /* the first file's string survives the second */
        assert_int_equal(o.json, 1);
        assert_int_equal(o.pipeline.median2d, 3);
        assert_int_equal(o.nconfigs, 2);
    }
    {
        const char *argv[] = {"sonard", "--replay", "x", "--config", a, "--min-points=9"};
        assert_int_equal(parse(6, argv), 0);
        assert_int_equal(o.pipeline.detector.min_points, 9);
    }
    bad = write_file("bad.conf", "range = 20\n\nlink-beams = 9\n");
    {
        const char *argv[] = {"sonard", "--replay", "x", "--config", bad};
        assert_int_equal(parse(5, argv), HOST_ERR_CONFIG);
        assert_non_null(strstr(err, "bad.conf:3: --join-beams: '9' is not a whole number in 1..8 beams"));
    }
    /* keys of another version (or slips) are named and skipped; the rest of the file applies */
    bad = write_file("unknown.conf", "rnage = 20\nmin-points = 9\nradar-mode = on\n");
    {
        const char *argv[] = {"sonard", "--replay", "x", "--config", bad};
        char said[1024] = "";
        FILE *f = tmpfile();
        assert_int_equal(parse(5, argv), HOST_OK);
        assert_int_equal(o.pipeline.detector.min_points, 9);
        assert_int_equal(o.given.unknown, 2);
        options_say_unknown(&o, f);
        rewind(f);
        assert_true(fread(said, 1, sizeof(said) - 1, f) > 0);
        fclose(f);
        assert_non_null(strstr(said, "unknown.conf:1: unknown key 'rnage' (did you mean 'range'?) skipped"));
        assert_non_null(strstr(said, "unknown.conf:3: unknown key 'radar-mode' skipped"));
    }
    bad = write_file("cmdonly.conf", "config = other.conf\n");
    {
        const char *argv[] = {"sonard", "--replay", "x", "--config", bad};
        assert_int_equal(parse(5, argv), HOST_ERR_CONFIG);
        assert_non_null(strstr(err, "cmdonly.conf:1: unknown key 'config'"));
    }
    flag = write_file("flag.conf", "json = maybe\n");
    {
        const char *argv[] = {"sonard", "--replay", "x", "--config", flag};
        assert_int_equal(parse(5, argv), HOST_ERR_CONFIG);
        assert_non_null(strstr(err, "flag.conf:1: json: 'maybe' is not true or false"));
    }
    {
        const char *argv[] = {"sonard", "--replay", "x", "--config", tmpdir};
        assert_int_equal(parse(5, argv), HOST_ERR_IO);
        assert_non_null(strstr(err, "not a regular file"));
    }
    {
        const char *argv[] = {"sonard", "--replay", "x", "--config", "/nonexistent/s.conf"};
        assert_int_equal(parse(5, argv), HOST_ERR_IO);
        assert_non_null(strstr(err, "--config /nonexistent/s.conf: No such file"));
    }
    /* A key valid alone but not with the other settings is refused at the file and line that set it (issue 44), and
       the unknown keys before it are still there to be said; given on the command line instead, no place is named. */
    bad = write_file("live.conf", "rnage = 20\n# the vehicle\npose-lcm = memq://\nmavlink = udpin:127.0.0.1:14550\n");
    {
        const char *argv[] = {"sonard", "--replay", "x", "--config", bad};
        assert_int_equal(parse(5, argv), HOST_ERR_CONFIG);
        assert_non_null(strstr(err, "live.conf:3: --pose-lcm URL is for a live sonar"));
        assert_int_equal(o.given.unknown, 1);
    }
    {
        const char *argv[] = {"sonard", "--replay", "x", "--config", bad, "--pose-lcm", "memq://"};
        assert_int_equal(parse(7, argv), HOST_ERR_CONFIG);
        assert_non_null(strstr(err, "--pose-lcm URL is for a live sonar"));
        assert_null(strstr(err, "live.conf"));
    }
    bad = write_file("mav.conf", "\nmavlink = udpin:127.0.0.1:14550\n");
    {
        const char *argv[] = {"sonard", "--replay", "x", "--config", bad};
        assert_int_equal(parse(5, argv), HOST_ERR_CONFIG);
        assert_non_null(strstr(err, "mav.conf:2: --mavlink URL goes with --sonar"));
    }
    /* --control: commands for a live sonar over LCM; a run that records --survey N and exits takes none. */
    bad = write_file("ctl.conf", "survey = /tmp/x.sv\ncontrol = yes\n");
    {
        const char *argv[] = {"sonard", "--replay", "x", "--config", bad};
        assert_int_equal(parse(5, argv), HOST_ERR_CONFIG);
        assert_non_null(strstr(err, "ctl.conf:2: --control takes commands for a live sonar"));
    }
    {
        const char *argv[] = {"sonard", "--sonar", "tcp:127.0.0.1:1", "--config", bad, "--no-lcm"};
        assert_int_equal(parse(6, argv), HOST_ERR_CONFIG);
        assert_non_null(strstr(err, "without --no-lcm"));
    }
    {
        const char *argv[] = {"sonard", "--sonar", "tcp:127.0.0.1:1", "--config", bad};
        assert_int_equal(parse(5, argv), 0);
        assert_int_equal(o.control, 1);
    }
    {
        const char *argv[] = {"sonard", "--sonar", "tcp:127.0.0.1:1", "--config", bad, "--survey", "20"};
        assert_int_equal(parse(7, argv), 0);
        assert_int_equal(o.control, 0);
    }
    bad = write_file("two.conf", "sonar = tcp:127.0.0.1:1\n");
    {
        const char *argv[] = {"sonard", "--replay", "x", "--config", bad};
        assert_int_equal(parse(5, argv), HOST_ERR_CONFIG);
        assert_non_null(strstr(err, "two.conf:1: give one of --sonar URL"));
    }
    (void)system("rm -rf /tmp/sonard-opt.*");
}

static void test_whole_config_checks_name_the_field(void **state)
{
    (void)state;
    {
        const char *argv[] = {"sonard", "--replay", "x", "--max-aspect", "0.05"};
        assert_int_equal(parse(5, argv), HOST_ERR_CONFIG);
        assert_non_null(strstr(err, "max_aspect: 0 (no limit) or 0.1..100"));
    }
    {
        const char *argv[] = {"sonard", "--sonar", "tcp:127.0.0.1:1", "--mode", "auto", "--step", "20"};
        assert_int_equal(parse(7, argv), HOST_ERR_CONFIG);
        assert_non_null(strstr(err, "--step: 20 gradians is more than auto_transmit's 10"));
    }
    {
        const char *argv[] = {"sonard", "--replay", "x", "--sonar", "tcp:127.0.0.1:1"};
        assert_int_equal(parse(5, argv), HOST_ERR_CONFIG);
        assert_non_null(strstr(err, "give one of --sonar URL"));
    }
    {
        const char *argv[] = {"sonard", "--replay", "x", "--background", "range"};
        assert_int_equal(parse(5, argv), 0);
        assert_int_equal(o.pipeline.background.warmup, 8); /* a beam per bin in range mode */
    }
    {
        const char *argv[] = {"sonard", "--replay", "x", "--background", "auto", "--threshold-mode", "cfar",
                              "--cfar-scale", "3", "--cfar-rank", "10"};
        assert_int_equal(parse(11, argv), 0);
        assert_int_equal(o.pipeline.background.mode, SONAR_BACKGROUND_AUTO);
        assert_int_equal(o.pipeline.background.warmup, 2); /* a visit per row, as per-angle */
        assert_int_equal(o.pipeline.detector.threshold_mode, SONAR_DET_CFAR);
        assert_true(o.pipeline.detector.cfar.scale == 3.0f);
        assert_int_equal(o.pipeline.detector.cfar.rank16, 10);
    }
    {
        const char *argv[] = {"sonard", "--replay", "x", "--background", "world"};
        assert_int_equal(parse(5, argv), HOST_ERR_CONFIG);
        assert_non_null(strstr(err, "--background"));
    }
    {
        const char *argv[] = {"sonard", "--sonar", "tcp:127.0.0.1:1", "--pose", "p.csv"};
        assert_int_equal(parse(5, argv), HOST_ERR_CONFIG);
        assert_non_null(strstr(err, "--pose FILE.csv goes with --replay"));
    }
    {
        const char *argv[] = {"sonard", "--replay", "x", "--json=1"};
        assert_int_equal(parse(4, argv), HOST_ERR_CONFIG);
        assert_non_null(strstr(err, "--json: takes no value"));
    }
    {
        const char *argv[] = {"sonard", "--replay"};
        assert_int_equal(parse(2, argv), HOST_ERR_CONFIG);
        assert_non_null(strstr(err, "--replay: needs a value"));
    }
    {
        const char *argv[] = {"sonard", "--replay", "x", "stray"};
        assert_int_equal(parse(4, argv), HOST_ERR_CONFIG);
        assert_non_null(strstr(err, "stray: unexpected argument"));
    }
    {
        const char *argv[] = {"sonard", "--replay", "x", "--channel-prefix", "0123456789012345678901234567890"};
        assert_int_equal(parse(5, argv), HOST_ERR_CONFIG);
        assert_non_null(strstr(err, "longer than 30 characters"));
    }
}

static void test_markdown_has_every_row(void **state)
{
    const struct opt_schema *s = options_schema();
    char buf[32768];
    FILE *f = fmemopen(buf, sizeof(buf), "w");
    size_t i;
    (void)state;
    options_markdown(f);
    fclose(f);
    for (i = 0; i < s->count; i++) {
        char want[80];
        if (s->spec[i].type == OPT_SECTION)
            continue;
        snprintf(want, sizeof(want), "| `%s` |", s->spec[i].name);
        if (strstr(buf, want) == NULL)
            fail_msg("docs lack %s", want);
    }
    assert_non_null(strstr(buf, "| `join-beams` | 1..8 beams | 2 | yes |"));
}

/*
 * The example configuration the package installs as /etc/sonard/sonard.conf runs what the tests score:
 * read as shipped, every setting but the sonar's address and the survey's file is sonard's default (issue 34: it used to
 * set another background, min-points and a channel prefix while saying "defaults shown").
 */
static void test_example_config_is_the_defaults(void **state)
{
    static struct sonard_options want;
    const char *a[] = {"sonard", "--sonar", "udp:192.168.2.2:12345"};
    const char *b[] = {"sonard", "--config", "docs/sonard.conf.example"};
    (void)state;
    if (access("docs/sonard.conf.example", R_OK) != 0)
        skip(); /* run from the source tree (make unit) */
    assert_int_equal(parse(3, a), 0);
    want = o;
    assert_int_equal(parse(3, b), 0);
    assert_string_equal(o.sonar, want.sonar);
    assert_memory_equal(&o.pipeline, &want.pipeline, sizeof(o.pipeline));
    assert_memory_equal(&o.device, &want.device, sizeof(o.device));
    assert_true(o.channel_prefix == want.channel_prefix || strcmp(o.channel_prefix, want.channel_prefix) == 0);
    assert_int_equal(o.log_level, want.log_level);
    assert_int_equal(o.publish_filtered, want.publish_filtered);
    assert_null(o.bg_load);
    assert_null(o.csv_out);
    assert_string_equal(o.survey, "/var/lib/sonard/site.survey"); /* under the unit's StateDirectory */
    assert_int_equal(o.survey_sweeps, 0);
}

/* --log-level is the diagnostics' and --quiet the per-sweep report's: one does not set the other. */
static void test_log_level_and_quiet(void **state)
{
    const char *a[] = {"sonard", "--replay", "x.csv", "--quiet"};
    const char *b[] = {"sonard", "--replay", "x.csv", "--log-level", "warn"};
    const char *c[] = {"sonard", "--replay", "x.csv", "--log-level", "chatty"};
    (void)state;
    assert_int_equal(parse(4, a), 0);
    assert_int_equal(o.quiet, 1);
    assert_int_equal(o.log_level, 2); /* info */
    assert_int_equal(parse(5, b), 0);
    assert_int_equal(o.quiet, 0);
    assert_int_equal(o.log_level, 1);
    assert_true(parse(5, c) < 0);
    assert_non_null(strstr(err, "--log-level: 'chatty' is not error, warn, info or debug"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_defaults),
        cmocka_unit_test(test_range_background_brings_the_study_rules),
        cmocka_unit_test(test_documented_defaults_are_the_defaults),
        cmocka_unit_test(test_every_numeric_row_bounds),
        cmocka_unit_test(test_names_unique_and_help_lists_all),
        cmocka_unit_test(test_config_files),
        cmocka_unit_test(test_whole_config_checks_name_the_field),
        cmocka_unit_test(test_markdown_has_every_row),
        cmocka_unit_test(test_example_config_is_the_defaults),
        cmocka_unit_test(test_log_level_and_quiet),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
