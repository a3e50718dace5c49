/* An axis homed by its drive (HOME_METHOD = drive:N): the master's homing
 * state machine (src/can/dhome.c) against cnc-drive-sim's homing mode. The
 * drive runs on one end of a socket pair, the master's poll and send on the
 * other; the SDO worker's mode switches are delivered by hand (the downloads
 * ncp_co_home_sdo_steps lists), as the worker would send them. Checked: the
 * controlword and statusword bits on the way, the time a switch-and-index
 * homing takes at the given speeds, where the drive stands after it (its
 * position at home is the home offset), that nothing jumps when it follows
 * targets again, and a homing error as the operator reads it. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "drive.h"

#define NODE 4

struct rig {
    struct drive dv;
    struct ncp_can_bus drive_rx;  /* the drive's end, read by the test */
    struct ncp_co_master m;
    long long now;
    uint16_t last_cw_seen;        /* the controlword the drive last got */
};

static void deliver(struct rig *r, const struct ncp_can_frame *f)
{
    if (f->id == NCP_COB_RPDO1 + NODE)
        r->last_cw_seen = (uint16_t)(f->data[0] | f->data[1] << 8);
    assert_int_equal(drive_on_frame(&r->dv, f, r->now), 0);
}

/* Whatever the master sent, to the drive. */
static void to_drive(struct rig *r)
{
    struct ncp_can_frame f;
    while (ncp_can_try_recv(&r->drive_rx, &f) == 1)
        deliver(r, &f);
}

static void sdo_download(struct rig *r, uint16_t index, uint8_t sub, uint32_t v, unsigned size)
{
    struct ncp_can_frame f;
    ncp_sdo_download_req(&f, NODE, index, sub, v, size);
    deliver(r, &f);
}

/* The SDO worker's part: the mode switch the loop asked for. */
static void serve_by_hand(struct rig *r)
{
    struct ncp_co_home *h = &r->m.home[0];
    uint32_t a = atomic_load(&h->ask);
    if (a == atomic_load(&h->done))
        return;
    struct ncp_co_sdo_step st[8];
    size_t n = ncp_co_home_sdo_steps(&h->cfg, atomic_load(&h->want), st, 8);
    for (size_t k = 0; k < n; k++)
        sdo_download(r, st[k].index, st[k].sub, st[k].value, st[k].size);
    atomic_store(&h->failed, 0);
    atomic_store(&h->done, a);
}

/* One 1 ms servo period of the master: take in, homing step, RPDO + SYNC,
 * the drive's answer. Returns what the homing step said. */
static int period(struct rig *r)
{
    r->now++;
    assert_int_equal(ncp_co_master_poll(&r->m, r->now, 64), 0);
    int h = ncp_co_home_step(&r->m, 0);
    assert_int_equal(ncp_co_master_send(&r->m), 0);
    to_drive(r);
    return h;
}

static int setup(void **state)
{
    struct rig *r = calloc(1, sizeof *r);
    int sv[2];
    assert_int_equal(socketpair(AF_UNIX, SOCK_SEQPACKET, 0, sv), 0);
    r->dv.o = (struct drive_opts){.node = NODE, .fault_after = -1, .emcy_after = -1,
                                  .hb_stop_after = -1, .abort_index = -1, .max_step = 1000000,
                                  .axis = -1, .sync_loss_ms = 0, .have_home_switch = 1,
                                  .home_switch = 5000, .index_pitch = 1000};
    r->dv.bus.fd = sv[0];
    r->drive_rx.fd = sv[0];
    r->now = 1000;
    drive_boot(&r->dv);
    sdo_download(r, 0x6060, 0, 8, 1);
    struct ncp_can_frame f;
    ncp_nmt_frame(&f, NCP_NMT_START, 0);
    deliver(r, &f);
    /* the master: one node, 1 ms, enabled and following */
    r->m.bus.fd = sv[1];
    r->m.n = 1;
    r->m.cfg.period_us = 1000;
    ncp_co_node_init(&r->m.node[0], NODE);
    r->m.enabled[0] = 1;
    const uint16_t walk[] = {NCP_402_CW_SHUTDOWN, NCP_402_CW_SWITCH_ON, NCP_402_CW_ENABLE};
    for (size_t k = 0; k < 3; k++) {
        r->m.cw[0] = walk[k];
        period(r);
    }
    assert_int_equal(r->dv.st, NCP_402_OPERATION_ENABLED);
    period(r);
    assert_int_equal(ncp_cia402_state(r->m.node[0].statusword), NCP_402_OPERATION_ENABLED);
    *state = r;
    return 0;
}

static int teardown(void **state)
{
    struct rig *r = *state;
    close(r->m.bus.fd);
    close(r->dv.bus.fd);
    free(r);
    return 0;
}

static void configure(struct rig *r, int method, int32_t offset)
{
    r->m.home[0].cfg = (struct ncp_co_home_cfg){.on = 1, .method = method, .search = 20000,
                                                .latch = 2000, .acc = 200000, .offset = offset,
                                                .timeout_periods = 5000};
}

/* Periods until the homing gives the target back; -1 on a fault. */
static long home(struct rig *r, uint16_t *sw_attained)
{
    assert_int_equal(ncp_co_home_start(&r->m, 0), 0);
    long k = 0;
    int saw_bit4 = 0;
    for (; k < 10000; k++) {
        int h = period(r);
        serve_by_hand(r);
        if (h < 0)
            return -1;
        saw_bit4 |= (r->last_cw_seen & NCP_402_CW_HOMING_START) != 0;
        /* the homing holds the target where the drive is */
        assert_int_equal(r->m.target[0], r->m.node[0].actual);
        if (r->m.home[0].phase == NCP_CH_TO_CSP && !*sw_attained)
            *sw_attained = r->m.node[0].statusword;
        int p = ncp_co_home_poll(&r->m, 0);
        if (p == 0)
            break;
        assert_int_equal(p, 1);
    }
    assert_true(saw_bit4);
    return k;
}

static void test_current_position(void **state)
{
    struct rig *r = *state;
    r->m.target[0] = 1234;
    for (int k = 0; k < 3; k++)
        period(r);
    assert_int_equal(r->dv.actual, 1234);
    configure(r, 35, -500);
    uint16_t sw = 0;
    long k = home(r, &sw);
    assert_true(k > NCP_CO_HOME_SETTLE_TPDOS && k < NCP_CO_HOME_SETTLE_TPDOS + 10);
    assert_true(sw & NCP_402_SW_HOMING_ATTAINED);
    assert_true(sw & NCP_402_SW_TARGET_REACHED);
    /* home is here: the drive counts from the home offset */
    assert_int_equal(r->dv.actual, -500);
    assert_int_equal(r->m.node[0].actual, -500);
    assert_int_equal(od_get(&r->dv.od, 0x6061, 0), 8);
    assert_int_equal(od_get(&r->dv.od, 0x6098, 0), 35);
}

static void test_switch_and_index(void **state)
{
    struct rig *r = *state;
    configure(r, 3, 7777);
    uint16_t sw = 0;
    long k = home(r, &sw);
    assert_true(k > 0);
    /* the speeds and acceleration reached the drive */
    assert_int_equal(od_get(&r->dv.od, 0x6099, 1), 20000);
    assert_int_equal(od_get(&r->dv.od, 0x6099, 2), 2000);
    assert_int_equal(od_get(&r->dv.od, 0x609A, 0), 200000);
    assert_int_equal(od_get(&r->dv.od, 0x607C, 0), 7777);
    /* it took real time: 5000 counts searching at 20 per period, 1000
     * latching back over the switch to the index at 4000, at 2 */
    assert_true(k > 5000 / 20 + 1000 / 2);
    assert_true(k < 2000);
    assert_true((sw & (NCP_402_SW_HOMING_ATTAINED | NCP_402_SW_TARGET_REACHED |
                       NCP_402_SW_HOMING_ERROR)) ==
                (NCP_402_SW_HOMING_ATTAINED | NCP_402_SW_TARGET_REACHED));
    /* the index at encoder 4000 is 7777 now; the drive braked past it from
     * 2 counts per period at 0.2 per period^2, moving negative */
    int32_t at = r->m.node[0].actual;
    assert_true(at <= 7777 && at >= 7777 - 15);
    assert_int_equal(r->dv.actual, at);
    assert_int_equal(od_get(&r->dv.od, 0x6061, 0), 8);
    /* CSP again: the target is where the drive stands, nothing moves ... */
    for (int j = 0; j < 5; j++)
        assert_int_equal(period(r), 0);
    assert_int_equal(r->dv.actual, at);
    /* ... until the NCK moves it */
    r->m.target[0] = at + 100;
    period(r);
    period(r);
    assert_int_equal(r->m.node[0].actual, at + 100);
}

static void test_error(void **state)
{
    struct rig *r = *state;
    r->dv.o.index_pitch = 0;  /* method 3 needs the index: a homing error */
    configure(r, 3, 0);
    uint16_t sw = 0;
    assert_int_equal(home(r, &sw), -1);
    assert_int_equal(r->m.fault.kind, NCP_CO_FAULT_HOMING);
    assert_true(r->m.fault.statusword & NCP_402_SW_HOMING_ERROR);
    char buf[256];
    ncp_co_fault_describe(&r->m.fault, "vcan0", buf, sizeof buf);
    assert_non_null(strstr(buf, "node 4: the drive's own homing (method 3) ended in a homing "
                                "error"));
    assert_non_null(strstr(buf, "the axis is not homed"));
    /* the drive is asked back to CSP for the reset */
    serve_by_hand(r);
    assert_int_equal(od_get(&r->dv.od, 0x6061, 0), 8);
    assert_int_equal(ncp_co_home_poll(&r->m, 0), -1);
}

static void test_interrupted(void **state)
{
    struct rig *r = *state;
    configure(r, 19, 0);
    assert_int_equal(ncp_co_home_start(&r->m, 0), 0);
    for (int k = 0; k < 100; k++) {
        assert_int_equal(period(r), 1);
        serve_by_hand(r);
    }
    assert_true(r->dv.actual > 0); /* searching */
    ncp_co_home_abort(&r->m, 0);
    period(r);
    assert_int_equal(r->last_cw_seen & NCP_402_CW_HOMING_START, 0);
    serve_by_hand(r);
    int32_t at = r->dv.actual;
    assert_int_equal(period(r), 1);   /* the answer is in: idle from the next */
    assert_int_equal(ncp_co_home_poll(&r->m, 0), -1);
    assert_int_equal(period(r), 0);
    assert_int_equal(od_get(&r->dv.od, 0x6061, 0), 8);
    assert_int_equal(r->dv.home.attained, 0);
    /* the counts are the encoder's still: nothing was homed */
    assert_int_equal(r->dv.home.ref, 0);
    assert_true(r->dv.actual - at <= 1 && at - r->dv.actual <= 1);
}

/* cnc-drive-sim --homing-error MS: the first homing ends in a homing
 * error MS ms in, the axis standing; the next one homes. */
static void test_error_option(void **state)
{
    struct rig *r = *state;
    r->dv.o.homing_error_ms = 50;
    configure(r, 3, 0);
    uint16_t sw = 0;
    assert_int_equal(home(r, &sw), -1);
    assert_int_equal(r->m.fault.kind, NCP_CO_FAULT_HOMING);
    assert_int_equal(r->m.fault.home_why, NCP_CH_WHY_ERROR);
    assert_true(r->m.fault.statusword & NCP_402_SW_HOMING_ERROR);
    /* 50 SYNCs of 1 ms into the homing, and its answer a period later */
    assert_true(r->m.fault.home_ms >= 50 && r->m.fault.home_ms <= 55);
    int32_t at = r->dv.actual;
    assert_true(at > 0 && at < 5000); /* stopped on its way to the switch */
    period(r);
    assert_int_equal(r->dv.actual, at);
    /* the operator's reset: the master idle and fault-free again */
    serve_by_hand(r);
    ncp_co_home_drop(&r->m);
    r->m.fault.kind = NCP_CO_FAULT_NONE;
    period(r);
    serve_by_hand(r);
    sw = 0;
    assert_true(home(r, &sw) > 0);
    assert_true(sw & NCP_402_SW_HOMING_ATTAINED);
    assert_int_equal(sw & NCP_402_SW_HOMING_ERROR, 0);
}

/* cnc-drive-sim --homing-stall: the search never sees the switch, the
 * master's timeout ends the homing. */
static void test_stall_option(void **state)
{
    struct rig *r = *state;
    r->dv.o.homing_stall = 1;
    configure(r, 3, 0);
    r->m.home[0].cfg.timeout_periods = 400;
    uint16_t sw = 0;
    assert_int_equal(home(r, &sw), -1);
    assert_int_equal(r->m.fault.kind, NCP_CO_FAULT_HOMING);
    assert_int_equal(r->m.fault.home_why, NCP_CH_WHY_TIMEOUT);
    assert_int_equal(r->m.fault.home_ms, 401);
    assert_int_equal(r->m.fault.statusword & (NCP_402_SW_HOMING_ATTAINED |
                                              NCP_402_SW_TARGET_REACHED), 0);
    /* searched on past the switch at 5000, at 20 counts per period */
    assert_true(r->dv.actual > 6000);
    char buf[256];
    ncp_co_fault_describe(&r->m.fault, "vcan0", buf, sizeof buf);
    assert_non_null(strstr(buf, "node 4: the drive's own homing (method 3) did not end within "
                                "0.4 s"));
    assert_non_null(strstr(buf, "homing still in progress"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_current_position, setup, teardown),
        cmocka_unit_test_setup_teardown(test_switch_and_index, setup, teardown),
        cmocka_unit_test_setup_teardown(test_error, setup, teardown),
        cmocka_unit_test_setup_teardown(test_interrupted, setup, teardown),
        cmocka_unit_test_setup_teardown(test_error_option, setup, teardown),
        cmocka_unit_test_setup_teardown(test_stall_option, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
