/* bgstore.c -- a site's survey or recorded background file read whole and written atomically (bgstore.h); two static image buffers, no heap. */
#include "bgstore.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "sonar/bgfile.h"

/* Two of the largest image (SONAR_BGFILE_MAX), + 1: a longer file is seen to be longer. The one the app holds
   (app_background_load keeps it to take the survey back) is never read into: a survey recorded while running is
   loaded into the other, so a file that fails leaves the one in use whole. The second's pages are touched only then. */
static uint8_t images[2][SONAR_BGFILE_MAX + SONAR_CLUTTER_WIRE + 1];

/* The buffer the app does not hold. */
static uint8_t *free_image(const struct app *a)
{
    return app_survey_image(a) == images[0] ? images[1] : images[0];
}

int bgstore_load(struct app *a, const char *what, const char *path, char *err, size_t errlen)
{
    uint8_t *image = free_image(a);
    size_t len = 0;
    ssize_t got;
    int fd = open(path, O_RDONLY);
    if (fd < 0) {
        snprintf(err, errlen, "%s %s: %s", what, path, strerror(errno));
        return HOST_ERR_IO;
    }
    while (len < sizeof(images[0]) && (got = read(fd, image + len, sizeof(images[0]) - len)) != 0) {
        if (got < 0 && errno == EINTR)
            continue;
        if (got < 0) {
            snprintf(err, errlen, "%s %s: %s", what, path, strerror(errno));
            close(fd);
            return HOST_ERR_IO;
        }
        len += (size_t)got;
    }
    close(fd);
    if (app_background_load(a, image, len, err, errlen) != HOST_OK) {
        char why[256];
        snprintf(why, sizeof(why), "%s", err);
        snprintf(err, errlen, "%s %s: %s", what, path, why);
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

int bgstore_write(const char *what, const char *path, const uint8_t *img, size_t len, char *err, size_t errlen)
{
    char tmp[4200];
    int fd, e;
    if ((size_t)snprintf(tmp, sizeof(tmp), "%s.tmp.%ld", path, (long)getpid()) >= sizeof(tmp)) {
        snprintf(err, errlen, "%s %s: the path is too long", what, path);
        return HOST_ERR_IO;
    }
    if ((fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC, 0644)) < 0) {
        snprintf(err, errlen, "%s %s: %s: %s", what, path, tmp, strerror(errno));
        return HOST_ERR_IO;
    }
    if (write_all(fd, img, len) != 0 || fsync(fd) != 0) {
        e = errno;
        close(fd);
        unlink(tmp);
        snprintf(err, errlen, "%s %s: writing %s: %s; the previous file is unchanged", what, path, tmp, strerror(e));
        return HOST_ERR_IO;
    }
    if (close(fd) != 0 || rename(tmp, path) != 0) {
        e = errno;
        unlink(tmp);
        snprintf(err, errlen, "%s %s: %s; the previous file is unchanged", what, path, strerror(e));
        return HOST_ERR_IO;
    }
    fsync_dir(path);
    return HOST_OK;
}

int bgstore_save(const struct app *a, const char *path, char *err, size_t errlen)
{
    uint8_t *image = free_image(a);
    int32_t len = app_background_image(a, image, sizeof(images[0]), err, errlen);
    if (len < 0)
        return len == HOST_ERR_STATE ? HOST_ERR_STATE : HOST_ERR_IO;
    return bgstore_write("--background-save", path, image, (size_t)len, err, errlen);
}
