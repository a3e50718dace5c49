/* The master's cyclic path, called by the position loop every servo period.
 * Real-time rules: one non-blocking send()/recv() per frame (MSG_DONTWAIT),
 * clock_gettime (vDSO) for heartbeat ages, no allocation, no locks, no
 * formatting: a fault is recorded as values in m->fault and described after
 * the loop has stopped. */
#include <errno.h>
#include <string.h>
#include <time.h>

#include "ncpar/can.h"
#include "ncpar/clock.h"

int64_t ncp_co_now_ms(void)
{
    return ncp_mono_ms();
}

static void set_bus_fault(struct ncp_co_master *m, uint32_t cob, int err)
{
    m->fault.kind = NCP_CO_FAULT_BUS;
    m->fault.node = (uint8_t)(cob & 0x7Fu);
    m->fault.cob = cob;
    m->fault.err = err;
}

static int emcy_fault(struct ncp_co_master *m, const struct ncp_can_frame *f)
{
    for (size_t i = 0; i < m->n; i++) {
        const struct ncp_co_node *nd = &m->node[i];
        /* code 0x0000 is "error reset / no error": the drive recovered */
        if (nd->id == (f->id & 0x7Fu) && nd->emcy.code != 0) {
            /* the first fault is the one the operator is told of: a drive
             * stopping on its own after it says nothing new */
            if (m->fault.kind == NCP_CO_FAULT_NONE) {
                m->fault.kind = NCP_CO_FAULT_EMCY;
                m->fault.node = nd->id;
                m->fault.emcy = nd->emcy;
            }
            return -1;
        }
    }
    return 0;
}

int ncp_co_master_poll(struct ncp_co_master *m, int64_t now_ms, int max)
{
    struct ncp_can_frame f;
    for (int k = 0; k < max; k++) {
        int r = ncp_can_try_recv(&m->bus, &f);
        if (r == 0)
            return 0;
        if (r < 0) {
            set_bus_fault(m, 0, errno);
            return -1;
        }
        if (ncp_co_track(m->node, m->n, &f, now_ms) == NCP_CO_EMCY && emcy_fault(m, &f))
            return -1;
    }
    return 0;
}

int ncp_co_master_check(struct ncp_co_master *m, int64_t now_ms)
{
    for (size_t i = 0; i < m->n; i++) {
        const struct ncp_co_node *nd = &m->node[i];
        int64_t last = nd->last_hb_ms >= 0 ? nd->last_hb_ms : m->started_ms;
        if (now_ms - last > m->cfg.hb_timeout_ms) {
            m->fault.kind = NCP_CO_FAULT_HEARTBEAT;
            m->fault.node = nd->id;
            m->fault.hb_age_ms = nd->last_hb_ms >= 0 ? now_ms - last : -1;
            m->fault.hb_timeout_ms = m->cfg.hb_timeout_ms;
            m->fault.hb_state = nd->hb_state;
            return -1;
        }
        if (!m->enabled[i])
            continue;
        if (nd->last_hb_ms >= 0 && nd->hb_state != NCP_NMT_OPERATIONAL) {
            m->fault.kind = NCP_CO_FAULT_NMT;
            m->fault.node = nd->id;
            m->fault.hb_state = nd->hb_state;
            return -1;
        }
        if (ncp_cia402_state(nd->statusword) != NCP_402_OPERATION_ENABLED) {
            m->fault.kind = NCP_CO_FAULT_STATE;
            m->fault.node = nd->id;
            m->fault.statusword = nd->statusword;
            m->fault.error_code = -1;
            return -1;
        }
    }
    return 0;
}

int ncp_co_master_send(struct ncp_co_master *m)
{
    struct ncp_can_frame f;
    for (size_t i = 0; i <= m->n; i++) {
        if (i < m->n)
            ncp_rpdo1_frame(&f, m->node[i].id, m->cw[i], m->target[i]);
        else
            ncp_sync_frame(&f);
        int r = ncp_can_try_send(&m->bus, &f);
        if (r < 0) {
            set_bus_fault(m, f.id, errno);
            return -1;
        }
        if (r > 0) {
            /* Frames already queued go out; without the SYNC the drives
             * merely take the new target one period later. */
            if (++m->tx_full >= 50) {
                set_bus_fault(m, f.id, 0);
                return -1;
            }
            return 0;
        }
    }
    m->tx_full = 0;
    m->cycle++;
    /* our own heartbeat, which the drives consume (0x1016): when it stops,
     * they stop on their own */
    int64_t now = ncp_co_now_ms();
    if (m->cfg.master_node && now >= m->next_hb_ms) {
        ncp_heartbeat_frame(&f, m->cfg.master_node, NCP_NMT_OPERATIONAL);
        if (ncp_can_try_send(&m->bus, &f) < 0) {
            set_bus_fault(m, f.id, errno);
            return -1;
        }
        m->next_hb_ms = now + m->cfg.hb_period_ms;
    }
    return 0;
}
