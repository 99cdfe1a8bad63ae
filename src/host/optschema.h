/* optschema.h -- one table per program describes every option once (name, field, type, range, unit, default, help); parsing argv and key = value files, --help and the Markdown docs all come from it; no heap. */
#ifndef SONARD_OPTSCHEMA_H
#define SONARD_OPTSCHEMA_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "herr.h"

enum opt_type {
    OPT_SECTION = 0, /* not an option: a heading in --help and the docs (name is the heading) */
    OPT_FLAG,        /* int field set to 1; in a file: true/false, yes/no, 1/0 */
    OPT_STR,         /* const char * field; hi > 0 bounds its length */
    OPT_LONG,        /* long field, whole number in lo..hi */
    OPT_U8,          /* uint8_t field, whole number in lo..hi */
    OPT_U16,         /* uint16_t field, whole number in lo..hi */
    OPT_F32,         /* float field, number in lo..hi */
    OPT_F64,         /* double field, number in lo..hi */
    OPT_CHOICE,      /* uint8_t field: one of choices, "name=value|name=value" */
    OPT_CUSTOM,      /* parse() does it */
    OPT_ACTION       /* handled by the caller (--help, --version, --config): no field */
};

struct opt_spec {
    const char *name;    /* long option without "--"; also the config-file key */
    const char *arg;     /* metavariable in --help; NULL for flags and actions without a value */
    uint8_t type;        /* enum opt_type */
    uint8_t file_ok;     /* may appear in a --config file */
    uint8_t reload;      /* takes effect on SIGHUP (filter and detector settings) */
    size_t offset;       /* of the field in the program's options struct */
    double lo, hi;       /* range (OPT_STR: hi = longest length) */
    const char *unit;    /* "metres", "gradians", ... shown in errors, --help and the docs */
    const char *def;     /* the default as shown */
    const char *help;    /* one sentence; '\n' breaks the --help line */
    const char *choices; /* OPT_CHOICE */
    /* OPT_CUSTOM: stores v into the struct at base; returns HOST_OK or HOST_ERR_CONFIG with err set. */
    int (*parse)(void *base, const char *v, char *err, size_t errlen);
};

/* One bit per table row (rows < OPT_GIVEN_ROWS), set when the option is applied. */
#define OPT_GIVEN_ROWS 128
#define OPT_UNKNOWN_KEPT 4 /* unknown file keys named in full; more are counted */
struct opt_given {
    uint64_t w[OPT_GIVEN_ROWS / 64];
    const char *value[OPT_GIVEN_ROWS];         /* each row's last value as given (argv or the file pool; "1" a flag) */
    const char *from[OPT_GIVEN_ROWS];          /* ... the file that gave it (the caller's path), NULL: the command line */
    unsigned long line[OPT_GIVEN_ROWS];        /* ... and its line there */
    uint32_t renamed_used;                     /* bit k: the schema's renamed[k] old name was used */
    unsigned unknown;                          /* file keys no row knows, skipped (a newer or older version's) */
    char unknown_said[OPT_UNKNOWN_KEPT][160];  /* "PATH:LINE: unknown key 'k' (did you mean 'range'?)" */
};

/* Whether row i was applied. */
int opt_was_given(const struct opt_given *g, size_t i);

/* Where row i's value came from, for a message: "PATH:LINE: " when a file gave it, else "" (the command line, or not given). */
const char *opt_where(const struct opt_given *g, size_t i, char *buf, size_t n);

/*
 * The rows without SIGHUP (reload 0) whose values differ between two parses, by name, comma
 * separated into out (cap bytes, truncated with "..."): what a reload cannot change. Returns how many.
 */
unsigned opt_restart_needed(const struct opt_spec *spec, size_t count, const struct opt_given *a, const struct opt_given *b,
                            char *out, size_t cap);

/* An option renamed: its old name (on the command line or in a file) still works, and is said deprecated. */
struct opt_rename {
    const char *old_name, *name;
};

/* The table and the struct it fills. */
struct opt_schema {
    const struct opt_spec *spec;
    size_t count;      /* rows, at most 64 */
    const char *prog;  /* for messages */
    const struct opt_rename *renamed; /* old names still taken (at most 32), or NULL */
    size_t nrenamed;
};

/*
 * Applies value v (NULL for a flag given on the command line) of row i to base. Returns HOST_OK or
 * HOST_ERR_CONFIG with err naming the option, the value, the range and its unit.
 */
HOST_CHECK int opt_apply(const struct opt_schema *s, size_t i, void *base, const char *v, struct opt_given *given, char *err,
                         size_t errlen);

/* The row of a name (an old name of a renamed row too), or -1. */
int opt_find(const struct opt_schema *s, const char *name);

/*
 * Reads one key = value file ('#' comments, blank lines). Values are copied into pool (cap bytes,
 * *used carried across files) so string fields can point at them. A key no row knows (one of a
 * newer or an older version) is skipped and named in given->unknown_said, with the nearest known
 * key when one is within two edits; the rest of the file applies. Returns HOST_OK, HOST_ERR_IO
 * (err: "--config PATH: reason"), or HOST_ERR_CONFIG (err: "PATH:LINE: what is wrong", also for
 * a command-line-only key in a file).
 */
HOST_CHECK int opt_read_file(const struct opt_schema *s, const char *path, void *base, struct opt_given *given, char *pool,
                             size_t cap, size_t *used, char *err, size_t errlen);

/* The same over an open stream (not closed); path names it in messages. */
HOST_CHECK int opt_read_stream(const struct opt_schema *s, FILE *f, const char *path, void *base, struct opt_given *given,
                               char *pool, size_t cap, size_t *used, char *err, size_t errlen);

/*
 * Parses argv[1..] (--name value, --name=value, flags) into base. Rows of type OPT_ACTION are
 * reported through *action (the row index; -1 when none) and parsing stops there, except "config"
 * rows, which are skipped (the caller reads files first). Returns HOST_OK or HOST_ERR_CONFIG.
 */
HOST_CHECK int opt_parse_argv(const struct opt_schema *s, int argc, char **argv, void *base, struct opt_given *given,
                              int *action, char *err, size_t errlen);

/* --help: sections, options, value, help, range and default, from the table. */
void opt_usage(const struct opt_schema *s, FILE *f);

/* The Markdown table of every option (key, values and unit, default, SIGHUP, what it does). */
void opt_markdown(const struct opt_schema *s, FILE *f);

#endif
