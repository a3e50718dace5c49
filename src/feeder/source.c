/* Program text loading and block splitting. The split is a pure function of the
 * text so the analyzer can re-read earlier blocks (loops, calls) without the file. */
#include "ncpar/feeder.h"
#include "text_mem.h"

#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

int ncp_source_percent_line(const char *s, size_t n)
{
    size_t i = 0;
    while (i < n && (s[i] == ' ' || s[i] == '\t'))
        i++;
    return i < n && s[i] == '%';
}

static int is_blank_line(const char *s, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (s[i] != ' ' && s[i] != '\t' && s[i] != '\r')
            return 0;
    return 1;
}

/* rs274: if the first non-blank line is '%', the program ends at the next '%'
 * line; otherwise it runs to the end of the file. */
static void find_body(struct ncp_source *src)
{
    struct ncp_span sp;
    uint64_t off = 0;
    uint32_t line = 1;
    src->begin = 0;
    src->end = src->len;
    src->begin_line = 1;
    src->has_percent = 0;
    while (ncp_source_span(src, off, line, &sp) == 0) {
        const char *s = src->text + sp.off;
        if (is_blank_line(s, sp.len)) {
            off = sp.next;
            line++;
            continue;
        }
        if (!ncp_source_percent_line(s, sp.len))
            return;
        src->has_percent = 1;
        src->begin = sp.next;
        src->begin_line = line + 1;
        break;
    }
    if (!src->has_percent)
        return;
    off = src->begin;
    line = src->begin_line;
    while (ncp_source_span(src, off, line, &sp) == 0) {
        if (ncp_source_percent_line(src->text + sp.off, sp.len)) {
            src->end = sp.off;
            return;
        }
        off = sp.next;
        line++;
    }
}

int ncp_source_span(const struct ncp_source *src, uint64_t off, uint32_t line,
                    struct ncp_span *out)
{
    if (off >= src->end)
        return 1;
    const char *start = src->text + off;
    size_t avail = src->end - off;
    const char *nl = memchr(start, '\n', avail);
    size_t len = nl ? (size_t)(nl - start) : avail;
    out->off = off;
    out->line = line;
    out->next = off + len + (nl ? 1 : 0);
    if (len > 0 && start[len - 1] == '\r')
        len--;
    out->len = (uint32_t)(len > UINT32_MAX ? UINT32_MAX : len);
    return 0;
}

uint64_t ncp_source_chunk_end(const struct ncp_source *src, uint64_t off, size_t want)
{
    if (off >= src->end || src->end - off <= want)
        return src->end;
    const char *from = src->text + off + want - 1; /* a line end right there ends it */
    const char *nl = memchr(from, '\n', src->end - (off + want - 1));
    return nl ? (uint64_t)(nl - src->text) + 1 : src->end;
}

/* 64 bytes a step: compare, collect the bit mask, count its bits. */
uint64_t ncp_source_count_newlines(const struct ncp_source *src, uint64_t off, uint64_t end)
{
    const char *p = src->text + off, *e = src->text + (end < src->end ? end : src->end);
    uint64_t n = 0;
#if defined(__SSE2__)
    const __m128i nl = _mm_set1_epi8('\n');
    for (; e - p >= 64; p += 64) {
        uint64_t m0 = (uint16_t)_mm_movemask_epi8(
            _mm_cmpeq_epi8(_mm_loadu_si128((const __m128i *)(const void *)p), nl));
        uint64_t m1 = (uint16_t)_mm_movemask_epi8(
            _mm_cmpeq_epi8(_mm_loadu_si128((const __m128i *)(const void *)(p + 16)), nl));
        uint64_t m2 = (uint16_t)_mm_movemask_epi8(
            _mm_cmpeq_epi8(_mm_loadu_si128((const __m128i *)(const void *)(p + 32)), nl));
        uint64_t m3 = (uint16_t)_mm_movemask_epi8(
            _mm_cmpeq_epi8(_mm_loadu_si128((const __m128i *)(const void *)(p + 48)), nl));
        n += (uint64_t)__builtin_popcountll(m0 | m1 << 16 | m2 << 32 | m3 << 48);
    }
#endif
    for (; p < e; p++)
        n += *p == '\n';
    return n;
}

int ncp_source_from_memory(struct ncp_source *src, const char *text, size_t len,
                           const char *name, struct ncp_diag *d)
{
    (void)d;
    memset(src, 0, sizeof *src);
    src->text = text;
    src->len = len;
    src->name = name;
    src->end = len;
    find_body(src);
    return NCP_OK;
}

static int read_all(int fd, char **buf, size_t *len)
{
    size_t cap = 1 << 16, n = 0;
    char *p = malloc(cap);
    if (!p)
        return -1;
    for (;;) {
        if (n == cap) {
            char *q = realloc(p, cap * 2);
            if (!q) {
                free(p);
                return -1;
            }
            p = q;
            cap *= 2;
        }
        ssize_t r = read(fd, p + n, cap - n);
        if (r < 0 && errno == EINTR)
            continue;
        if (r < 0) {
            free(p);
            return -1;
        }
        if (r == 0)
            break;
        n += (size_t)r;
    }
    *buf = p;
    *len = n;
    return 0;
}

/* src takes over the copy in m. */
static void adopt_copy(struct ncp_source *src, struct ncp_text_mem *m)
{
    ncp_source_from_memory(src, m->text, m->len, NULL, NULL);
    src->copy = m->mem.base;
    src->copy_len = m->mem.base_len;
}

/* A pipe's text: on huge pages where the kernel offers them, else on the heap. */
static int read_stream(struct ncp_source *src, int fd)
{
    if (ncp_mem_huge_usable()) {
        struct ncp_text_mem m;
        if (ncp_text_mem_read_stream(&m, fd) != 0)
            return -1;
        adopt_copy(src, &m);
        return 0;
    }
    char *buf;
    size_t n;
    if (read_all(fd, &buf, &n) != 0)
        return -1;
    ncp_source_from_memory(src, buf, n, NULL, NULL);
    src->owned = 1;
    return 0;
}

int ncp_source_open(struct ncp_source *src, const char *path, struct ncp_diag *d)
{
    memset(src, 0, sizeof *src);
    src->name = path;
    if (strcmp(path, "-") == 0) {
        if (read_stream(src, 0) != 0)
            return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot read standard input: %s",
                                strerror(errno));
        src->name = path;
        return NCP_OK;
    }
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot open program: %s",
                            strerror(errno));
    struct stat st;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        /* not a regular file (a FIFO, a device): read it like a pipe */
        int rc = read_stream(src, fd);
        close(fd);
        if (rc != 0)
            return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot read program: %s",
                                strerror(errno));
        src->name = path;
        return NCP_OK;
    }
    size_t size = (size_t)st.st_size;
    if (size > 0 && size <= NCP_SOURCE_COPY_MAX && ncp_mem_huge_usable()) {
        struct ncp_text_mem m;
        if (ncp_text_mem_read_file(&m, fd, size) == 0) {
            close(fd);
            adopt_copy(src, &m);
            src->name = path;
            return NCP_OK;
        }
        /* no room for a copy: map it instead */
    }
    const char *text = "";
    if (size > 0) {
        void *m = mmap(NULL, size, PROT_READ, MAP_PRIVATE | MAP_POPULATE, fd, 0);
        if (m == MAP_FAILED) {
            close(fd);
            return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot map program: %s",
                                strerror(errno));
        }
        madvise(m, size, MADV_SEQUENTIAL);
        text = m;
        src->mapped = 1;
    }
    close(fd);
    src->text = text;
    src->len = size;
    src->end = size;
    find_body(src);
    return NCP_OK;
}

void ncp_source_close(struct ncp_source *src)
{
    if (src->mapped)
        munmap((void *)src->text, src->len);
    else if (src->copy)
        munmap(src->copy, src->copy_len);
    else if (src->owned)
        free((void *)src->text);
    memset(src, 0, sizeof *src);
}

uint64_t ncp_source_after(const struct ncp_source *src, uint64_t off, size_t len)
{
    uint64_t pos = off + len;
    if (pos < src->end && src->text[pos] == '\r')
        pos++;
    if (pos < src->end && src->text[pos] == '\n')
        pos++;
    return pos < src->end ? pos : src->end;
}
