/* Program text loading and block splitting. The split is a pure function of the
 * text so the analyzer can re-read earlier blocks (loops, calls) without the file. */
#include "ncpar/feeder.h"
#include "stream_end.h"
#include "text_mem.h"

#include "ncpar/lex.h"

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
    src->fd = -1;
    src->text = text;
    src->len = len;
    src->name = name;
    src->end = len;
    find_body(src);
    return NCP_OK;
}

/* src takes over the copy in m. */
static void adopt_copy(struct ncp_source *src, struct ncp_text_mem *m)
{
    ncp_source_from_memory(src, m->text, m->len, NULL, NULL);
    src->copy = m->mem.base;
    src->copy_len = m->mem.base_len;
}

/* A pipe's text, up to the program's end (stream_end.h) and no more than
 * NCP_SOURCE_STREAM_MAX bytes: a pipe need not end at all. */
static int read_stream(struct ncp_source *src, int fd, const char *what, struct ncp_diag *d)
{
    struct ncp_text_mem m;
    struct ncp_stream_end e;
    memset(&e, 0, sizeof e);
    if (ncp_text_mem_read_stream(&m, fd, NCP_SOURCE_STREAM_MAX, ncp_stream_end_scan, &e) == 0) {
        adopt_copy(src, &m);
        return NCP_OK;
    }
    if (errno == EFBIG)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                            "%s gave more than %zu MB without the program's end (M2, M30 "
                            "or a closing %%): give a program this long as a file",
                            what, NCP_SOURCE_STREAM_MAX >> 20);
    return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot read %s: %s", what, strerror(errno));
}

/* A first line too long to lex, and long enough that reading it costs
 * (a file of zeros): "Command too long" before the text is mapped or
 * copied, as the lexer would report it at 1:1 (a '%' line is no command). */
static int first_line_too_long(int fd, size_t size)
{
    char head[NCP_LINE_MAX];
    if (size < NCP_SOURCE_LONG_LINE_CHECK)
        return 0;
    ssize_t k = pread(fd, head, sizeof head, 0);
    if (k != (ssize_t)sizeof head || memchr(head, '\n', sizeof head))
        return 0;
    return !ncp_source_percent_line(head, sizeof head);
}

/* The file as fstat saw it when read, to notice a change later. */
static void note_file(struct ncp_source *src, const struct stat *st)
{
    src->dev = (uint64_t)st->st_dev;
    src->ino = (uint64_t)st->st_ino;
    src->file_size = (int64_t)st->st_size;
    src->mtime_ns = (int64_t)st->st_mtim.tv_sec * 1000000000 + st->st_mtim.tv_nsec;
}

static int same_file_state(const struct ncp_source *src, int fd)
{
    struct stat st;
    if (fstat(fd, &st) != 0)
        return 0;
    return (int64_t)st.st_size == src->file_size &&
           (int64_t)st.st_mtim.tv_sec * 1000000000 + st.st_mtim.tv_nsec == src->mtime_ns;
}

static int changed(struct ncp_diag *d)
{
    return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "input changed while reading");
}

int ncp_source_open(struct ncp_source *src, const char *path, struct ncp_diag *d)
{
    memset(src, 0, sizeof *src);
    src->fd = -1;
    src->name = path;
    if (strcmp(path, "-") == 0) {
        struct stat st;
        if (fstat(0, &st) == 0 && S_ISREG(st.st_mode))
            note_file(src, &st);   /* `< file`: still the file the outputs must not be */
        uint64_t dev = src->dev, ino = src->ino;
        int rc = read_stream(src, 0, "standard input", d);
        src->name = path;
        src->dev = dev;
        src->ino = ino;
        return rc;
    }
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot open program: %s",
                            strerror(errno));
    struct stat st;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        /* not a regular file (a FIFO, a device): read it like a pipe */
        int rc = read_stream(src, fd, "the program", d);
        close(fd);
        src->name = path;
        src->fd = -1;
        return rc;
    }
    size_t size = (size_t)st.st_size;
    if (first_line_too_long(fd, size)) {
        close(fd);
        return ncp_diag_set(d, NCP_ERR_SYNTAX, 1, 0, "Command too long");
    }
    if (size > 0 && size <= NCP_SOURCE_COPY_MAX && ncp_mem_huge_usable()) {
        struct ncp_text_mem m;
        if (ncp_text_mem_read_file(&m, fd, size) == 0) {
            /* the copy is ours from here on: only a change during the read
             * can make it a mix of two versions */
            struct ncp_source was;
            memset(&was, 0, sizeof was);
            note_file(&was, &st);
            int same = m.len == size && same_file_state(&was, fd);
            close(fd);
            if (!same) {
                ncp_text_mem_free(&m);
                return changed(d);
            }
            adopt_copy(src, &m);
            note_file(src, &st);
            src->fd = -1;
            src->name = path;
            return NCP_OK;
        }
        /* no room for a copy: map it instead */
    }
    const char *text = "";
    if (size > 0) {
        /* not MAP_POPULATE: it maps the whole file before the first block
         * (the process then holds all of it); the readers' windows
         * (ncp_source_window) bring it in and hand it back as they go */
        void *m = mmap(NULL, size, PROT_READ, MAP_PRIVATE, fd, 0);
        if (m == MAP_FAILED) {
            close(fd);
            return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot map program: %s",
                                strerror(errno));
        }
        madvise(m, size, MADV_SEQUENTIAL);
        text = m;
        src->mapped = 1;
    }
    /* a mapped file is read as long as the run lasts: its descriptor stays
     * to tell afterwards whether it changed meanwhile */
    note_file(src, &st);
    if (src->mapped)
        src->fd = fd;
    else
        close(fd);
    src->text = text;
    src->len = size;
    src->end = size;
    find_body(src);
    return NCP_OK;
}

int ncp_source_changed(const struct ncp_source *src)
{
    return src->mapped && src->fd >= 0 && !same_file_state(src, src->fd);
}

void ncp_source_close(struct ncp_source *src)
{
    if (src->mapped) {
        munmap((void *)src->text, src->len);
        if (src->fd >= 0)
            close(src->fd);
    }
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
