/* Thread maps: defaults per mode, the maps shipped in rt-config, and every
 * kind of error naming its line and key. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "ncpar/pipeline.h"

static void test_default_det(void **state)
{
    (void)state;
    struct ncp_thread_map m;
    ncp_thread_map_default(&m, NCP_MODE_DET, 3, 2);
    assert_int_equal(m.mode, NCP_MODE_DET);
    assert_int_equal(m.n_lexers, 3);
    assert_int_equal(m.n_executors, 2);
    assert_true(m.string_rows > 0 && m.parsed_rows > 0 && m.cmd_slots > 0);
    assert_true(m.start_timeout_us >= 0);
    assert_int_equal(m.feeder.cpu, -1);
    assert_int_equal(m.analyzer.cpu, -1);
    assert_int_equal(m.output.cpu, -1);
    for (int i = 0; i < NCP_MAX_LEXERS; i++) {
        assert_int_equal(m.lexer[i].cpu, -1);
        assert_int_equal(m.lexer[i].policy, SCHED_OTHER);
    }
    for (int j = 0; j < NCP_MAX_EXECUTORS; j++)
        assert_int_equal(m.executor[j].cpu, -1);
}

static void test_default_att(void **state)
{
    (void)state;
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    int ncpu = n > 0 ? (int)n : 1;
    struct ncp_thread_map m;
    ncp_thread_map_default(&m, NCP_MODE_ATT, 4, 1);
    assert_int_equal(m.mode, NCP_MODE_ATT);
    assert_int_equal(m.feeder.cpu, 0);
    for (int i = 0; i < 4; i++) {
        assert_int_equal(m.lexer[i].cpu, (1 + i) % ncpu);
        assert_int_equal(m.lexer[i].policy, SCHED_OTHER);
    }
    assert_int_equal(m.analyzer.cpu, 5 % ncpu);
    assert_int_equal(m.executor[0].cpu, 6 % ncpu);
    assert_int_equal(m.output.cpu, m.analyzer.cpu);
    assert_true(m.analyzer.cpu >= 0 && m.analyzer.cpu < ncpu);
    /* no executor threads: the output executes, on the next CPU */
    ncp_thread_map_default(&m, NCP_MODE_ATT, 1, 0);
    assert_int_equal(m.feeder.cpu, 0);
    assert_int_equal(m.lexer[0].cpu, 1 % ncpu);
    assert_int_equal(m.analyzer.cpu, 2 % ncpu);
    assert_int_equal(m.output.cpu, 3 % ncpu);
}

static void test_default_clamps_counts(void **state)
{
    (void)state;
    struct ncp_thread_map m;
    ncp_thread_map_default(&m, NCP_MODE_DET, 0, 99); /* 0 lexers: the analyzer lexes */
    assert_int_equal(m.n_lexers, 0);
    assert_int_equal(m.n_executors, NCP_MAX_EXECUTORS);
    ncp_thread_map_default(&m, NCP_MODE_ATT, -5, -1);
    assert_int_equal(m.n_lexers, 0);
    assert_int_equal(m.n_executors, 0);
    /* 0 executors: the output thread executes; no executor gets a CPU */
    ncp_thread_map_default(&m, NCP_MODE_ATT, 1, 0);
    assert_int_equal(m.n_executors, 0);
    assert_int_equal(m.executor[0].cpu, -1);
}

/* The tests run from the top of the tree or from build/tests. */
static const char *shipped(const char *name, char *buf, size_t len)
{
    static const char *const dirs[] = { "rt-config", "../rt-config", "../../rt-config" };
    for (size_t i = 0; i < sizeof dirs / sizeof *dirs; i++) {
        snprintf(buf, len, "%s/%s", dirs[i], name);
        if (access(buf, R_OK) == 0)
            return buf;
    }
    fail_msg("cannot find rt-config/%s", name);
    return NULL;
}

static void load_ok(const char *name, struct ncp_thread_map *m)
{
    char path[256];
    struct ncp_diag d;
    int rc = ncp_thread_map_load(m, shipped(name, path, sizeof path), &d);
    if (rc != NCP_OK)
        fail_msg("%s:%u: %s", name, d.line, d.msg);
}

static void test_shipped_maps_load(void **state)
{
    (void)state;
    static const char *const names[] = {
        "serial.ini", "det2.ini", "att2.ini", "det4.ini", "att4.ini", "det8.ini", "att8.ini",
        "det2-fifo.ini", "att2-fifo.ini", "det4-fifo.ini", "att4-fifo.ini",
        "det8-fifo.ini", "att8-fifo.ini",
    };
    for (size_t i = 0; i < sizeof names / sizeof *names; i++) {
        struct ncp_thread_map m;
        load_ok(names[i], &m);
        int fifo = strstr(names[i], "fifo") != NULL;
        assert_int_equal(m.feeder.policy, fifo ? SCHED_FIFO : SCHED_OTHER);
        if (fifo)
            assert_int_equal(m.lexer[0].priority, 90);
    }
}

static void test_paper_att4_and_att8(void **state)
{
    (void)state;
    struct ncp_thread_map m;
    load_ok("att4.ini", &m);
    assert_int_equal(m.mode, NCP_MODE_ATT);
    assert_int_equal(m.n_lexers, 3);
    assert_int_equal(m.feeder.cpu, 0);
    for (int i = 0; i < 3; i++)
        assert_int_equal(m.lexer[i].cpu, 1 + i);
    load_ok("att8.ini", &m);
    assert_int_equal(m.n_lexers, 7);
    static const int cpu8[7] = { 1, 2, 3, 0, 1, 2, 3 };
    for (int i = 0; i < 7; i++)
        assert_int_equal(m.lexer[i].cpu, cpu8[i]);
    load_ok("det4.ini", &m);
    assert_int_equal(m.mode, NCP_MODE_DET);
    assert_int_equal(m.n_lexers, 3);
    assert_int_equal(m.lexer[2].cpu, -1);
    load_ok("serial.ini", &m);
    assert_int_equal(m.mode, NCP_MODE_SERIAL);
}

/* ---- errors ---------------------------------------------------------------- */

static int load_text(const char *text, struct ncp_diag *d, struct ncp_thread_map *m)
{
    char path[] = "/tmp/ncp_threadmap_XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    FILE *f = fdopen(fd, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
    int rc = ncp_thread_map_load(m, path, d);
    unlink(path);
    return rc;
}

static void expect_error(const char *text, uint32_t line, const char *needle)
{
    struct ncp_diag d;
    struct ncp_thread_map m;
    int rc = load_text(text, &d, &m);
    if (rc == NCP_OK)
        fail_msg("accepted:\n%s", text);
    assert_int_equal(rc, d.code);
    if (d.line != line || !strstr(d.msg, needle))
        fail_msg("got line %u '%s', want line %u with '%s'", d.line, d.msg, line, needle);
}

static void test_loaded_values_override_defaults(void **state)
{
    (void)state;
    struct ncp_diag d;
    struct ncp_thread_map m;
    int rc = load_text("; comment\n[pipeline]\nmode = att\nlexers = 2\nexecutors = 3\n"
                       "string_rows = 10\nparsed_rows = 5\ncmd_slots = 7\n"
                       "start_timeout_us = 0\n[lexer.1]\ncpu = 5\npolicy = fifo\n"
                       "priority = 10\n[executor.2]\ncpu = -1\n",
                       &d, &m);
    assert_int_equal(rc, NCP_OK);
    assert_int_equal(m.mode, NCP_MODE_ATT);
    assert_int_equal(m.n_lexers, 2);
    assert_int_equal(m.n_executors, 3);
    assert_int_equal(m.string_rows, 10);
    assert_int_equal(m.parsed_rows, 5);
    assert_int_equal(m.cmd_slots, 7);
    assert_int_equal(m.start_timeout_us, 0);
    assert_int_equal(m.lexer[1].cpu, 5);
    assert_int_equal(m.lexer[1].policy, SCHED_FIFO);
    assert_int_equal(m.lexer[1].priority, 10);
    assert_int_equal(m.executor[2].cpu, -1);
    assert_int_equal(m.feeder.cpu, 0); /* ATT default */
}

/* lexers = 0: the analyzer lexes the text itself; a [lexer.0] section then
 * names a thread the map does not have. */
static void test_no_lexer_threads(void **state)
{
    (void)state;
    struct ncp_diag d;
    struct ncp_thread_map m;
    assert_int_equal(load_text("[pipeline]\nmode = att\nlexers = 0\nexecutors = 0\n", &d, &m),
                     NCP_OK);
    assert_int_equal(m.n_lexers, 0);
    assert_int_equal(m.n_executors, 0);
    if (sysconf(_SC_NPROCESSORS_ONLN) >= 2) /* two busy threads, two CPUs */
        assert_int_not_equal(m.analyzer.cpu, m.output.cpu);
    expect_error("[pipeline]\nlexers = 0\n[lexer.0]\ncpu = 1\n", 3, "lexer.0");
    /* the output thread lexes ahead in 8 KB chunks unless told otherwise */
    assert_int_equal(m.lex_ahead_bytes, 32768);
    assert_int_equal(load_text("[pipeline]\nlexers = 0\nexecutors = 0\nlex_ahead_bytes = 0\n",
                               &d, &m), NCP_OK);
    assert_int_equal(m.lex_ahead_bytes, 0);
    assert_int_equal(load_text("[pipeline]\nlex_ahead_bytes = 64\n", &d, &m), NCP_OK);
    assert_int_equal(m.lex_ahead_bytes, 64);
    expect_error("[pipeline]\nlexers = 0\nlex_ahead_bytes = -1\n", 3, "lex_ahead_bytes");
    expect_error("[pipeline]\nlex_ahead_bytes = 2000000\n", 2, "lex_ahead_bytes");
}

/* inline_output: the analyzer executes and writes, so it goes with no
 * executor threads and no [output] section. */
static void test_inline_output(void **state)
{
    (void)state;
    struct ncp_diag d;
    struct ncp_thread_map m;
    assert_int_equal(load_text("[pipeline]\nexecutors = 0\ninline_output = 1\n", &d, &m), NCP_OK);
    assert_int_equal(m.inline_output, 1);
    assert_int_equal(m.n_executors, 0);
    assert_int_equal(load_text("[pipeline]\nexecutors = 0\n", &d, &m), NCP_OK);
    assert_int_equal(m.inline_output, 0);
    ncp_thread_map_default(&m, NCP_MODE_DET, 2, 0);
    assert_int_equal(m.inline_output, 0);
    expect_error("[pipeline]\ninline_output = 1\nexecutors = 1\n", 2, "executors = 0");
    expect_error("[pipeline]\nexecutors = 0\ninline_output = 2\n", 3, "inline_output");
    expect_error("[pipeline]\nexecutors = 0\ninline_output = 1\n[output]\ncpu = 1\n", 4,
                 "[output]");
}

static void test_errors(void **state)
{
    (void)state;
    expect_error("[pipeline]\nlexers = 2\nthreads = 4\n", 3, "threads");
    expect_error("[pipeline]\nmode = fast\n", 2, "mode");
    expect_error("[pipeline]\nlexers = -1\n", 2, "lexers");
    expect_error("[pipeline]\nlexers = 17\n", 2, "lexers");
    expect_error("[pipeline]\nexecutors = two\n", 2, "executors");
    expect_error("[pipeline]\nexecutors = -1\n", 2, "executors");
    expect_error("[pipeline]\nexecutors = 0\n\n[executor.0]\ncpu = 0\n", 4, "executor.0");
    expect_error("[pipeline]\nstring_rows = -1\n", 2, "string_rows");
    expect_error("[pipeline]\nparsed_rows = 3x\n", 2, "parsed_rows");
    expect_error("[pipeline]\ncmd_slots = 99999999999\n", 2, "cmd_slots");
    expect_error("[pipeline]\nstart_timeout_us = -5\n", 2, "start_timeout_us");
    expect_error("# x\n[feeder]\ncpu = -2\n", 3, "cpu");
    expect_error("[feeder]\ncpu = 1\n\n[analyzer]\npolicy = SCHED_RR\n", 5, "policy");
    expect_error("[output]\npriority = 100\n", 2, "priority");
    expect_error("[output]\ncolour = red\n", 2, "colour");
    expect_error("[pipeline]\nlexers = 2\n[lexer.16]\ncpu = 1\n", 3, "lexer.16");
    expect_error("[pipeline]\nlexers = 2\n[gpu]\ncpu = 1\n", 3, "gpu");
    expect_error("[pipeline]\n[nothing_here]\n", 2, "nothing_here");
    expect_error("cpu = 1\n", 1, "cpu");
    expect_error("[pipeline]\nlexers\n", 2, "key = value");
    /* checks that need the whole file point at the section */
    expect_error("[lexer.3]\ncpu = 1\n[pipeline]\nlexers = 2\n", 1, "lexer.3");
    expect_error("[pipeline]\nexecutors = 1\n\n[executor.1]\ncpu = 0\n", 4, "executor.1");
    expect_error("[feeder]\npolicy = SCHED_FIFO\n", 1, "priority");
}

static void test_missing_file(void **state)
{
    (void)state;
    struct ncp_diag d;
    struct ncp_thread_map m;
    int rc = ncp_thread_map_load(&m, "/nonexistent/map.ini", &d);
    assert_int_not_equal(rc, NCP_OK);
    assert_int_equal(d.line, 0);
    assert_non_null(strstr(d.msg, "cannot open"));
}

static void test_warning_text(void **state)
{
    (void)state;
    uint32_t w = NCP_WARN_NO_FIFO | NCP_WARN_NO_CPU;
    assert_non_null(strstr(ncp_run_warning_next(&w), "SCHED_FIFO"));
    assert_non_null(ncp_run_warning_next(&w));
    assert_null(ncp_run_warning_next(&w));
    assert_int_equal(w, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_default_det),
        cmocka_unit_test(test_default_att),
        cmocka_unit_test(test_default_clamps_counts),
        cmocka_unit_test(test_no_lexer_threads),
        cmocka_unit_test(test_shipped_maps_load),
        cmocka_unit_test(test_paper_att4_and_att8),
        cmocka_unit_test(test_loaded_values_override_defaults),
        cmocka_unit_test(test_inline_output),
        cmocka_unit_test(test_errors),
        cmocka_unit_test(test_missing_file),
        cmocka_unit_test(test_warning_text),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
