/* test_optschema.c -- the option-table engine on a table of every type: argv and key = value files into a struct, every refusal naming the option (and the file and line), --help and the Markdown from the same rows. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "optschema.h"

#include <cmocka.h>

struct opts {
    int verbose;
    const char *name;
    long count;
    uint8_t level;
    uint16_t port;
    float gain;
    double range;
    uint8_t mode;
    int custom;
};

static int parse_even(void *base, const char *v, char *err, size_t n)
{
    struct opts *o = base;
    int x = 0;
    if (sscanf(v, "%d", &x) != 1 || x % 2 != 0) {
        snprintf(err, n, "--even: '%s' is not an even number", v);
        return HOST_ERR_CONFIG;
    }
    o->custom = x;
    return HOST_OK;
}

#define F(x) offsetof(struct opts, x)
static const struct opt_spec spec[] = {
    {"General", NULL, OPT_SECTION, 0, 0, 0, 0, 0, NULL, NULL, NULL, NULL, NULL},
    {"verbose", NULL, OPT_FLAG, 1, 0, F(verbose), 0, 0, NULL, "off", "say more", NULL, NULL},
    {"name", "S", OPT_STR, 1, 0, F(name), 0, 8, "characters", "none", "a name", NULL, NULL},
    {"count", "N", OPT_LONG, 1, 0, F(count), 1, 100, "things", "10", "how many", NULL, NULL},
    {"level", "L", OPT_U8, 1, 1, F(level), 0, 9, "levels", "3", "how loud", NULL, NULL},
    {"port", "P", OPT_U16, 0, 0, F(port), 1, 65535, "", "5000", "where", NULL, NULL},
    {"gain", "G", OPT_F32, 1, 1, F(gain), 0.5, 2, "times", "1", "how much", NULL, NULL},
    {"range", "M", OPT_F64, 1, 0, F(range), 1, 60, "metres", "30", "how far", NULL, NULL},
    {"mode", "M", OPT_CHOICE, 1, 0, F(mode), 0, 0, "fast or slow", "fast", "how", "fast=1|slow=2", NULL},
    {"even", "E", OPT_CUSTOM, 1, 0, 0, 0, 0, NULL, "0", "an even number", NULL, parse_even},
    {"help", NULL, OPT_ACTION, 0, 0, 0, 0, 0, NULL, NULL, "this text", NULL, NULL},
    {"config", "FILE", OPT_ACTION, 0, 0, 0, 0, 0, NULL, NULL, "read FILE first", NULL, NULL},
};
static const struct opt_schema schema = {spec, sizeof(spec) / sizeof(spec[0]), "test", NULL, 0};

static int parse(struct opts *o, struct opt_given *g, int *action, char *err, size_t n, int argc, ...)
{
    char *argv[16];
    va_list ap;
    int i;
    argv[0] = (char *)"test";
    va_start(ap, argc);
    for (i = 1; i <= argc; i++)
        argv[i] = va_arg(ap, char *);
    va_end(ap);
    memset(o, 0, sizeof(*o));
    memset(g, 0, sizeof(*g));
    return opt_parse_argv(&schema, argc + 1, argv, o, g, action, err, n);
}

static void argv_fills_every_type(void **state)
{
    struct opts o;
    struct opt_given g;
    char err[256];
    int action;
    (void)state;
    assert_int_equal(parse(&o, &g, &action, err, sizeof(err), 10, "--verbose", "--name=abc", "--count", "42", "--level", "9",
                           "--gain=0.5", "--range", "60", "--mode=slow"),
                     HOST_OK);
    assert_int_equal(action, -1);
    assert_int_equal(o.verbose, 1);
    assert_string_equal(o.name, "abc");
    assert_int_equal(o.count, 42);
    assert_int_equal(o.level, 9);
    assert_true(o.gain == 0.5f && o.range == 60.0);
    assert_int_equal(o.mode, 2);
    assert_true(opt_was_given(&g, (size_t)opt_find(&schema, "count")));
    assert_false(opt_was_given(&g, (size_t)opt_find(&schema, "port")));
    assert_int_equal(parse(&o, &g, &action, err, sizeof(err), 3, "--even", "4", "--help"), HOST_OK);
    assert_int_equal(o.custom, 4);
    assert_int_equal(action, opt_find(&schema, "help"));
    /* --config is the caller's, read before: skipped here with its value */
    assert_int_equal(parse(&o, &g, &action, err, sizeof(err), 4, "--config", "x.conf", "--count", "5"), HOST_OK);
    assert_int_equal(action, -1);
    assert_int_equal(o.count, 5);
}

/* Each refusal says which option and what it takes. */
static void argv_refusals_are_named(void **state)
{
    static const struct {
        const char *a, *b, *says;
    } bad[] = {
        {"--count", "0", "--count: '0' is not a whole number in 1..100 things"},
        {"--count", "5x", "--count: '5x' is not a whole number"},
        {"--count", "", "--count: '' is not a whole number"},
        {"--level", "10", "--level: '10' is not a whole number in 0..9 levels"},
        {"--gain", "nan", "--gain: 'nan' is not a number in 0.5..2 times"},
        {"--range", "1e9", "--range: '1e9' is not a number in 1..60 metres"},
        {"--mode", "medium", "--mode: 'medium' is not fast or slow"},
        {"--name", "toolongname", "--name: 'toolongname' is longer than 8 characters"},
        {"--even", "3", "--even: '3' is not an even number"},
        {"--nosuch", "1", "--nosuch: unknown option"},
        {"count", "1", "count: unexpected argument"},
        {"--verbose=1", NULL, "--verbose: takes no value"},
        {"--count", NULL, "--count: needs a value"},
    };
    struct opts o;
    struct opt_given g;
    char err[256];
    int action;
    size_t i;
    (void)state;
    for (i = 0; i < sizeof(bad) / sizeof(bad[0]); i++) {
        int r = bad[i].b ? parse(&o, &g, &action, err, sizeof(err), 2, bad[i].a, bad[i].b)
                         : parse(&o, &g, &action, err, sizeof(err), 1, bad[i].a);
        assert_int_equal(r, HOST_ERR_CONFIG);
        if (strstr(err, bad[i].says) == NULL)
            fail_msg("%s %s: said '%s', expected '%s'", bad[i].a, bad[i].b ? bad[i].b : "", err, bad[i].says);
    }
}

/* A reload: only rows without SIGHUP whose values changed, given or dropped, are named (custom rows too). */
static void restart_needed_names_what_reload_cannot_change(void **state)
{
    struct opts a, b;
    struct opt_given ga, gb;
    char err[160], names[64];
    int action;
    (void)state;
    assert_int_equal(parse(&a, &ga, &action, err, sizeof(err), 6, "--count", "5", "--level", "2", "--even", "4"), HOST_OK);
    assert_int_equal(parse(&b, &gb, &action, err, sizeof(err), 4, "--count", "5", "--level", "7"), HOST_OK);
    assert_int_equal(opt_restart_needed(spec, schema.count, &ga, &gb, names, sizeof(names)), 1);
    assert_string_equal(names, "even"); /* level has SIGHUP; count is the same */
    assert_int_equal(parse(&b, &gb, &action, err, sizeof(err), 7, "--count", "6", "--even", "4", "--range", "2",
                           "--verbose"), HOST_OK);
    assert_int_equal(opt_restart_needed(spec, schema.count, &ga, &gb, names, sizeof(names)), 3);
    assert_string_equal(names, "verbose, count, range");
    assert_int_equal(opt_restart_needed(spec, schema.count, &ga, &gb, names, 12), 3);
    assert_string_equal(names, "verbose,...");
}

static int read_text(const char *text, struct opts *o, char *err, size_t n)
{
    static char pool[256];
    size_t used = 0;
    struct opt_given g;
    int r;
    FILE *f = tmpfile();
    fputs(text, f);
    rewind(f);
    memset(o, 0, sizeof(*o));
    memset(&g, 0, sizeof(g));
    r = opt_read_stream(&schema, f, "t.conf", o, &g, pool, sizeof(pool), &used, err, n);
    fclose(f);
    return r;
}

static void files_fill_and_refuse_by_line(void **state)
{
    struct opts o;
    char err[256];
    (void)state;
    assert_int_equal(read_text("# a comment\n\n  count = 7  \nverbose = yes\nname = boat\nmode = fast\nverbose = false\n", &o, err,
                               sizeof(err)),
                     HOST_OK);
    assert_int_equal(o.count, 7);
    assert_int_equal(o.verbose, 1);
    assert_string_equal(o.name, "boat"); /* the value lives in the pool, not the line buffer */
    assert_int_equal(o.mode, 1);
    assert_int_equal(read_text("count = 7\nlevel = 12\n", &o, err, sizeof(err)), HOST_ERR_CONFIG);
    assert_string_equal(err, "t.conf:2: --level: '12' is not a whole number in 0..9 levels");
    assert_int_equal(read_text("port = 80\n", &o, err, sizeof(err)), HOST_ERR_CONFIG);
    assert_string_equal(err, "t.conf:1: unknown key 'port'"); /* command line only */
    assert_int_equal(read_text("count 7\n", &o, err, sizeof(err)), HOST_ERR_CONFIG);
    assert_string_equal(err, "t.conf:1: expected key = value");
    assert_int_equal(read_text("verbose = maybe\n", &o, err, sizeof(err)), HOST_ERR_CONFIG);
    assert_string_equal(err, "t.conf:1: verbose: 'maybe' is not true or false");
    assert_int_equal(opt_read_file(&schema, "/nonexistent/x.conf", &o, NULL, NULL, 0, NULL, err, sizeof(err)), HOST_ERR_IO);
    assert_non_null(strstr(err, "--config /nonexistent/x.conf: "));
    assert_int_equal(opt_read_file(&schema, "/", &o, NULL, NULL, 0, NULL, err, sizeof(err)), HOST_ERR_IO);
    assert_string_equal(err, "--config /: not a regular file");
}

/* What f holds, as text. */
static const char *text_of(FILE *f, char *buf, size_t cap)
{
    size_t n;
    rewind(f);
    n = fread(buf, 1, cap - 1, f);
    buf[n] = '\0';
    fclose(f);
    return buf;
}

static void help_and_docs_come_from_the_rows(void **state)
{
    static char text[8192];
    FILE *f = tmpfile();
    (void)state;
    opt_usage(&schema, f);
    text_of(f, text, sizeof(text));
    assert_non_null(strstr(text, "--count N"));
    assert_non_null(strstr(text, "how many"));
    assert_non_null(strstr(text, "General"));
    f = tmpfile();
    opt_markdown(&schema, f);
    text_of(f, text, sizeof(text));
    assert_non_null(strstr(text, "### General"));
    assert_non_null(strstr(text, "| `level` | 0..9 levels | 3 | yes | how loud |"));
    assert_non_null(strstr(text, "| `port` | 1..65535  | 5000 |  | where (command line only) |"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(argv_fills_every_type),
        cmocka_unit_test(argv_refusals_are_named),
        cmocka_unit_test(files_fill_and_refuse_by_line),
        cmocka_unit_test(help_and_docs_come_from_the_rows),
        cmocka_unit_test(restart_needed_names_what_reload_cannot_change),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
