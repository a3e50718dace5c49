/* Lexing ahead (src/pipeline/lex_ahead.h): whichever side lexes a chunk, the
 * analyzer gets the very blocks the plain text feed gives, line numbers and
 * errors included, through every kind of line, chunk cut and slot overflow;
 * and the two sides may run on two threads. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../src/pipeline/lex_ahead.h"
#include "ncpar/blocks.h"

/* Lines of every kind the lexer knows, good and bad, CR/LF variants. */
static const char *const kinds[] = {
    "G1 X1.5 Y-2 Z3",
    "g0x0y0",
    "N10 G2 X1 Y1 I0.5 J0.5 F100",
    "#1 = [2 * #2 + 1]",
    "G1 X[#1 + 2] (comment) Y3",
    "(MSG, hello)",
    "; just a comment",
    "",
    "   ",
    "/G1 X9",
    "o100 sub",
    "o100 endsub",
    "G1 X1 X2",          /* Multiple X words: a lexer error */
    "G1 X1..2",          /* bad number */
    "G1 X[1 +",          /* unclosed expression */
    "(unterminated comment",
    "G1 X1\r",           /* CRLF line: the \r is not part of it */
    "M3 S1000 \t",
    "#<name> = 4.25",
};

static size_t make_text(char *buf, size_t cap, unsigned seed, unsigned lines)
{
    size_t n = 0;
    srand(seed);
    for (unsigned i = 0; i < lines; i++) {
        const char *k = kinds[(unsigned)rand() % (sizeof kinds / sizeof *kinds)];
        size_t len = strlen(k);
        if (n + len + 2 >= cap)
            break;
        memcpy(buf + n, k, len);
        n += len;
        buf[n++] = '\n';
    }
    if (seed % 3 == 1 && n > 0)
        n--; /* no line end at the very end */
    return n;
}

/* Two blocks are the same if they pack to the same bytes: packing keeps every
 * field a reader may use (test_lex holds it to that). */
static void assert_same_block(const struct ncp_block *a, const struct ncp_block *b)
{
    static unsigned char pa[NCP_BLOCK_PACK_MAX], pb[NCP_BLOCK_PACK_MAX];
    size_t na = ncp_block_pack(a, pa), nb = ncp_block_pack(b, pb);
    assert_int_equal(a->line, b->line);
    assert_int_equal(a->offset, b->offset);
    assert_int_equal(a->err.code, b->err.code);
    assert_int_equal(a->err.line, b->err.line);
    assert_string_equal(a->err.msg, b->err.msg);
    assert_int_equal(na, nb);
    assert_memory_equal(pa, pb, na);
}

static struct ncp_text_feed ref;
static struct ncp_lex_ahead la;

/* Reads both feeds to their ends, block against block; before each block
 * the helper is called 0-3 times in this thread, one time in `help_every`
 * (0: never; the helper may also be another thread). */
static uint64_t compare_feeds(unsigned help_every)
{
    uint64_t blocks = 0;
    for (;;) {
        if (help_every && (unsigned)rand() % help_every == 0) {
            unsigned times = (unsigned)rand() % 4;
            for (unsigned t = 0; t < times; t++)
                (void)ncp_lex_ahead_help(&la);
        }
        const struct ncp_block *want = ncp_text_feed_next(&ref);
        const struct ncp_block *got = ncp_lex_ahead_next(&la);
        if (!want) {
            assert_null(got);
            break;
        }
        assert_non_null(got);
        assert_same_block(got, want);
        blocks++;
    }
    assert_int_equal(la.feed.blocks, ref.blocks);
    ncp_lex_ahead_finish(&la);
    return blocks;
}

/* The analyzer's feed against the plain one, the helper in the same thread. */
static uint64_t run_against_reference(const struct ncp_source *src, unsigned help_every,
                                      unsigned seed)
{
    ncp_lex_ahead_start(&la, src);
    ncp_text_feed_start(&ref, src);
    srand(seed);
    uint64_t blocks = compare_feeds(help_every);
    assert_int_equal(ncp_lex_ahead_help(&la), 0); /* finished: no more help */
    return blocks;
}

static void test_same_blocks_whoever_lexes(void **state)
{
    (void)state;
    static char text[64 * 1024];
    static const uint64_t chunks[] = { 1, 7, 64, 300, 4096 };
    uint64_t helped = 0;
    for (size_t c = 0; c < sizeof chunks / sizeof *chunks; c++) {
        assert_int_equal(ncp_lex_ahead_init(&la, chunks[c]), 0);
        for (unsigned seed = 0; seed < 40; seed++) {
            size_t len = make_text(text, sizeof text, seed, 50 + seed * 40);
            struct ncp_source src;
            struct ncp_diag d;
            assert_int_equal(ncp_source_from_memory(&src, text, len, "t.ngc", &d), 0);
            run_against_reference(&src, seed % 4, seed);
            helped += la.h_blocks;
            ncp_source_close(&src);
        }
        ncp_lex_ahead_destroy(&la);
    }
    assert_true(helped > 1000); /* the helper's path was taken, and often */
}

/* Lines so short that a chunk's packed blocks overflow its slot: the helper
 * stops there and the analyzer lexes the rest of the chunk itself. */
static void test_slot_overflow(void **state)
{
    (void)state;
    static char text[256 * 1024];
    size_t len = 0;
    while (len + 3 < sizeof text) {
        memcpy(text + len, "X1\n", 3);
        len += 3;
    }
    struct ncp_source src;
    struct ncp_diag d;
    assert_int_equal(ncp_source_from_memory(&src, text, len, "short.ngc", &d), 0);
    assert_int_equal(ncp_lex_ahead_init(&la, 16384), 0);
    uint64_t blocks = run_against_reference(&src, 1, 5);
    assert_int_equal(blocks, len / 3);
    assert_true(la.h_chunks > 0);
    /* a 16 KB chunk has 5461 lines; fewer fit its slot */
    assert_true(la.h_blocks < la.h_chunks * 5461u);
    ncp_lex_ahead_destroy(&la);
    ncp_source_close(&src);
}

/* The two sides on two threads, as in the pipeline: the helper takes what it
 * can while the analyzer reads, and sometimes the analyzer reaches a chunk the
 * helper is still lexing and waits for it. */
struct helper_arg {
    struct ncp_lex_ahead *la;
    _Atomic int stop;
};

static void *helper(void *arg)
{
    struct helper_arg *h = arg;
    while (!atomic_load(&h->stop))
        if (!ncp_lex_ahead_help(h->la))
            sched_yield();
    return NULL;
}

static void test_two_threads(void **state)
{
    (void)state;
    static char text[200 * 1024];
    uint64_t helped = 0;
    assert_int_equal(ncp_lex_ahead_init(&la, 256), 0);
    for (unsigned seed = 0; seed < 30; seed++) {
        size_t len = make_text(text, sizeof text, seed + 100, 4000);
        struct ncp_source src;
        struct ncp_diag d;
        assert_int_equal(ncp_source_from_memory(&src, text, len, "t.ngc", &d), 0);
        ncp_lex_ahead_start(&la, &src);
        ncp_text_feed_start(&ref, &src);
        struct helper_arg h = { &la, 0 };
        pthread_t t;
        assert_int_equal(pthread_create(&t, NULL, helper, &h), 0);
        compare_feeds(0);
        atomic_store(&h.stop, 1);
        pthread_join(t, NULL);
        helped += la.h_blocks;
        ncp_source_close(&src);
    }
    ncp_lex_ahead_destroy(&la);
    printf("two threads: the helper lexed %llu blocks\n", (unsigned long long)helped);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_same_blocks_whoever_lexes),
        cmocka_unit_test(test_slot_overflow),
        cmocka_unit_test(test_two_threads),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
