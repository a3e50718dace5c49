/* Canonical text through a 1 MB buffer: a write() per slot would dominate.
 *
 * The write() calls stay in the thread that emits. A writer thread of its
 * own (an earlier version) made the pipeline slower once the output thread
 * could lex ahead when it had nothing to write: on two CPUs a third busy
 * thread takes time from both, and the buffers it read crossed cores twice. */
#include "canon_writer.h"

#include "ncpar/executor.h"
#include "ncpar/mem.h"

#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/xattr.h>
#include <unistd.h>

#define WRITER_BUF (1u << 20)

/* Prefaulted before the run (ncpar/mem.h): touched page by page instead, the
 * buffer costs 256 page faults in the thread that emits, and in a virtual
 * machine a fault is microseconds. */
struct canon_writer {
    int fd;
    char *buf;
    struct ncp_mem mem;         /* where buf is */
    size_t used;
    int failed;                 /* errno of the first failed write */
};

/* 0, or the errno of the failed write. */
static int write_all(int fd, const char *p, size_t n)
{
    size_t off = 0;
    while (off < n) {
        ssize_t k = write(fd, p + off, n - off);
        if (k < 0 && errno == EINTR)
            continue;
        if (k <= 0)
            return k < 0 ? errno : EIO;
        off += (size_t)k;
    }
    return 0;
}

/* The filled buffer goes out; the caller continues in it, empty. */
static int hand_over(struct canon_writer *w)
{
    if (!w->failed)
        w->failed = write_all(w->fd, w->buf, w->used);
    w->used = 0;
    return w->failed;
}

/* (PRINT,...) text goes where rs274's goes, beside the canonical stream: to
 * stderr here, since the canonical text may be on stdout. */
static void write_prints(const struct ncp_cmd *cmd)
{
    if (cmd->text_used)
        (void)ncp_exec_write_prints(cmd, stderr);
}

int canon_writer_emit(void *ctx, const struct ncp_cmd *cmd)
{
    struct canon_writer *w = ctx;
    write_prints(cmd);
    if (!w)
        return 0;
    if (w->used + cmd->out_len > WRITER_BUF && hand_over(w))
        return 1;
    memcpy(w->buf + w->used, cmd->out, cmd->out_len);
    w->used += cmd->out_len;
    return w->failed != 0;
}

char *canon_writer_reserve(void *ctx)
{
    struct canon_writer *w = ctx;
    if (!w || (w->used + NCP_CMD_OUT_MAX > WRITER_BUF && hand_over(w)))
        return NULL;
    return w->buf + w->used;
}

int canon_writer_commit(void *ctx, const struct ncp_cmd *cmd)
{
    struct canon_writer *w = ctx;
    write_prints(cmd);
    w->used += cmd->out_len;
    return w->failed != 0;
}

static void writer_free(struct canon_writer *w)
{
    ncp_mem_unmap(&w->mem);
    free(w);
}

static void *close_thread(void *arg)
{
    int *fd = arg;
    close(*fd);
    free(fd);
    return NULL;
}

/* close(fd) in a detached thread; here if no thread can be had. */
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

/* Rewriting a file that holds the last run's output with O_TRUNC costs
 * twice: the truncation frees its page cache in the call, and ext4, seeing a
 * file truncated to zero and written again, starts its writeback when it is
 * closed. A new file under the
 * old name has neither. Only a file the user could not tell from the one
 * O_TRUNC would leave is replaced: a regular file of ours that we may write,
 * one link, no extended attributes (ACLs, labels), whose mode carries over.
 * Anything else (a symlink, a device, a FIFO, a hard-linked, read-only or
 * foreign file) is opened with O_TRUNC as before. The old file's pages are
 * freed when its last descriptor closes, in a short thread of its own, so
 * the run does not wait for it (an unlink() of the last name frees them in
 * the call). The serial reference gets the same thread: it is
 * file-system housekeeping, not interpretation, and serial and parallel runs
 * must pay alike for their output. Returns the new descriptor or -1 (then the
 * caller truncates). */
static int open_replacing(const char *path)
{
    struct stat st;
    /* no write permission: O_TRUNC must refuse it (or, for root, write it) as
     * it always did, not an unlink the directory would allow */
    if (lstat(path, &st) != 0 || !S_ISREG(st.st_mode) || st.st_nlink != 1 ||
        st.st_uid != geteuid() || !(st.st_mode & S_IWUSR) || st.st_size == 0)
        return -1;
    ssize_t xattrs = llistxattr(path, NULL, 0);
    if (xattrs != 0)
        return -1;
    int old = open(path, O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
    struct stat ost;
    if (old < 0 || fstat(old, &ost) != 0 || ost.st_ino != st.st_ino || ost.st_dev != st.st_dev) {
        if (old >= 0)
            close(old);
        return -1;
    }
    int fd = -1;
    if (unlink(path) == 0) {
        fd = open(path, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, st.st_mode & 0777);
        /* the umask may have narrowed the mode; a failure leaves a file as
         * writable as O_CREAT made it, so the run goes on */
        if (fd >= 0)
            (void)fchmod(fd, st.st_mode & 0777);
    }
    close_in_background(old);
    return fd;
}

struct canon_writer *canon_writer_open(const char *path)
{
    struct canon_writer *w = calloc(1, sizeof *w);
    if (!w) {
        fprintf(stderr, "cnc-run: out of memory for the output buffers\n");
        return NULL;
    }
    if (ncp_mem_map(&w->mem, WRITER_BUF) == 0)
        w->buf = w->mem.p;
    if (!w->buf) {
        fprintf(stderr, "cnc-run: out of memory for the output buffers\n");
        writer_free(w);
        return NULL;
    }
    if (!strcmp(path, "-")) {
        w->fd = 1;
    } else {
        w->fd = open_replacing(path);
        if (w->fd < 0)
            w->fd = open(path, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
        if (w->fd < 0) {
            fprintf(stderr, "cnc-run: cannot write %s: %s\n", path, strerror(errno));
            writer_free(w);
            return NULL;
        }
    }
    return w;
}

int canon_writer_close(struct canon_writer *w)
{
    if (!w)
        return 0;
    if (w->used)
        hand_over(w);
    int failed = w->failed;
    if (w->fd != 1 && close(w->fd) != 0 && !failed)
        failed = errno;
    writer_free(w);
    return failed;
}
