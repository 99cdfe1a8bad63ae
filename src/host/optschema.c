/* optschema.c -- the option-table engine: argv and key = value files into a struct, range-checked with named errors; --help and Markdown from the same rows; no heap. */
#include "optschema.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

int opt_find(const struct opt_schema *s, const char *name)
{
    size_t i;
    for (i = 0; i < s->count; i++)
        if (s->spec[i].type != OPT_SECTION && strcmp(s->spec[i].name, name) == 0)
            return (int)i;
    for (i = 0; i < s->nrenamed && i < 32; i++)
        if (strcmp(s->renamed[i].old_name, name) == 0)
            return opt_find(s, s->renamed[i].name);
    return -1;
}

/* opt_find, noting an old name's use in given (said by the program: the old name works, the new one is named). */
static int find_noting(const struct opt_schema *s, const char *name, struct opt_given *given)
{
    size_t k;
    for (k = 0; given != NULL && k < s->nrenamed && k < 32; k++)
        if (strcmp(s->renamed[k].old_name, name) == 0)
            given->renamed_used |= (uint32_t)1 << k;
    return opt_find(s, name);
}

static int bad_number(const struct opt_spec *o, const char *v, int whole, char *err, size_t n)
{
    snprintf(err, n, "--%s: '%s' is not a %s in %g..%g %s", o->name, v, whole ? "whole number" : "number", o->lo, o->hi,
             o->unit ? o->unit : "");
    return HOST_ERR_CONFIG;
}

/* OPT_CHOICE: finds v among "a=1|b=2". */
static int choice(const struct opt_spec *o, const char *v, uint8_t *out, char *err, size_t n)
{
    const char *c = o->choices;
    size_t vl = strlen(v);
    while (c != NULL && *c != '\0') {
        const char *eq = strchr(c, '='), *bar = strchr(c, '|');
        if (eq != NULL && (size_t)(eq - c) == vl && strncmp(c, v, vl) == 0) {
            *out = (uint8_t)strtoul(eq + 1, NULL, 10);
            return HOST_OK;
        }
        c = bar != NULL ? bar + 1 : NULL;
    }
    snprintf(err, n, "--%s: '%s' is not %s", o->name, v, o->unit);
    return HOST_ERR_CONFIG;
}

int opt_was_given(const struct opt_given *g, size_t i)
{
    return i < OPT_GIVEN_ROWS && ((g->w[i / 64] >> (i % 64)) & 1u) != 0;
}

unsigned opt_restart_needed(const struct opt_spec *spec, size_t count, const struct opt_given *a, const struct opt_given *b,
                            char *out, size_t cap)
{
    size_t i, used = 0;
    unsigned n = 0;
    if (cap > 0)
        out[0] = '\0';
    for (i = 0; i < count && i < OPT_GIVEN_ROWS; i++) {
        const char *va = opt_was_given(a, i) ? a->value[i] : NULL, *vb = opt_was_given(b, i) ? b->value[i] : NULL;
        int w;
        if (spec[i].reload || spec[i].type == OPT_SECTION || spec[i].type == OPT_ACTION ||
            (va == NULL && vb == NULL) || (va != NULL && vb != NULL && strcmp(va, vb) == 0))
            continue;
        n++;
        if (used >= cap)
            continue;
        w = snprintf(out + used, cap - used, "%s%s", n > 1 ? ", " : "", spec[i].name);
        used += w > 0 ? (size_t)w : 0;
        if (used >= cap && cap > 4)
            memcpy(out + cap - 4, "...", 4);
    }
    return n;
}

int opt_apply(const struct opt_schema *s, size_t i, void *base, const char *v, struct opt_given *given, char *err, size_t errlen)
{
    const struct opt_spec *o = &s->spec[i];
    char *field = (char *)base + o->offset, *end;
    double x = 0.0;
    int r = HOST_OK;
    if (o->type != OPT_FLAG && o->type != OPT_ACTION && v == NULL) {
        snprintf(err, errlen, "--%s: needs a value", o->name);
        return HOST_ERR_CONFIG;
    }
    if (o->type >= OPT_LONG && o->type <= OPT_F64) {
        int whole = o->type <= OPT_U16;
        errno = 0;
        x = whole ? (double)strtol(v, &end, 10) : strtod(v, &end);
        if (*v == '\0' || *end != '\0' || errno != 0 || !(x >= o->lo && x <= o->hi))
            return bad_number(o, v, whole, err, errlen);
    }
    switch (o->type) {
    case OPT_FLAG: *(int *)(void *)field = 1; break;
    case OPT_STR:
        if (o->hi > 0 && (double)strlen(v) > o->hi) {
            snprintf(err, errlen, "--%s: '%s' is longer than %g characters", o->name, v, o->hi);
            return HOST_ERR_CONFIG;
        }
        *(const char **)(void *)field = v;
        break;
    case OPT_LONG: *(long *)(void *)field = (long)x; break;
    case OPT_U8: *(uint8_t *)field = (uint8_t)x; break;
    case OPT_U16: *(uint16_t *)(void *)field = (uint16_t)x; break;
    case OPT_F32: *(float *)(void *)field = (float)x; break;
    case OPT_F64: *(double *)(void *)field = x; break;
    case OPT_CHOICE: r = choice(o, v, (uint8_t *)field, err, errlen); break;
    case OPT_CUSTOM: r = o->parse(base, v, err, errlen); break;
    default: break;
    }
    if (r == HOST_OK && given != NULL && i < OPT_GIVEN_ROWS) {
        given->w[i / 64] |= (uint64_t)1 << (i % 64);
        given->value[i] = v != NULL ? v : "1";
        given->from[i] = NULL; /* the command line's, unless the file reader says which line */
        given->line[i] = 0;
    }
    return r;
}

const char *opt_where(const struct opt_given *g, size_t i, char *buf, size_t n)
{
    if (n == 0)
        return "";
    buf[0] = '\0';
    if (g != NULL && i < OPT_GIVEN_ROWS && opt_was_given(g, i) && g->from[i] != NULL)
        snprintf(buf, n, "%s:%lu: ", g->from[i], g->line[i]);
    return buf;
}

static char *strip(char *s)
{
    char *e;
    while (*s == ' ' || *s == '\t')
        s++;
    for (e = s + strlen(s); e > s && (e[-1] == '\n' || e[-1] == '\r' || e[-1] == ' ' || e[-1] == '\t'); e--)
        ;
    *e = '\0';
    return s;
}

static int is_true(const char *v) { return !strcmp(v, "true") || !strcmp(v, "yes") || !strcmp(v, "1"); }
static int is_false(const char *v) { return !strcmp(v, "false") || !strcmp(v, "no") || !strcmp(v, "0"); }

/* Edits between a and b (insert, delete, substitute, swap two neighbours), counted up to 3. */
static unsigned edits(const char *a, const char *b)
{
    unsigned m[3][40], i, j, la = (unsigned)strlen(a), lb = (unsigned)strlen(b);
    if (la >= 40 || lb >= 40)
        return 3;
    for (j = 0; j <= lb; j++)
        m[0][j] = j;
    for (i = 1; i <= la; i++) {
        unsigned *cur = m[i % 3], *up = m[(i - 1) % 3], *up2 = m[(i + 1) % 3];
        cur[0] = i;
        for (j = 1; j <= lb; j++) {
            unsigned best = up[j - 1] + (a[i - 1] != b[j - 1]);
            if (up[j] + 1 < best)
                best = up[j] + 1;
            if (cur[j - 1] + 1 < best)
                best = cur[j - 1] + 1;
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] && up2[j - 2] + 1 < best)
                best = up2[j - 2] + 1;
            cur[j] = best;
        }
    }
    return m[la % 3][lb] < 3 ? m[la % 3][lb] : 3;
}

/* A key of another version (or a slip): named with the nearest file key, skipped. */
static void unknown_key(const struct opt_schema *s, struct opt_given *g, const char *path, unsigned long ln, const char *k)
{
    const char *near = NULL;
    unsigned best = 3;
    size_t i;
    for (i = 0; i < s->count; i++) {
        unsigned d = s->spec[i].file_ok ? edits(k, s->spec[i].name) : 3;
        if (d < best) {
            best = d;
            near = s->spec[i].name;
        }
    }
    if (g->unknown < OPT_UNKNOWN_KEPT)
        snprintf(g->unknown_said[g->unknown], sizeof g->unknown_said[0], "%.80s:%lu: unknown key '%.32s'%s%s%s", path, ln, k,
                 near ? " (did you mean '" : "", near ? near : "", near ? "'?)" : "");
    g->unknown++;
}

int opt_read_file(const struct opt_schema *s, const char *path, void *base, struct opt_given *given, char *pool, size_t cap,
                  size_t *used, char *err, size_t errlen)
{
    struct stat st;
    int r;
    FILE *f = fopen(path, "r");
    if (f == NULL) {
        snprintf(err, errlen, "--config %s: %s", path, strerror(errno));
        return HOST_ERR_IO;
    }
    /* fopen succeeds on a directory and reading it gives nothing: that is not an empty config. */
    if (fstat(fileno(f), &st) != 0 || !S_ISREG(st.st_mode)) {
        snprintf(err, errlen, "--config %s: not a regular file", path);
        fclose(f);
        return HOST_ERR_IO;
    }
    r = opt_read_stream(s, f, path, base, given, pool, cap, used, err, errlen);
    fclose(f);
    return r;
}

int opt_read_stream(const struct opt_schema *s, FILE *f, const char *path, void *base, struct opt_given *given, char *pool,
                    size_t cap, size_t *used, char *err, size_t errlen)
{
    char line[512], msg[256];
    unsigned long ln = 0;
    int r = HOST_OK;
    while (r == HOST_OK && fgets(line, sizeof(line), f) != NULL) {
        char *k, *eq, *v;
        int i;
        size_t len = strlen(line);
        ln++;
        if (len == sizeof(line) - 1 && line[len - 1] != '\n' && !feof(f)) {
            snprintf(err, errlen, "%s:%lu: line longer than %zu bytes", path, ln, sizeof(line) - 2);
            r = HOST_ERR_CONFIG;
            break;
        }
        if (memchr(line, '\0', len) != NULL && strlen(line) != len) {
            snprintf(err, errlen, "%s:%lu: NUL byte in the line", path, ln);
            r = HOST_ERR_CONFIG;
            break;
        }
        k = strip(line);
        if (*k == '#' || *k == '\0')
            continue;
        if ((eq = strchr(k, '=')) == NULL) {
            snprintf(err, errlen, "%s:%lu: expected key = value", path, ln);
            r = HOST_ERR_CONFIG;
            break;
        }
        *eq = '\0';
        k = strip(k);
        v = strip(eq + 1);
        i = find_noting(s, k, given);
        if (i < 0 && given != NULL) {
            unknown_key(s, given, path, ln, k);
            continue;
        }
        if (i < 0 || !s->spec[i].file_ok) {
            snprintf(err, errlen, "%s:%lu: unknown key '%.64s'", path, ln, k);
            r = HOST_ERR_CONFIG;
            break;
        }
        if (s->spec[i].type == OPT_FLAG) {
            if (is_false(v))
                continue;
            if (!is_true(v)) {
                snprintf(err, errlen, "%s:%lu: %s: '%.64s' is not true or false", path, ln, k, v);
                r = HOST_ERR_CONFIG;
                break;
            }
        }
        len = strlen(v) + 1;
        if (*used + len > cap) {
            snprintf(err, errlen, "%s:%lu: the files' values exceed %zu bytes", path, ln, cap);
            r = HOST_ERR_CONFIG;
            break;
        }
        memcpy(pool + *used, v, len);
        v = pool + *used;
        *used += len;
        if (opt_apply(s, (size_t)i, base, v, given, msg, sizeof(msg)) != HOST_OK) {
            snprintf(err, errlen, "%s:%lu: %s", path, ln, msg);
            r = HOST_ERR_CONFIG;
        } else if (given != NULL && i < OPT_GIVEN_ROWS) {
            given->from[i] = path;
            given->line[i] = ln;
        }
    }
    if (r == HOST_OK && ferror(f)) {
        snprintf(err, errlen, "--config %s: read error", path);
        r = HOST_ERR_IO;
    }
    return r;
}

int opt_parse_argv(const struct opt_schema *s, int argc, char **argv, void *base, struct opt_given *given, int *action,
                   char *err, size_t errlen)
{
    int a;
    *action = -1;
    for (a = 1; a < argc; a++) {
        char name[64];
        const char *arg = argv[a], *eq, *v = NULL;
        size_t nl;
        int i;
        if (strncmp(arg, "--", 2) != 0 || arg[2] == '\0') {
            snprintf(err, errlen, "%s: unexpected argument (see --help)", arg);
            return HOST_ERR_CONFIG;
        }
        eq = strchr(arg + 2, '=');
        nl = eq != NULL ? (size_t)(eq - arg - 2) : strlen(arg + 2);
        if (nl >= sizeof(name)) {
            snprintf(err, errlen, "%.40s...: unknown option (see --help)", arg);
            return HOST_ERR_CONFIG;
        }
        memcpy(name, arg + 2, nl);
        name[nl] = '\0';
        if ((i = find_noting(s, name, given)) < 0) {
            snprintf(err, errlen, "--%s: unknown option (see --help)", name);
            return HOST_ERR_CONFIG;
        }
        if (s->spec[i].arg != NULL) {
            if (eq != NULL)
                v = eq + 1;
            else if (a + 1 < argc)
                v = argv[++a];
            else {
                snprintf(err, errlen, "--%s: needs a value", name);
                return HOST_ERR_CONFIG;
            }
        } else if (eq != NULL) {
            snprintf(err, errlen, "--%s: takes no value", name);
            return HOST_ERR_CONFIG;
        }
        if (s->spec[i].type == OPT_ACTION) {
            if (strcmp(name, "config") == 0)
                continue; /* read by the caller before argv */
            *action = i;
            return HOST_OK;
        }
        if (opt_apply(s, (size_t)i, base, v, given, err, errlen) != HOST_OK)
            return HOST_ERR_CONFIG;
    }
    return HOST_OK;
}

/* Writes text with '\n' continued at the help column. */
static void help_text(FILE *f, const char *t)
{
    for (; *t != '\0'; t++) {
        fputc(*t, f);
        if (*t == '\n')
            fputs("                           ", f);
    }
}

void opt_usage(const struct opt_schema *s, FILE *f)
{
    size_t i;
    for (i = 0; i < s->count; i++) {
        const struct opt_spec *o = &s->spec[i];
        char head[64];
        int w;
        if (o->type == OPT_SECTION) {
            fprintf(f, "%s\n", o->name);
            continue;
        }
        w = snprintf(head, sizeof(head), "  --%s%s%s", o->name, o->arg ? " " : "", o->arg ? o->arg : "");
        fprintf(f, "%s%*s", head, w < 27 ? 27 - w : 1, "");
        help_text(f, o->help);
        if (o->type >= OPT_LONG && o->type <= OPT_F64)
            fprintf(f, ", %g..%g %s", o->lo, o->hi, o->unit ? o->unit : "");
        else if (o->unit != NULL && o->type != OPT_FLAG && o->type != OPT_ACTION)
            fprintf(f, ": %s", o->unit);
        if (o->def != NULL)
            fprintf(f, " (default %s)", o->def);
        if (o->reload)
            fputs(" [SIGHUP]", f);
        fputc('\n', f);
    }
}

/* Markdown cell text: '\n' becomes a space, '|' is escaped. */
static void cell(FILE *f, const char *t)
{
    for (; t != NULL && *t != '\0'; t++) {
        if (*t == '\n')
            fputc(' ', f);
        else if (*t == '|')
            fputs("\\|", f);
        else
            fputc(*t, f);
    }
}

void opt_markdown(const struct opt_schema *s, FILE *f)
{
    size_t i;
    for (i = 0; i < s->count; i++) {
        const struct opt_spec *o = &s->spec[i];
        if (o->type == OPT_SECTION) {
            fprintf(f, "%s### %s\n\n| key | values | default | SIGHUP | what it does |\n|---|---|---|---|---|\n",
                    i ? "\n" : "", o->name);
            continue;
        }
        fprintf(f, "| `%s` | ", o->name);
        if (o->type >= OPT_LONG && o->type <= OPT_F64)
            fprintf(f, "%g..%g %s", o->lo, o->hi, o->unit ? o->unit : "");
        else if (o->type == OPT_FLAG)
            fputs("flag", f);
        else
            cell(f, o->unit != NULL ? o->unit : o->arg);
        fputs(" | ", f);
        cell(f, o->def != NULL ? o->def : "—");
        fprintf(f, " | %s | ", o->reload ? "yes" : "");
        cell(f, o->help);
        fprintf(f, "%s |\n", o->file_ok ? "" : " (command line only)");
    }
    for (i = 0; i < s->nrenamed; i++)
        fprintf(f, "\n`%s` is the old name of `%s`: still taken, and said deprecated.\n",
                s->renamed[i].old_name, s->renamed[i].name);
}
