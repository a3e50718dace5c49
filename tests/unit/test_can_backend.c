/* The socketcan backend's pieces that need no bus: the INI's [CAN] section
 * and per-axis NODE_ID / COUNTS_PER_MM, mm <-> counts scaling, the
 * configuration check, the master's fault watch on hand-made node states,
 * the fault messages and the 0x60C2 period encoding; and the sim backend
 * behind the backend interface. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include <linux/can.h>

#include "ncpar/backend.h"
#include "ncpar/can.h"
#include "ncpar/config.h"

/* ---- INI ------------------------------------------------------------------ */

/* what every machine INI states for each axis */
#define LIMITS "MIN_LIMIT = -500\nMAX_LIMIT = 500\nMAX_VELOCITY = 200\nMAX_ACCELERATION = 2000\nFERROR = 1\n"
#define AXES "[AXIS_X]\n" LIMITS "[AXIS_Y]\n" LIMITS "[AXIS_Z]\n" LIMITS

static char ini_path[64];

static int load_ini(const char *text, struct ncp_machine_cfg *c, struct ncp_diag *d)
{
    snprintf(ini_path, sizeof ini_path, "/tmp/ncp-test-can-XXXXXX");
    int fd = mkstemp(ini_path);
    assert_true(fd >= 0);
    FILE *f = fdopen(fd, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
    ncp_machine_cfg_default(c);
    int rc = ncp_machine_cfg_load(c, ini_path, d);
    unlink(ini_path);
    return rc;
}

static void test_ini_can_section(void **state)
{
    (void)state;
    struct ncp_machine_cfg c;
    struct ncp_diag d;
    assert_int_equal(load_ini("[CAN]\nINTERFACE = can1\nHEARTBEAT_PERIOD_MS = 20\n"
                              "HEARTBEAT_TIMEOUT_MS = 300\nSDO_TIMEOUT_MS = 150\n"
                              "MASTER_NODE = 100\nHEARTBEAT_CONSUMER_MS = 70\n"
                              "RPDO_TIMEOUT_MS = 0\nABORT_CONNECTION_OPTION = 1\n"
                              "FAULT_REACTION_OPTION = 0\n"
                              "[AXIS_X]\nNODE_ID = 4\nCOUNTS_PER_MM = 1000\n" LIMITS
                              "[AXIS_Y]\n" LIMITS
                              "[AXIS_Z]\nnode_id = 127\nCOUNTS_PER_MM = 2.5\n" LIMITS,
                              &c, &d),
                     NCP_OK);
    assert_string_equal(c.can.interface, "can1");
    assert_int_equal(c.can.heartbeat_period_ms, 20);
    assert_int_equal(c.can.heartbeat_timeout_ms, 300);
    assert_int_equal(c.can.sdo_timeout_ms, 150);
    assert_int_equal(c.can.master_node, 100);
    assert_int_equal(c.can.hb_consumer_ms, 70);
    assert_int_equal(c.can.rpdo_timeout_ms, 0);
    assert_int_equal(c.can.abort_option, 1);
    assert_int_equal(c.can.fault_reaction, 0);
    assert_int_equal(c.axis[0].node_id, 4);
    assert_true(c.axis[0].counts_per_mm == 1000.0);
    assert_int_equal(c.axis[1].node_id, 0);
    assert_int_equal(c.axis[2].node_id, 127);
    assert_true(c.axis[2].counts_per_mm == 2.5);
    /* an INI saying nothing of CAN keeps the defaults and the sim backend */
    assert_int_equal(load_ini(AXES, &c, &d), NCP_OK);
    assert_int_equal(c.backend, NCP_BACKEND_SIM);
    assert_string_equal(c.can.interface, "");
    assert_int_equal(c.can.heartbeat_timeout_ms, 500);
    assert_int_equal(c.can.sdo_timeout_ms, 200);
    /* the drives guard a master at node 127 and quick-stop without it */
    assert_int_equal(c.can.master_node, 127);
    assert_int_equal(c.can.hb_consumer_ms, 150);
    assert_int_equal(c.can.abort_option, 3);
}

static void expect_error(const char *text, const char *want)
{
    struct ncp_machine_cfg c;
    struct ncp_diag d;
    assert_int_not_equal(load_ini(text, &c, &d), NCP_OK);
    if (!strstr(d.msg, want) || !strstr(d.msg, "/tmp/ncp-test-can-"))
        fail_msg("'%s' lacks '%s' or the file name", d.msg, want);
}

static void test_ini_can_errors(void **state)
{
    (void)state;
    expect_error("[CAN]\nBITRATE = 500000\n", "[CAN] unknown key BITRATE");
    expect_error("[CAN]\nINTERFACE = can0 x\n", "[CAN] INTERFACE: bad value 'can0 x'");
    expect_error("[CAN]\nINTERFACE = averyveryverylongname\n", "[CAN] INTERFACE: bad value");
    expect_error("[CAN]\nHEARTBEAT_TIMEOUT_MS = 0\n", "[CAN] HEARTBEAT_TIMEOUT_MS: bad value '0'");
    expect_error("[CAN]\nSDO_TIMEOUT_MS = 1.5\n", "[CAN] SDO_TIMEOUT_MS: bad value '1.5'");
    expect_error("[AXIS_Y]\nNODE_ID = 128\n", "[AXIS_Y] NODE_ID: bad value '128'");
    expect_error("[AXIS_Y]\nNODE_ID = 0\n", "[AXIS_Y] NODE_ID: bad value '0'");
    expect_error("[AXIS_X]\nCOUNTS_PER_MM = -5\n", "[AXIS_X] COUNTS_PER_MM: bad value '-5'");
    expect_error("[AXIS_X]\nCOUNTS_PER_MM = lots\n", "[AXIS_X] COUNTS_PER_MM: bad value 'lots'");
    expect_error("[AXIS_X]\nNODE_ID = 3\n" LIMITS "[AXIS_Y]\n" LIMITS "[AXIS_Z]\nNODE_ID = 3\n" LIMITS,
                 "[AXIS_Z] NODE_ID 3 is already the node of [AXIS_X]");
    expect_error("[CAN]\nHEARTBEAT_PERIOD_MS = 100\nHEARTBEAT_TIMEOUT_MS = 100\n" AXES,
                 "HEARTBEAT_TIMEOUT_MS 100 must be longer than HEARTBEAT_PERIOD_MS 100");
    expect_error("[CAN]\nHEARTBEAT_PERIOD_MS = 100\nHEARTBEAT_TIMEOUT_MS = 500\n"
                 "HEARTBEAT_CONSUMER_MS = 100\n" AXES,
                 "HEARTBEAT_CONSUMER_MS 100 must be longer than HEARTBEAT_PERIOD_MS 100");
    expect_error("[AXIS_X]\nNODE_ID = 127\n" LIMITS "[AXIS_Y]\n" LIMITS "[AXIS_Z]\n" LIMITS,
                 "[CAN] MASTER_NODE 127 is the NODE_ID of [AXIS_X]");
    expect_error("[CAN]\nABORT_CONNECTION_OPTION = 4\n",
                 "[CAN] ABORT_CONNECTION_OPTION: bad value '4'");
    expect_error("[CAN]\nMASTER_NODE = 128\n", "[CAN] MASTER_NODE: bad value '128'");
}

/* ---- scaling and the configuration check ------------------------------------- */

static void test_counts_scaling(void **state)
{
    (void)state;
    int32_t c = 0;
    assert_int_equal(ncp_mm_to_counts(1.23456, 10000, &c), 0);
    assert_int_equal(c, 12346);
    assert_int_equal(ncp_mm_to_counts(-1.23454, 10000, &c), 0);
    assert_int_equal(c, -12345);
    assert_int_equal(ncp_mm_to_counts(0, 10000, &c), 0);
    assert_int_equal(c, 0);
    assert_int_equal(ncp_mm_to_counts(214748.3647, 10000, &c), 0);
    assert_int_equal(c, INT32_MAX);
    c = 7;
    assert_int_equal(ncp_mm_to_counts(214748.3648, 10000, &c), -1);
    assert_int_equal(c, 7);
    assert_int_equal(ncp_mm_to_counts(-300000, 10000, &c), -1);
    assert_int_equal(ncp_mm_to_counts(NAN, 10000, &c), -1);
    assert_true(ncp_counts_to_mm(12346, 10000) == 1.2346);
    assert_true(ncp_counts_to_mm(-5, 2.5) == -2.0);
    /* a round trip stays within half a count */
    for (double mm = -3.0; mm < 3.0; mm += 0.01237) {
        assert_int_equal(ncp_mm_to_counts(mm, 4096, &c), 0);
        assert_true(ncp_counts_to_mm(c, 4096) - mm <= 0.5 / 4096 + 1e-12);
        assert_true(mm - ncp_counts_to_mm(c, 4096) <= 0.5 / 4096 + 1e-12);
    }
}

static void can_machine(struct ncp_machine_cfg *c)
{
    ncp_machine_cfg_default(c);
    c->backend = NCP_BACKEND_SOCKETCAN;
    snprintf(c->can.interface, sizeof c->can.interface, "vcan0");
    for (int j = 0; j < NCP_AXES; j++) {
        c->axis[j].node_id = j + 1;
        c->axis[j].counts_per_mm = 10000;
    }
}

static void test_socketcan_check_cfg(void **state)
{
    (void)state;
    struct ncp_machine_cfg c;
    struct ncp_diag d;
    can_machine(&c);
    assert_int_equal(ncp_socketcan_check_cfg(&c, &d), NCP_OK);
    c.axis[1].node_id = 0;
    assert_int_not_equal(ncp_socketcan_check_cfg(&c, &d), NCP_OK);
    assert_non_null(strstr(d.msg, "[AXIS_Y] NODE_ID missing"));
    can_machine(&c);
    c.axis[2].counts_per_mm = 0;
    assert_int_not_equal(ncp_socketcan_check_cfg(&c, &d), NCP_OK);
    assert_non_null(strstr(d.msg, "[AXIS_Z] COUNTS_PER_MM missing"));
    can_machine(&c);
    c.axis[0].counts_per_mm = 1e7; /* 500 mm * 1e7 > 2^31 */
    assert_int_not_equal(ncp_socketcan_check_cfg(&c, &d), NCP_OK);
    assert_non_null(strstr(d.msg, "[AXIS_X] MIN_LIMIT..MAX_LIMIT"));
    can_machine(&c);
    c.can.interface[0] = 0;
    assert_int_not_equal(ncp_socketcan_check_cfg(&c, &d), NCP_OK);
    assert_non_null(strstr(d.msg, "[CAN] INTERFACE"));
}

/* ---- the master's fault watch, on nodes set by hand --------------------------- */

static void fake_master(struct ncp_co_master *m)
{
    memset(m, 0, sizeof *m);
    m->bus.fd = -1;
    snprintf(m->bus.ifname, sizeof m->bus.ifname, "vcan0");
    m->cfg = (struct ncp_co_master_cfg){.period_us = 1000, .sdo_timeout_ms = 200,
                                        .hb_period_ms = 50, .hb_timeout_ms = 500};
    m->n = 2;
    for (size_t i = 0; i < m->n; i++) {
        ncp_co_node_init(&m->node[i], (uint8_t)(i + 1));
        m->node[i].statusword = ncp_cia402_statusword(NCP_402_OPERATION_ENABLED);
        m->node[i].last_hb_ms = 1000;
        m->node[i].hb_state = NCP_NMT_OPERATIONAL;
        m->enabled[i] = 1;
    }
    m->started_ms = 900;
}

static void describe(const struct ncp_co_master *m, char *buf, size_t len)
{
    ncp_co_fault_describe(&m->fault, m->bus.ifname, buf, len);
}

static void test_master_check(void **state)
{
    (void)state;
    struct ncp_co_master m;
    char buf[NCP_DIAG_MSG_MAX];
    fake_master(&m);
    assert_int_equal(ncp_co_master_check(&m, 1500), 0);
    assert_int_equal(m.fault.kind, NCP_CO_FAULT_NONE);
    /* heartbeat 501 ms old: lost */
    assert_int_equal(ncp_co_master_check(&m, 1501), -1);
    assert_int_equal(m.fault.kind, NCP_CO_FAULT_HEARTBEAT);
    describe(&m, buf, sizeof buf);
    assert_string_equal(buf, "node 1: heartbeat (0x701) lost: last one 501 ms ago, timeout "
                             "500 ms (last state operational)");
    /* never one at all: counted from the NMT start */
    fake_master(&m);
    m.node[1].last_hb_ms = -1;
    assert_int_equal(ncp_co_master_check(&m, 1400), 0);
    assert_int_equal(ncp_co_master_check(&m, 1401), -1);
    describe(&m, buf, sizeof buf);
    assert_string_equal(buf, "node 2: heartbeat (0x702) lost: none received within 500 ms");
    /* a drive leaving Operation enabled */
    fake_master(&m);
    m.node[1].statusword = ncp_cia402_statusword(NCP_402_FAULT);
    assert_int_equal(ncp_co_master_check(&m, 1100), -1);
    assert_int_equal(m.fault.kind, NCP_CO_FAULT_STATE);
    assert_int_equal(m.fault.node, 2);
    describe(&m, buf, sizeof buf);
    assert_non_null(strstr(buf, "node 2: drive left Operation enabled: now Fault (statusword "
                                "0x6041 = 0x"));
    assert_non_null(strstr(buf, "error code 0x603F = unreadable"));
    m.fault.error_code = 0x7305;
    describe(&m, buf, sizeof buf);
    assert_non_null(strstr(buf, "error code 0x603F = 0x7305)"));
    /* a drive not yet enabled is not judged by its state */
    fake_master(&m);
    m.enabled[1] = 0;
    m.node[1].statusword = ncp_cia402_statusword(NCP_402_SWITCHED_ON);
    assert_int_equal(ncp_co_master_check(&m, 1100), 0);
    /* heartbeat saying pre-operational */
    fake_master(&m);
    m.node[0].hb_state = NCP_NMT_PREOP;
    assert_int_equal(ncp_co_master_check(&m, 1100), -1);
    describe(&m, buf, sizeof buf);
    assert_string_equal(buf, "node 1: heartbeat (0x701) reports NMT state pre-operational, "
                             "not operational");
}

/* ---- the cyclic path over a socket pair (a CAN_RAW socket's frame format) ------ */

static int peer_send(int fd, uint32_t id, const uint8_t *data, uint8_t len)
{
    struct can_frame cf;
    memset(&cf, 0, sizeof cf);
    cf.can_id = id;
    cf.can_dlc = len;
    memcpy(cf.data, data, len);
    return send(fd, &cf, sizeof cf, 0) == (ssize_t)sizeof cf ? 0 : -1;
}

static int peer_recv(int fd, struct can_frame *cf)
{
    return recv(fd, cf, sizeof *cf, MSG_DONTWAIT) == (ssize_t)sizeof *cf ? 0 : -1;
}

static void test_master_rt_path(void **state)
{
    (void)state;
    int sv[2];
    assert_int_equal(socketpair(AF_UNIX, SOCK_DGRAM, 0, sv), 0);
    struct ncp_co_master m;
    fake_master(&m);
    m.bus.fd = sv[0];
    m.cw[0] = m.cw[1] = NCP_402_CW_ENABLE;
    m.target[0] = 1234;
    m.target[1] = -5;
    /* nothing waiting: no fault */
    assert_int_equal(ncp_co_master_poll(&m, 1000, 64), 0);
    /* RPDO1 per node, then SYNC */
    assert_int_equal(ncp_co_master_send(&m), 0);
    assert_int_equal(m.cycle, 1);
    struct can_frame cf;
    assert_int_equal(peer_recv(sv[1], &cf), 0);
    assert_int_equal(cf.can_id, 0x201);
    assert_int_equal(cf.can_dlc, 6);
    assert_int_equal(cf.data[0], 0x0F);
    assert_int_equal(cf.data[2] | cf.data[3] << 8, 1234);
    assert_int_equal(peer_recv(sv[1], &cf), 0);
    assert_int_equal(cf.can_id, 0x202);
    assert_int_equal(peer_recv(sv[1], &cf), 0);
    assert_int_equal(cf.can_id, 0x080);
    assert_int_equal(peer_recv(sv[1], &cf), -1);
    /* TPDOs and heartbeats come in */
    const uint8_t tpdo[6] = {0x37, 0x02, 0xD2, 0x04, 0, 0}; /* op enabled, 1234 */
    const uint8_t hb[1] = {NCP_NMT_OPERATIONAL};
    assert_int_equal(peer_send(sv[1], 0x181, tpdo, 6), 0);
    assert_int_equal(peer_send(sv[1], 0x702, hb, 1), 0);
    assert_int_equal(ncp_co_master_poll(&m, 1200, 64), 0);
    assert_int_equal(m.node[0].actual, 1234);
    assert_int_equal(m.node[0].tpdos, 1);
    assert_true(m.node[1].last_hb_ms == 1200);
    assert_int_equal(ncp_co_master_check(&m, 1200), 0);
    /* "error reset" EMCY (code 0) is no fault; a real one is */
    const uint8_t reset[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    const uint8_t emcy[8] = {0x11, 0x86, 0x21, 0, 0, 0, 0, 0};
    assert_int_equal(peer_send(sv[1], 0x082, reset, 8), 0);
    assert_int_equal(ncp_co_master_poll(&m, 1200, 64), 0);
    assert_int_equal(peer_send(sv[1], 0x082, emcy, 8), 0);
    assert_int_equal(ncp_co_master_poll(&m, 1200, 64), -1);
    assert_int_equal(m.fault.kind, NCP_CO_FAULT_EMCY);
    assert_int_equal(m.fault.node, 2);
    assert_int_equal(m.fault.emcy.code, 0x8611);
    /* at most max frames per call: a backlog drains over several periods */
    fake_master(&m);
    m.bus.fd = sv[0];
    for (int k = 0; k < 10; k++)
        assert_int_equal(peer_send(sv[1], 0x181, tpdo, 6), 0);
    assert_int_equal(ncp_co_master_poll(&m, 1000, 4), 0);
    assert_int_equal(m.node[0].tpdos, 4);
    assert_int_equal(ncp_co_master_poll(&m, 1000, 64), 0);
    assert_int_equal(m.node[0].tpdos, 10);
    close(sv[0]);
    close(sv[1]);
}

static void test_master_tx_full(void **state)
{
    (void)state;
    int sv[2];
    assert_int_equal(socketpair(AF_UNIX, SOCK_DGRAM, 0, sv), 0);
    struct ncp_co_master m;
    fake_master(&m);
    m.bus.fd = sv[0];
    /* nobody reads: the queue fills, periods are skipped, then a fault */
    int rc = 0;
    long k;
    for (k = 0; k < 100000 && rc == 0; k++)
        rc = ncp_co_master_send(&m);
    assert_int_equal(rc, -1);
    assert_int_equal(m.fault.kind, NCP_CO_FAULT_BUS);
    assert_int_equal(m.fault.err, 0);
    assert_int_equal(m.tx_full, 50);
    char buf[NCP_DIAG_MSG_MAX];
    describe(&m, buf, sizeof buf);
    assert_non_null(strstr(buf, "CAN vcan0: transmit queue full for 50 periods"));
    /* a closed peer is a send error, reported at once */
    fake_master(&m);
    m.bus.fd = sv[0];
    close(sv[1]);
    assert_int_equal(ncp_co_master_send(&m), -1);
    assert_int_equal(m.fault.kind, NCP_CO_FAULT_BUS);
    assert_int_not_equal(m.fault.err, 0);
    close(sv[0]);
}

static void test_fault_messages(void **state)
{
    (void)state;
    struct ncp_co_fault f;
    char buf[NCP_DIAG_MSG_MAX];
    memset(&f, 0, sizeof f);
    f.kind = NCP_CO_FAULT_EMCY;
    f.node = 5;
    f.emcy = (struct ncp_emcy){.code = 0x8611, .reg = 0x21, .vendor = {0}};
    ncp_co_fault_describe(&f, "vcan0", buf, sizeof buf);
    assert_string_equal(buf, "node 5: EMCY (0x085): error code 0x8611 following error; error "
                             "register 0x21: generic, device profile");
    f.kind = NCP_CO_FAULT_BUS;
    f.node = 3;
    f.cob = 0x203;
    f.err = 100; /* ENETDOWN */
    ncp_co_fault_describe(&f, "can0", buf, sizeof buf);
    assert_non_null(strstr(buf, "CAN can0: cannot send frame 0x203 (node 3): "));
    f.err = 0;
    ncp_co_fault_describe(&f, "can0", buf, sizeof buf);
    assert_non_null(strstr(buf, "transmit queue full for 50 periods, frame 0x203 (node 3)"));
    f.kind = NCP_CO_FAULT_START;
    snprintf(f.text, sizeof f.text, "node 9: SDO write 0x6060:00 aborted: 0x06090030 invalid");
    ncp_co_fault_describe(&f, "can0", buf, sizeof buf);
    assert_string_equal(buf, f.text);
    /* a short buffer truncates, still a string */
    f.kind = NCP_CO_FAULT_EMCY;
    char tiny[12];
    memset(tiny, 'x', sizeof tiny);
    ncp_co_fault_describe(&f, "vcan0", tiny, sizeof tiny);
    assert_int_equal(strlen(tiny), sizeof tiny - 1);
}

static void test_interp_period(void **state)
{
    (void)state;
    uint8_t v = 0; /* no expected value is 0: an unset result fails */
    int8_t e = 0;
    /* period in us -> value x 10^exponent seconds (0x60C2) */
    static const struct { uint32_t us; uint8_t v; int8_t e; } ok[] = {
        { 1000, 1, -3 }, { 4000, 4, -3 }, { 250, 25, -5 }, { 125, 125, -6 }, { 1500, 15, -4 },
    };
    for (size_t k = 0; k < sizeof ok / sizeof ok[0]; k++) {
        assert_int_equal(ncp_co_interp_period(ok[k].us, &v, &e), 0);
        assert_int_equal(v, ok[k].v);
        assert_int_equal(e, ok[k].e);
    }
    assert_int_equal(ncp_co_interp_period(300000, &v, &e), -1);
    assert_int_equal(ncp_co_interp_period(0, &v, &e), -1);
}

/* ---- the sim behind the backend interface -------------------------------------- */

static void test_sim_backend(void **state)
{
    (void)state;
    struct ncp_machine_cfg c;
    struct ncp_diag d;
    ncp_machine_cfg_default(&c);
    struct ncp_backend b;
    assert_int_equal(ncp_backend_open(&b, &c, NULL, &d), NCP_OK);
    assert_string_equal(b.ops->name, "sim");
    assert_int_equal(b.real_clock_only, 0);
    double pos[NCP_AXES] = {1, 1, 1};
    assert_int_equal(b.ops->start(&b, pos), 0);
    assert_true(pos[0] == 0 && pos[1] == 0 && pos[2] == 0);
    struct ncp_sim ref;
    static const double origin[NCP_AXES];
    ncp_sim_init(&ref, &c, origin);
    for (int k = 0; k < 200; k++) {
        double cmd[NCP_AXES] = {0.01 * k, -0.02 * k, 0}, next[NCP_AXES];
        double act[NCP_AXES], want[NCP_AXES];
        for (int j = 0; j < NCP_AXES; j++)
            next[j] = cmd[j] * (k + 1) / (k ? k : 1);
        assert_int_equal(b.ops->cycle(&b, cmd, next, act), 0);
        ncp_sim_step(&ref, cmd, next, want);
        assert_memory_equal(act, want, sizeof act);
    }
    b.ops->stop(&b);
    b.ops->close(&b);
    /* socketcan without its configuration: refused before any bus access */
    c.backend = NCP_BACKEND_SOCKETCAN;
    assert_int_not_equal(ncp_backend_open(&b, &c, NULL, &d), NCP_OK);
    assert_non_null(strstr(d.msg, "[CAN] INTERFACE"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ini_can_section),
        cmocka_unit_test(test_ini_can_errors),
        cmocka_unit_test(test_counts_scaling),
        cmocka_unit_test(test_socketcan_check_cfg),
        cmocka_unit_test(test_master_check),
        cmocka_unit_test(test_master_rt_path),
        cmocka_unit_test(test_master_tx_full),
        cmocka_unit_test(test_fault_messages),
        cmocka_unit_test(test_interp_period),
        cmocka_unit_test(test_sim_backend),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
