/* bgstore.c -- a recorded background file read whole and written atomically (bgstore.h); one static image buffer, no heap. */
#include "bgstore.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "sonar/bgfile.h"

/* The largest image: SONAR_MAX_ANGLES x SONAR_MAX_SAMPLES plus its header, visits and CRC. */
#define BGSTORE_MAX ((size_t)SONAR_BGFILE_HEADER + SONAR_MAX_ANGLES + 1u + SONAR_MAX_SAMPLES + \
                     (size_t)SONAR_MAX_ANGLES * SONAR_MAX_SAMPLES + 4u)
static uint8_t image[BGSTORE_MAX + 1]; /* + 1: a longer file is seen to be longer */

int bgstore_load(struct app *a, const char *path, char *err, size_t errlen)
{
    size_t len = 0;
    ssize_t got;
    int fd = open(path, O_RDONLY);
    if (fd < 0) {
        snprintf(err, errlen, "--background-load %s: %s", path, strerror(errno));
        return HOST_ERR_IO;
    }
    while (len < sizeof(image) && (got = read(fd, image + len, sizeof(image) - len)) != 0) {
        if (got < 0 && errno == EINTR)
            continue;
        if (got < 0) {
            snprintf(err, errlen, "--background-load %s: %s", path, strerror(errno));
            close(fd);
            return HOST_ERR_IO;
        }
        len += (size_t)got;
    }
    close(fd);
    if (app_background_load(a, image, len, err, errlen) != HOST_OK) {
        char why[256];
        snprintf(why, sizeof(why), "%s", err);
        snprintf(err, errlen, "--background-load %s: %s", path, why);
        return HOST_ERR_CONFIG;
    }
    return HOST_OK;
}

/* write(2) until done; 0 or -1 with errno. */
static int write_all(int fd, const uint8_t *p, size_t n)
{
    while (n > 0) {
        ssize_t w = write(fd, p, n);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0)
            return -1;
        p += w;
        n -= (size_t)w;
    }
    return 0;
}

/* The folder holding path, for its fsync after the rename. */
static void fsync_dir(const char *path)
{
    char dir[4096];
    const char *slash = strrchr(path, '/');
    int fd;
    if (slash == NULL)
        snprintf(dir, sizeof(dir), ".");
    else if (slash == path)
        snprintf(dir, sizeof(dir), "/");
    else
        snprintf(dir, sizeof(dir), "%.*s", (int)(slash - path), path);
    if ((fd = open(dir, O_RDONLY)) >= 0) {
        (void)fsync(fd);
        close(fd);
    }
}

int bgstore_save(const struct app *a, const char *path, char *err, size_t errlen)
{
    char tmp[4200];
    int32_t len = app_background_image(a, image, sizeof(image), err, errlen);
    int fd, e;
    if (len < 0)
        return len == HOST_ERR_STATE ? HOST_ERR_STATE : HOST_ERR_IO;
    if ((size_t)snprintf(tmp, sizeof(tmp), "%s.tmp.%ld", path, (long)getpid()) >= sizeof(tmp)) {
        snprintf(err, errlen, "--background-save %s: the path is too long", path);
        return HOST_ERR_IO;
    }
    if ((fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC, 0644)) < 0) {
        snprintf(err, errlen, "--background-save %s: %s: %s", path, tmp, strerror(errno));
        return HOST_ERR_IO;
    }
    if (write_all(fd, image, (size_t)len) != 0 || fsync(fd) != 0) {
        e = errno;
        close(fd);
        unlink(tmp);
        snprintf(err, errlen, "--background-save %s: writing %s: %s; the previous file is unchanged", path, tmp,
                 strerror(e));
        return HOST_ERR_IO;
    }
    if (close(fd) != 0 || rename(tmp, path) != 0) {
        e = errno;
        unlink(tmp);
        snprintf(err, errlen, "--background-save %s: %s; the previous file is unchanged", path, strerror(e));
        return HOST_ERR_IO;
    }
    fsync_dir(path);
    return HOST_OK;
}
