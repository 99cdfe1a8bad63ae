/* csv_file.c -- where a recording's rows come from: a file, stdin, or a gzip-compressed file read through a gzip -dc child (no shell), reaped and judged at the end; a pipe and a pid per reader, no heap. */
#include "csv.h"

#include <signal.h>
#include <string.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include "csv_internal.h"

/* Does f start with gzip's magic bytes? Leaves f at its start. */
static int gzipped(FILE *f)
{
    int c0 = getc(f), c1 = getc(f);
    rewind(f);
    return c0 == 0x1f && c1 == 0x8b;
}

/* r->f becomes the read end of a pipe from gzip -dc path (no shell: the path is one argument). */
static int open_gunzip(struct csv_reader *r, const char *path)
{
    int fd[2];
    pid_t pid;
    if (pipe(fd) != 0)
        return HOST_ERR_IO;
    pid = fork();
    if (pid < 0) {
        close(fd[0]);
        close(fd[1]);
        return HOST_ERR_IO;
    }
    if (pid == 0) {
        close(fd[0]);
        if (dup2(fd[1], STDOUT_FILENO) < 0)
            _exit(126);
        close(fd[1]);
        execlp("gzip", "gzip", "-dc", "--", path, (char *)NULL);
        _exit(127);
    }
    close(fd[1]);
    r->f = fdopen(fd[0], "r");
    if (r->f == NULL) {
        close(fd[0]);
        kill(pid, SIGTERM);
        (void)waitpid(pid, NULL, 0);
        return HOST_ERR_IO;
    }
    r->gunzip = (long)pid;
    return 0;
}

int csv_open(struct csv_reader *r, const char *path)
{
    memset(r, 0, sizeof(*r));
    r->path = path;
    if (strcmp(path, "-") == 0) {
        r->f = stdin;
        return 0;
    }
    r->f = fopen(path, "r");
    if (r->f == NULL)
        return HOST_ERR_IO;
    if (gzipped(r->f)) {
        fclose(r->f);
        r->f = NULL;
        if (open_gunzip(r, path) != 0)
            return HOST_ERR_IO;
    }
    /* Recordings are megabytes of text: read them in large blocks. */
    setvbuf(r->f, r->iobuf, _IOFBF, sizeof(r->iobuf));
    r->owned = 1;
    return 0;
}

void csv_open_stream(struct csv_reader *r, FILE *f, const char *name)
{
    memset(r, 0, sizeof(*r));
    r->path = name;
    r->f = f;
}

/* Waits for the gzip child; returns its exit status, or -1 when it did not exit by itself. */
static int reap(struct csv_reader *r)
{
    int st = 0;
    pid_t pid = (pid_t)r->gunzip;
    r->gunzip = 0;
    if (waitpid(pid, &st, 0) != pid)
        return -1;
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

void csv_close(struct csv_reader *r)
{
    if (r->owned && r->f != NULL)
        fclose(r->f);
    r->f = NULL;
    if (r->gunzip != 0) {
        /* Stopped before the end (--sweeps): the child would only get SIGPIPE. */
        kill((pid_t)r->gunzip, SIGTERM);
        (void)reap(r);
    }
}

int csv_file_end(struct csv_reader *r, char *err, size_t errlen)
{
    int st;
    if (r->gunzip == 0)
        return 0;
    st = reap(r);
    if (st == 0)
        return 0;
    r->bad++;
    if (st == 127)
        snprintf(err, errlen, "compressed (gzip), but gzip could not be run to read it");
    else
        snprintf(err, errlen, "compressed (gzip) and truncated or corrupt: gzip -dc ended with status %d after %lu lines; "
                 "the rows before were read", st, r->line);
    return HOST_ERR_ROW;
}
