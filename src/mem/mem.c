/* Prefaulted working memory; the program text on huge pages (mem.h). */
#include "ncpar/mem.h"

#include <fcntl.h>
#include <pthread.h>
#include <stdint.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#define HUGE_BYTES ((size_t)2 << 20)
#define PAGE_BYTES ((size_t)4096)
/* Below this a 2 MB page is mostly zeroing for nothing */
#define HUGE_FROM ((size_t)512 << 10)

static int huge_usable;
static pthread_once_t huge_once = PTHREAD_ONCE_INIT;

static void read_thp_setting(void)
{
    int fd = open("/sys/kernel/mm/transparent_hugepage/enabled", O_RDONLY | O_CLOEXEC);
    if (fd < 0)
        return;
    char buf[128];
    ssize_t n = read(fd, buf, sizeof buf - 1);
    close(fd);
    if (n <= 0)
        return;
    buf[n] = '\0';
    /* "[never]" accepts MADV_HUGEPAGE and ignores it */
    huge_usable = strstr(buf, "[always]") != NULL || strstr(buf, "[madvise]") != NULL;
}

int ncp_mem_huge_usable(void)
{
    pthread_once(&huge_once, read_thp_setting);
    return huge_usable;
}

static size_t round_up(size_t n, size_t unit)
{
    return n > SIZE_MAX - unit ? 0 : (n + unit - 1) / unit * unit;
}

/* Whole 4 KB pages, each faulted in now (MAP_POPULATE) or at first touch. */
static int map_small(struct ncp_mem *m, size_t bytes, int flags)
{
    memset(m, 0, sizeof *m);
    size_t want = round_up(bytes, PAGE_BYTES);
    if (want == 0)
        return -1;
    void *p = mmap(NULL, want, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS | flags, -1, 0);
    if (p == MAP_FAILED)
        return -1;
    m->base = m->p = p;
    m->base_len = m->bytes = want;
    return 0;
}

int ncp_mem_map(struct ncp_mem *m, size_t bytes)
{
    return map_small(m, bytes, MAP_POPULATE);
}

int ncp_mem_reserve_huge(struct ncp_mem *m, size_t bytes)
{
    if (bytes < HUGE_FROM || !ncp_mem_huge_usable())
        return map_small(m, bytes, MAP_NORESERVE);
    memset(m, 0, sizeof *m);
    size_t want = round_up(bytes, HUGE_BYTES);
    if (want == 0 || want > SIZE_MAX - HUGE_BYTES)
        return -1;
    size_t len = want + HUGE_BYTES; /* slack to align the start */
    void *base = mmap(NULL, len, PROT_READ | PROT_WRITE,
                      MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
    if (base == MAP_FAILED)
        return -1;
    size_t skip = (HUGE_BYTES - (uintptr_t)base % HUGE_BYTES) % HUGE_BYTES;
    m->base = base;
    m->base_len = len;
    m->p = (char *)base + skip;
    m->bytes = want;
    m->huge = 1;
    (void)madvise(m->p, want, MADV_HUGEPAGE);
    return 0;
}

void ncp_mem_unmap(struct ncp_mem *m)
{
    if (m->base)
        munmap(m->base, m->base_len);
    memset(m, 0, sizeof *m);
}
