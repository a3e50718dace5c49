/* Program text copied into anonymous memory on 2 MB pages (text_mem.h). */
#include "text_mem.h"

#include <errno.h>
#include <stdint.h>
#include <string.h>
#include <unistd.h>

#define FIRST_STREAM_BYTES ((size_t)2 << 20)
#define FIRST_STREAM_MAX ((size_t)1 << 30)

static int reserve(struct ncp_text_mem *m, size_t bytes)
{
    memset(m, 0, sizeof *m);
    if (ncp_mem_reserve_huge(&m->mem, bytes) != 0)
        return -1;
    m->text = m->mem.p;
    m->cap = m->mem.bytes;
    return 0;
}

void ncp_text_mem_free(struct ncp_text_mem *m)
{
    ncp_mem_unmap(&m->mem);
    memset(m, 0, sizeof *m);
}

/* read() until `want` bytes or the end; EINTR is retried. */
static int read_into(int fd, char *dst, size_t want, size_t *got)
{
    size_t n = 0;
    while (n < want) {
        ssize_t r = read(fd, dst + n, want - n);
        if (r < 0 && errno == EINTR)
            continue;
        if (r < 0)
            return -1;
        if (r == 0)
            break;
        n += (size_t)r;
    }
    *got = n;
    return 0;
}

int ncp_text_mem_read_file(struct ncp_text_mem *m, int fd, size_t size)
{
    if (size == 0 || reserve(m, size) != 0)
        return -1;
    if (read_into(fd, m->text, size, &m->len) != 0) {
        int e = errno;
        ncp_text_mem_free(m);
        errno = e;
        return -1;
    }
    return 0;
}

/* One read(), EINTR retried: what a pipe has now, so that the end of the
 * program is seen as soon as it arrives. */
static ssize_t read_some(int fd, char *dst, size_t want)
{
    for (;;) {
        ssize_t r = read(fd, dst, want);
        if (r >= 0 || errno != EINTR)
            return r;
    }
}

int ncp_text_mem_read_stream(struct ncp_text_mem *m, int fd, size_t max,
                             ncp_text_stop_fn stop, void *ctx)
{
    /* room for the whole limit at once: only what is read is touched, and
     * no growth copies, which would hold the text twice */
    if (reserve(m, max < FIRST_STREAM_MAX ? max + 1 : FIRST_STREAM_BYTES) != 0)
        return -1;
    for (;;) {
        if (m->len == m->cap) {
            /* a new region twice the size (no bigger than the limit needs):
             * copying whole 2 MB pages is cheap next to reading, and the
             * copy stays on huge pages */
            struct ncp_text_mem bigger;
            if (m->len > max) {
                ncp_text_mem_free(m);
                errno = EFBIG;
                return -1;
            }
            size_t want = m->cap <= max / 2 ? m->cap * 2 : max + 1;
            if (reserve(&bigger, want) != 0) {
                ncp_text_mem_free(m);
                errno = ENOMEM;
                return -1;
            }
            memcpy(bigger.text, m->text, m->len);
            bigger.len = m->len;
            ncp_text_mem_free(m);
            *m = bigger;
        }
        ssize_t got = read_some(fd, m->text + m->len, m->cap - m->len);
        if (got < 0) {
            int e = errno;
            ncp_text_mem_free(m);
            errno = e;
            return -1;
        }
        if (got == 0)
            return 0;
        m->len += (size_t)got;
        size_t keep = stop ? stop(ctx, m->text, m->len) : 0;
        if (keep) {
            m->len = keep;
            return 0;
        }
        if (m->len > max) {
            ncp_text_mem_free(m);
            errno = EFBIG;
            return -1;
        }
    }
}
