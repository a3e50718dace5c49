/* The operator's E-stop and reset on CiA 402 drives (cnc-run serve): what
 * the master sends while the NCK's setpoints are frozen, and the walk back
 * to Operation enabled. On the real-time path: values only, no I/O here. */
#include "ncpar/can.h"

int ncp_cia402_at_rest(uint16_t sw, int still_tpdos)
{
    return ncp_cia402_state(sw) != NCP_402_QUICK_STOP_ACTIVE ||
           (sw & NCP_402_SW_TARGET_REACHED) || still_tpdos >= NCP_402_STILL_TPDOS;
}

uint16_t ncp_cia402_estop_cw(uint16_t sw, int still_tpdos)
{
    switch (ncp_cia402_state(sw)) {
    /* the drive brakes at its quick stop deceleration (0x6085), torque on:
     * switching the voltage off in motion would let the axis coast */
    case NCP_402_OPERATION_ENABLED: return NCP_402_CW_QUICK_STOP;
    case NCP_402_QUICK_STOP_ACTIVE:
        return ncp_cia402_at_rest(sw, still_tpdos) ? NCP_402_CW_DISABLE : NCP_402_CW_QUICK_STOP;
    default: return NCP_402_CW_DISABLE;
    }
}

void ncp_co_master_seat(struct ncp_co_master *m, int on)
{
    /* on while running (the loop's first period) changes nothing: a fault
     * from before the loop must stay what the loop reports */
    if (on && m->mode == NCP_CO_RUN)
        return;
    m->mode = on ? NCP_CO_ENABLING : NCP_CO_ESTOP;
    m->mode_cycles = 0;
    /* a drive that was homing itself stops with the others and is back in
     * CSP for the reset's walk */
    ncp_co_home_drop(m);
    for (size_t i = 0; i < m->n; i++) {
        m->enabled[i] = 0;
        m->still[i] = 0;
        m->seen[i] = m->node[i].tpdos;
        m->last_act[i] = m->node[i].actual;
        if (on)
            m->node[i].emcy.code = 0;
    }
    if (on)
        m->fault.kind = NCP_CO_FAULT_NONE;
}

/* A new TPDO with the same actual position as the one before counts. */
static void watch_still(struct ncp_co_master *m, size_t i)
{
    const struct ncp_co_node *nd = &m->node[i];
    if (nd->tpdos == m->seen[i])
        return;
    m->seen[i] = nd->tpdos;
    if (nd->actual == m->last_act[i]) {
        if (m->still[i] < 255)
            m->still[i]++;
    } else {
        m->still[i] = 0;
    }
    m->last_act[i] = nd->actual;
}

int ncp_co_master_seat_step(struct ncp_co_master *m)
{
    if (m->mode == NCP_CO_RUN)
        return 0;
    m->mode_cycles++;
    size_t ready = 0;
    for (size_t i = 0; i < m->n; i++) {
        struct ncp_co_node *nd = &m->node[i];
        m->target[i] = nd->actual;
        if (m->mode == NCP_CO_ESTOP) {
            watch_still(m, i);
            m->cw[i] = nd->tpdos ? ncp_cia402_estop_cw(nd->statusword, m->still[i])
                                 : NCP_402_CW_DISABLE;
            continue;
        }
        enum ncp_cia402_state s = ncp_cia402_state(nd->statusword);
        if (nd->tpdos > 0 && s == NCP_402_OPERATION_ENABLED)
            m->enabled[i] = 1;
        ready += m->enabled[i];
        m->cw[i] = nd->tpdos ? ncp_cia402_step(s, m->cw[i]) : NCP_402_CW_DISABLE;
    }
    if (m->mode == NCP_CO_ENABLING && ready == m->n) {
        m->mode = NCP_CO_RUN;
        return 0;
    }
    if (m->mode == NCP_CO_ENABLING && m->mode_cycles > NCP_CO_ENABLE_PERIODS) {
        for (size_t i = 0; i < m->n; i++) {
            if (m->enabled[i])
                continue;
            m->fault.kind = NCP_CO_FAULT_STATE;
            m->fault.node = m->node[i].id;
            m->fault.statusword = m->node[i].statusword;
            m->fault.error_code = m->node[i].emcy.code ? m->node[i].emcy.code : -1;
            break;
        }
        m->mode = NCP_CO_ESTOP;
        return -1;
    }
    return 1;
}
