/* Block splitting and the feeder's chunks: cutting the program into chunks at
 * line ends and reading each chunk's lines on its own must give exactly the
 * blocks (offsets, lengths, line numbers) that splitting the whole text gives. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ncpar/feeder.h"
#include "ncpar/lex.h"
#include "../../src/feeder/stream_end.h"
#include "../../src/feeder/text_mem.h"

#include <fcntl.h>
#include <unistd.h>

#define MAX_SPANS 4096

static int whole_spans(const struct ncp_source *src, struct ncp_span *out)
{
    int n = 0;
    uint64_t off = src->begin;
    uint32_t line = src->begin_line;
    while (n < MAX_SPANS && ncp_source_span(src, off, line, &out[n]) == 0) {
        off = out[n].next;
        line++;
        n++;
    }
    return n;
}

/* What the pipeline does: chunks of about `want` bytes, line numbers carried
 * from chunk to chunk by counting line ends, and each line of a chunk read by
 * the lexer, which finds its end itself within the chunk (ncp_lex_line). The
 * spans come back from the blocks: offset, line, length, and where the next
 * line starts. */
static int chunked_spans(const struct ncp_source *src, size_t want, struct ncp_span *out)
{
    static struct ncp_block b;
    int n = 0;
    uint64_t off = src->begin;
    uint32_t line = src->begin_line;
    while (off < src->end) {
        uint64_t end = ncp_source_chunk_end(src, off, want);
        assert_true(end > off);
        assert_true(end == src->end || src->text[end - 1] == '\n');
        uint32_t l = line;
        for (uint64_t o = off; n < MAX_SPANS && o < end; n++, l++) {
            size_t next;
            ncp_lex_line(src->text + o, end - o, l, o, &b, &next);
            /* lines here stay far below the block's 16-bit length */
            out[n] = (struct ncp_span){ b.offset, b.length, b.line, o + next };
            assert_true(o + next <= end);
            o += next;
        }
        line += (uint32_t)ncp_source_count_newlines(src, off, end);
        off = end;
    }
    return n;
}

static void expect_same_split(const char *text, size_t len)
{
    struct ncp_source src;
    struct ncp_diag d;
    static struct ncp_span a[MAX_SPANS], b[MAX_SPANS];
    assert_int_equal(ncp_source_from_memory(&src, text, len, "t", &d), 0);
    int na = whole_spans(&src, a);
    static const size_t wants[] = { 1, 2, 7, 63, 64, 65, 200, 4096 };
    for (size_t w = 0; w < sizeof wants / sizeof *wants; w++) {
        int nb = chunked_spans(&src, wants[w], b);
        assert_int_equal(nb, na);
        for (int i = 0; i < na; i++) {
            assert_int_equal(b[i].off, a[i].off);
            assert_int_equal(b[i].len, a[i].len);
            assert_int_equal(b[i].line, a[i].line);
            assert_int_equal(b[i].next, a[i].next);
        }
    }
}

static void test_chunks_split_like_the_whole(void **state)
{
    (void)state;
    static const char *const texts[] = {
        "",
        "\n",
        "G1 X1",
        "G1 X1\n",
        "G1 X1\r\nG1 X2\r\n\r\n\nG1 X3",
        "%\nG0 X1\n\nG1 Y2\n%\nafter the end\n",
        "  %  \nG0 X1\n%",
        "\n\n\n\nG0\n\n",
        "a lone \r carriage return\nnext\n",
    };
    for (size_t i = 0; i < sizeof texts / sizeof *texts; i++)
        expect_same_split(texts[i], strlen(texts[i]));
}

/* Random texts from a small alphabet heavy in line ends, long and short
 * lines, so that chunk boundaries and the 64-byte steps of the counter fall
 * everywhere. */
static void test_random_texts(void **state)
{
    (void)state;
    static const char alphabet[] = "\n\n\r G1X0.5(%;";
    char *text = malloc(3000);
    assert_non_null(text);
    uint64_t seed = 12345;
    for (int iter = 0; iter < 300; iter++) {
        seed = seed * 6364136223846793005u + 1442695040888963407u;
        size_t len = (size_t)(seed >> 33) % 3000;
        for (size_t i = 0; i < len; i++) {
            seed = seed * 6364136223846793005u + 1442695040888963407u;
            int run = (int)((seed >> 60) & 1); /* long lines now and then */
            text[i] = run && i % 97 ? 'x' : alphabet[(seed >> 33) % (sizeof alphabet - 1)];
        }
        expect_same_split(text, len);
    }
    free(text);
}

static void test_count_newlines(void **state)
{
    (void)state;
    char text[300];
    for (size_t i = 0; i < sizeof text; i++)
        text[i] = i % 3 == 0 ? '\n' : 'g';
    struct ncp_source src;
    struct ncp_diag d;
    assert_int_equal(ncp_source_from_memory(&src, text, sizeof text, "t", &d), 0);
    for (uint64_t off = 0; off < 70; off++)
        for (uint64_t end = off; end <= sizeof text; end += 13) {
            uint64_t want = 0;
            for (uint64_t i = off; i < end; i++)
                want += text[i] == '\n';
            assert_int_equal(ncp_source_count_newlines(&src, off, end), want);
        }
}

/* A text of `n` bytes of G-code-like lines, different from run to run of the
 * generator's seed so a copy that drops or repeats a piece cannot match. */
static char *some_text(size_t n, unsigned seed)
{
    char *t = malloc(n);
    assert_non_null(t);
    srand(seed);
    for (size_t i = 0; i < n; i++)
        t[i] = rand() % 23 == 0 ? '\n' : "G01XYZ.-23456789"[rand() % 16];
    return t;
}

static void write_file(const char *path, const char *text, size_t n)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(text, 1, n, f), n);
    assert_int_equal(fclose(f), 0);
}

/* Sizes around the 2 MB page: one byte, just below, at and above a page, and
 * several pages (the huge-page copy, or the mapping where THP is off). */
static void test_open_regular_file(void **state)
{
    (void)state;
    char path[] = "/tmp/ncp-feeder-XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    const size_t sizes[] = { 1, 4095, ((size_t)2 << 20) - 1, (size_t)2 << 20,
                             ((size_t)2 << 20) + 1, ((size_t)5 << 20) + 777 };
    for (size_t i = 0; i < sizeof sizes / sizeof sizes[0]; i++) {
        char *text = some_text(sizes[i], (unsigned)i + 1);
        write_file(path, text, sizes[i]);
        struct ncp_source src;
        struct ncp_diag d;
        assert_int_equal(ncp_source_open(&src, path, &d), NCP_OK);
        assert_int_equal(src.len, sizes[i]);
        assert_memory_equal(src.text, text, sizes[i]);
        if (ncp_mem_huge_usable()) {
            assert_non_null(src.copy);
            assert_int_equal(src.mapped, 0);
            /* 2 MB pages from 512 KB up (ncpar/mem.h), 4 KB ones below */
            uintptr_t page = sizes[i] >= ((size_t)512 << 10) ? (uintptr_t)2 << 20 : 4096;
            assert_int_equal((uintptr_t)src.text % page, 0);
        } else {
            assert_null(src.copy);
            assert_int_equal(src.mapped, 1);
        }
        ncp_source_close(&src);
        assert_null(src.text);
        free(text);
    }
    unlink(path);
}

/* The process's share of a mapped file, from /proc/self/status. */
static long rss_file_kb(void)
{
    char buf[4096];
    int fd = open("/proc/self/status", O_RDONLY);
    if (fd < 0)
        return -1;
    ssize_t n = read(fd, buf, sizeof buf - 1);
    close(fd);
    if (n <= 0)
        return -1;
    buf[n] = '\0';
    const char *at = strstr(buf, "RssFile:");
    return at ? strtol(at + 8, NULL, 10) : -1;
}

/* A sum of every line's bytes and length, read line by line as a reader in
 * file order does, its window moved as it goes; the most file RSS seen. */
static uint64_t read_through(const struct ncp_source *src, long *peak_kb)
{
    struct ncp_source_window w;
    struct ncp_span sp;
    uint64_t sum = 0, off = src->begin;
    uint32_t line = src->begin_line;
    ncp_source_window_start(&w, src, NCP_SOURCE_WINDOW_LAG);
    while (ncp_source_span(src, off, line, &sp) == 0) {
        ncp_source_window_at(&w, off);
        sum = sum * 31 + sp.len;
        for (uint32_t i = 0; i < sp.len; i++)
            sum += (unsigned char)src->text[sp.off + i];
        if (sp.line % 4096 == 0) {
            long kb = rss_file_kb();
            if (kb > *peak_kb)
                *peak_kb = kb;
        }
        off = sp.next;
        line++;
    }
    return sum;
}

/* A program over NCP_SOURCE_COPY_MAX is mapped, and a reader holds only a
 * window of it: the pages behind are handed back as it goes. Read again from
 * the start, the text is the same (the pages come back from the file). */
static void test_mapped_window(void **state)
{
    (void)state;
    char path[] = "/tmp/ncp-feeder-XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    size_t size = NCP_SOURCE_COPY_MAX + ((size_t)16 << 20) + 12345;
    char *text = some_text(size, 7);
    write_file(path, text, size);
    struct ncp_source src, mem;
    struct ncp_diag d;
    assert_int_equal(ncp_source_open(&src, path, &d), NCP_OK);
    assert_int_equal(src.mapped, 1);
    assert_int_equal(ncp_source_from_memory(&mem, text, size, NULL, &d), NCP_OK);
    long base = rss_file_kb(), peak = 0, ignored = 0;
    assert_true(base >= 0);
    uint64_t want = read_through(&mem, &ignored);
    assert_true(read_through(&src, &peak) == want);
    /* the lag, the step being read and the one asked for ahead, and slack
     * for pages the kernel maps around a fault */
    long bound = (long)((NCP_SOURCE_WINDOW_LAG + 4 * NCP_SOURCE_WINDOW_STEP) >> 10);
    assert_true(peak - base <= bound);
    peak = 0;
    assert_true(read_through(&src, &peak) == want);
    ncp_source_close(&src);
    free(text);
    unlink(path);
}

/* A pipe: read to its end through every growth of the copy (2, 4, 8 MB). */
static void test_read_stream_grows(void **state)
{
    (void)state;
    const size_t n = ((size_t)7 << 20) + 12345;
    char *text = some_text(n, 99);
    char path[] = "/tmp/ncp-feeder-XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    write_file(path, text, n);
    fd = open(path, O_RDONLY);
    assert_true(fd >= 0);
    struct ncp_text_mem m;
    assert_int_equal(ncp_text_mem_read_stream(&m, fd, SIZE_MAX, NULL, NULL), 0);
    close(fd);
    assert_int_equal(m.len, n);
    assert_true(m.cap >= n && m.cap % ((size_t)2 << 20) == 0);
    assert_memory_equal(m.text, text, n);
    ncp_text_mem_free(&m);
    assert_null(m.text);

    /* exactly a whole region: the read that finds the end needs a bigger one */
    const size_t whole = (size_t)2 << 20;
    write_file(path, text, whole);
    fd = open(path, O_RDONLY);
    assert_true(fd >= 0);
    assert_int_equal(ncp_text_mem_read_stream(&m, fd, SIZE_MAX, NULL, NULL), 0);
    close(fd);
    assert_int_equal(m.len, whole);
    assert_memory_equal(m.text, text, whole);
    ncp_text_mem_free(&m);

    /* an empty stream is an empty text, not an error */
    write_file(path, text, 0);
    fd = open(path, O_RDONLY);
    assert_true(fd >= 0);
    assert_int_equal(ncp_text_mem_read_stream(&m, fd, SIZE_MAX, NULL, NULL), 0);
    close(fd);
    assert_int_equal(m.len, 0);
    ncp_text_mem_free(&m);
    unlink(path);
    free(text);
}

/* A file that shrank between its size being taken and the read: the copy
 * holds what there is, no stale or zero bytes counted as text. */
static void test_read_file_shorter_than_said(void **state)
{
    (void)state;
    char *text = some_text(1000, 7);
    char path[] = "/tmp/ncp-feeder-XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    write_file(path, text, 1000);
    fd = open(path, O_RDONLY);
    assert_true(fd >= 0);
    struct ncp_text_mem m;
    assert_int_equal(ncp_text_mem_read_file(&m, fd, 5000), 0);
    close(fd);
    assert_int_equal(m.len, 1000);
    assert_memory_equal(m.text, text, 1000);
    ncp_text_mem_free(&m);
    unlink(path);
    free(text);
}

/* Where a pipe's program certainly ends: the bytes to keep, 0 = read on. */
static size_t stream_end_of(const char *text)
{
    struct ncp_stream_end e;
    memset(&e, 0, sizeof e);
    return ncp_stream_end_scan(&e, text, strlen(text));
}

static void test_stream_end(void **state)
{
    (void)state;
    assert_int_equal(stream_end_of("G1 X1\nM2\nG1 X2\n"), 9);
    assert_int_equal(stream_end_of("G1 X1\nN20 m030 (end)\nG1\n"), 21);
    assert_int_equal(stream_end_of("G1 X1\nM2"), 0);            /* the line is not whole yet */
    assert_int_equal(stream_end_of("G1 X1\nM21\nM3\n"), 0);    /* M21, M3: no end */
    assert_int_equal(stream_end_of("(M2)\n#<m2> = 1\n"), 0);   /* a comment, a name */
    assert_int_equal(stream_end_of("/M2\n"), 0);                /* block delete may skip it */
    assert_int_equal(stream_end_of("\n%\nM2\nX1\n%\n"), 6);  /* M2 inside % still ends */
    assert_int_equal(stream_end_of("%\nG1 X1\n%\nG1\n"), 10);
    /* inside a block the M2 may never run; after it, it must */
    assert_int_equal(stream_end_of("o1 if [#1]\nM2\no1 endif\nG1\n"), 0);
    assert_int_equal(stream_end_of("o1 if [#1]\nM2\no1 endif\nM2\n"), 26);
    assert_int_equal(stream_end_of("o2 do\nG1\no2 while [#1]\nM30\n"), 27);
    assert_int_equal(stream_end_of("o<s> sub\nM2\no<s> endsub\nM2\n"), 27);
    /* a call may find its sub below the M2 */
    assert_int_equal(stream_end_of("o<s> call\nM2\n"), 0);
    assert_int_equal(stream_end_of("M98 P100\nM30\n"), 0);
    /* an unterminated line too long to lex ends it; a '%' first line does not */
    char line[600];
    memset(line, 'G', sizeof line - 1);
    line[sizeof line - 1] = 0;
    assert_int_equal(stream_end_of(line), sizeof line - 1);
    line[0] = '%';
    assert_int_equal(stream_end_of(line), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_chunks_split_like_the_whole),
        cmocka_unit_test(test_random_texts),
        cmocka_unit_test(test_count_newlines),
        cmocka_unit_test(test_open_regular_file),
        cmocka_unit_test(test_read_stream_grows),
        cmocka_unit_test(test_read_file_shorter_than_said),
        cmocka_unit_test(test_stream_end),
        cmocka_unit_test(test_mapped_window),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
