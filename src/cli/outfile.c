/* Output files written whole or not at all (outfile.h). */
#include "outfile.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/xattr.h>
#include <unistd.h>

/* The temporary files a signal handler must not leave behind. */
#define MAX_OPEN 8
static char *volatile open_tmp[MAX_OPEN];

static void remember(char *tmp)
{
    for (int i = 0; i < MAX_OPEN; i++)
        if (!open_tmp[i]) {
            open_tmp[i] = tmp;
            return;
        }
}

static void forget(const char *tmp)
{
    for (int i = 0; i < MAX_OPEN; i++)
        if (open_tmp[i] == tmp)
            open_tmp[i] = NULL;
}

void ncp_outfile_discard_all_now(void)
{
    for (int i = 0; i < MAX_OPEN; i++)
        if (open_tmp[i])
            unlink(open_tmp[i]);
}

int ncp_file_id_add(struct ncp_file_id *ids, int n, const char *path, const char *what)
{
    struct stat st;
    if (!path || strcmp(path, "-") == 0 || stat(path, &st) != 0)
        return n;
    ids[n].dev = (uint64_t)st.st_dev;
    ids[n].ino = (uint64_t)st.st_ino;
    ids[n].what = what;
    return n + 1;
}

static int refuse(const char *path, const char *why)
{
    fprintf(stderr, "cnc-run: cannot write %s: %s\n", path, why);
    return -1;
}

static void *close_thread(void *arg)
{
    int *fd = arg;
    close(*fd);
    free(fd);
    return NULL;
}

/* close(fd) in a detached thread, here if no thread can be had: the last
 * close of a replaced file frees its page cache, tens of milliseconds for
 * the canonical text of a big program, which the run need not wait for. */
static void close_in_background(int fd)
{
    pthread_t t;
    pthread_attr_t attr;
    int *arg = malloc(sizeof *arg);
    if (arg && pthread_attr_init(&attr) == 0) {
        *arg = fd;
        pthread_attr_setdetachstate(&attr, PTHREAD_CREATE_DETACHED);
        int spawned = pthread_create(&t, &attr, close_thread, arg) == 0;
        pthread_attr_destroy(&attr);
        if (spawned)
            return;
    }
    free(arg);
    close(fd);
}

/* Devices and the kernel's files are written where they are: /dev/stdout
 * resolves to whatever the shell opened, which a rename must not replace. */
static int kernel_path(const char *p)
{
    return !strncmp(p, "/dev/", 5) || !strncmp(p, "/proc/", 6);
}

static int open_in_place(struct ncp_outfile *of, int creat)
{
    of->fd = open(of->path, O_WRONLY | O_TRUNC | O_CLOEXEC | (creat ? O_CREAT : 0), 0644);
    if (of->fd < 0)
        return refuse(of->path, strerror(errno));
    return 0;
}

/* The old file's extended attributes onto the new one, as far as we may
 * set them (a security label may need privileges we lack). */
static void copy_xattrs(int from, int to)
{
    ssize_t n = flistxattr(from, NULL, 0);
    if (n <= 0)
        return;
    char *names = malloc((size_t)n);
    char *val = malloc(65536);
    if (names && val && (n = flistxattr(from, names, (size_t)n)) > 0)
        for (char *p = names; p < names + n; p += strlen(p) + 1) {
            ssize_t k = fgetxattr(from, p, val, 65536);
            if (k >= 0)
                (void)fsetxattr(to, p, val, (size_t)k, 0);
        }
    free(names);
    free(val);
}

/* A temporary file beside target with the old file's attributes (or a new
 * file's mode when there is none). */
static int open_beside(struct ncp_outfile *of, const struct stat *old)
{
    const char *slash = strrchr(of->target, '/');
    size_t dir_len = slash ? (size_t)(slash - of->target) + 1 : 0;
    const char *base = slash ? slash + 1 : of->target;
    size_t n = strlen(of->target) + 16;
    of->tmp = malloc(n);
    if (!of->tmp)
        return refuse(of->path, strerror(ENOMEM));
    snprintf(of->tmp, n, "%.*s.%s.XXXXXX", (int)dir_len, of->target, base);
    of->fd = mkostemp(of->tmp, O_CLOEXEC);
    if (of->fd < 0) {
        int e = errno;
        free(of->tmp);
        of->tmp = NULL;
        /* a file we may write in a folder we may not: as O_TRUNC would */
        if (old && e == EACCES)
            return open_in_place(of, 0);
        return refuse(of->path, strerror(e));
    }
    remember(of->tmp);
    if (old) {
        if (old->st_uid != geteuid() || old->st_gid != getegid())
            (void)fchown(of->fd, old->st_uid, old->st_gid);
        (void)fchmod(of->fd, old->st_mode & 07777);
        of->old_fd = open(of->target, O_RDONLY | O_CLOEXEC);
        if (of->old_fd >= 0)
            copy_xattrs(of->old_fd, of->fd);
    } else {
        mode_t mask = umask(0);
        umask(mask);
        (void)fchmod(of->fd, 0644 & ~mask);
    }
    return 0;
}

/* The record of the run before (a crash's, perhaps) is kept as NAME.1
 * (one generation): the old file, locked by us, is renamed, and a new one
 * made in its place and locked. Through a symlink the target is rotated and
 * the link kept. A run that makes NAME meanwhile holds it: refused. */
static int rotate_live(struct ncp_outfile *of, const struct stat *st)
{
    char *target = realpath(of->path, NULL);
    if (!target)
        return refuse(of->path, strerror(errno));
    size_t n = strlen(target) + 3;
    char *kept = malloc(n);
    int fd = -1, e = 0;
    if (!kept) {
        e = ENOMEM;
    } else {
        snprintf(kept, n, "%s.1", target);
        if (rename(target, kept) != 0 ||
            (fd = open(target, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644)) < 0)
            e = errno;
        else if (flock(fd, LOCK_EX | LOCK_NB) != 0)
            e = errno == EWOULDBLOCK ? EEXIST : errno;
    }
    if (e) {
        if (fd >= 0)
            close(fd);
        char why[PATH_MAX + 96] = "another run is writing it";
        if (e != EEXIST)
            snprintf(why, sizeof why, "cannot keep the last run's trace as %s: %s",
                     kept ? kept : "NAME.1", strerror(e));
        free(kept);
        free(target);
        return refuse(of->path, why);
    }
    (void)fchmod(fd, st->st_mode & 07777);
    close(of->fd);
    of->fd = fd;
    free(kept);
    free(target);
    return 0;
}

/* A live record: made afresh only once no other run holds it, the last
 * run's kept beside it. */
static int open_live(struct ncp_outfile *of)
{
    of->fd = open(of->path, O_WRONLY | O_CREAT | O_CLOEXEC, 0644);
    if (of->fd < 0)
        return refuse(of->path, strerror(errno));
    struct stat st;
    if (fstat(of->fd, &st) == 0 && S_ISREG(st.st_mode)) {
        if (flock(of->fd, LOCK_EX | LOCK_NB) != 0) {
            int e = errno;
            close(of->fd);
            of->fd = -1;
            return refuse(of->path, e == EWOULDBLOCK ? "another run is writing it"
                                                     : strerror(e));
        }
        if (st.st_size > 0 && rotate_live(of, &st) != 0) {
            close(of->fd);
            of->fd = -1;
            return -1;
        }
    }
    return 0;
}

int ncp_outfile_open(struct ncp_outfile *of, const char *path, const struct ncp_file_id *ids,
                     int n_ids, int flags)
{
    memset(of, 0, sizeof *of);
    of->path = path;
    of->fd = of->old_fd = -1;
    of->sync = !!(flags & NCP_OUT_SYNC);
    if (!strcmp(path, "-")) {
        of->fd = 1;
        return 0;
    }
    struct stat st, lst;
    int exists = stat(path, &st) == 0;
    if (!exists && errno != ENOENT)
        return refuse(path, strerror(errno));
    if (exists && S_ISDIR(st.st_mode))
        return refuse(path, strerror(EISDIR));
    for (int i = 0; exists && i < n_ids; i++)
        if (ids[i].dev == (uint64_t)st.st_dev && ids[i].ino == (uint64_t)st.st_ino) {
            char why[128];
            snprintf(why, sizeof why, "it is %s (an output never overwrites an input)",
                     ids[i].what);
            return refuse(path, why);
        }
    if (kernel_path(path) || (exists && (!S_ISREG(st.st_mode) || st.st_nlink > 1)))
        return open_in_place(of, 0);
    if (flags & NCP_OUT_LIVE)
        return open_live(of);
    if (!exists) {
        /* a dangling symlink: O_CREAT makes its target */
        if (lstat(path, &lst) == 0 && S_ISLNK(lst.st_mode))
            return open_in_place(of, 1);
        of->target = strdup(path);
        if (!of->target)
            return refuse(path, strerror(ENOMEM));
        return open_beside(of, NULL);
    }
    /* what O_TRUNC would refuse (no write permission) stays refused */
    if (faccessat(AT_FDCWD, path, W_OK, AT_EACCESS) != 0)
        return refuse(path, strerror(errno));
    of->target = realpath(path, NULL);
    if (!of->target)
        return refuse(path, strerror(errno));
    if (kernel_path(of->target)) {
        free(of->target);
        of->target = NULL;
        return open_in_place(of, 0);
    }
    return open_beside(of, &st);
}

static void drop(struct ncp_outfile *of)
{
    if (of->tmp) {
        forget(of->tmp);
        free(of->tmp);
    }
    free(of->target);
    of->tmp = of->target = NULL;
    of->fd = of->old_fd = -1;
}

void ncp_outfile_discard(struct ncp_outfile *of)
{
    if (of->fd > 1)
        close(of->fd);
    if (of->tmp)
        unlink(of->tmp);
    if (of->old_fd >= 0)
        close(of->old_fd);
    drop(of);
}

/* Over an existing file, an exchange of the two names and the old one's
 * removal instead of a rename: ext4 starts writing a file back at once
 * when it is renamed over another (auto_da_alloc), 10-20 ms for the
 * canonical text of a big program, a durability that fsync asks for where
 * it matters (of->sync). The target's name shows either file throughout. */
static int swapped(const struct ncp_outfile *of)
{
    if (of->sync || of->old_fd < 0 ||
        renameat2(AT_FDCWD, of->tmp, AT_FDCWD, of->target, RENAME_EXCHANGE) != 0)
        return 0;
    unlink(of->tmp);
    return 1;
}

int ncp_outfile_commit(struct ncp_outfile *of)
{
    int err = 0;
    if (of->fd < 0)
        return 0;
    if (of->fd == 1) {
        drop(of);
        return 0;
    }
    if (of->sync && of->tmp && fsync(of->fd) != 0)
        err = errno;
    if (close(of->fd) != 0 && !err)
        err = errno;
    of->fd = -1;
    if (!err && of->tmp && !swapped(of) && rename(of->tmp, of->target) != 0)
        err = errno;
    if (err && of->tmp)
        unlink(of->tmp);
    if (of->old_fd >= 0)
        close_in_background(of->old_fd);
    drop(of);
    return err;
}
