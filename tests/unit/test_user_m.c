/* User M codes (M100..M199): where their programs are found
 * (ncp_user_m_find, the machine INI's [DISPLAY] PROGRAM_PREFIX and
 * [RS274NGC] USER_M_PATH), and the call the interpreter makes of one found
 * there (USER_M, with LinuxCNC's -1 for a missing P or Q), or its refusal. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "ncpar/analyzer.h"
#include "ncpar/config.h"
#include "ncpar/feeder.h"
#include "ncpar/lex.h"

#include "mem_feed.h"

static char dir_a[64], dir_b[64];

static void touch(const char *dir, const char *name, mode_t mode)
{
    char path[128];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs("#!/bin/sh\n", f);
    fclose(f);
    assert_int_equal(chmod(path, mode), 0);
}

static int make_dirs(void **state)
{
    (void)state;
    snprintf(dir_a, sizeof dir_a, "/tmp/ncp-userm-a-XXXXXX");
    snprintf(dir_b, sizeof dir_b, "/tmp/ncp-userm-b-XXXXXX");
    if (!mkdtemp(dir_a) || !mkdtemp(dir_b))
        return -1;
    touch(dir_a, "M101", 0644);   /* not executable: passed over */
    touch(dir_b, "M101", 0755);
    touch(dir_a, "M102", 0755);   /* in both: the first folder's */
    touch(dir_b, "M102", 0755);
    return 0;
}

static int remove_dirs(void **state)
{
    (void)state;
    char cmd[200];
    snprintf(cmd, sizeof cmd, "rm -rf %s %s", dir_a, dir_b);
    return system(cmd) == 0 ? 0 : -1;
}

static void test_find(void **state)
{
    (void)state;
    char dirs[160], path[256], want[128];
    snprintf(dirs, sizeof dirs, "%s::%s", dir_a, dir_b);
    assert_int_equal(ncp_user_m_find(dirs, 101, path, sizeof path), 0);
    snprintf(want, sizeof want, "%s/M101", dir_b);
    assert_string_equal(path, want);
    assert_int_equal(ncp_user_m_find(dirs, 102, path, sizeof path), 0);
    snprintf(want, sizeof want, "%s/M102", dir_a);
    assert_string_equal(path, want);
    assert_int_equal(ncp_user_m_find(dirs, 150, path, sizeof path), -1);
    assert_int_equal(ncp_user_m_find(dirs, 99, path, sizeof path), -1);
    assert_int_equal(ncp_user_m_find("", 101, path, sizeof path), -1);
    assert_int_equal(ncp_user_m_find(NULL, 101, path, sizeof path), -1);
    /* a path that does not fit is not found, rather than cut */
    assert_int_equal(ncp_user_m_find(dirs, 101, path, 8), -1);
}

static void test_ini_folders(void **state)
{
    (void)state;
    struct ncp_rs274_cfg r;
    memset(&r, 0, sizeof r);
    char why[128];
    setenv("HOME", "/home/op", 1);
    assert_int_equal(ncp_rs274_cfg_key(&r, "/etc/ncpar/mill.ini", "RS274NGC", "USER_M_PATH",
                                       "mcodes:/opt/m:~/m", why, sizeof why), 1);
    assert_string_equal(r.user_m_path, "/etc/ncpar/mcodes:/opt/m:/home/op/m");
    ncp_rs274_cfg_finish(&r);
    assert_string_equal(r.user_m_dirs, "/etc/ncpar/mcodes:/opt/m:/home/op/m");
    /* PROGRAM_PREFIX is searched first, as LinuxCNC's task searches it */
    assert_int_equal(ncp_rs274_cfg_key(&r, "mill.ini", "DISPLAY", "PROGRAM_PREFIX", "nc_files",
                                       why, sizeof why), 1);
    ncp_rs274_cfg_finish(&r);
    assert_string_equal(r.user_m_dirs, "nc_files:/etc/ncpar/mcodes:/opt/m:/home/op/m");
    /* an INI in the root folder, and one named without a folder */
    assert_int_equal(ncp_rs274_cfg_key(&r, "/m.ini", "RS274NGC", "USER_M_PATH", "mc", why,
                                       sizeof why), 1);
    assert_string_equal(r.user_m_path, "/mc");
    assert_int_equal(ncp_rs274_cfg_key(&r, "m.ini", "RS274NGC", "USER_M_PATH", "mc:/a", why,
                                       sizeof why), 1);
    assert_string_equal(r.user_m_path, "mc:/a");
    char big[2000];
    memset(big, 'x', sizeof big - 1);
    big[sizeof big - 1] = '\0';
    assert_int_equal(ncp_rs274_cfg_key(&r, "m.ini", "RS274NGC", "USER_M_PATH", big, why,
                                       sizeof why), -1);
    assert_int_equal(ncp_rs274_cfg_key(&r, "m.ini", "RS274NGC", "INI_VARS", "maybe", why,
                                       sizeof why), -1);
    assert_int_equal(ncp_rs274_cfg_key(&r, "m.ini", "RS274NGC", "REMAP", "", why, sizeof why), -1);
    assert_int_equal(ncp_rs274_cfg_key(&r, "m.ini", "RS274NGC", "FEATURES", "0", why,
                                       sizeof why), 0);
    assert_int_equal(ncp_rs274_cfg_key(&r, "m.ini", "DISPLAY", "DISPLAY", "axis", why,
                                       sizeof why), 0);
    assert_int_equal(ncp_rs274_cfg_key(&r, "m.ini", "TRAJ", "USER_M_PATH", "x", why,
                                       sizeof why), -2);
}

/* ---- the interpreter's call ---- */

struct calls {
    struct ncp_cmd cur;
    struct ncp_canon user[8];
    int n_user;
    struct ncp_diag err;
    uint64_t next_id;
};

static struct ncp_cmd *c_acquire(void *ctx)
{
    struct calls *c = ctx;
    ncp_cmd_reset_header(&c->cur, c->next_id++);
    return &c->cur;
}

static void c_publish(void *ctx, struct ncp_cmd *cmd)
{
    struct calls *c = ctx;
    for (unsigned k = 0; k < cmd->n_ops; k++)
        if (cmd->ops[k].kind == NCP_C_USER_M && c->n_user < 8)
            c->user[c->n_user++] = cmd->ops[k];
    if (cmd->flags & NCP_CMD_F_ERROR)
        c->err = cmd->diag;
}

static int run(const char *text, const char *dirs, struct calls *c)
{
    static struct mem_feed feed;
    struct ncp_diag d;
    memset(c, 0, sizeof *c);
    memset(&feed, 0, sizeof feed);
    assert_int_equal(ncp_source_from_memory(&feed.src, text, strlen(text), "t.ngc", &d), 0);
    feed.off = feed.src.begin;
    feed.line = feed.src.begin_line;
    struct ncp_analyzer_cfg cfg = { .user_m_dirs = dirs };
    struct ncp_analyzer *a = ncp_analyzer_new(&cfg, &d);
    assert_non_null(a);
    struct ncp_block_feed bf = { &feed, mf_next, mf_release, &feed.src };
    struct ncp_cmd_sink sink = { c, c_acquire, c_publish };
    int rc = ncp_analyzer_run(a, &bf, &sink);
    ncp_analyzer_free(a);
    return rc;
}

static void test_call(void **state)
{
    (void)state;
    struct calls c;
    assert_int_equal(run("G1 X1 F10\n M101 P2\nM102 Q-3.5\nM2\n", dir_b, &c), NCP_END);
    assert_int_equal(c.n_user, 2);
    assert_int_equal(c.user[0].user_m.code, 101);
    assert_int_equal(c.user[0].user_m.col, 2);
    assert_true(c.user[0].user_m.p == 2.0 && c.user[0].user_m.q == -1.0);
    assert_int_equal(c.user[1].user_m.code, 102);
    assert_true(c.user[1].user_m.p == -1.0 && c.user[1].user_m.q == -3.5);
}

static void test_refused(void **state)
{
    (void)state;
    struct calls c;
    /* no machine (parse, check): rs274 -g's refusal */
    assert_int_equal(run("G1 X1 F10\nM101 P2\nM2\n", NULL, &c), NCP_ERR_SEMANTIC);
    assert_int_equal(c.n_user, 0);
    assert_string_equal(c.err.msg, "Unknown m code used: M101");
    assert_int_equal(c.err.line, 2);
    /* a machine without that program: the same */
    assert_int_equal(run("M150\nM2\n", dir_b, &c), NCP_ERR_SEMANTIC);
    assert_string_equal(c.err.msg, "Unknown m code used: M150");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_find),
        cmocka_unit_test(test_ini_folders),
        cmocka_unit_test(test_call),
        cmocka_unit_test(test_refused),
    };
    return cmocka_run_group_tests(tests, make_dirs, remove_dirs);
}
