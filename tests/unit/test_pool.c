/* The pre-started pipeline: one pool runs program after program (good ones,
 * errors mid-way, an early M2 with more text behind it, an empty file, a
 * failing writer) and every run must give what the serial reference gives,
 * byte for byte, in every placement. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ncpar/pipeline.h"

struct text_out {
    char *buf;
    size_t len, cap;
    long fail_after; /* emit fails at this slot (-1: never) */
    long slots;
};

static int collect(void *ctx, const struct ncp_cmd *cmd)
{
    struct text_out *t = ctx;
    if (t->fail_after >= 0 && t->slots++ == t->fail_after)
        return -1;
    if (t->len + cmd->out_len > t->cap) {
        t->cap = (t->len + cmd->out_len) * 2 + 4096;
        t->buf = realloc(t->buf, t->cap);
        assert_non_null(t->buf);
    }
    memcpy(t->buf + t->len, cmd->out, cmd->out_len);
    t->len += cmd->out_len;
    return 0;
}

struct outcome {
    int rc;
    struct ncp_diag d;
    struct text_out text;
    struct ncp_run_stats st;
};

static void run_one(struct ncp_pipeline_pool *pool, const char *prog, long fail_after,
                    struct outcome *o)
{
    struct ncp_source src;
    struct ncp_diag d;
    memset(o, 0, sizeof *o);
    o->text.fail_after = fail_after;
    assert_int_equal(ncp_source_from_memory(&src, prog, strlen(prog), "t.ngc", &d), 0);
    struct ncp_analyzer_cfg cfg = { .max_loop_iterations = 1000 };
    struct ncp_output out = { .ctx = &o->text, .emit = collect };
    o->rc = pool ? ncp_pipeline_pool_run(pool, &src, &cfg, &out, &o->st, &o->d)
                 : ncp_serial_run(&src, &cfg, &out, &o->st, &o->d);
    ncp_source_close(&src);
}

static char *big_program(int blocks)
{
    size_t cap = (size_t)blocks * 48 + 64;
    char *s = malloc(cap);
    assert_non_null(s);
    size_t n = (size_t)snprintf(s, cap, "G21 G90 F600\n");
    for (int i = 0; i < blocks; i++)
        n += (size_t)snprintf(s + n, cap - n, i % 10 ? "G1 X%d.5 Y%d Z-1\n"
                                                       : "G2 X%d Y%d I1 J0\n",
                              i % 97, (i * 7) % 89);
    snprintf(s + n, cap - n, "M2\n");
    return s;
}

static void test_runs_equal_serial(void **state)
{
    (void)state;
    char *big = big_program(20000);
    const char *progs[] = {
        "G21\nG1 X1 Y2 F100\nG2 X3 Y2 I1 J0\n#1 = 5\no1 while [#1 GT 0]\nG1 X#1\n#1 = [#1 - 1]\no1 endwhile\nM2\n",
        "G1 X1 F100\nG1 X2 Y\nG1 X3\nM2\n",            /* error mid-way */
        "G0 X1\nM2\nG1 X2 F10\n(more after the end)\nG0 Y1\n", /* ends early */
        "",                                                 /* empty file */
        "G1 X1 F100\n",                                     /* no M2, no percent */
        big,
        "%\nG0 X1\n%\n",
    };
    /* the fourth: the analyzer writes the output itself; the fifth: it lexes
     * the text itself (no feeder, no lexer threads) */
    static const int lexers[] = { 1, 2, 3, 2, 0 }, execs[] = { 0, 1, 2, 0, 0 };
    for (int c = 0; c < 5; c++) {
        struct ncp_thread_map map;
        ncp_thread_map_default(&map, c == 1 ? NCP_MODE_ATT : NCP_MODE_DET, lexers[c], execs[c]);
        map.inline_output = c == 3;
        map.string_rows = 4;  /* small rings: every run wraps and waits */
        map.parsed_rows = 4;
        map.cmd_slots = 8;
        struct ncp_diag d;
        struct ncp_pipeline_pool *pool = ncp_pipeline_pool_new(&map, &d);
        assert_non_null(pool);
        for (int round = 0; round < 3; round++) {
            for (size_t k = 0; k < sizeof progs / sizeof progs[0]; k++) {
                struct outcome want, got;
                run_one(NULL, progs[k], -1, &want);
                run_one(pool, progs[k], -1, &got);
                assert_int_equal(got.rc, want.rc);
                assert_int_equal(got.d.line, want.d.line);
                assert_string_equal(got.d.msg, want.d.msg);
                assert_int_equal(got.text.len, want.text.len);
                if (want.text.len)
                    assert_memory_equal(got.text.buf, want.text.buf, want.text.len);
                assert_int_equal(got.st.setup_ms, 0.0);
                assert_int_equal(got.st.commands, want.st.commands);
                free(want.text.buf);
                free(got.text.buf);
            }
        }
        /* a writer that fails stops the run; the next run is whole again */
        struct outcome failed, after;
        run_one(pool, big, 10, &failed);
        assert_int_equal(failed.rc, NCP_ERR_IO);
        free(failed.text.buf);
        run_one(pool, progs[0], -1, &after);
        assert_int_equal(after.rc, NCP_OK);
        assert_true(after.text.len > 0);
        free(after.text.buf);
        ncp_pipeline_pool_free(pool);
    }
    free(big);
}

static void test_serial_pool_is_serial(void **state)
{
    (void)state;
    struct ncp_thread_map map;
    ncp_thread_map_default(&map, NCP_MODE_SERIAL, 1, 1);
    struct ncp_diag d;
    struct ncp_pipeline_pool *pool = ncp_pipeline_pool_new(&map, &d);
    assert_non_null(pool);
    struct outcome got;
    run_one(pool, "G1 X1 F100\nM2\n", -1, &got);
    assert_int_equal(got.rc, NCP_OK);
    assert_int_equal(got.st.threads, 1);
    free(got.text.buf);
    ncp_pipeline_pool_free(pool);
    ncp_pipeline_pool_free(NULL);
}

/* ---- the thread hooks a scheduler ranks the pipeline's threads by ---- */

static _Atomic int hook_started[NCP_PIPE_KINDS], hook_ended[NCP_PIPE_KINDS], hook_bad;

static void check_fill(const struct ncp_pipe_thread *t)
{
    struct ncp_pipe_fill f;
    ncp_pipe_thread_fill(t, &f);
    /* a source has no input ring, a sink no output ring, the rest both */
    int want_in = t->kind != NCP_PIPE_FEEDER, want_out = t->kind != NCP_PIPE_OUTPUT;
    if (f.in_fill > f.in_cap || f.out_fill > f.out_cap || (f.in_cap > 0) != want_in ||
        (f.out_cap > 0) != want_out)
        atomic_fetch_add(&hook_bad, 1);
}

static void on_started(void *ctx, const struct ncp_pipe_thread *t)
{
    (void)ctx;
    check_fill(t);
    atomic_fetch_add(&hook_started[t->kind], 1);
}

static void on_ended(void *ctx, const struct ncp_pipe_thread *t)
{
    (void)ctx;
    check_fill(t);
    atomic_fetch_add(&hook_ended[t->kind], 1);
}

static void test_thread_hooks(void **state)
{
    (void)state;
    static const struct ncp_pipe_hooks hooks = { NULL, on_started, on_ended };
    size_t cap = 5000 * 32 + 64, len = 0;
    char *big = malloc(cap);
    assert_non_null(big);
    for (int i = 0; i < 5000; i++)
        len += (size_t)snprintf(big + len, cap - len, "G1 X%d Y%d F600\n", i % 97, i % 89);
    snprintf(big + len, cap - len, "M2\n");
    struct ncp_thread_map map;
    ncp_thread_map_default(&map, NCP_MODE_DET, 2, 1);
    struct ncp_pipeline_pool *pool = ncp_pipeline_pool_new(&map, &(struct ncp_diag){ 0 });
    assert_non_null(pool);
    for (int run = 0; run < 3; run++) {
        for (int k = 0; k < NCP_PIPE_KINDS; k++)
            atomic_store(&hook_started[k], 0), atomic_store(&hook_ended[k], 0);
        struct ncp_source src;
        struct ncp_diag d;
        assert_int_equal(ncp_source_from_memory(&src, big, strlen(big), "t.ngc", &d), 0);
        struct ncp_analyzer_cfg cfg = { .max_loop_iterations = 1000 };
        struct text_out text = { NULL, 0, 0, -1, 0 };
        struct ncp_output out = { .ctx = &text, .emit = collect, .threads = &hooks };
        struct ncp_run_stats st;
        /* run 0 starts its own threads, the others reuse the pool's */
        int rc = run == 0 ? ncp_pipeline_run(&src, &map, &cfg, &out, &st, &d)
                          : ncp_pipeline_pool_run(pool, &src, &cfg, &out, &st, &d);
        assert_int_equal(rc, NCP_OK);
        ncp_source_close(&src);
        free(text.buf);
        static const int want[NCP_PIPE_KINDS] = { 1, 2, 1, 1, 1 };
        for (int k = 0; k < NCP_PIPE_KINDS; k++) {
            assert_int_equal(atomic_load(&hook_started[k]), want[k]);
            assert_int_equal(atomic_load(&hook_ended[k]), want[k]);
        }
    }
    assert_int_equal(atomic_load(&hook_bad), 0);
    assert_string_equal(ncp_pipe_kind_name(NCP_PIPE_EXECUTOR), "executor");
    ncp_pipeline_pool_free(pool);
    free(big);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_runs_equal_serial),
        cmocka_unit_test(test_serial_pool_is_serial),
        cmocka_unit_test(test_thread_hooks),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
