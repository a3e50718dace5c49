/* Block splitting and the feeder's chunks: cutting the program into chunks at
 * line ends and reading each chunk's lines on its own must give exactly the
 * blocks (offsets, lengths, line numbers) that splitting the whole text gives. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdlib.h>
#include <string.h>

#include "ncpar/feeder.h"
#include "ncpar/lex.h"

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

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_chunks_split_like_the_whole),
        cmocka_unit_test(test_random_texts),
        cmocka_unit_test(test_count_newlines),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
