/* O-word control flow: the order in which blocks reach the analyzer core, and
 * every error, checked against what LinuxCNC's rs274 does with the same
 * program (expected sequences were taken from rs274 -g with a debug comment on
 * each non-O line). A tiny stand-in for the core applies parameter assignments
 * and stops at M2/M30. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "ncpar/feeder.h"
#include "ncpar/lex.h"
#include "../../src/analyzer/flow.h"

/* ---- a feed over an in-memory program, lexing on demand ----------------- */

struct test_feed {
    const struct ncp_source *src;
    uint64_t off;
    uint32_t line;
    int held;
    unsigned delivered;
    struct ncp_block block;
};

static const struct ncp_block *tf_next(void *ctx)
{
    struct test_feed *t = ctx;
    struct ncp_span sp;
    assert_false(t->held); /* the flow releases before asking again */
    if (ncp_source_span(t->src, t->off, t->line, &sp) != 0)
        return NULL;
    ncp_lex_block(t->src->text + sp.off, sp.len, sp.line, sp.off, &t->block);
    t->off = sp.next;
    t->line++;
    t->held = 1;
    t->delivered++;
    return &t->block;
}

static void tf_release(void *ctx)
{
    struct test_feed *t = ctx;
    assert_true(t->held);
    t->held = 0;
}

/* ---- a minimal core ----------------------------------------------------- */

#define MAX_TRACE 4096

struct result {
    int rc;
    struct ncp_diag d;
    char trace[MAX_TRACE];   /* executed lines, space separated */
    unsigned blocks;
    unsigned delivered;
};

static int is_program_end(const struct ncp_block *b)
{
    for (int i = 0; i < b->n_words; i++)
        if (b->words[i].letter == 'M' && b->words[i].v.is_const &&
            (b->words[i].v.value == 2 || b->words[i].v.value == 30))
            return 1;
    return 0;
}

/* rs274 evaluates every value of a block first, then assigns in order. */
static int apply_assignments(struct ncp_params *p, const struct ncp_block *b,
                             struct ncp_diag *d)
{
    struct ncp_param_ops ops = ncp_params_ops(p);
    double val[NCP_BLOCK_MAX_ASSIGN], idx[NCP_BLOCK_MAX_ASSIGN];
    for (int i = 0; i < b->n_assign; i++) {
        const struct ncp_assign *a = &b->assign[i];
        int rc = ncp_expr_eval(b, &a->value, &ops, &val[i], d);
        if (rc == NCP_OK && a->kind == NCP_ASSIGN_NUMBERED)
            rc = ncp_expr_eval(b, &a->index, &ops, &idx[i], d);
        if (rc != NCP_OK)
            return rc;
    }
    for (int i = 0; i < b->n_assign; i++) {
        const struct ncp_assign *a = &b->assign[i];
        int rc = a->kind == NCP_ASSIGN_NUMBERED
                     ? ncp_params_set(p, (int)idx[i], val[i], d)
                     : ncp_params_set_named(p, b->pool + a->name_off, a->name_len,
                                            val[i], d);
        if (rc != NCP_OK)
            return rc;
    }
    return NCP_OK;
}

static void run_cfg(const char *text, const struct ncp_analyzer_cfg *cfg, struct result *r)
{
    struct ncp_source src;
    struct ncp_diag d;
    memset(r, 0, sizeof *r);
    assert_int_equal(ncp_source_from_memory(&src, text, strlen(text), "t.ngc", &d), NCP_OK);
    struct test_feed *tf = calloc(1, sizeof *tf);
    assert_non_null(tf);
    tf->src = &src;
    tf->off = src.begin;
    tf->line = src.begin_line;
    struct ncp_block_feed feed = { .ctx = tf, .next = tf_next, .release = tf_release,
                                   .src = &src };
    struct ncp_params *p = ncp_params_new();
    struct ncp_flow *f = ncp_flow_new(&feed, p, cfg);
    assert_non_null(f);
    size_t used = 0;
    for (;;) {
        const struct ncp_block *b = NULL;
        r->rc = ncp_flow_next(f, &b, &r->d);
        if (r->rc != NCP_OK)
            break;
        if (b->err.code != NCP_OK) { /* a plain line the lexer refused: ours to report */
            r->rc = b->err.code;
            r->d = b->err;
            break;
        }
        r->blocks++;
        if (used + 12 < sizeof r->trace)
            used += (size_t)snprintf(r->trace + used, sizeof r->trace - used, "%s%u",
                                     used ? " " : "", b->line);
        r->rc = apply_assignments(p, b, &r->d);
        if (r->rc != NCP_OK)
            break;
        if (is_program_end(b)) {
            ncp_flow_reset(f);
            r->rc = NCP_END;
            break;
        }
    }
    r->delivered = tf->delivered;
    ncp_flow_free(f);
    assert_false(tf->held);
    ncp_params_free(p);
    free(tf);
}

static void run(const char *text, struct result *r)
{
    run_cfg(text, NULL, r);
}

static void expect_trace(const char *text, const char *trace)
{
    struct result r;
    run(text, &r);
    if (r.rc != NCP_END)
        fail_msg("unexpected status %d: %u:%u: %s (trace %s)", r.rc, r.d.line, r.d.col,
                 r.d.msg, r.trace);
    assert_string_equal(r.trace, trace);
}

static void expect_error(const char *text, int code, uint32_t line, const char *msg,
                         const char *trace)
{
    struct result r;
    run(text, &r);
    if (r.rc != code)
        fail_msg("status %d, want %d: %u: %s (trace %s)", r.rc, code, r.d.line, r.d.msg,
                 r.trace);
    assert_string_equal(r.d.msg, msg);
    assert_int_equal(r.d.line, line);
    assert_string_equal(r.trace, trace);
}

/* ---- execution order ------------------------------------------------------ */

static void test_straight(void **state)
{
    (void)state;
    expect_trace("g0x1\ng0x2\nm2", "1 2 3");
}

static void test_if(void **state)
{
    (void)state;
    expect_trace("o1 if [1]\ng0x1\no1 else\ng0x2\no1 endif\nm2", "2 6");
    expect_trace("o1 if [0]\ng0x1\no1 else\ng0x2\no1 endif\nm2", "4 6");
    expect_trace("#1=2\no1 if [#1 eq 1]\ng0x1\no1 elseif [#1 eq 2]\ng0x2\n"
                 "o1 elseif [#1 eq 2]\ng0x3\no1 else\ng0x4\no1 endif\nm2",
                 "1 5 11");
    expect_trace("o1 if [1]\no2 if [0]\ng0x1\no2 else\ng0x2\no2 endif\no1 else\ng0x3\n"
                 "o1 endif\nm2",
                 "5 10");
}

static void test_loops(void **state)
{
    (void)state;
    expect_trace("#1=0\no1 while [#1 lt 3]\n#1=[#1+1]\no1 endwhile\nm2", "1 3 3 3 5");
    expect_trace("o1 while [0]\ng0x1\no1 endwhile\nm2", "4");
    expect_trace("#1=0\no1 do\n#1=[#1+1]\no1 while [#1 lt 3]\nm2", "1 3 3 3 5");
    expect_trace("o1 do\ng0x1\no1 while [0]\nm2", "2 4");
    expect_trace("o1 repeat [3]\ng0x1\no1 endrepeat\nm2", "2 2 2 4");
    expect_trace("o1 repeat [0]\ng0x1\no1 endrepeat\nm2", "4");
    expect_trace("#1=0\no1 while [#1 lt 2]\n#1=[#1+1]\no2 repeat [2]\ng0x1\no2 endrepeat\n"
                 "o1 endwhile\nm2",
                 "1 3 5 5 3 5 5 8");
}

static void test_break_continue(void **state)
{
    (void)state;
    expect_trace("#1=0\no1 while [1]\n#1=[#1+1]\no2 if [#1 ge 3]\no1 break\no2 endif\n"
                 "g0x1\no1 endwhile\nm2",
                 "1 3 7 3 7 3 9");
    expect_trace("#1=0\no1 while [#1 lt 4]\n#1=[#1+1]\no2 if [#1 eq 2]\no1 continue\n"
                 "o2 endif\ng0x1\no1 endwhile\nm2",
                 "1 3 7 3 3 7 3 7 9");
    expect_trace("#1=0\no1 do\n#1=[#1+1]\no2 if [#1 lt 3]\no1 continue\no2 endif\ng0x1\n"
                 "o1 while [#1 lt 5]\nm2",
                 "1 3 3 3 7 3 7 3 7 9");
    /* rs274 keeps its break flag after leaving a while loop with break, so the
     * next do/while loop runs only once */
    expect_trace("o1 while [1]\no1 break\no1 endwhile\n#1=0\no2 do\n#1=[#1+1]\n"
                 "o2 while [#1 lt 3]\nm2",
                 "4 6 8");
}

static void test_calls(void **state)
{
    (void)state;
    expect_trace("o1 sub\ng0x1\no1 endsub\ng0x2\no1 call\ng0x3\no1 call\nm2", "4 2 6 2 8");
    expect_trace("o<s> sub\n#<_r>=[#1+#2]\no<s> endsub\no<s> call [1] [2]\n#3=#<_r>\n"
                 "o3 if [#3 ne 3]\ng0x9\no3 endif\nm2",
                 "2 5 9");
    expect_trace("g0x1\no1 call\ng0x2\nm2\no1 sub\ng0x3\no1 endsub", "1 6 3 4");
    expect_trace("o1 sub\no2 repeat [2]\ng0x1\no2 endrepeat\no1 endsub\no2 repeat [2]\n"
                 "o1 call\no2 endrepeat\nm2",
                 "3 3 3 3 9");
    expect_trace("o1 sub\no2 while [1]\ng0x1\no1 return\no2 endwhile\no1 endsub\no1 call\n"
                 "g0x2\nm2",
                 "3 8 9");
    expect_trace("o1 sub\ng0x1\no2 call\ng0x3\no1 endsub\no2 sub\ng0x2\no2 endsub\no1 call\n"
                 "m2",
                 "2 7 4 10");
    /* if/loop labels are local to the subroutine they are written in */
    expect_trace("o1 sub\no100 if [1]\ng0x1\no100 endif\no1 endsub\no2 sub\no100 if [1]\n"
                 "g0x2\no100 endif\no2 endsub\no1 call\no2 call\no100 if [1]\ng0x3\n"
                 "o100 endif\nm2",
                 "3 8 14 16");
}

/* Fanuc-style subs (rs274 2.9): O100 ... M99, called with M98 P100 [L n] */
static void test_fanuc_calls(void **state)
{
    (void)state;
    /* the sub after the program end is found by reading on, then by its label */
    expect_trace("g0x1\nm98 p100\ng0x2\nm98 p100\nm30\no100\ng0x3\nm99", "1 7 3 7 5");
    /* L repeats: the M98 line runs again; L0 enters the level and reads on */
    expect_trace("m98 p100 l3\nm30\no100\ng0x3\nm99", "4 4 4 2");
    expect_trace("m98 p1 l0\ng0x1\nm99\nm30", "2 2 3 4");
    /* the same counter rule for repeats inside repeats: 2 x (1 + 2) */
    expect_trace("m98 p1 l2\nm30\no1\ng0x1\nm98 p2 l2\nm99\no2\ng0x2\nm99",
                 "4 8 8 4 8 8 2");
    /* #1..#30 are shared with the caller, P is read anew on every repeat */
    expect_trace("#1=1\nm98 p#1 l2\nm30\no1\n#1=2\nm99\no2\ng0x2\nm99", "1 5 8 3");
    /* run into at level 0: a bare O line defines nothing; M99 there is a block */
    expect_trace("g0x1\no100\ng0x2\nm99\nm30", "1 3 4 5");
    /* M98 lines are read where rs274 skips, but not acted on */
    expect_trace("o1 if [0]\nm98 p5\no1 endif\nm30", "4");
}

static void test_fanuc_errors(void **state)
{
    (void)state;
    expect_error("o1 if [0]\nm98\no1 endif\nm30", NCP_ERR_SEMANTIC, 2,
                 "Found 'm98' code with no P-word", "");
    expect_error("m98 p1.5\nm30", NCP_ERR_SEMANTIC, 1, "Non integer value for integer", "");
    expect_error("o100 call\nm30\no100\ng0x1\nm99", NCP_ERR_SEMANTIC, 3,
                 "Fanuc 'O....' subroutine must be called with 'M98'", "");
    expect_error("m98 p100\nm30\no100 sub\nm99", NCP_ERR_SEMANTIC, 3,
                 "'O.... sub' subroutine must be called with 'O.... call'", "");
    expect_error("m98 p100\nm30\no100\ng0x1\no100 endsub", NCP_ERR_SEMANTIC, 5,
                 "Fanuc 'O....' subroutine definition must end with 'M99'", "4");
    expect_error("o100 call\nm30\no100 sub\ng0x1\nm99\no100 endsub", NCP_ERR_SEMANTIC, 5,
                 "'O.... endsub' or 'O.... return' must follow 'O.... sub' subroutine "
                 "definition", "4");
    expect_error("m98 p1\nm30\no1\nm99 g0x1", NCP_ERR_SEMANTIC, 4,
                 "Unexpected character after O-word", "");
    expect_error("m98 p1\nm30\no1\nm98 p1\nm99", NCP_ERR_LIMIT, 4,
                 "Too many subroutine levels", "");
    expect_error("m98 p7\nm30", NCP_ERR_SEMANTIC, 1,
                 "EOF in file:t.ngc seeking o-word: o<7> from line: 1", "");
}

static void test_return_values(void **state)
{
    (void)state;
    expect_trace("o<fact> sub\no1 if [#1 le 1]\no<fact> return [1]\no1 endif\n"
                 "o<fact> call [#1-1]\no<fact> return [#1*#<_value>]\no<fact> endsub\n"
                 "o<fact> call [5]\no2 if [#<_value> ne 120]\ng0x9\no2 endif\nm2",
                 "12");
    /* endsub without a value clears #<_value_returned> */
    expect_trace("o1 sub\no1 return [7]\no1 endsub\no2 sub\no2 endsub\no1 call\n"
                 "o3 if [#<_value_returned>]\ng0x1\no3 endif\no2 call\n"
                 "o4 if [#<_value_returned>]\ng0x2\no4 endif\nm2",
                 "8 14");
}

static void test_skipped_text_not_evaluated(void **state)
{
    (void)state;
    expect_trace("o1 if [0]\ng0x1 #<nope>\no2 if [#<nope>]\no2 endif\no1 endif\nm2", "6");
    expect_error("o1 if [#<nope>]\no1 endif\nm2", NCP_ERR_SEMANTIC, 1,
                 "Named parameter #<nope> not defined", "");
}

static void test_line_endings_and_block_delete(void **state)
{
    (void)state;
    expect_trace("#1=0\r\no1 while [#1 lt 2]\r\n#1=[#1+1]\r\no1 endwhile\r\nm2\r\n",
                 "1 3 3 5");
    /* rs274 -g runs with the block delete switch off */
    expect_trace("/g0x1\ng0x2\nm2", "1 2 3");
    expect_trace("%\ng0x1\no1 repeat [2]\ng0x2\no1 endrepeat\nm2\n%\n", "2 4 4 6");
}

/* A loop body larger than the block cache, and a long loop. */
static void test_big_and_long_loops(void **state)
{
    (void)state;
    size_t cap = 64 * 1024;
    char *text = malloc(cap);
    assert_non_null(text);
    size_t n = (size_t)snprintf(text, cap, "#1=0\no1 while [#1 lt 3]\n#1=[#1+1]\n");
    for (int i = 0; i < 600; i++)
        n += (size_t)snprintf(text + n, cap - n, "g0x%d\n", i);
    n += (size_t)snprintf(text + n, cap - n, "o1 endwhile\nm2\n");
    assert_true(n < cap);
    struct result r;
    run(text, &r);
    assert_int_equal(r.rc, NCP_END);
    assert_int_equal(r.blocks, 1 + 3 * 601 + 1);
    /* the feed delivers every line once, however often it runs */
    assert_int_equal(r.delivered, 605);

    run("#1=0\no1 while [#1 lt 100000]\n#1=[#1+1]\no1 endwhile\nm2", &r);
    assert_int_equal(r.rc, NCP_END);
    assert_int_equal(r.blocks, 100002);
    free(text);
}

/* ---- limits --------------------------------------------------------------- */

static void test_loop_limit(void **state)
{
    (void)state;
    struct ncp_analyzer_cfg cfg = { .max_loop_iterations = 100 };
    struct result r;
    run_cfg("g0x1\no1 while [1]\ng0x1\no1 endwhile\nm2", &cfg, &r);
    assert_int_equal(r.rc, NCP_ERR_LIMIT);
    assert_int_equal(r.d.line, 2);
    assert_non_null(strstr(r.d.msg, "loop o1 at line 2"));
    assert_int_equal(r.blocks, 101);

    run_cfg("o<x> do\no<x> while [1]\nm2", &cfg, &r);
    assert_int_equal(r.rc, NCP_ERR_LIMIT);
    assert_non_null(strstr(r.d.msg, "loop o<x> at line 1"));

    run_cfg("o1 repeat [1000]\no1 endrepeat\nm2", &cfg, &r);
    assert_int_equal(r.rc, NCP_ERR_LIMIT);

    /* the count is per run of the loop, not over the whole program */
    run_cfg("o2 repeat [3]\no1 repeat [60]\ng0x1\no1 endrepeat\no2 endrepeat\nm2", &cfg, &r);
    assert_int_equal(r.rc, NCP_END);
    assert_int_equal(r.blocks, 181);

    /* rs274 keeps its continue flag after a do/while loop: an exhausted
     * repeat then starts over once more (q1), or for ever (q2) */
    expect_trace("#1=0\no1 do\n#1=[#1+1]\no2 if [#1 lt 2]\no1 continue\no2 endif\n"
                 "o1 while [#1 lt 2]\no3 repeat [2]\ng0x1\no3 endrepeat\nm2",
                 "1 3 3 9 9 9 9 11");
    run_cfg("o3 repeat [2]\n#1=0\no1 do\n#1=[#1+1]\no2 if [#1 lt 2]\no1 continue\n"
            "o2 endif\no1 while [#1 lt 2]\no3 endrepeat\nm2", &cfg, &r);
    assert_int_equal(r.rc, NCP_ERR_LIMIT);
    assert_non_null(strstr(r.d.msg, "loop o3 at line 1"));

    /* ... even when each run is left by return */
    run_cfg("o1 sub\no2 while [1]\ng0x1\no1 return\no2 endwhile\no1 endsub\n"
            "o3 repeat [15]\no4 repeat [10]\no1 call\no4 endrepeat\no3 endrepeat\nm2",
            &cfg, &r);
    assert_int_equal(r.rc, NCP_END);
    assert_int_equal(r.blocks, 151);
}

/* A stop request ends a run within 64 blocks: in a loop of long laps or
 * short ones, in a loop sent back by a jump, in a loop too short to count
 * much and in a program without loops; a flag that stays clear changes
 * nothing. */
static int read_flag(void *ctx)
{
    return *(const int *)ctx;
}

static void test_loop_cancel(void **state)
{
    (void)state;
    int stop = 1;
    struct ncp_analyzer_cfg cfg = { .cancel = read_flag, .cancel_ctx = &stop };
    struct result r;
    run_cfg("#1=0\no1 while [#1 lt 1000000]\n#1=[#1+1]\no1 endwhile\ng0x1\nm2", &cfg, &r);
    assert_int_equal(r.rc, NCP_ERR_LIMIT);
    assert_true(r.d.line >= 2 && r.d.line <= 4);
    assert_non_null(strstr(r.d.msg, "stopped on request at line"));
    assert_true(r.blocks < 64);

    /* the laps of a loop sent back by a jump count too */
    run_cfg("o1 repeat [1000000]\no1 endrepeat\nm2", &cfg, &r);
    assert_int_equal(r.rc, NCP_ERR_LIMIT);
    assert_non_null(strstr(r.d.msg, "stopped on request"));

    /* an outer loop of inner loops too short to reach a lap count */
    run_cfg("o1 repeat [1000000]\no2 repeat [3]\ng0x1\no2 endrepeat\no1 endrepeat\nm2",
            &cfg, &r);
    assert_int_equal(r.rc, NCP_ERR_LIMIT);
    assert_true(r.blocks < 64);

    /* between the blocks of a program without loops */
    char prog[200 * 8 + 8];
    size_t at = 0;
    for (int i = 0; i < 200; i++)
        at += (size_t)snprintf(prog + at, sizeof prog - at, "g0x%d\n", i % 10);
    snprintf(prog + at, sizeof prog - at, "m2");
    run_cfg(prog, &cfg, &r);
    assert_int_equal(r.rc, NCP_ERR_LIMIT);
    assert_true(r.d.line >= 1 && r.d.line <= 64);
    assert_true(r.blocks < 64);

    stop = 0;
    run_cfg("#1=0\no1 while [#1 lt 100000]\n#1=[#1+1]\no1 endwhile\nm2", &cfg, &r);
    assert_int_equal(r.rc, NCP_END);
}

/* ---- subroutine files ---------------------------------------------------- */

static void write_file(const char *dir, const char *name, const char *text)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *fp = fopen(path, "w");
    assert_non_null(fp);
    fputs(text, fp);
    fclose(fp);
}

/* o<name> call of a sub not defined yet reads name.ngc from the subroutine
 * path (after the current folder), from its start: a sub defined before the
 * called one there is skipped and stays unknown, as in rs274; the called one
 * is known from then on, so a second call jumps to it. Lines count in the
 * file they are in. */
static void test_sub_files(void **state)
{
    (void)state;
    char dir[] = "/tmp/ncp-flow-subs.XXXXXX";
    assert_non_null(mkdtemp(dir));
    write_file(dir, "tflow_a.ngc", "o<tflow_x> sub\ng0x9\no<tflow_x> endsub\n"
                                   "o<tflow_a> sub\ng0x#1\no<tflow_b> call\no<tflow_a> endsub\n");
    write_file(dir, "tflow_b.ngc", "o<tflow_b> sub\no1 repeat [2]\ng0y1\no1 endrepeat\n"
                                   "o<tflow_b> endsub\nm2\n");
    write_file(dir, "tflow_bad.ngc", "o<tflow_bad> sub\ng0x1\ng2x2\no<tflow_bad> endsub\n");
    char path[600];
    snprintf(path, sizeof path, "/nonexistent-folder:%s", dir);
    struct ncp_analyzer_cfg cfg = { .subroutine_path = path };
    struct result r;
    run_cfg("g0x0\no<tflow_a> call [1]\no<tflow_a> call [2]\nm2", &cfg, &r);
    assert_int_equal(r.rc, NCP_END);
    assert_string_equal(r.trace, "1 5 3 3 5 3 3 4");
    /* the sub skipped over in tflow_a.ngc is not defined: read on for it */
    run_cfg("o<tflow_a> call [1]\no<tflow_x> call\nm2", &cfg, &r);
    assert_int_equal(r.rc, NCP_ERR_SEMANTIC);
    assert_string_equal(r.d.msg, "EOF in file:t.ngc seeking o-word: o<tflow_x> from line: 2");
    /* without the path, the files are not found */
    run_cfg("o<tflow_a> call [1]\nm2", NULL, &r);
    assert_int_equal(r.rc, NCP_ERR_SEMANTIC);
    /* a file without the sub: searched to its end, from its line 0 as
     * rs274 says, and reported at the call */
    write_file(dir, "tflow_c.ngc", "g0x7\n");
    run_cfg("g0x1\n  o<tflow_c> call\nm2", &cfg, &r);
    assert_int_equal(r.rc, NCP_ERR_SEMANTIC);
    assert_int_equal(r.d.line, 2);
    assert_int_equal(r.d.col, 3);
    assert_non_null(strstr(r.d.msg, "tflow_c.ngc seeking o-word: o<tflow_c> from line: 0"));
    const char *names[] = { "tflow_a.ngc", "tflow_b.ngc", "tflow_bad.ngc", "tflow_c.ngc" };
    for (unsigned k = 0; k < 4; k++) {
        snprintf(path, sizeof path, "%s/%s", dir, names[k]);
        remove(path);
    }
    rmdir(dir);
}

/* Diagnostics name subroutine files through a table that outlives the run. */
static void test_diag_file_names(void **state)
{
    (void)state;
    unsigned a = ncp_diag_file_tag("dir/a.ngc"), b = ncp_diag_file_tag("dir/b.ngc");
    assert_true(a > 0 && b > 0 && a != b);
    assert_int_equal(ncp_diag_file_tag("dir/a.ngc"), a);
    assert_string_equal(ncp_diag_file_of_tag(a), "dir/a.ngc");
    assert_ptr_equal(ncp_diag_file_of_tag(ncp_diag_file_tag("dir/b.ngc")),
                     ncp_diag_file_of_tag(b));
    assert_null(ncp_diag_file_of_tag(0));
    assert_null(ncp_diag_file_of_tag(NCP_DIAG_FILE_TAGS + 1));
    struct ncp_diag d;
    d.file = "x";
    ncp_diag_set(&d, NCP_ERR_SEMANTIC, 1, 1, "m");
    assert_null(d.file);
}

static void test_call_depth(void **state)
{
    (void)state;
    expect_error("o1 sub\ng0x1\no1 call\no1 endsub\no1 call\nm2", NCP_ERR_LIMIT, 3,
                 "Too many subroutine levels", "2 2 2 2 2 2 2 2 2");
    struct ncp_analyzer_cfg cfg = { .max_call_depth = 3 };
    struct result r;
    run_cfg("o1 sub\ng0x1\no1 call\no1 endsub\no1 call\nm2", &cfg, &r);
    assert_int_equal(r.rc, NCP_ERR_LIMIT);
    assert_string_equal(r.trace, "2 2");
}

/* ---- errors, with rs274's wording (its "LINE: " prefix is in d.line) ----- */

static void test_label_errors(void **state)
{
    (void)state;
    expect_error("o1 endwhile\nm2", NCP_ERR_SEMANTIC, 1,
                 "undefined O-word label: 'o1 endwhile'", "");
    expect_error("o1 while [1]\no2 endwhile\nm2", NCP_ERR_SEMANTIC, 2,
                 "undefined O-word label: 'o2 endwhile'", "");
    expect_error("o1 while [1]\no1 endrepeat\nm2", NCP_ERR_SEMANTIC, 2,
                 "no matching label: 'o1 endrepeat' (found 'while' in line 1)", "");
    expect_error("o1 repeat [3]\no1 break\no1 endrepeat\nm2", NCP_ERR_SEMANTIC, 2,
                 "no matching while/do label: 'o1 break' (found 'repeat' in line 1)", "");
    expect_error("o1 if [1]\no1 continue\nm2", NCP_ERR_SEMANTIC, 2,
                 "no matching while/do label: 'o1 continue' (found 'if' in line 1)", "");
    expect_error("o1 if [1]\no1 endif\no1 if [1]\no1 endif\nm2", NCP_ERR_SEMANTIC, 3,
                 "duplicate O-word label - already defined in line 1: 'o1 if [1]'", "");
    expect_error("o1 while [0]\no1 endwhile\no1 while [0]\no1 endwhile\nm2",
                 NCP_ERR_SEMANTIC, 3,
                 "duplicate O-word label: 'o1 while [0]' - defined in line 1", "");
    expect_error("o1 repeat [1]\no1 endrepeat\no1 repeat [1]\no1 endrepeat\nm2",
                 NCP_ERR_SEMANTIC, 3,
                 "duplicate O-word label: 'o1 repeat [1]' - defined in line 1", "");
    expect_error("o1 else\nm2", NCP_ERR_SEMANTIC, 1, "undefined O-word label: 'o1 else'", "");
    expect_error("o1 elseif [1]\nm2", NCP_ERR_SEMANTIC, 1,
                 "undefined O-word label: 'o1 elseif [1]'", "");
    expect_error("o1 while [1]\no1 else\nm2", NCP_ERR_SEMANTIC, 2,
                 "no matching 'if' label: 'o1 else' (found 'while' in line 1)", "");
    expect_error("o1 while [0]\no1 endif\nm2", NCP_ERR_SEMANTIC, 2,
                 "no matching label: '#1' (found 'while' in line 1): 'o1 endif'", "");
}

static void test_sub_errors(void **state)
{
    (void)state;
    expect_error("g0x1\no1 return\nm2", NCP_ERR_SEMANTIC, 2,
                 "not in a subroutine definition: 'o1 return'", "1");
    expect_error("o1 endsub  \nm2", NCP_ERR_SEMANTIC, 1,
                 "not in a subroutine definition: 'o1 endsub'", "");
    /* once a call has returned to the main program, rs274 ignores a stray
     * return there, and rejects a stray endsub with other words */
    expect_error("o1 sub\no1 endsub\no1 call\no2 return\ng0x1\no3 endsub\nm2",
                 NCP_ERR_SEMANTIC, 6, "Not in subroutine definition", "5");
    expect_error("o1 sub\no1 endsub\no1 call\no2 return\ng0x1\no3 sub\no3 endsub\n"
                 "o2 return\ng0x2\nm2",
                 NCP_ERR_SEMANTIC, 8, "not in a subroutine definition: 'o2 return'", "5");
    expect_error("o1 sub\no2 sub\no2 endsub\no1 endsub\nm2", NCP_ERR_SEMANTIC, 2,
                 "Nested subroutine definition", "");
    expect_error("o1 sub\no1 endsub\no1 sub\no1 endsub\nm2", NCP_ERR_SEMANTIC, 3,
                 "File:t.ngc line:3 redefining sub: o|1| already defined in file:t.ngc", "");
    expect_error("o5 call\ng0x2\no5 sub\ng0x1\no5 endsub\nm2", NCP_ERR_SEMANTIC, 3,
                 "File:t.ngc line:3 sub: o|5| found in illegal location", "4 2");
    expect_error("o1 while [1]\no1 sub\no1 endsub\no1 endwhile\nm2", NCP_ERR_SEMANTIC, 2,
                 "File:t.ngc line:2 sub: o|1| found in illegal location", "");
}

static void test_end_of_file(void **state)
{
    (void)state;
    expect_error("g0x3\no5 call\ng0x4", NCP_ERR_SEMANTIC, 2,
                 "EOF in file:t.ngc seeking o-word: o<5> from line: 2", "1");
    expect_error("%\ng0x3\no5 call\ng0x4\n%", NCP_ERR_SEMANTIC, 5,
                 "Failed to find sub 'O5' before EOF", "2");
    expect_error("%\ng0x1\no1 if [0]\ng0x2\n%", NCP_ERR_SEMANTIC, 5,
                 "Failed to find sub 'O#1' before EOF", "2");
    /* without '%', the end of the text is the core's to report */
    struct result r;
    run("g0x1\no1 if [0]\ng0x2", &r);
    assert_int_equal(r.rc, NCP_END);
    assert_string_equal(r.trace, "1");
    run("o1 while [1]\ng0x2", &r);
    assert_int_equal(r.rc, NCP_END);
    assert_string_equal(r.trace, "2");
}

static void test_syntax_errors(void **state)
{
    (void)state;
    struct result r;
    run("g0x1\no1 if [1\no1 endif\nm2", &r);
    assert_int_equal(r.rc, NCP_ERR_SYNTAX);
    assert_int_equal(r.d.line, 2);
    run("g0x1\ng0x[1\nm2", &r);
    assert_int_equal(r.rc, NCP_ERR_SYNTAX);
    assert_int_equal(r.d.line, 2);
    /* rs274 does not parse what it skips */
    expect_trace("o1 if [0]\ng0x[1\no1 endif\nm2", "4");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_straight),
        cmocka_unit_test(test_if),
        cmocka_unit_test(test_loops),
        cmocka_unit_test(test_break_continue),
        cmocka_unit_test(test_calls),
        cmocka_unit_test(test_fanuc_calls),
        cmocka_unit_test(test_fanuc_errors),
        cmocka_unit_test(test_return_values),
        cmocka_unit_test(test_skipped_text_not_evaluated),
        cmocka_unit_test(test_line_endings_and_block_delete),
        cmocka_unit_test(test_big_and_long_loops),
        cmocka_unit_test(test_loop_limit),
        cmocka_unit_test(test_loop_cancel),
        cmocka_unit_test(test_call_depth),
        cmocka_unit_test(test_sub_files),
        cmocka_unit_test(test_diag_file_names),
        cmocka_unit_test(test_label_errors),
        cmocka_unit_test(test_sub_errors),
        cmocka_unit_test(test_end_of_file),
        cmocka_unit_test(test_syntax_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
