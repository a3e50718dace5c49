/* The seat's E-stop and reset on CiA 402 drives (src/can/seat.c): the
 * controlwords an E-stop sends as a drive brakes and comes to rest, the walk
 * back to Operation enabled from Fault with the targets at the actual
 * positions, a reset that cannot enable a drive, and the EMCY code texts
 * the operator reads. No bus: node states are made by hand. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <string.h>

#include "ncpar/can.h"

static void test_estop_controlwords(void **state)
{
    (void)state;
    uint16_t oe = ncp_cia402_statusword(NCP_402_OPERATION_ENABLED);
    uint16_t qs = ncp_cia402_statusword(NCP_402_QUICK_STOP_ACTIVE);
    /* enabled: Quick Stop, never Disable Voltage first (the axis would coast) */
    assert_int_equal(ncp_cia402_estop_cw(oe, 0), NCP_402_CW_QUICK_STOP);
    assert_int_equal(ncp_cia402_estop_cw(oe, 10), NCP_402_CW_QUICK_STOP);
    /* braking: Quick Stop held until bit 10 or a still actual position */
    assert_int_equal(ncp_cia402_estop_cw(qs, 0), NCP_402_CW_QUICK_STOP);
    assert_int_equal(ncp_cia402_estop_cw(qs, NCP_402_STILL_TPDOS - 1), NCP_402_CW_QUICK_STOP);
    assert_int_equal(ncp_cia402_estop_cw(qs, NCP_402_STILL_TPDOS), NCP_402_CW_DISABLE);
    assert_int_equal(ncp_cia402_estop_cw(qs | NCP_402_SW_TARGET_REACHED, 0), NCP_402_CW_DISABLE);
    /* a drive in Fault or already off: Disable Voltage, no fault reset */
    assert_int_equal(ncp_cia402_estop_cw(ncp_cia402_statusword(NCP_402_FAULT), 0),
                     NCP_402_CW_DISABLE);
    assert_int_equal(ncp_cia402_estop_cw(ncp_cia402_statusword(NCP_402_SWITCH_ON_DISABLED), 0),
                     NCP_402_CW_DISABLE);
    /* what the drive does with them: Quick stop active, then Switch on disabled */
    assert_int_equal(ncp_cia402_apply(NCP_402_OPERATION_ENABLED, NCP_402_CW_QUICK_STOP,
                                      NCP_402_CW_ENABLE),
                     NCP_402_QUICK_STOP_ACTIVE);
    assert_int_equal(ncp_cia402_apply(NCP_402_QUICK_STOP_ACTIVE, NCP_402_CW_DISABLE,
                                      NCP_402_CW_QUICK_STOP),
                     NCP_402_SWITCH_ON_DISABLED);
}

static void master_of(struct ncp_co_master *m, size_t n)
{
    memset(m, 0, sizeof *m);
    m->n = n;
    for (size_t i = 0; i < n; i++) {
        ncp_co_node_init(&m->node[i], (uint8_t)(i + 1));
        m->node[i].statusword = ncp_cia402_statusword(NCP_402_OPERATION_ENABLED);
        m->node[i].tpdos = 1;
        m->enabled[i] = 1;
        m->cw[i] = NCP_402_CW_ENABLE;
    }
}

/* One TPDO of node i: its new statusword and actual position. */
static void tpdo(struct ncp_co_master *m, size_t i, enum ncp_cia402_state s, int32_t actual)
{
    m->node[i].statusword = ncp_cia402_statusword(s);
    m->node[i].actual = actual;
    m->node[i].tpdos++;
}

static void test_estop_sequence(void **state)
{
    (void)state;
    struct ncp_co_master m;
    master_of(&m, 2);
    m.node[0].actual = 1000;
    m.target[0] = 1500;
    ncp_co_master_seat(&m, 0);
    assert_int_equal(m.mode, NCP_CO_ESTOP);
    assert_int_equal(ncp_co_master_seat_step(&m), 1);
    assert_int_equal(m.cw[0], NCP_402_CW_QUICK_STOP);
    assert_int_equal(m.cw[1], NCP_402_CW_QUICK_STOP);
    /* the frozen setpoint is not sent: the drive brakes from where it is */
    assert_int_equal(m.target[0], 1000);
    /* node 1 brakes over two TPDOs, then reports the same position */
    int32_t at[] = {1100, 1150, 1150, 1150, 1150};
    for (size_t k = 0; k < sizeof at / sizeof at[0]; k++) {
        tpdo(&m, 0, NCP_402_QUICK_STOP_ACTIVE, at[k]);
        tpdo(&m, 1, NCP_402_QUICK_STOP_ACTIVE, 0);
        assert_int_equal(ncp_co_master_seat_step(&m), 1);
        /* still since the TPDO at k = 1: at rest after NCP_402_STILL_TPDOS more */
        int rest0 = k >= 1 + NCP_402_STILL_TPDOS;
        assert_int_equal(m.cw[0], rest0 ? NCP_402_CW_DISABLE : NCP_402_CW_QUICK_STOP);
        assert_int_equal(m.target[0], at[k]);
    }
    /* no new TPDO: no new evidence of rest */
    master_of(&m, 1);
    ncp_co_master_seat(&m, 0);
    tpdo(&m, 0, NCP_402_QUICK_STOP_ACTIVE, 5);
    for (int k = 0; k < 10; k++)
        assert_int_equal(ncp_co_master_seat_step(&m), 1);
    assert_int_equal(m.cw[0], NCP_402_CW_QUICK_STOP);
    /* bit 10: at rest at once */
    m.node[0].statusword |= NCP_402_SW_TARGET_REACHED;
    ncp_co_master_seat_step(&m);
    assert_int_equal(m.cw[0], NCP_402_CW_DISABLE);
}

static void test_reset_walk(void **state)
{
    (void)state;
    struct ncp_co_master m;
    master_of(&m, 2);
    /* running: on changes nothing, a fault recorded before stays */
    m.fault.kind = NCP_CO_FAULT_HEARTBEAT;
    ncp_co_master_seat(&m, 1);
    assert_int_equal(m.mode, NCP_CO_RUN);
    assert_int_equal(m.fault.kind, NCP_CO_FAULT_HEARTBEAT);
    assert_int_equal(ncp_co_master_seat_step(&m), 0);
    /* node 1 faulted with an EMCY, node 2 was E-stopped to Switch on disabled */
    m.fault.kind = NCP_CO_FAULT_EMCY;
    m.node[0].emcy.code = 0x8611;
    ncp_co_master_seat(&m, 0);
    tpdo(&m, 0, NCP_402_FAULT, 7000);
    tpdo(&m, 1, NCP_402_SWITCH_ON_DISABLED, -300);
    ncp_co_master_seat_step(&m);
    ncp_co_master_seat(&m, 1);
    assert_int_equal(m.mode, NCP_CO_ENABLING);
    assert_int_equal(m.fault.kind, NCP_CO_FAULT_NONE);
    assert_int_equal(m.node[0].emcy.code, 0);
    /* fault reset (rising bit 7), then shutdown, switch on, enable */
    enum ncp_cia402_state s0 = NCP_402_FAULT, s1 = NCP_402_SWITCH_ON_DISABLED;
    uint16_t seen0[8], seen1[8];
    int k = 0, rc = 1;
    for (; k < 8 && rc == 1; k++) {
        rc = ncp_co_master_seat_step(&m);
        seen0[k] = m.cw[0];
        seen1[k] = m.cw[1];
        if (rc == 1) {
            assert_int_equal(m.target[0], 7000);
            assert_int_equal(m.target[1], -300);
        }
        s0 = ncp_cia402_apply(s0, m.cw[0], k ? seen0[k - 1] : NCP_402_CW_DISABLE);
        s1 = ncp_cia402_apply(s1, m.cw[1], k ? seen1[k - 1] : NCP_402_CW_DISABLE);
        tpdo(&m, 0, s0, 7000);
        tpdo(&m, 1, s1, -300);
    }
    assert_int_equal(rc, 0);
    assert_int_equal(m.mode, NCP_CO_RUN);
    assert_int_equal(seen0[0], NCP_402_CW_FAULT_RESET);
    assert_int_equal(seen0[1], NCP_402_CW_SHUTDOWN);
    assert_int_equal(seen0[2], NCP_402_CW_SWITCH_ON);
    assert_int_equal(seen0[3], NCP_402_CW_ENABLE);
    assert_int_equal(seen1[0], NCP_402_CW_SHUTDOWN);
    assert_int_equal(seen1[1], NCP_402_CW_SWITCH_ON);
    assert_int_equal(seen1[2], NCP_402_CW_ENABLE);
    assert_true(m.enabled[0] && m.enabled[1]);
}

static void test_reset_gives_up(void **state)
{
    (void)state;
    struct ncp_co_master m;
    master_of(&m, 2);
    ncp_co_master_seat(&m, 0);
    tpdo(&m, 0, NCP_402_SWITCH_ON_DISABLED, 0);
    tpdo(&m, 1, NCP_402_FAULT, 0);
    ncp_co_master_seat(&m, 1);
    /* node 2's fault does not go: the reset ends in a STATE fault naming it */
    int rc = 1;
    for (int k = 0; k <= NCP_CO_ENABLE_PERIODS && rc == 1; k++) {
        rc = ncp_co_master_seat_step(&m);
        tpdo(&m, 0, NCP_402_OPERATION_ENABLED, 0);
        tpdo(&m, 1, NCP_402_FAULT, 0);
    }
    assert_int_equal(rc, -1);
    assert_int_equal(m.fault.kind, NCP_CO_FAULT_STATE);
    assert_int_equal(m.fault.node, 2);
    assert_int_equal(m.mode, NCP_CO_ESTOP);
    char buf[256];
    ncp_co_fault_describe(&m.fault, "vcan0", buf, sizeof buf);
    assert_non_null(strstr(buf, "node 2: drive left Operation enabled: now Fault"));
}

static void test_emcy_texts(void **state)
{
    (void)state;
    assert_string_equal(ncp_emcy_code_text(0x2310), "continuous over-current");
    assert_string_equal(ncp_emcy_code_text(0x8611), "following error");
    assert_string_equal(ncp_emcy_code_text(0x5530), "EEPROM / data storage fault");
    assert_string_equal(ncp_emcy_code_text(0x8130), "life guard or heartbeat error");
    assert_string_equal(ncp_emcy_code_text(0x8250), "RPDO timeout");
    assert_string_equal(ncp_emcy_code_text(0x8700), "sync controller: SYNC lost");
    assert_string_equal(ncp_emcy_code_text(0x2399), "current error");
    struct ncp_co_fault f = {.kind = NCP_CO_FAULT_EMCY, .node = 2,
                             .emcy = {.code = 0x8611, .reg = 0x21}};
    char buf[256];
    ncp_co_fault_describe(&f, "vcan0", buf, sizeof buf);
    assert_string_equal(buf, "node 2: EMCY (0x082): error code 0x8611 following error; error "
                             "register 0x21: generic, device profile");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_estop_controlwords),
        cmocka_unit_test(test_estop_sequence),
        cmocka_unit_test(test_reset_walk),
        cmocka_unit_test(test_reset_gives_up),
        cmocka_unit_test(test_emcy_texts),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
