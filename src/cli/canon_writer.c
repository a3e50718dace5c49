/* Canonical text through a 1 MB buffer: a write() per slot would dominate.
 *
 * The write() calls stay in the thread that emits. A writer thread of its
 * own (an earlier version) made the pipeline slower once the output thread
 * could lex ahead when it had nothing to write: on two CPUs a third busy
 * thread takes time from both, and the buffers it read crossed cores twice. */
#include "canon_writer.h"
#include "outfile.h"

#include "ncpar/executor.h"
#include "ncpar/mem.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#define WRITER_BUF (1u << 20)
/* A long output to a regular file is streamed: past STREAM_FROM bytes each
 * buffer written is sent to the disk at once (sync_file_range, not waited
 * for), and the text more than STREAM_LAG behind is dropped from the page
 * cache (fadvise DONTNEED drops only what is already on the disk). Left to
 * the page cache, the canonical text of a long program takes as much fresh
 * memory, and in a virtual machine fresh memory can cost far more per page
 * when hundreds of MB are taken at once (bench/RESULTS.md, "Scale").
 * Shorter outputs stay in the page cache as before: they cost little there,
 * and streaming them would put the disk's work into their run. */
#define STREAM_FROM ((off_t)64 << 20)
#define STREAM_LAG ((off_t)16 << 20)

/* Prefaulted before the run (ncpar/mem.h): touched page by page instead, the
 * buffer costs 256 page faults in the thread that emits, and in a virtual
 * machine a fault is microseconds. */
struct canon_writer {
    struct ncp_outfile out;
    int fd;
    char *buf;
    struct ncp_mem mem;         /* where buf is */
    size_t used;
    int failed;                 /* errno of the first failed write */
    int stream;                 /* a regular file: stream a long output */
    off_t start;                /* the file offset of the first byte written */
    off_t written;              /* bytes written so far */
    off_t dropped;              /* bytes from start handed to fadvise DONTNEED */
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
static void stream_out(struct canon_writer *w, size_t just)
{
    w->written += (off_t)just;
    if (!w->stream || w->written <= STREAM_FROM)
        return;
    (void)sync_file_range(w->fd, w->start + w->written - (off_t)just, (off_t)just,
                          SYNC_FILE_RANGE_WRITE);
    off_t upto = w->written - STREAM_LAG;
    if (upto > w->dropped) {
        (void)posix_fadvise(w->fd, w->start + w->dropped, upto - w->dropped,
                            POSIX_FADV_DONTNEED);
        w->dropped = upto;
    }
}

static int hand_over(struct canon_writer *w)
{
    if (!w->failed) {
        w->failed = write_all(w->fd, w->buf, w->used);
        if (!w->failed)
            stream_out(w, w->used);
    }
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

struct canon_writer *canon_writer_open(const char *path, const struct ncp_file_id *inputs,
                                      int n_inputs)
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
    if (ncp_outfile_open(&w->out, path, inputs, n_inputs, 0) != 0) {
        writer_free(w);
        return NULL;
    }
    w->fd = w->out.fd;
    struct stat st;
    w->start = lseek(w->fd, 0, SEEK_CUR);
    w->stream = w->start >= 0 && fstat(w->fd, &st) == 0 && S_ISREG(st.st_mode);
    return w;
}

int canon_writer_close(struct canon_writer *w, int keep)
{
    if (!w)
        return 0;
    if (w->used)
        hand_over(w);
    int failed = w->failed;
    if (failed || !keep)
        ncp_outfile_discard(&w->out);
    else
        failed = ncp_outfile_commit(&w->out);
    writer_free(w);
    return failed;
}
