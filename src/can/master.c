/* The master's blocking side: bus set-up, SDO start-up of each drive, NMT
 * start, the CiA 402 walk to Operation enabled and the controlled stop. None
 * of it runs on the real-time thread (see master_rt.c for what does). */
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "ncpar/can.h"

#define ENABLE_CYCLES 200 /* periods the CiA 402 walk may take */
#define HOLD_CYCLES 5     /* periods of holding still before the shutdown */

static void sleep_ms(int64_t ms)
{
    struct timespec ts = {(time_t)(ms / 1000), (long)(ms % 1000) * 1000000L};
    nanosleep(&ts, NULL);
}

int ncp_co_master_open(struct ncp_co_master *m, const char *ifname, const uint8_t *nodes,
                       size_t n, const struct ncp_co_master_cfg *cfg, struct ncp_diag *d)
{
    memset(m, 0, sizeof *m);
    m->bus.fd = -1;
    m->cfg = *cfg;
    if (n == 0 || n > NCP_CO_MAX_NODES)
        return ncp_diag_set(d, NCP_ERR_LIMIT, 0, 0, "%zu CAN drives (1..%d supported)", n,
                            NCP_CO_MAX_NODES);
    for (size_t i = 0; i < n; i++)
        ncp_co_node_init(&m->node[i], nodes[i]);
    m->n = n;
    uint32_t ids[5 * NCP_CO_MAX_NODES];
    size_t nids = ncp_co_filter_ids(m->node, n, ids, sizeof ids / sizeof ids[0]);
    if (ncp_can_open(&m->bus, ifname, d) != NCP_OK)
        return d->code;
    if (ncp_can_filter(&m->bus, ids, nids, d) != NCP_OK) {
        ncp_can_close(&m->bus);
        return d->code;
    }
    m->started_ms = ncp_co_now_ms();
    return NCP_OK;
}

void ncp_co_master_close(struct ncp_co_master *m)
{
    ncp_can_close(&m->bus);
}

/* A failure of the start-up, kept as the master's fault too. */
static int start_fault(struct ncp_co_master *m, uint8_t node, struct ncp_diag *d)
{
    m->fault.kind = NCP_CO_FAULT_START;
    m->fault.node = node;
    snprintf(m->fault.text, sizeof m->fault.text, "%s", d->msg);
    return d->code ? d->code : NCP_ERR_IO;
}

struct sdo_step { uint16_t index; uint8_t sub; uint32_t value; unsigned size; };

/* Writes steps[0..n) to node in order; stops at the first that fails. */
static int write_steps(struct ncp_co_master *m, uint8_t node, const struct sdo_step *steps,
                       size_t n, struct ncp_diag *d)
{
    for (size_t k = 0; k < n; k++) {
        const struct sdo_step *s = &steps[k];
        if (ncp_sdo_write(&m->bus, node, s->index, s->sub, s->value, s->size,
                          m->cfg.sdo_timeout_ms, NULL, d))
            return -1;
    }
    return 0;
}

int ncp_co_master_configure(struct ncp_co_master *m, size_t i, struct ncp_diag *d)
{
    uint8_t node = m->node[i].id, ipv;
    int8_t ipi;
    if (ncp_co_interp_period(m->cfg.period_us, &ipv, &ipi))
        return ncp_diag_set(d, NCP_ERR_SEMANTIC, 0, 0,
                            "servo period %ld us cannot be written to 0x60C2", m->cfg.period_us);
    const struct sdo_step steps[] = {
        {0x6060, 0, 8, 1},                      /* cyclic synchronous position */
        {0x60C2, 1, ipv, 1}, {0x60C2, 2, (uint8_t)ipi, 1},
        {0x1600, 0, 0, 1}, {0x1600, 1, 0x60400010, 4}, {0x1600, 2, 0x607A0020, 4},
        {0x1600, 0, 2, 1},                      /* RPDO1 = controlword + target */
        {0x1A00, 0, 0, 1}, {0x1A00, 1, 0x60410010, 4}, {0x1A00, 2, 0x60640020, 4},
        {0x1A00, 0, 2, 1},                      /* TPDO1 = statusword + actual */
        {0x1017, 0, (uint32_t)m->cfg.hb_period_ms, 2}, /* heartbeat producer */
    };
    /* the drive guards us: consumer of our heartbeat, RPDO deadline, what
     * it does on its own when either stops (a killed master), and how hard
     * it brakes then (last, only when known) */
    const struct sdo_step guard[] = {
        {0x1006, 0, (uint32_t)m->cfg.period_us, 4},
        {0x1016, 1, (uint32_t)m->cfg.master_node << 16 | (uint32_t)m->cfg.hb_consumer_ms, 4},
        {0x1400, 5, (uint32_t)m->cfg.rpdo_timeout_ms, 2},
        {0x6007, 0, (uint32_t)m->cfg.abort_option, 2},
        {0x605E, 0, (uint32_t)m->cfg.fault_reaction, 2},
        {0x6085, 0, m->quick_stop_dec[i], 4},
    };
    size_t n_guard = !m->cfg.master_node       ? 0
                     : m->quick_stop_dec[i] != 0 ? sizeof guard / sizeof guard[0]
                                               : sizeof guard / sizeof guard[0] - 1;
    /* TPDO2 = the digital inputs, at every SYNC (only where homing needs
     * the switch: a start-up without it stays as it was) */
    const struct sdo_step din[] = {
        {0x1801, 2, 1, 1},
        {0x1A01, 0, 0, 1}, {0x1A01, 1, 0x60FD0020, 4}, {0x1A01, 0, 1, 1},
    };
    uint32_t v;
    int to = m->cfg.sdo_timeout_ms;
    if (ncp_sdo_read(&m->bus, node, 0x1000, 0, &v, to, NULL, d) != NCP_OK)
        return start_fault(m, node, d);
    if ((v & 0xFFFFu) != 402) {
        ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                     "node %u: device type 0x%08X (object 0x1000) is not a CiA 402 drive", node,
                     v);
        return start_fault(m, node, d);
    }
    if (write_steps(m, node, steps, sizeof steps / sizeof steps[0], d) ||
        (m->cfg.map_din && write_steps(m, node, din, sizeof din / sizeof din[0], d)) ||
        write_steps(m, node, guard, n_guard, d))
        return start_fault(m, node, d);
    if (ncp_sdo_read(&m->bus, node, 0x6061, 0, &v, to, NULL, d) != NCP_OK)
        return start_fault(m, node, d);
    if (v != 8) {
        ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                     "node %u: modes of operation display 0x6061 = %u, wanted 8 (CSP)", node, v);
        return start_fault(m, node, d);
    }
    if (m->log)
        fprintf(m->log, "node %u: CiA 402 drive, CSP mode confirmed, PDO 1 mapped, heartbeat %d ms\n",
                node, m->cfg.hb_period_ms);
    if (m->log && m->cfg.master_node)
        fprintf(m->log,
                "node %u: guards master node %u: heartbeat consumer %d ms, RPDO deadline %d ms, "
                "abort connection option %d, fault reaction option %d\n",
                node, m->cfg.master_node, m->cfg.hb_consumer_ms, m->cfg.rpdo_timeout_ms,
                m->cfg.abort_option, m->cfg.fault_reaction);
    return NCP_OK;
}

static int fault_diag(struct ncp_co_master *m, struct ncp_diag *d)
{
    char buf[NCP_DIAG_MSG_MAX];
    ncp_co_fault_describe(&m->fault, m->bus.ifname, buf, sizeof buf);
    return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "%s", buf);
}

/* Waits until every node's TPDO count reaches want[] or the deadline. */
static int collect_until(struct ncp_co_master *m, const uint32_t *want, int64_t deadline,
                         struct ncp_diag *d)
{
    for (;;) {
        size_t done = 0;
        for (size_t i = 0; i < m->n; i++)
            done += m->node[i].tpdos >= want[i];
        int64_t left = deadline - ncp_co_now_ms();
        if (done == m->n)
            return NCP_OK;
        /* past the deadline: still take in what is already there */
        if (left < 0)
            left = 0;
        struct ncp_can_frame f;
        int r = ncp_can_recv(&m->bus, &f, (int)left, d);
        if (r < 0)
            return d->code;
        if (r == 0)
            return NCP_OK;
        enum ncp_co_event ev = ncp_co_track(m->node, m->n, &f, ncp_co_now_ms());
        for (size_t i = 0; ev == NCP_CO_TPDO && m->on_tpdo && i < m->n; i++)
            if (m->node[i].id == (f.id & 0x7Fu))
                m->on_tpdo(m->on_tpdo_ctx, i);
        if (ev == NCP_CO_EMCY) {
            for (size_t i = 0; i < m->n; i++)
                if (m->node[i].id == (f.id & 0x7Fu) && m->node[i].emcy.code != 0) {
                    m->fault.kind = NCP_CO_FAULT_EMCY;
                    m->fault.node = m->node[i].id;
                    m->fault.emcy = m->node[i].emcy;
                    return fault_diag(m, d);
                }
        }
    }
}

int ncp_co_master_cycle(struct ncp_co_master *m, struct ncp_diag *d)
{
    int64_t t0 = ncp_co_now_ms();
    uint32_t want[NCP_CO_MAX_NODES] = {0};
    /* what came since the last period (late TPDOs, heartbeats, EMCY) first,
     * so that the wait below counts only answers to this SYNC */
    for (size_t i = 0; i < m->n; i++)
        want[i] = UINT32_MAX;
    if (collect_until(m, want, t0, d) != NCP_OK)
        return d->code;
    if (ncp_co_master_send(m))
        return fault_diag(m, d);
    for (size_t i = 0; i < m->n; i++)
        want[i] = m->node[i].tpdos + 1;
    if (collect_until(m, want, ncp_co_now_ms() + m->cfg.period_us / 1000 + 100, d) != NCP_OK)
        return d->code;
    if (ncp_co_master_check(m, ncp_co_now_ms()))
        return fault_diag(m, d);
    int64_t left = t0 + (m->cfg.period_us + 999) / 1000 - ncp_co_now_ms();
    if (left > 0)
        sleep_ms(left);
    return NCP_OK;
}

static int enable_step(struct ncp_co_master *m, size_t i)
{
    struct ncp_co_node *nd = &m->node[i];
    enum ncp_cia402_state s = ncp_cia402_state(nd->statusword);
    if (nd->tpdos > 0 && s == NCP_402_OPERATION_ENABLED && !m->enabled[i]) {
        m->enabled[i] = 1;
        m->target[i] = nd->actual;
        if (m->log)
            fprintf(m->log, "node %u: Operation enabled at %d counts\n", nd->id, nd->actual);
    }
    uint16_t next = nd->tpdos ? ncp_cia402_step(s, m->cw[i]) : 0;
    if (next != m->cw[i] && !m->enabled[i] && m->log)
        fprintf(m->log, "node %u: %s -> controlword 0x%02X\n", nd->id, ncp_cia402_state_name(s),
                next);
    m->cw[i] = next;
    return m->enabled[i];
}

int ncp_co_master_enable(struct ncp_co_master *m, struct ncp_diag *d)
{
    for (int k = 0; k < ENABLE_CYCLES; k++) {
        size_t ready = 0;
        for (size_t i = 0; i < m->n; i++)
            ready += (size_t)enable_step(m, i);
        if (ready == m->n)
            return NCP_OK;
        if (ncp_co_master_cycle(m, d) != NCP_OK)
            return d->code;
    }
    for (size_t i = 0; i < m->n; i++) {
        const struct ncp_co_node *nd = &m->node[i];
        if (m->enabled[i])
            continue;
        ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                     "node %u: no Operation enabled after %d periods: still %s "
                     "(statusword 0x6041 = 0x%04X)",
                     nd->id, ENABLE_CYCLES, ncp_cia402_state_name(ncp_cia402_state(nd->statusword)),
                     nd->statusword);
        return start_fault(m, nd->id, d);
    }
    return NCP_OK;
}

int ncp_co_master_startup(struct ncp_co_master *m, struct ncp_diag *d)
{
    for (size_t i = 0; i < m->n; i++)
        if (ncp_co_master_configure(m, i, d) != NCP_OK)
            return d->code;
    struct ncp_can_frame f;
    ncp_nmt_frame(&f, NCP_NMT_START, 0);
    if (ncp_can_send(&m->bus, &f, d) != NCP_OK)
        return start_fault(m, 0, d);
    m->started_ms = ncp_co_now_ms();
    return ncp_co_master_enable(m, d);
}

void ncp_co_master_stop(struct ncp_co_master *m)
{
    struct ncp_diag d;
    if (m->fault.kind == NCP_CO_FAULT_STATE) {
        uint32_t code = 0;
        m->fault.error_code = ncp_sdo_read(&m->bus, m->fault.node, 0x603F, 0, &code,
                                           m->cfg.sdo_timeout_ms, NULL, &d) == NCP_OK
                                  ? (int32_t)(code & 0xFFFFu)
                                  : -1;
    }
    struct ncp_co_fault keep = m->fault;
    size_t enabled = 0;
    for (size_t i = 0; i < m->n; i++) {
        /* after a fault every drive stays where it is; after a normal end
         * it holds the last target, where the axis is coming to rest */
        if (keep.kind != NCP_CO_FAULT_NONE)
            m->target[i] = m->node[i].actual;
        enabled += m->enabled[i];
    }
    /* holding still: a second fault meanwhile changes nothing of the stop */
    for (int k = 0; enabled && k < HOLD_CYCLES; k++)
        if (ncp_co_master_cycle(m, &d) != NCP_OK)
            break;
    for (size_t i = 0; i < m->n; i++)
        m->cw[i] = NCP_402_CW_SHUTDOWN;
    ncp_co_master_send(m);
    struct ncp_can_frame f;
    ncp_nmt_frame(&f, NCP_NMT_PRE_OPERATIONAL, 0);
    ncp_can_send(&m->bus, &f, &d);
    m->fault = keep;
}
