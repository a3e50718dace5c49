/* Temporary file, fsync, rename, fsync of the folder (save_whole.h). */
#include "save_whole.h"

#include <errno.h>
#include <fcntl.h>
#include <libgen.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static int write_all(int fd, const char *p, size_t len)
{
    while (len > 0) {
        ssize_t n = write(fd, p, len);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            return -1;
        p += n;
        len -= (size_t)n;
    }
    return 0;
}

/* The rename is only lasting once the folder's entry is on the disk. */
static int sync_folder(const char *path)
{
    char dir[PATH_MAX];
    snprintf(dir, sizeof dir, "%s", path);
    int fd = open(dirname(dir), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0)
        return -1;
    int rc = fsync(fd);
    close(fd);
    return rc;
}

int ncp_save_whole(const char *path, const char *text, size_t len, const char *what,
                   struct ncp_diag *d)
{
    char tmp[PATH_MAX];
    if ((size_t)snprintf(tmp, sizeof tmp, "%s.XXXXXX", path) >= sizeof tmp)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "%s %s: path too long", what, path);
    mode_t mode = 0644;
    struct stat st;
    if (stat(path, &st) == 0)
        mode = st.st_mode & 07777;
    int fd = mkostemp(tmp, O_CLOEXEC);
    if (fd < 0)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot write %s %s: %s", what, path,
                            strerror(errno));
    int e = 0;
    if (fchmod(fd, mode) != 0 || write_all(fd, text, len) != 0 || fsync(fd) != 0)
        e = errno ? errno : EIO;
    if (close(fd) != 0 && !e)
        e = errno;
    if (!e && rename(tmp, path) != 0)
        e = errno;
    if (e) {
        unlink(tmp);
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot write %s %s: %s", what, path,
                            strerror(e));
    }
    if (sync_folder(path) != 0)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "%s %s written, but its folder could not "
                            "be flushed to the disk: %s", what, path, strerror(errno));
    return NCP_OK;
}
