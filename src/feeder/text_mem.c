/* Program text copied into anonymous memory on 2 MB pages (text_mem.h). */
#include "text_mem.h"

#include <errno.h>
#include <fcntl.h>
#include <stdint.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#define HUGE_BYTES ((size_t)2 << 20)

static size_t round_huge(size_t n)
{
    return (n + HUGE_BYTES - 1) / HUGE_BYTES * HUGE_BYTES;
}

/* "[always]" or "[madvise]" in the kernel's setting: MADV_HUGEPAGE is
 * honoured. With "[never]" the advice is accepted and ignored, and a copy on
 * small pages is what must be avoided (text_mem.h). */
int ncp_text_mem_usable(void)
{
    int fd = open("/sys/kernel/mm/transparent_hugepage/enabled", O_RDONLY | O_CLOEXEC);
    if (fd < 0)
        return 0;
    char buf[128];
    ssize_t n = read(fd, buf, sizeof buf - 1);
    close(fd);
    if (n <= 0)
        return 0;
    buf[n] = '\0';
    return strstr(buf, "[always]") != NULL || strstr(buf, "[madvise]") != NULL;
}

/* A region of at least `bytes` (> 0) whose start is 2 MB aligned, so that
 * every whole 2 MB of it can be one page. */
static int reserve(struct ncp_text_mem *m, size_t bytes)
{
    size_t want = round_huge(bytes);
    if (want < bytes || want > SIZE_MAX - HUGE_BYTES)
        return -1;
    size_t len = want + HUGE_BYTES; /* slack to align the start */
    void *base = mmap(NULL, len, PROT_READ | PROT_WRITE,
                      MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
    if (base == MAP_FAILED)
        return -1;
    size_t skip = (HUGE_BYTES - (uintptr_t)base % HUGE_BYTES) % HUGE_BYTES;
    m->base = base;
    m->base_len = len;
    m->text = (char *)base + skip;
    m->cap = want;
    (void)madvise(m->text, m->cap, MADV_HUGEPAGE);
    return 0;
}

void ncp_text_mem_free(struct ncp_text_mem *m)
{
    if (m->base)
        munmap(m->base, m->base_len);
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
    memset(m, 0, sizeof *m);
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

int ncp_text_mem_read_stream(struct ncp_text_mem *m, int fd)
{
    memset(m, 0, sizeof *m);
    if (reserve(m, HUGE_BYTES) != 0)
        return -1;
    for (;;) {
        if (m->len == m->cap) {
            /* a new region twice the size: copying whole 2 MB pages is cheap
             * next to reading, and the copy stays on huge pages */
            struct ncp_text_mem bigger;
            if (m->cap > SIZE_MAX / 2 || reserve(&bigger, m->cap * 2) != 0) {
                ncp_text_mem_free(m);
                errno = ENOMEM;
                return -1;
            }
            memcpy(bigger.text, m->text, m->len);
            bigger.len = m->len;
            ncp_text_mem_free(m);
            *m = bigger;
        }
        size_t got;
        if (read_into(fd, m->text + m->len, m->cap - m->len, &got) != 0) {
            int e = errno;
            ncp_text_mem_free(m);
            errno = e;
            return -1;
        }
        m->len += got;
        if (m->len < m->cap)
            return 0; /* the end came before the region was full */
    }
}
