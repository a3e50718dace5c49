/* The channels INI of cnc-run serve ([CHANNEL_n] CONFIG, BACKEND, DP):
 * what the reader takes and every line it refuses, the channel's backend
 * over its machine's, and the checks of the channels against their
 * backends (a socketcan channel's axes are CAN drives; no CAN node, CAN
 * interface, LLC or LCM URL is two channels'). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "ncpar/backend.h"
#include "ncpar/config.h"
#include "ncpar/msg.h"

static char dir[64], path[128];

static int setup(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "/tmp/ncp-test-cell-XXXXXX");
    if (!mkdtemp(dir))
        return -1;
    snprintf(path, sizeof path, "%s/cell.ini", dir);
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    unlink(path);
    return rmdir(dir);
}

static int load(const char *text, struct ncp_cell *cell, struct ncp_diag *d)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
    return ncp_cell_load(cell, path, d);
}

static struct ncp_cell cell;   /* 64 KiB: not on the stack */

static void test_reads_channels(void **state)
{
    (void)state;
    struct ncp_diag d;
    assert_int_equal(load("# a cell\n"
                          "[CHANNEL_3]\n"
                          "CONFIG = /etc/ncpar/drives.ini\n"
                          "backend = socketcan:can1\n"
                          "\n"
                          "[CHANNEL_0]\n"
                          "CONFIG = mill.ini\n"
                          "BACKEND = sim\n"
                          "[channel_1]\n"
                          "config = sub/slide.ini\n"
                          "BACKEND = LCM\n"
                          "DP = 4\n"
                          "[CHANNEL_2]\n"
                          "CONFIG = lathe.ini\n",
                          &cell, &d),
                     1);
    assert_int_equal(cell.n, 4);
    /* ascending, whatever the file's order */
    const struct ncp_cell_channel *c0 = &cell.ch[0], *c1 = &cell.ch[1], *c2 = &cell.ch[2],
                                  *c3 = &cell.ch[3];
    assert_int_equal(c0->num, 0);
    assert_int_equal(c1->num, 1);
    assert_int_equal(c2->num, 2);
    assert_int_equal(c3->num, 3);
    char want[160];
    snprintf(want, sizeof want, "%s/mill.ini", dir);
    assert_string_equal(c0->config, want);
    snprintf(want, sizeof want, "%s/sub/slide.ini", dir);
    assert_string_equal(c1->config, want);
    assert_string_equal(c3->config, "/etc/ncpar/drives.ini");
    assert_int_equal(c0->backend, NCP_BACKEND_SIM);
    assert_int_equal(c1->backend, NCP_BACKEND_LCM);
    assert_int_equal(c1->dp, 4);
    assert_int_equal(c2->backend, -1);   /* the machine INI's */
    assert_int_equal(c2->dp, 0);
    assert_int_equal(c3->backend, NCP_BACKEND_SOCKETCAN);
    assert_string_equal(c3->interface, "can1");
    /* where each was given */
    assert_int_equal(c3->line, 2);
    assert_int_equal(c3->config_line, 3);
    assert_int_equal(c3->backend_line, 4);
    assert_int_equal(c0->line, 6);
    assert_int_equal(c1->dp_line, 12);
    assert_int_equal(c2->backend_line, 0);
    assert_int_equal(c2->dp_line, 0);
}

static void test_machine_ini_is_no_cell(void **state)
{
    (void)state;
    struct ncp_diag d;
    assert_int_equal(load("[EMCMOT]\nSERVO_PERIOD = 1000000\n[AXIS_X]\nMIN_LIMIT = 0\n", &cell,
                          &d),
                     0);
    assert_int_equal(cell.n, 0);
}

/* text refused at line, with msg holding what */
static void refused(const char *text, unsigned line, const char *what)
{
    struct ncp_diag d;
    int rc = load(text, &cell, &d);
    if (rc != -1 || d.line != line || !strstr(d.msg, what))
        fail_msg("%s: rc %d, line %u (want %u): %s (want '%s')", text, rc, d.line, line, d.msg,
                 what);
    assert_int_equal(cell.n, 0);
}

static void test_refusals_name_the_line(void **state)
{
    (void)state;
    const char *h = "[CHANNEL_0]\nCONFIG = a.ini\n";
    char t[256];
#define WITH(x) (snprintf(t, sizeof t, "%s%s", h, x), t)
    refused(WITH("BACKEND = foo\n"), 3, "BACKEND: bad value 'foo'");
    refused(WITH("BACKEND = socketcan:\n"), 3, "bad value");
    refused(WITH("BACKEND = socketcan:can/0\n"), 3, "bad value");
    refused(WITH("BACKEND = socketcan:averyveryverylongname\n"), 3, "bad value");
    refused(WITH("BACKEND = socketcanx\n"), 3, "bad value");
    refused(WITH("BACKEND = sim\nBACKEND = lcm\n"), 4, "BACKEND given twice (first on line 3)");
    refused(WITH("DP = 0\n"), 3, "DP: bad value '0'");
    refused(WITH("DP = 6\n"), 3, "DP: bad value");
    refused(WITH("DP = 2.5\n"), 3, "DP: bad value");
    refused(WITH("DP = 0x2\n"), 3, "DP: bad value");
    refused(WITH("NODE_ID = 3\n"), 3, "[CHANNEL_0] NODE_ID: unknown key");
    refused(WITH("CONFIG = b.ini\n"), 3, "CONFIG given twice");
    refused(WITH("[CHANNEL_0]\nCONFIG = b.ini\n"), 3, "[CHANNEL_0] given twice (first on line 1)");
    refused(WITH("[CHANNEL_16]\nCONFIG = b.ini\n"), 3, "channels are [CHANNEL_0] .. [CHANNEL_15]");
    refused(WITH("[CHANNEL_x]\nCONFIG = b.ini\n"), 3, "channels are");
    refused(WITH("[CHANNEL_-1]\nCONFIG = b.ini\n"), 3, "channels are");
    refused(WITH("[CHANNEL_1]\nBACKEND = sim\n"), 3, "[CHANNEL_1] has no CONFIG");
    refused(WITH("[EMCMOT]\nBACKEND = lcm\n"), 3, "[EMCMOT] beside [CHANNEL_n] sections");
    refused("[EMCMOT]\nSERVO_PERIOD = 1\n[CHANNEL_0]\nCONFIG = a.ini\n", 1, "[EMCMOT] beside");
    refused(WITH("CONFIG =\n"), 3, "given twice");
    refused("[CHANNEL_0]\nCONFIG =\n", 2, "CONFIG is empty");
    refused(WITH("just words\n"), 3, "not a line of an INI");
#undef WITH
}

static void test_apply_over_the_machine(void **state)
{
    (void)state;
    struct ncp_machine_cfg c;
    struct ncp_diag d;
    memset(&d, 0, sizeof d);
    ncp_machine_cfg_default(&c);
    snprintf(c.can.interface, sizeof c.can.interface, "can0");
    struct ncp_cell_channel ch = { .num = 1, .backend = NCP_BACKEND_SOCKETCAN,
                                   .interface = "can4", .line = 5, .backend_line = 7 };
    assert_int_equal(ncp_cell_apply(&ch, &c, &d), NCP_OK);
    assert_int_equal(c.backend, NCP_BACKEND_SOCKETCAN);
    assert_string_equal(c.can.interface, "can4");
    /* socketcan without :IFACE keeps the machine's [CAN] INTERFACE */
    ncp_machine_cfg_default(&c);
    snprintf(c.can.interface, sizeof c.can.interface, "can0");
    ch.interface[0] = 0;
    assert_int_equal(ncp_cell_apply(&ch, &c, &d), NCP_OK);
    assert_string_equal(c.can.interface, "can0");
    /* no BACKEND: the machine's; a DP goes with lcm only */
    ncp_machine_cfg_default(&c);
    c.backend = NCP_BACKEND_LCM;
    c.lcm.dp = 5;
    ch = (struct ncp_cell_channel){ .num = 2, .backend = -1, .dp = 3, .dp_line = 9 };
    assert_int_equal(ncp_cell_apply(&ch, &c, &d), NCP_OK);
    assert_int_equal(c.backend, NCP_BACKEND_LCM);
    assert_int_equal(c.lcm.dp, 3);
    ncp_machine_cfg_default(&c);
    assert_int_not_equal(ncp_cell_apply(&ch, &c, &d), NCP_OK);
    assert_int_equal(d.line, 9);
    assert_non_null(strstr(d.msg, "[CHANNEL_2] DP goes with BACKEND = lcm"));
}

/* a machine INI in the cell's folder, loaded */
static void machine(const char *text, struct ncp_machine_cfg *c)
{
    char mp[160];
    snprintf(mp, sizeof mp, "%s/m.ini", dir);
    FILE *f = fopen(mp, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
    struct ncp_diag d;
    ncp_machine_cfg_default(c);
    int rc = ncp_machine_cfg_load(c, mp, &d);
    unlink(mp);
    if (rc != NCP_OK)
        fail_msg("%s", d.msg);
}

#define LIMITS "MIN_LIMIT = -500\nMAX_LIMIT = 500\nMAX_VELOCITY = 200\nMAX_ACCELERATION = 2000\nFERROR = 1\n"

static void test_channel_axes_are_its_drives(void **state)
{
    (void)state;
    struct ncp_machine_cfg c;
    struct ncp_diag d;
    memset(&d, 0, sizeof d);
    /* a socketcan channel on a machine whose Y has no drive */
    machine("[TRAJ]\nCOORDINATES = XY\n[CAN]\nINTERFACE = can0\n"
            "[AXIS_X]\nNODE_ID = 1\nCOUNTS_PER_MM = 1000\n" LIMITS "[AXIS_Y]\n" LIMITS, &c);
    struct ncp_cell_channel ch = { .num = 1, .backend = NCP_BACKEND_SOCKETCAN, .line = 4,
                                   .backend_line = 6 };
    assert_int_equal(ncp_cell_apply(&ch, &c, &d), NCP_OK);
    assert_int_not_equal(ncp_backend_cell_channel(&ch, &c, &d), NCP_OK);
    assert_int_equal(d.line, 6);
    assert_non_null(strstr(d.msg, "[CHANNEL_1] socketcan"));
    assert_non_null(strstr(d.msg, "[AXIS_Y] NODE_ID missing"));
    /* the machine's own BACKEND = socketcan: the section's line */
    ch.backend = -1;
    ch.backend_line = 0;
    c.backend = NCP_BACKEND_SOCKETCAN;
    assert_int_not_equal(ncp_backend_cell_channel(&ch, &c, &d), NCP_OK);
    assert_int_equal(d.line, 4);
    /* as sim or lcm the same machine is fine */
    c.backend = NCP_BACKEND_SIM;
    assert_int_equal(ncp_backend_cell_channel(&ch, &c, &d), NCP_OK);
    c.backend = NCP_BACKEND_LCM;
    assert_int_equal(ncp_backend_cell_channel(&ch, &c, &d), NCP_OK);
    /* every axis a drive: taken */
    machine("[TRAJ]\nCOORDINATES = XY\n[CAN]\nINTERFACE = can0\n"
            "[AXIS_X]\nNODE_ID = 1\nCOUNTS_PER_MM = 1000\n" LIMITS
            "[AXIS_Y]\nNODE_ID = 2\nCOUNTS_PER_MM = 1000\n" LIMITS, &c);
    ch.backend = NCP_BACKEND_SOCKETCAN;
    assert_int_equal(ncp_cell_apply(&ch, &c, &d), NCP_OK);
    assert_int_equal(ncp_backend_cell_channel(&ch, &c, &d), NCP_OK);
    /* ADCAI's distributed points are 1-4 */
    ncp_machine_cfg_default(&c);
    c.nck = NCP_NCK_ADCAI;
    ch = (struct ncp_cell_channel){ .num = 1, .backend = NCP_BACKEND_LCM, .dp = 5, .line = 4,
                                    .backend_line = 6, .dp_line = 7 };
    assert_int_equal(ncp_cell_apply(&ch, &c, &d), NCP_OK);
    assert_int_not_equal(ncp_backend_cell_channel(&ch, &c, &d), NCP_OK);
    assert_int_equal(d.line, 7);
    assert_non_null(strstr(d.msg, "adcai"));
    ch.dp = 4;
    assert_int_equal(ncp_cell_apply(&ch, &c, &d), NCP_OK);
    assert_int_equal(ncp_backend_cell_channel(&ch, &c, &d), NCP_OK);
}

static struct ncp_machine_cfg m[3];

/* channel k of the cell on backend be, section on line 10k, BACKEND on 10k+2 */
static void chan(int k, enum ncp_backend_kind be, unsigned axes)
{
    cell.ch[k] = (struct ncp_cell_channel){ .num = k, .backend = (int)be, .line = 10u * k + 1,
                                            .backend_line = 10u * k + 2 };
    ncp_machine_cfg_default(&m[k]);
    m[k].backend = be;
    m[k].axis_mask = axes;
    for (int j = 0; j < NCP_AXES; j++)
        m[k].axis[j].node_id = 0;
    cell.n = k + 1 > cell.n ? k + 1 : cell.n;
}

static int shared(struct ncp_diag *d)
{
    const struct ncp_machine_cfg *cfgs[3] = { &m[0], &m[1], &m[2] };
    memset(d, 0, sizeof *d);
    return ncp_backend_cell_shared(&cell, cfgs, d);
}

static void test_no_can_node_or_bus_twice(void **state)
{
    (void)state;
    struct ncp_diag d;
    memset(&cell, 0, sizeof cell);
    chan(0, NCP_BACKEND_SIM, 0x7);
    chan(1, NCP_BACKEND_SOCKETCAN, 0x3);
    chan(2, NCP_BACKEND_SOCKETCAN, 0x4);
    snprintf(m[1].can.interface, sizeof m[1].can.interface, "can0");
    snprintf(m[2].can.interface, sizeof m[2].can.interface, "can1");
    m[1].axis[0].node_id = 1;
    m[1].axis[1].node_id = 2;
    m[2].axis[2].node_id = 2;
    /* node 2 on two buses: two drives */
    assert_int_equal(shared(&d), NCP_OK);
    /* one bus: node 2 is channel 1's Y and channel 2's Z */
    snprintf(m[2].can.interface, sizeof m[2].can.interface, "can0");
    assert_int_not_equal(shared(&d), NCP_OK);
    assert_int_equal(d.line, 22);
    assert_non_null(strstr(d.msg, "CAN node 2 on can0 is channel 1's axis Y and channel 2's "
                                  "axis Z"));
    /* one bus, other nodes: still two masters sending SYNC */
    m[2].axis[2].node_id = 3;
    assert_int_not_equal(shared(&d), NCP_OK);
    assert_int_equal(d.line, 22);
    assert_non_null(strstr(d.msg, "channels 1 and 2 on one CAN interface can0"));
}

static void test_no_llc_or_lcm_url_twice(void **state)
{
    (void)state;
    struct ncp_diag d;
    unsetenv("LCM_DEFAULT_URL");
    memset(&cell, 0, sizeof cell);
    chan(0, NCP_BACKEND_LCM, 0x7);
    chan(1, NCP_BACKEND_SIM, 0x7);   /* a simulated X is no LLC */
    chan(2, NCP_BACKEND_LCM, 0x1);
    /* "" is LCM's default URL: the same network */
    snprintf(m[2].lcm.url, sizeof m[2].lcm.url, "%s", NCP_MSG_DEFAULT_URL);
    assert_int_not_equal(shared(&d), NCP_OK);
    assert_int_equal(d.line, 22);
    assert_non_null(strstr(d.msg, "the LLC of axis X on udpm://239.255.76.67:7667 would be "
                                  "channel 0's and channel 2's"));
    /* other axes, one URL: every LLC there hears both HLCs */
    m[2].axis_mask = NCP_AXIS_BIT(NCP_AXIS_A);
    assert_int_not_equal(shared(&d), NCP_OK);
    assert_non_null(strstr(d.msg, "channels 0 and 2 on one LCM URL"));
    /* another port: another network, the same letters allowed */
    m[2].axis_mask = 0x1;
    snprintf(m[2].lcm.url, sizeof m[2].lcm.url, "udpm://239.255.76.67:7700?ttl=0");
    assert_int_equal(shared(&d), NCP_OK);
    /* an lcm channel beside a socketcan one on the same letters */
    chan(1, NCP_BACKEND_SOCKETCAN, 0x7);
    snprintf(m[1].can.interface, sizeof m[1].can.interface, "can0");
    assert_int_equal(shared(&d), NCP_OK);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_reads_channels, setup, teardown),
        cmocka_unit_test_setup_teardown(test_machine_ini_is_no_cell, setup, teardown),
        cmocka_unit_test_setup_teardown(test_refusals_name_the_line, setup, teardown),
        cmocka_unit_test(test_apply_over_the_machine),
        cmocka_unit_test_setup_teardown(test_channel_axes_are_its_drives, setup, teardown),
        cmocka_unit_test(test_no_can_node_or_bus_twice),
        cmocka_unit_test(test_no_llc_or_lcm_url_twice),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
