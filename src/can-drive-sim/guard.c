/* The drive guards its master, as a CiA 402 drive on a real machine must: a
 * master that dies (killed, crashed, unplugged) stops sending its heartbeat,
 * SYNC and RPDO1, and a drive left alone would keep following the last
 * target it got. When a deadline passes while the drive is enabled, it sends
 * an EMCY and reacts as 0x6007 (abort connection option) says: 0 nothing,
 * 1 fault (then 0x605E, the fault reaction option), 2 disable voltage,
 * 3 quick stop. A ramp (quick stop or fault reaction) brakes on the drive's
 * own clock at 0x6085 and sends TPDO1 at each step, as an event-driven PDO
 * would, so the stop shows on the bus without a SYNC. */
#include <math.h>
#include <stdio.h>

#include "drive.h"

/* EMCY codes: CiA 301's heartbeat and RPDO timeout, CiA 402's sync controller */
#define EMCY_HEARTBEAT 0x8130u
#define EMCY_RPDO_TIMEOUT 0x8250u
#define EMCY_SYNC_LOST 0x8700u

size_t drive_listen_ids(struct drive *dv, uint32_t ids[6])
{
    uint8_t n = dv->o.node;
    size_t k = 0;
    ids[k++] = NCP_COB_NMT;
    ids[k++] = NCP_COB_SYNC;
    ids[k++] = NCP_COB_SDO_RX + n;
    ids[k++] = NCP_COB_RPDO1 + n;
    if (drive_master_node(dv))
        ids[k++] = NCP_COB_HEARTBEAT + drive_master_node(dv);
    return k;
}

/* The deadline that has passed at now, as its EMCY code, or 0. Each is armed
 * by the first frame of its kind (CiA 301: a consumer starts with the first
 * heartbeat it receives). */
static uint16_t deadline_passed(struct drive *dv, long long now)
{
    uint32_t consumer_ms = od_get(&dv->od, 0x1016, 1) & 0xFFFFu;
    uint32_t rpdo_ms = od_get(&dv->od, 0x1400, 5);
    if (drive_master_node(dv) && consumer_ms && dv->last_master_hb >= 0 &&
        now - dv->last_master_hb > (long long)consumer_ms)
        return EMCY_HEARTBEAT;
    if (dv->o.sync_loss_ms > 0 && dv->last_sync >= 0 && now - dv->last_sync > dv->o.sync_loss_ms)
        return EMCY_SYNC_LOST;
    if (rpdo_ms && dv->last_rpdo >= 0 && now - dv->last_rpdo > (long long)rpdo_ms)
        return EMCY_RPDO_TIMEOUT;
    return 0;
}

static int period_ms(struct drive *dv)
{
    int ms = (int)lround(drive_period_s(dv) * 1000);
    return ms > 0 ? ms : 1;
}

static int react(struct drive *dv, uint16_t code, long long now)
{
    dv->lost = code;
    struct ncp_emcy e = {.code = code, .reg = 0x11, .vendor = {0}}; /* generic + communication */
    struct ncp_can_frame f;
    ncp_emcy_frame(&f, dv->o.node, &e);
    if (drive_send(dv, &f) < 0)
        return -1;
    if (dv->o.verbose)
        fprintf(stderr, "cnc-drive-sim node %u: master lost (EMCY 0x%04X)\n", dv->o.node, code);
    switch ((int16_t)od_get(&dv->od, 0x6007, 0)) {
    case 0:
        return 0;
    case 2:
        dv->target = dv->actual;
        drive_set_state(dv, NCP_402_SWITCH_ON_DISABLED);
        return drive_send_tpdo(dv);
    case 3:
        return drive_start_ramp(dv, NCP_402_QUICK_STOP_ACTIVE, NCP_402_SWITCH_ON_DISABLED, now);
    default:
        od_set(&dv->od, 0x603F, 0, code);
        od_set(&dv->od, 0x1001, 0, 0x11);
        if ((int16_t)od_get(&dv->od, 0x605E, 0) == 0) {  /* disable drive: no ramp */
            dv->target = dv->actual;
            drive_set_state(dv, NCP_402_FAULT);
            return drive_send_tpdo(dv);
        }
        return drive_start_ramp(dv, NCP_402_FAULT_REACTION_ACTIVE, NCP_402_FAULT, now);
    }
}

/* One step of the ramp: the speed falls by the quick stop deceleration. */
static int ramp_step(struct drive *dv)
{
    double t = drive_period_s(dv);
    double dv_step = (double)od_get(&dv->od, 0x6085, 0) * t * t;
    if (fabs(dv->stop_vel) <= dv_step || dv_step <= 0)
        dv->stop_vel = 0;
    else
        dv->stop_vel -= copysign(dv_step, dv->stop_vel);
    dv->actual += (int32_t)lround(dv->stop_vel);
    dv->target = dv->actual;
    od_set(&dv->od, 0x6064, 0, (uint32_t)dv->actual);
    if (dv->stop_vel == 0) {
        drive_set_state(dv, dv->after_stop);
        dv->halted = 1;
        od_set(&dv->od, 0x6041, 0, drive_statusword(dv));
    }
    return drive_send_tpdo(dv);
}

static int ramping(const struct drive *dv)
{
    return (dv->st == NCP_402_QUICK_STOP_ACTIVE || dv->st == NCP_402_FAULT_REACTION_ACTIVE) &&
           !dv->halted;
}

int drive_guard_tick(struct drive *dv, long long now)
{
    if (ramping(dv)) {
        while (ramping(dv) && now >= dv->next_step) {
            if (ramp_step(dv) < 0)
                return -1;
            dv->next_step += period_ms(dv);
        }
        return 0;
    }
    uint16_t code = deadline_passed(dv, now);
    if (!code) {
        dv->lost = 0;
        return 0;
    }
    if (dv->lost || dv->nmt != NCP_NMT_OPERATIONAL || dv->st != NCP_402_OPERATION_ENABLED)
        return 0;
    return react(dv, code, now);
}

int drive_guard_wait_ms(struct drive *dv, long long now)
{
    if (ramping(dv))
        return dv->next_step > now ? (int)(dv->next_step - now) : 0;
    /* deadlines are checked every millisecond while the drive is enabled */
    return dv->st == NCP_402_OPERATION_ENABLED ? 1 : 100;
}
