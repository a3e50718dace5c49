/* The simulated drive: NMT slave, SDO server, CiA 402 device control and a
 * position plant run on SYNC (cyclic synchronous position). */
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "drive.h"

unsigned drive_master_node(struct drive *dv)
{
    return od_get(&dv->od, 0x1016, 1) >> 16 & 0x7Fu;
}

int drive_send(struct drive *dv, const struct ncp_can_frame *f)
{
    struct ncp_diag d;
    if (ncp_can_send(&dv->bus, f, &d) != NCP_OK) {
        fprintf(stderr, "cnc-drive-sim node %u: %s\n", dv->o.node, d.msg);
        return -1;
    }
    return 0;
}

void drive_set_state(struct drive *dv, enum ncp_cia402_state s)
{
    if (s != dv->st && dv->o.verbose)
        fprintf(stderr, "cnc-drive-sim node %u: %s -> %s\n", dv->o.node,
                ncp_cia402_state_name(dv->st), ncp_cia402_state_name(s));
    if (s != dv->st)
        dv->halted = 0;
    dv->st = s;
    od_set(&dv->od, 0x6041, 0, drive_statusword(dv));
}

uint16_t drive_statusword(const struct drive *dv)
{
    uint16_t sw = ncp_cia402_statusword(dv->st);
    if (dv->home.mode6 && dv->st == NCP_402_OPERATION_ENABLED)
        return sw | drive_home_statusword(dv);
    return dv->halted && dv->st == NCP_402_QUICK_STOP_ACTIVE ? sw | NCP_402_SW_TARGET_REACHED : sw;
}

void drive_boot(struct drive *dv)
{
    od_init(&dv->od);
    dv->nmt = NCP_NMT_PREOP;
    dv->cw = dv->prev_cw = 0;
    dv->target = dv->actual;
    dv->syncs_enabled = 0;
    dv->syncs_moving = 0;
    dv->heartbeat_on = 1;
    dv->last_master_hb = dv->last_sync = dv->last_rpdo = -1;
    dv->lost = 0;
    dv->home = (struct drive_homing){0};
    drive_set_state(dv, dv->o.fault_at_start ? NCP_402_FAULT : NCP_402_SWITCH_ON_DISABLED);
    if (dv->o.fault_at_start)
        od_set(&dv->od, 0x603F, 0, 0x5530);
    struct ncp_can_frame f;
    ncp_heartbeat_frame(&f, dv->o.node, NCP_NMT_BOOTUP);
    drive_send(dv, &f);
}

int drive_send_tpdo(struct drive *dv)
{
    struct ncp_can_frame f;
    ncp_tpdo1_frame(&f, dv->o.node, drive_statusword(dv), dv->actual);
    return drive_send(dv, &f);
}

int drive_send_heartbeat(struct drive *dv)
{
    if (!dv->heartbeat_on)
        return 0;
    struct ncp_can_frame f;
    ncp_heartbeat_frame(&f, dv->o.node, dv->nmt);
    return drive_send(dv, &f);
}

int drive_start_ramp(struct drive *dv, enum ncp_cia402_state during,
                     enum ncp_cia402_state after, long long now_ms)
{
    dv->stop_vel = (double)dv->actual - dv->prev_actual;
    dv->after_stop = after;
    dv->next_step = now_ms;
    drive_set_state(dv, during);
    dv->halted = 0;
    return drive_send_tpdo(dv);
}

static int apply_controlword(struct drive *dv, uint16_t cw)
{
    dv->prev_cw = dv->cw;
    dv->cw = cw;
    od_set(&dv->od, 0x6040, 0, cw);
    enum ncp_cia402_state next = ncp_cia402_apply(dv->st, cw, dv->prev_cw);
    if (dv->st == NCP_402_FAULT && next != NCP_402_FAULT)
        od_set(&dv->od, 0x603F, 0, 0);
    if (next == NCP_402_OPERATION_ENABLED && dv->st != next) {
        dv->target = dv->enabled_at = dv->actual; /* no jump on enabling */
        dv->prev_actual = dv->actual;
        drive_servo_enable(dv);
    }
    if (next == NCP_402_QUICK_STOP_ACTIVE && dv->st == NCP_402_OPERATION_ENABLED) {
        drive_home_halt(dv); /* a quick stop ends a homing: nothing attained */
        return drive_start_ramp(dv, next, next, dv->now_ms);
    }
    drive_set_state(dv, next);
    drive_home_control(dv, cw, dv->prev_cw);
    return 0;
}

int drive_go_fault(struct drive *dv, uint16_t code, int with_emcy)
{
    drive_set_state(dv, NCP_402_FAULT);
    od_set(&dv->od, 0x603F, 0, code);
    od_set(&dv->od, 0x1001, 0, 0x21);
    if (!with_emcy)
        return 0;
    struct ncp_emcy e = {.code = code, .reg = 0x21, .vendor = {0}};
    struct ncp_can_frame f;
    ncp_emcy_frame(&f, dv->o.node, &e);
    return drive_send(dv, &f);
}

static int32_t plant_step(int32_t actual, int32_t target, int32_t max_step)
{
    int64_t err = (int64_t)target - actual;
    if (err > max_step)
        err = max_step;
    if (err < -max_step)
        err = -max_step;
    return (int32_t)(actual + err);
}

/* TPDO2 with the digital inputs 0x60FD, where the master mapped it and
 * asked for it at every SYNC. */
static int send_inputs(struct drive *dv)
{
    uint32_t din = drive_home_switch(dv) ? NCP_402_DIN_HOME_SWITCH : 0;
    od_set(&dv->od, 0x60FD, 0, din);
    uint32_t tt = od_get(&dv->od, 0x1801, 2);
    if (od_get(&dv->od, 0x1A01, 0) != 1 || od_get(&dv->od, 0x1A01, 1) != 0x60FD0020u ||
        tt < 1 || tt > 240)
        return 0;
    struct ncp_can_frame f = {.id = NCP_COB_TPDO2 + dv->o.node, .len = 4,
                              .data = {(uint8_t)din, (uint8_t)(din >> 8), (uint8_t)(din >> 16),
                                       (uint8_t)(din >> 24)}};
    return drive_send(dv, &f);
}

static int on_sync(struct drive *dv)
{
    if (dv->nmt != NCP_NMT_OPERATIONAL)
        return 0;
    if (dv->st == NCP_402_OPERATION_ENABLED) {
        dv->syncs_enabled++;
        if (dv->syncs_moving > 0 || dv->target != dv->enabled_at)
            dv->syncs_moving++;
        long k = dv->o.count_from_motion ? dv->syncs_moving : dv->syncs_enabled;
        dv->prev_actual = dv->actual;
        dv->actual = dv->home.mode6 ? drive_home_step(dv)
                     : dv->servo    ? drive_servo_step(dv)
                                    : plant_step(dv->actual, dv->target, dv->o.max_step);
        od_set(&dv->od, 0x6064, 0, (uint32_t)dv->actual);
        if (k == dv->o.emcy_after && drive_go_fault(dv, 0x8611, 1) < 0)
            return -1;
        if (k == dv->o.fault_after)
            drive_go_fault(dv, 0x7305, 0);
        if (k == dv->o.hb_stop_after)
            dv->heartbeat_on = 0;
    }
    dv->tpdos++;
    if (dv->o.drop_every > 0 && dv->tpdos % dv->o.drop_every == 0)
        return 0;
    return drive_send_tpdo(dv) < 0 ? -1 : send_inputs(dv);
}

static int on_nmt(struct drive *dv, const struct ncp_can_frame *f)
{
    if (f->len < 2 || (f->data[1] != 0 && f->data[1] != dv->o.node))
        return 0;
    switch (f->data[0]) {
    case NCP_NMT_START: dv->nmt = NCP_NMT_OPERATIONAL; break;
    case NCP_NMT_STOP: dv->nmt = NCP_NMT_STOPPED; break;
    case NCP_NMT_PRE_OPERATIONAL: dv->nmt = NCP_NMT_PREOP; break;
    case NCP_NMT_RESET_NODE:
    case NCP_NMT_RESET_COMM: drive_boot(dv); return 0;
    default: return 0;
    }
    return drive_send_heartbeat(dv);
}

/* A write the drive refuses, or 0. */
static uint32_t check_write(struct drive *dv, const struct od_entry *e, uint32_t v)
{
    if (e->access == OD_RO)
        return 0x06010002u;
    if (e->index == 0x6060 && v != 1 && v != 3 && v != 6 && v != 8 && v != 9 && v != 10)
        return 0x06090030u;
    if (e->index >= 0x1400 && e->index < 0x1C00 && dv->nmt == NCP_NMT_OPERATIONAL)
        return 0x08000022u; /* PDO setup only in pre-operational */
    return 0;
}

static void after_write(struct drive *dv, struct od_entry *e, uint32_t v)
{
    e->value = v;
    if (e->index == 0x6060) {
        od_set(&dv->od, 0x6061, 0, v);
        drive_home_mode(dv, v);
        /* a position mode again: the drive holds where homing left it */
        if (v == 8 && dv->st == NCP_402_OPERATION_ENABLED) {
            dv->target = dv->prev_actual = dv->actual;
            drive_servo_enable(dv);
        }
        od_set(&dv->od, 0x6041, 0, drive_statusword(dv));
    }
    else if (e->index == 0x6040)
        (void)apply_controlword(dv, (uint16_t)v);
    else if (e->index == 0x607A)
        dv->target = (int32_t)v;
}

static int on_sdo(struct drive *dv, const struct ncp_can_frame *f)
{
    if (f->len < 8)
        return 0;
    uint8_t cs = f->data[0];
    uint16_t index = (uint16_t)(f->data[1] | f->data[2] << 8);
    uint8_t sub = f->data[3];
    uint32_t v = (uint32_t)f->data[4] | (uint32_t)f->data[5] << 8 |
                 (uint32_t)f->data[6] << 16 | (uint32_t)f->data[7] << 24;
    if (dv->o.slow_sdo_ms > 0) {
        struct timespec ts = {dv->o.slow_sdo_ms / 1000, (dv->o.slow_sdo_ms % 1000) * 1000000L};
        nanosleep(&ts, NULL);
    }
    struct ncp_can_frame r;
    uint32_t abort = 0;
    struct od_entry *e = od_find(&dv->od, index, sub, &abort);
    if (e && index == dv->o.abort_index)
        abort = 0x06090030u, e = NULL;
    if ((cs & 0xE0u) == 0x40u) { /* upload */
        if (e)
            ncp_sdo_upload_resp(&r, dv->o.node, index, sub, e->value, e->size);
    } else if ((cs & 0xE0u) == 0x20u) { /* download */
        if (e && !(cs & 0x02u))
            abort = 0x05040001u, e = NULL; /* segmented: not supported here */
        if (e && (abort = check_write(dv, e, v)) != 0)
            e = NULL;
        if (e) {
            after_write(dv, e, v);
            ncp_sdo_download_resp(&r, dv->o.node, index, sub);
        }
    } else {
        abort = 0x05040001u, e = NULL;
    }
    if (!e)
        ncp_sdo_abort_frame(&r, NCP_COB_SDO_TX + dv->o.node, index, sub, abort);
    return drive_send(dv, &r);
}

int drive_on_frame(struct drive *dv, const struct ncp_can_frame *f, long long now_ms)
{
    uint8_t n = dv->o.node;
    unsigned master = drive_master_node(dv);
    dv->now_ms = now_ms;
    if (f->id == NCP_COB_NMT)
        return on_nmt(dv, f);
    if (master && f->id == NCP_COB_HEARTBEAT + master) {
        dv->last_master_hb = now_ms;
        return 0;
    }
    if (f->id == NCP_COB_SYNC) {
        dv->last_sync = now_ms;
        return on_sync(dv);
    }
    if (f->id == NCP_COB_SDO_RX + n && dv->nmt != NCP_NMT_STOPPED)
        return on_sdo(dv, f);
    if (f->id == NCP_COB_RPDO1 + n && dv->nmt == NCP_NMT_OPERATIONAL) {
        uint16_t cw;
        int32_t target;
        dv->last_rpdo = now_ms;
        if (ncp_rpdo1_decode(f, &cw, &target) == 0) {
            if (cw != dv->cw && apply_controlword(dv, cw) < 0)
                return -1;
            if (dv->st == NCP_402_OPERATION_ENABLED)
                dv->target = target;
        }
    }
    return 0;
}
