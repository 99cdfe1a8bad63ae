/* posefile.c -- the pose CSV reader (header by name, rows checked field by field, read ahead of the beams); O(line) per row. */
#include "posefile.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char *const names[4] = {"utime_us", "north_m", "east_m", "yaw_deg"};

/* One line into buf without its end of line. Returns 1, 0 at end of file, -1 when longer than the buffer. */
static int read_line(struct posefile *p)
{
    size_t k;
    if (fgets(p->buf, sizeof(p->buf), p->f) == NULL)
        return 0;
    p->line++;
    k = strlen(p->buf);
    if (k > 0 && p->buf[k - 1] != '\n' && !feof(p->f)) {
        int c;
        while ((c = fgetc(p->f)) != EOF && c != '\n')
            ;
        return -1;
    }
    while (k > 0 && (p->buf[k - 1] == '\n' || p->buf[k - 1] == '\r'))
        p->buf[--k] = '\0';
    return 1;
}

/* Splits buf at commas in place (blanks around fields dropped). Returns the field count, at most max. */
static int split(char *buf, char **f, int max)
{
    int n = 0;
    char *s = buf;
    for (;;) {
        char *e = strchr(s, ','), *t;
        if (e != NULL)
            *e = '\0';
        while (*s == ' ' || *s == '\t')
            s++;
        for (t = s + strlen(s); t > s && (t[-1] == ' ' || t[-1] == '\t'); t--)
            t[-1] = '\0';
        if (n < max)
            f[n++] = s;
        if (e == NULL)
            return n;
        s = e + 1;
    }
}

int posefile_open(struct posefile *p, const char *path, char *err, size_t errlen)
{
    FILE *f = fopen(path, "r");
    if (f == NULL) {
        memset(p, 0, sizeof(*p));
        snprintf(err, errlen, "%s: %s", path, strerror(errno));
        return HOST_ERR_IO;
    }
    return posefile_open_stream(p, f, path, err, errlen);
}

int posefile_open_stream(struct posefile *p, FILE *stream, const char *path, char *err, size_t errlen)
{
    char *f[32];
    int n, i, k, r;
    memset(p, 0, sizeof(*p));
    p->path = path;
    p->f = stream;
    if ((r = read_line(p)) <= 0) {
        snprintf(err, errlen, "%s:1: %s", path, r == 0 ? "empty: expected the header utime_us,north_m,east_m,yaw_deg"
                                                       : "header line too long");
        posefile_close(p);
        return HOST_ERR_CONFIG;
    }
    n = split(p->buf, f, 32);
    p->ncol = n;
    for (k = 0; k < 4; k++) {
        p->col[k] = -1;
        for (i = 0; i < n; i++)
            if (strcmp(f[i], names[k]) == 0)
                p->col[k] = i;
        if (p->col[k] < 0) {
            snprintf(err, errlen, "%s:1: the header has no column %s (it needs utime_us,north_m,east_m,yaw_deg)", path,
                     names[k]);
            posefile_close(p);
            return HOST_ERR_CONFIG;
        }
    }
    return HOST_OK;
}

/* Parses the row in buf into *s. Returns 0, or -1 with the reason in err. */
static int parse(struct posefile *p, struct sonar_pose *s, char *err, size_t errlen)
{
    char *f[32], *end;
    double v[4];
    int n = split(p->buf, f, 32), k;
    if (n < p->ncol) {
        snprintf(err, errlen, "%d fields, the header has %d", n, p->ncol);
        return -1;
    }
    for (k = 0; k < 4; k++) {
        const char *t = f[p->col[k]];
        errno = 0;
        v[k] = strtod(t, &end);
        if (*t == '\0' || *end != '\0' || errno == ERANGE || !isfinite(v[k])) {
            snprintf(err, errlen, "%s '%.24s' is not a number", names[k], t);
            return -1;
        }
    }
    /* Whole microseconds since the epoch, within what int64_t and the year 9999 allow. */
    if (!(v[0] >= 0.0 && v[0] <= 2.6e17) || v[0] != floor(v[0])) {
        snprintf(err, errlen, "utime_us %.24s is not whole microseconds since the epoch", f[p->col[0]]);
        return -1;
    }
    s->utime = (int64_t)v[0];
    s->north_m = (float)v[1];
    s->east_m = (float)v[2];
    s->yaw_deg = (float)v[3];
    return 0;
}

void posefile_feed(struct posefile *p, struct app *a, int64_t until_us, FILE *errf)
{
    char err[160];
    while (!p->eof || p->have_next) {
        const char *why = NULL;
        if (!p->have_next) {
            int r = read_line(p);
            if (r == 0) {
                p->eof = 1;
                return;
            }
            if (r < 0 || p->buf[0] == '\0' || parse(p, &p->next, err, sizeof(err)) != 0) {
                if (r >= 0 && p->buf[0] == '\0')
                    continue; /* a blank line */
                p->bad++;
                if (errf != NULL)
                    fprintf(errf, "%s:%lu: %s; row skipped\n", p->path, p->line, r < 0 ? "line too long" : err);
                continue;
            }
            p->have_next = 1;
            p->next_line = p->line;
        }
        if (p->next.utime > until_us)
            return;
        p->have_next = 0;
        if (app_pose(a, &p->next, &why) == HOST_OK) {
            p->good++;
        } else {
            p->bad++;
            if (errf != NULL)
                fprintf(errf, "%s:%lu: pose at %.6f s is %s; row skipped\n", p->path, p->next_line,
                        (double)p->next.utime * 1e-6, why);
        }
    }
}

void posefile_close(struct posefile *p)
{
    if (p->f != NULL)
        fclose(p->f);
    p->f = NULL;
}
