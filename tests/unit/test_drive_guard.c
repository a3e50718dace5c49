/* cnc-drive-sim guards its master: with the master's heartbeat, SYNC or RPDO1
 * gone for longer than the drive was told (0x1016:01, --sync-loss-ms,
 * 0x1400:05) while it is enabled, it sends the matching EMCY and stops as
 * 0x6007 and 0x605E say, on its own clock. The drive runs here on one end of
 * a socket pair (frames are struct can_frame, as on a CAN socket), the test
 * plays the master on the other and steps the drive's clock by hand. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <linux/can.h>
#include <poll.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "drive.h"

#define NODE 3
#define MASTER 127

struct rig {
    struct drive dv;
    int master_fd;
    long long now;
};

static struct ncp_can_frame frame(uint32_t id, const uint8_t *data, uint8_t len)
{
    struct ncp_can_frame f;
    memset(&f, 0, sizeof f);
    f.id = id;
    f.len = len;
    if (len)
        memcpy(f.data, data, len);
    return f;
}

static void deliver(struct rig *r, struct ncp_can_frame f)
{
    assert_int_equal(drive_on_frame(&r->dv, &f, r->now), 0);
}

/* Frames the drive sent since the last call: EMCY codes and the last TPDO1. */
struct sent {
    int emcy;
    uint16_t emcy_code;
    int tpdos;
    uint16_t statusword;
    int32_t actual;
};

static struct sent drain(struct rig *r)
{
    struct sent s = {0, 0, 0, 0, 0};
    struct pollfd p = {.fd = r->master_fd, .events = POLLIN};
    while (poll(&p, 1, 0) > 0) {
        struct can_frame cf;
        assert_int_equal(read(r->master_fd, &cf, sizeof cf), (ssize_t)sizeof cf);
        if (cf.can_id == NCP_COB_EMCY + NODE) {
            s.emcy++;
            s.emcy_code = (uint16_t)(cf.data[0] | cf.data[1] << 8);
        } else if (cf.can_id == NCP_COB_TPDO1 + NODE) {
            s.tpdos++;
            s.statusword = (uint16_t)(cf.data[0] | cf.data[1] << 8);
            memcpy(&s.actual, &cf.data[2], 4);
        }
    }
    return s;
}

static void sdo_write(struct rig *r, uint16_t index, uint8_t sub, uint32_t v)
{
    uint8_t d[8] = {0x23, (uint8_t)index, (uint8_t)(index >> 8), sub, (uint8_t)v,
                    (uint8_t)(v >> 8), (uint8_t)(v >> 16), (uint8_t)(v >> 24)};
    deliver(r, frame(NCP_COB_SDO_RX + NODE, d, 8));
}

static void rpdo(struct rig *r, uint16_t cw, int32_t target)
{
    uint8_t d[6] = {(uint8_t)cw, (uint8_t)(cw >> 8)};
    memcpy(&d[2], &target, 4);
    deliver(r, frame(NCP_COB_RPDO1 + NODE, d, 6));
}

static void master_heartbeat(struct rig *r)
{
    uint8_t d[1] = {NCP_NMT_OPERATIONAL};
    deliver(r, frame(NCP_COB_HEARTBEAT + MASTER, d, 1));
}

/* One 1 ms period of a live master: RPDO1 with the target, SYNC, and the
 * heartbeat every 50 ms; each source can be switched off. */
static void period(struct rig *r, int32_t target, int with_hb, int with_sync, int with_rpdo)
{
    r->now++;
    if (with_rpdo)
        rpdo(r, NCP_402_CW_ENABLE, target);
    if (with_sync)
        deliver(r, frame(NCP_COB_SYNC, NULL, 0));
    if (with_hb && r->now % 50 == 0)
        master_heartbeat(r);
    assert_int_equal(drive_guard_tick(&r->dv, r->now), 0);
}

static int setup(void **state)
{
    static struct rig r;
    memset(&r, 0, sizeof r);
    int sv[2];
    assert_int_equal(socketpair(AF_UNIX, SOCK_SEQPACKET, 0, sv), 0);
    r.dv.o = (struct drive_opts){.node = NODE, .fault_after = -1, .emcy_after = -1,
                                 .hb_stop_after = -1, .abort_index = -1, .max_step = 1000000,
                                 .axis = -1, .sync_loss_ms = 100};
    r.dv.bus.fd = sv[0];
    r.master_fd = sv[1];
    r.now = 1000;
    drive_boot(&r.dv);
    /* the master's start-up: guarding, CSP, 1 ms interpolation period */
    sdo_write(&r, 0x1016, 1, (uint32_t)MASTER << 16 | 150);
    sdo_write(&r, 0x1400, 5, 100);
    sdo_write(&r, 0x6060, 0, 8);
    uint8_t start[2] = {NCP_NMT_START, 0};
    deliver(&r, frame(NCP_COB_NMT, start, 2));
    rpdo(&r, NCP_402_CW_SHUTDOWN, 0);
    rpdo(&r, NCP_402_CW_SWITCH_ON, 0);
    rpdo(&r, NCP_402_CW_ENABLE, 0);
    assert_int_equal(r.dv.st, NCP_402_OPERATION_ENABLED);
    master_heartbeat(&r);
    drain(&r);
    *state = &r;
    return 0;
}

static int teardown(void **state)
{
    struct rig *r = *state;
    close(r->dv.bus.fd);
    close(r->master_fd);
    return 0;
}

/* Moving at 50 counts per period when the master's sources stop. */
static void run_moving(struct rig *r, int32_t *target)
{
    for (int k = 0; k < 200; k++) {
        *target += 50;
        period(r, *target, 1, 1, 1);
    }
    assert_int_equal(r->dv.st, NCP_402_OPERATION_ENABLED);
    assert_int_equal(drain(r).emcy, 0);
}

/* Heartbeat gone, SYNC and RPDO going on (a master whose heartbeat task
 * died): EMCY 0x8130 after the consumer time, quick stop (0x6007 = 3 by
 * sdo), ramp at 0x6085, then Switch on disabled; later targets are ignored. */
static void test_heartbeat_loss_quick_stops(void **state)
{
    struct rig *r = *state;
    int32_t target = 0;
    sdo_write(r, 0x6007, 0, 3);
    sdo_write(r, 0x6085, 0, 1000000); /* 1 count per period^2 at 1 ms */
    drain(r);
    run_moving(r, &target);
    long long last_hb = r->now - r->now % 50;
    int reacted_at = -1;
    for (int k = 0; k < 400 && reacted_at < 0; k++) {
        target += 50;
        period(r, target, 0, 1, 1);
        struct sent s = drain(r);
        if (s.emcy) {
            assert_int_equal(s.emcy_code, 0x8130);
            reacted_at = (int)(r->now - last_hb);
        }
    }
    assert_true(reacted_at > 150 && reacted_at <= 152);
    assert_int_equal(r->dv.st, NCP_402_QUICK_STOP_ACTIVE);
    /* braking from 50 counts/period at 1 count/period^2: 50 steps */
    int32_t before = r->dv.actual;
    for (int k = 0; k < 60; k++) {
        r->now++;
        assert_int_equal(drive_guard_tick(&r->dv, r->now), 0);
    }
    struct sent s = drain(r);
    assert_int_equal(r->dv.st, NCP_402_SWITCH_ON_DISABLED);
    assert_int_equal(s.statusword, ncp_cia402_statusword(NCP_402_SWITCH_ON_DISABLED));
    /* sum of 49..1 (the first step already slower) within a step of it */
    assert_true(r->dv.actual - before >= 1200 && r->dv.actual - before <= 1275);
    int32_t stopped = r->dv.actual;
    for (int k = 0; k < 20; k++)
        period(r, target + 1000 * k, 1, 1, 1); /* a stale master: ignored */
    assert_int_equal(r->dv.actual, stopped);
}

/* Moves for a while, then runs periods with only the sources asked for
 * until the drive's EMCY (at most 300 ms): what it sent then, and after how
 * many ms without the missing source. */
static struct sent lose_source(struct rig *r, int with_hb, int with_sync, int with_rpdo,
                               int *after_ms)
{
    int32_t target = 0;
    run_moving(r, &target);
    long long lost_at = r->now;
    struct sent s = {0, 0, 0, 0, 0};
    while (!s.emcy && r->now < lost_at + 300) {
        period(r, target, with_hb, with_sync, with_rpdo);
        s = drain(r);
    }
    *after_ms = (int)(r->now - lost_at);
    return s;
}

/* SYNC gone (the master's cycle stopped, heartbeat thread alive): EMCY
 * 0x8700 after --sync-loss-ms; 0x6007 = 1 makes it a fault, and 0x605E = 0
 * disables at once (Fault, no ramp). */
static void test_sync_loss_faults(void **state)
{
    struct rig *r = *state;
    sdo_write(r, 0x6007, 0, 1);
    sdo_write(r, 0x605E, 0, 0);
    drain(r);
    int after_ms;
    struct sent s = lose_source(r, 1, 0, 0, &after_ms);
    assert_int_equal(s.emcy_code, 0x8700);
    assert_int_equal(after_ms, 101);
    assert_int_equal(r->dv.st, NCP_402_FAULT);
    assert_int_equal(od_get(&r->dv.od, 0x603F, 0), 0x8700);
}

/* RPDO1 gone while SYNC and heartbeat go on: EMCY 0x8250 after the event
 * timer 0x1400:05; 0x6007 = 2 disables voltage at once. */
static void test_rpdo_loss_disables(void **state)
{
    struct rig *r = *state;
    sdo_write(r, 0x6007, 0, 2);
    drain(r);
    int after_ms;
    struct sent s = lose_source(r, 1, 1, 0, &after_ms);
    assert_int_equal(s.emcy_code, 0x8250);
    assert_int_equal(after_ms, 101);
    assert_int_equal(r->dv.st, NCP_402_SWITCH_ON_DISABLED);
}

/* A drive that is not enabled has nothing to stop: no EMCY, no change. */
static void test_disabled_drive_stays_quiet(void **state)
{
    struct rig *r = *state;
    rpdo(r, NCP_402_CW_SHUTDOWN, 0);
    drain(r);
    for (int k = 0; k < 400; k++) {
        r->now++;
        assert_int_equal(drive_guard_tick(&r->dv, r->now), 0);
    }
    assert_int_equal(drain(r).emcy, 0);
    assert_int_equal(r->dv.st, NCP_402_READY_TO_SWITCH_ON);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_heartbeat_loss_quick_stops, setup, teardown),
        cmocka_unit_test_setup_teardown(test_sync_loss_faults, setup, teardown),
        cmocka_unit_test_setup_teardown(test_rpdo_loss_disables, setup, teardown),
        cmocka_unit_test_setup_teardown(test_disabled_drive_stays_quiet, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
