/* The files an operator's settings persist in: LinuxCNC's parameter file
 * (read, written, refused with its line when malformed) and the tool table
 * written back after G10 L1 (changed lines anew, everything else as it was). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "ncpar/analyzer.h"
#include "ncpar/config.h"
#include "ncpar/pipeline.h"

static char dir[64];

static int setup(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "/tmp/ncp-persist-XXXXXX");
    return mkdtemp(dir) ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    char cmd[96];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    return system(cmd) == 0 ? 0 : -1;
}

static const char *path_of(const char *name)
{
    static char p[128];
    snprintf(p, sizeof p, "%s/%s", dir, name);
    return p;
}

static void put(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

static char *get(const char *path)
{
    static char buf[8192];
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = '\0';
    return buf;
}

static void test_persistent_set(void **state)
{
    (void)state;
    /* LinuxCNC's _required_parameters: G28, G30, G92 and its flag, the
     * system, G54..G59.3 with R; nothing between the systems' blocks */
    int n = 0;
    for (int k = 1; k < NCP_VAR_PARAMS; k++)
        n += ncp_var_persistent(k);
    assert_int_equal(n, 9 + 9 + 10 + 1 + 9 * 10);
    assert_true(ncp_var_persistent(5161) && ncp_var_persistent(5189));
    assert_true(ncp_var_persistent(5210) && ncp_var_persistent(5230));
    assert_true(ncp_var_persistent(5381) && ncp_var_persistent(5390));
    assert_false(ncp_var_persistent(5170) || ncp_var_persistent(5231));
    assert_false(ncp_var_persistent(5391) || ncp_var_persistent(5400));
}

static void test_missing_file_is_defaults(void **state)
{
    (void)state;
    struct ncp_var_file *vf = malloc(sizeof *vf);
    struct ncp_diag d;
    int existed = 1;
    assert_int_equal(ncp_var_file_read(path_of("none.var"), vf, &existed, &d), NCP_OK);
    assert_int_equal(existed, 0);
    assert_true(vf->value[5220] == 1.0 && vf->value[5221] == 0.0);
    assert_true(vf->listed[5221] && !vf->listed[31]);
    free(vf);
}

/* What LinuxCNC writes ("%d\t%f"), an extra parameter it keeps, back out
 * the same; values six decimals cannot hold come back to 1e-12. */
static void test_round_trip(void **state)
{
    (void)state;
    struct ncp_var_file *vf = malloc(sizeof *vf);
    struct ncp_diag d;
    int existed;
    const char *p = path_of("lcnc.var");
    ncp_var_file_init(vf);
    vf->value[5241] = 1.25;
    vf->value[5220] = 2;
    vf->listed[31] = 1;
    vf->value[31] = 7;
    assert_int_equal(ncp_var_file_write(p, vf, &d), NCP_OK);
    char *text = get(p);
    assert_non_null(strstr(text, "31\t7.000000\n5161\t0.000000\n"));
    assert_non_null(strstr(text, "5220\t2.000000\n5221\t0.000000\n"));
    assert_non_null(strstr(text, "5241\t1.250000\n"));
    assert_null(strstr(text, "5231"));
    assert_null(strstr(text, "5400"));

    vf->value[5241] = 10 * 0.03937007874016; /* 10 mm in inch */
    vf->value[5161] = -1e-9;
    assert_int_equal(ncp_var_file_write(p, vf, &d), NCP_OK);
    struct ncp_var_file *back = malloc(sizeof *back);
    assert_int_equal(ncp_var_file_read(p, back, &existed, &d), NCP_OK);
    assert_int_equal(existed, 1);
    for (int k = 1; k < NCP_VAR_PARAMS; k++) {
        assert_int_equal(back->listed[k], vf->listed[k]);
        assert_true(fabs(back->value[k] - vf->value[k]) <= 1e-12);
    }
    /* and no temporary file is left beside it */
    assert_int_equal(access(path_of("lcnc.var.tmp"), F_OK), -1);
    free(back);
    free(vf);
}

static void expect_bad(const char *text, unsigned line, const char *words)
{
    struct ncp_var_file *vf = malloc(sizeof *vf);
    struct ncp_diag d;
    int existed;
    put(path_of("bad.var"), text);
    memset(&d, 0, sizeof d);
    assert_int_equal(ncp_var_file_read(path_of("bad.var"), vf, &existed, &d), NCP_ERR_SEMANTIC);
    assert_int_equal(d.line, line);
    if (!strstr(d.msg, words))
        fail_msg("line %u: '%s' does not say '%s'", line, d.msg, words);
    free(vf);
}

static void test_malformed_names_line(void **state)
{
    (void)state;
    expect_bad("5161\t0.000000\n5162 x\n", 2, "not a parameter line");
    expect_bad("5161\t0.000000\n\n5163\t0\n5162\t0\n", 4, "increasing order");
    expect_bad("5161\t0\n5161\t1\n", 2, "increasing order");
    expect_bad("6000\t1.0\n", 1, "out of range");
    expect_bad("0\t1.0\n", 1, "out of range");
    expect_bad("5220\t10.000000\n", 1, "coordinate system");
    expect_bad("5221\tnan\n", 1, "finite");
    expect_bad("5221\t1.0 2.0\n", 1, "not a parameter line");
    expect_bad("# offsets\n", 1, "not a parameter line");
}

static int ignore(void *ctx, const struct ncp_cmd *cmd)
{
    (void)ctx;
    (void)cmd;
    return 0;
}

/* G10 L1 through a resident interpreter, as the NCK runs it. */
static struct ncp_analyzer *run_on_table(const char *table, const char *prog)
{
    struct ncp_diag d;
    static struct ncp_analyzer_cfg cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.tool_table_path = table;
    cfg.resident = 1;
    struct ncp_analyzer *a = ncp_analyzer_new(&cfg, &d);
    assert_non_null(a);
    cfg.instance = a;
    struct ncp_source src;
    assert_int_equal(ncp_source_from_memory(&src, prog, strlen(prog), "MDI", &d), NCP_OK);
    struct ncp_output out = { .ctx = NULL, .emit = ignore };
    struct ncp_run_stats st;
    int rc = ncp_serial_run(&src, &cfg, &out, &st, &d);
    assert_true(rc == NCP_OK || rc == NCP_END);
    ncp_source_close(&src);
    return a;
}

static const char table[] =
    "; shop tools, inches\n"
    "T1 P1 Z0.0000 D0.3937 ;10 mm flat end mill\n"
    "\n"
    "T2 P2 Z0.1200 D0.2362 ;6 mm flat end mill\n"
    "T3 P7 X0.01 Z0.25 D0.2362 I10 J-5 Q2\n"
    "junk line\n"
    "T4 P4 Z0.3100 ; slot drill\n";

static void test_tool_table_write_back(void **state)
{
    (void)state;
    const char *p = path_of("tools.tbl");
    put(p, table);
    struct ncp_analyzer *a = run_on_table(p, "G20\nG10 L1 P2 Z0.5 R0.25\nG10 L1 P3 X0\n");
    struct ncp_diag d;
    int written = 0;
    assert_int_equal(ncp_analyzer_save_tool_table(a, NULL, p, &written, &d), NCP_OK);
    assert_int_equal(written, 1);
    assert_string_equal(get(p),
                        "; shop tools, inches\n"
                        "T1 P1 Z0.0000 D0.3937 ;10 mm flat end mill\n"
                        "\n"
                        "T2 P2 Z+0.500000 D0.500000 ;6 mm flat end mill\n"
                        "T3 P7 Z+0.250000 D0.236200 I+10.000000 J-5.000000 Q2\n"
                        "junk line\n"
                        "T4 P4 Z0.3100 ; slot drill\n");
    /* nothing changed since: the file is left alone */
    assert_int_equal(ncp_analyzer_save_tool_table(a, NULL, p, &written, &d), NCP_OK);
    assert_int_equal(written, 0);
    ncp_analyzer_free(a);

    /* read again, the table gives the interpreter what G10 left */
    a = run_on_table(p, "G20 G10 L1 P4 Z0.31\n");
    size_t n;
    int changed = 1;
    const char *text = get(p);
    char *again = ncp_analyzer_tool_table_text(a, NULL, text, strlen(text), &n, &changed);
    assert_non_null(again);
    assert_int_equal(changed, 0);
    assert_string_equal(again, text);
    free(again);
    ncp_analyzer_free(a);
}

/* Two interpreters on one table (two NC channels), each against the table
 * as it loaded it: each writes only the tool it changed, the other's
 * change stays. */
static void test_tool_table_two_writers(void **state)
{
    (void)state;
    const char *p = path_of("shared.tbl");
    put(p, table);
    struct ncp_analyzer *a = run_on_table(p, "G20 G10 L1 P1 Z0.75\n");
    struct ncp_analyzer *b = run_on_table(p, "G20 G10 L1 P4 Z0.5\n");
    struct ncp_diag d;
    struct ncp_analyzer *base_a = ncp_analyzer_new(NULL, &d), *base_b = ncp_analyzer_new(NULL, &d);
    struct ncp_analyzer *fresh = run_on_table(p, "G20\n");
    ncp_analyzer_copy_tools(base_a, fresh);
    ncp_analyzer_copy_tools(base_b, fresh);
    int written = 0;
    assert_int_equal(ncp_analyzer_save_tool_table(a, base_a, p, &written, &d), NCP_OK);
    assert_int_equal(written, 1);
    assert_int_equal(ncp_analyzer_save_tool_table(b, base_b, p, &written, &d), NCP_OK);
    assert_int_equal(written, 1);
    const char *text = get(p);
    assert_non_null(strstr(text, "T1 P1 Z+0.750000 D0.393700 ;10 mm flat end mill\n"));
    assert_non_null(strstr(text, "T4 P4 Z+0.500000 ; slot drill\n"));
    assert_non_null(strstr(text, "T2 P2 Z0.1200 D0.2362 ;6 mm flat end mill\n"));
    /* against the line itself, b would have put T1 back */
    ncp_analyzer_free(fresh);
    ncp_analyzer_free(base_a);
    ncp_analyzer_free(base_b);
    ncp_analyzer_free(a);
    ncp_analyzer_free(b);
}

/* A table that can be read but not replaced (its temporary file's name
 * would be too long): an error naming it, the old file as it was. */
static void test_tool_table_unwritable(void **state)
{
    (void)state;
    char name[256], p[400];
    memset(name, 'T', 250);
    name[250] = '\0';
    snprintf(p, sizeof p, "%s/%s", dir, name);
    put(p, table);
    struct ncp_analyzer *a = run_on_table(p, "G20 G10 L1 P1 Z1\n");
    struct ncp_diag d;
    int written = 1;
    assert_int_equal(ncp_analyzer_save_tool_table(a, NULL, p, &written, &d), NCP_ERR_IO);
    assert_int_equal(written, 0);
    assert_non_null(strstr(d.msg, "cannot write tool table"));
    assert_string_equal(get(p), table);
    ncp_analyzer_free(a);
}

/* sim-3axis.ini with more lines: the machine INI's load of them */
static int load_ini(const char *more, struct ncp_machine_cfg *c, struct ncp_diag *d)
{
    char *base = malloc(16384);
    FILE *f = fopen("rt-config/sim-3axis.ini", "r");
    assert_non_null(f);
    size_t n = fread(base, 1, 16383, f);
    fclose(f);
    base[n] = '\0';
    char *text = malloc(n + strlen(more) + 2);
    sprintf(text, "%s\n%s", base, more);
    put(path_of("m.ini"), text);
    free(text);
    free(base);
    ncp_machine_cfg_default(c);
    memset(d, 0, sizeof *d);
    return ncp_machine_cfg_load(c, path_of("m.ini"), d);
}

static void test_ini_keys(void **state)
{
    (void)state;
    struct ncp_machine_cfg *c = malloc(sizeof *c);
    struct ncp_diag d;
    assert_int_equal(load_ini("", c, &d), NCP_OK);
    assert_string_equal(c->op.parameter_file, "");
    assert_true(c->op.max_feed_override == 1.0 && c->op.max_spindle_override == 2.0);
    /* relative to the INI's folder, as LinuxCNC opens them */
    assert_int_equal(load_ini("[RS274NGC]\nPARAMETER_FILE = mill.var\n[EMCIO]\n"
                              "TOOL_TABLE = /abs/t.tbl\n[DISPLAY]\nMAX_FEED_OVERRIDE = 1.2\n"
                              "MIN_SPINDLE_OVERRIDE = 0.5\nMAX_SPINDLE_OVERRIDE = 1.5\n", c, &d),
                     NCP_OK);
    char want[160];
    snprintf(want, sizeof want, "%s/mill.var", dir);
    assert_string_equal(c->op.parameter_file, want);
    assert_string_equal(c->op.tool_table, "/abs/t.tbl");
    assert_true(c->op.max_feed_override == 1.2 && c->op.min_spindle_override == 0.5 &&
                c->op.max_spindle_override == 1.5);
    assert_int_not_equal(load_ini("[DISPLAY]\nMAX_FEED_OVERRIDE = 2.5\n", c, &d), NCP_OK);
    assert_non_null(strstr(d.msg, "MAX_FEED_OVERRIDE"));
    assert_int_not_equal(load_ini("[DISPLAY]\nMIN_SPINDLE_OVERRIDE = 1.5\n"
                                  "MAX_SPINDLE_OVERRIDE = 1.2\n", c, &d), NCP_OK);
    assert_non_null(strstr(d.msg, "MIN_SPINDLE_OVERRIDE 1.5 is above"));
    /* the section is shared with the interpreter's keys; an unknown one is still refused */
    assert_int_equal(load_ini("[RS274NGC]\nREMAP = M400 ngc=x\nPARAMETER_FILE = m.var\n", c, &d),
                     NCP_OK);
    assert_int_not_equal(load_ini("[RS274NGC]\nPARAMTER_FILE = m.var\n", c, &d), NCP_OK);
    assert_non_null(strstr(d.msg, "PARAMTER_FILE"));
    free(c);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_persistent_set),
        cmocka_unit_test(test_missing_file_is_defaults),
        cmocka_unit_test(test_round_trip),
        cmocka_unit_test(test_malformed_names_line),
        cmocka_unit_test(test_tool_table_write_back),
        cmocka_unit_test(test_tool_table_two_writers),
        cmocka_unit_test(test_tool_table_unwritable),
        cmocka_unit_test(test_ini_keys),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
