/* The master's side of a drive's own homing (src/can/dhome.c) on values, as
 * test_can_seat does: the SDO downloads of each mode switch, the statusword
 * of a homing before not taken for this one's, the timeout, a failed mode
 * switch, and an E-stop in the middle. test_drive_homing runs the same
 * state machine against the simulated drive. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <string.h>

#include "ncpar/can.h"

static void master_of(struct ncp_co_master *m)
{
    memset(m, 0, sizeof *m);
    m->n = 1;
    m->cfg.period_us = 1000;
    ncp_co_node_init(&m->node[0], 6);
    m->node[0].statusword = ncp_cia402_statusword(NCP_402_OPERATION_ENABLED);
    m->node[0].tpdos = 1;
    m->enabled[0] = 1;
    m->cw[0] = NCP_402_CW_ENABLE;
    m->home[0].cfg = (struct ncp_co_home_cfg){.on = 1, .method = 19, .timeout_periods = 50};
}

static void tpdo(struct ncp_co_master *m, uint16_t extra, int32_t actual)
{
    m->node[0].statusword = ncp_cia402_statusword(NCP_402_OPERATION_ENABLED) | extra;
    m->node[0].actual = actual;
    m->node[0].tpdos++;
}

/* The worker's answer: the mode switch done, or failed with why. */
static void answer(struct ncp_co_master *m, int want, const char *why)
{
    struct ncp_co_home *h = &m->home[0];
    assert_int_not_equal(atomic_load(&h->ask), atomic_load(&h->done));
    assert_int_equal(atomic_load(&h->want), want);
    atomic_store(&h->failed, why != NULL);
    if (why)
        snprintf(h->why, sizeof h->why, "%s", why);
    atomic_store(&h->done, atomic_load(&h->ask));
}

/* A master whose axis 0 was asked to home and whose drive is now in homing
 * mode (the worker's SDO answered). */
static void homing_mode_asked(struct ncp_co_master *m)
{
    master_of(m);
    ncp_co_home_start(m, 0);
    ncp_co_home_step(m, 0);
    answer(m, NCP_402_MODE_HOMING, NULL);
}

static void test_sdo_steps(void **state)
{
    (void)state;
    struct ncp_co_home_cfg c = {.on = 1, .method = -3, .search = 5000, .latch = 500,
                                .acc = 90000, .offset = -1200};
    struct ncp_co_sdo_step st[8];
    size_t n = ncp_co_home_sdo_steps(&c, NCP_402_MODE_HOMING, st, 8);
    assert_int_equal(n, 6);
    assert_int_equal(st[0].index, 0x607C);
    assert_int_equal(st[0].value, (uint32_t)-1200);
    assert_int_equal(st[1].index, 0x6098);
    assert_int_equal(st[1].value, 0xFD);   /* INTEGER8 -3 */
    assert_int_equal(st[1].size, 1);
    assert_true(st[2].index == 0x6099 && st[2].sub == 1 && st[2].value == 5000);
    assert_true(st[3].index == 0x6099 && st[3].sub == 2 && st[3].value == 500);
    assert_true(st[4].index == 0x609A && st[4].value == 90000);
    /* the mode last: the drive starts from the parameters it was given */
    assert_true(st[5].index == 0x6060 && st[5].value == 6 && st[5].size == 1);
    /* speeds left to the drive are not written */
    c.search = c.latch = c.acc = 0;
    assert_int_equal(ncp_co_home_sdo_steps(&c, NCP_402_MODE_HOMING, st, 8), 3);
    assert_int_equal(st[2].index, 0x6060);
    assert_int_equal(ncp_co_home_sdo_steps(&c, NCP_402_MODE_CSP, st, 8), 1);
    assert_true(st[0].index == 0x6060 && st[0].value == 8);
}

static void test_homes(void **state)
{
    (void)state;
    struct ncp_co_master m;
    master_of(&m);
    /* not while the seat holds the drives, nor an axis without it */
    m.mode = NCP_CO_ESTOP;
    assert_int_equal(ncp_co_home_start(&m, 0), -1);
    m.mode = NCP_CO_RUN;
    m.home[0].cfg.on = 0;
    assert_int_equal(ncp_co_home_start(&m, 0), -1);
    m.home[0].cfg.on = 1;
    assert_int_equal(ncp_co_home_start(&m, 0), 0);
    assert_int_equal(ncp_co_home_start(&m, 0), -1);
    /* waiting for homing mode: bit 4 down, the target at the actual */
    tpdo(&m, 0, 300);
    m.target[0] = 999;
    assert_int_equal(ncp_co_home_step(&m, 0), 1);
    assert_int_equal(m.cw[0], NCP_402_CW_ENABLE);
    assert_int_equal(m.target[0], 300);
    assert_int_equal(ncp_co_home_poll(&m, 0), 1);
    answer(&m, NCP_402_MODE_HOMING, NULL);
    assert_int_equal(ncp_co_home_step(&m, 0), 1);
    assert_int_equal(m.cw[0], NCP_402_CW_ENABLE | NCP_402_CW_HOMING_START);
    /* the first TPDO after the edge still shows the homing before */
    uint16_t done = NCP_402_SW_HOMING_ATTAINED | NCP_402_SW_TARGET_REACHED;
    tpdo(&m, done, 300);
    assert_int_equal(ncp_co_home_step(&m, 0), 1);
    assert_int_equal(m.home[0].phase, NCP_CH_HOMING);
    int32_t at[] = {320, 380, 420, 410};
    for (size_t k = 0; k < 4; k++) {
        tpdo(&m, 0, at[k]);
        assert_int_equal(ncp_co_home_step(&m, 0), 1);
        assert_int_equal(m.cw[0], NCP_402_CW_ENABLE | NCP_402_CW_HOMING_START);
        assert_int_equal(m.target[0], at[k]);
    }
    /* attained without target reached: still braking */
    tpdo(&m, NCP_402_SW_HOMING_ATTAINED, 55);
    ncp_co_home_step(&m, 0);
    assert_int_equal(m.home[0].phase, NCP_CH_HOMING);
    tpdo(&m, done, 50);
    assert_int_equal(ncp_co_home_step(&m, 0), 1);
    assert_int_equal(m.cw[0], NCP_402_CW_ENABLE);
    assert_int_equal(m.home[0].phase, NCP_CH_TO_CSP);
    assert_int_equal(atomic_load(&m.home[0].phase_sw),
                     ncp_cia402_statusword(NCP_402_OPERATION_ENABLED) | done);
    tpdo(&m, 0, 50);
    ncp_co_home_step(&m, 0);
    answer(&m, NCP_402_MODE_CSP, NULL);
    assert_int_equal(ncp_co_home_step(&m, 0), 1);
    assert_int_equal(m.target[0], 50);
    /* held until the NCK took it, then the NCK's targets again */
    assert_int_equal(ncp_co_home_poll(&m, 0), 0);
    assert_int_equal(ncp_co_home_step(&m, 0), 0);
    assert_int_equal(ncp_co_home_poll(&m, 0), -1);
    assert_int_equal(m.fault.kind, NCP_CO_FAULT_NONE);
}

static void test_timeout(void **state)
{
    (void)state;
    struct ncp_co_master m;
    homing_mode_asked(&m);
    int rc = 1;
    long k = 0;
    for (; rc == 1 && k < 100; k++) {
        tpdo(&m, 0, (int32_t)k);
        rc = ncp_co_home_step(&m, 0);
    }
    assert_int_equal(rc, -1);
    assert_int_equal(k, 52);   /* 50 periods homing, and the one that asked for it */
    assert_int_equal(m.fault.kind, NCP_CO_FAULT_HOMING);
    assert_int_equal(m.fault.node, 6);
    char buf[256];
    ncp_co_fault_describe(&m.fault, "can0", buf, sizeof buf);
    assert_non_null(strstr(buf, "node 6: the drive's own homing (method 19) did not end within "
                                "0.1 s"));
    assert_non_null(strstr(buf, "homing still in progress"));
    /* back to CSP for the reset */
    assert_int_equal(atomic_load(&m.home[0].want), NCP_402_MODE_CSP);
    assert_int_equal(ncp_co_home_poll(&m, 0), -1);
}

static void test_mode_switch_fails(void **state)
{
    (void)state;
    struct ncp_co_master m;
    master_of(&m);
    m.home[0].cfg.method = 35;
    ncp_co_home_start(&m, 0);
    ncp_co_home_step(&m, 0);
    answer(&m, NCP_402_MODE_HOMING,
           "node 6: SDO write 0x6098:00 aborted: 0x06090030 invalid value for parameter");
    assert_int_equal(ncp_co_home_step(&m, 0), -1);
    char buf[256];
    ncp_co_fault_describe(&m.fault, "can0", buf, sizeof buf);
    assert_string_equal(buf, "node 6: SDO write 0x6098:00 aborted: 0x06090030 invalid value for "
                             "parameter (the drive's own homing, method 35); the axis is not "
                             "homed");
}

static void test_estop_drops_homing(void **state)
{
    (void)state;
    struct ncp_co_master m;
    homing_mode_asked(&m);
    ncp_co_home_step(&m, 0);
    assert_int_equal(m.home[0].phase, NCP_CH_HOMING);
    ncp_co_master_seat(&m, 0);
    assert_int_equal(m.home[0].phase, NCP_CH_IDLE);
    assert_int_equal(atomic_load(&m.home[0].want), NCP_402_MODE_CSP);
    assert_int_not_equal(atomic_load(&m.home[0].ask), atomic_load(&m.home[0].done));
    /* the seat's controlwords now, not bit 4 */
    ncp_co_master_seat_step(&m);
    assert_int_equal(m.cw[0], NCP_402_CW_QUICK_STOP);
    assert_int_equal(ncp_co_home_poll(&m, 0), -1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sdo_steps),
        cmocka_unit_test(test_homes),
        cmocka_unit_test(test_timeout),
        cmocka_unit_test(test_mode_switch_fails),
        cmocka_unit_test(test_estop_drops_homing),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
