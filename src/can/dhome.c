/* The drive's own homing mode (CiA 402 homing, 0x6060 = 6) for an axis
 * whose INI says HOME_METHOD = drive:N. The loop's side runs on values:
 * the controlword (bit 4 starts the homing), the statusword's bits 10, 12
 * and 13, the target held at the actual position so nothing jumps when the
 * drive is back in CSP. The mode switches are SDO exchanges, which block:
 * the loop asks for them through atomics and a worker thread outside the
 * loop serves them (ncp_co_home_serve) on its own socket. */
#include <string.h>

#include "ncpar/can.h"

size_t ncp_co_home_sdo_steps(const struct ncp_co_home_cfg *c, int mode,
                             struct ncp_co_sdo_step *out, size_t max)
{
    struct ncp_co_sdo_step all[6];
    size_t n = 0;
    if (mode == NCP_402_MODE_HOMING) {
        /* the parameters first: a drive may start from what it holds the
         * moment the mode changes */
        all[n++] = (struct ncp_co_sdo_step){0x607C, 0, (uint32_t)c->offset, 4};
        all[n++] = (struct ncp_co_sdo_step){0x6098, 0, (uint32_t)(c->method & 0xFF), 1};
        if (c->search)
            all[n++] = (struct ncp_co_sdo_step){0x6099, 1, c->search, 4};
        if (c->latch)
            all[n++] = (struct ncp_co_sdo_step){0x6099, 2, c->latch, 4};
        if (c->acc)
            all[n++] = (struct ncp_co_sdo_step){0x609A, 0, c->acc, 4};
    }
    all[n++] = (struct ncp_co_sdo_step){0x6060, 0, (uint32_t)mode, 1};
    if (n > max)
        n = max;
    memcpy(out, all, n * sizeof all[0]);
    return n;
}

/* ---- the loop's side: values only ------------------------------------ */

static void ask_mode(struct ncp_co_home *h, int mode)
{
    atomic_store_explicit(&h->want, mode, memory_order_relaxed);
    atomic_fetch_add_explicit(&h->ask, 1, memory_order_release);
}

static int answered(struct ncp_co_home *h)
{
    return atomic_load_explicit(&h->done, memory_order_acquire) ==
           atomic_load_explicit(&h->ask, memory_order_relaxed);
}

static void begin(struct ncp_co_home *h, int phase)
{
    h->phase = phase;
    h->periods = 0;
}

static int fail(struct ncp_co_master *m, size_t i, int why)
{
    struct ncp_co_home *h = &m->home[i];
    if (m->fault.kind == NCP_CO_FAULT_NONE) {
        m->fault.kind = NCP_CO_FAULT_HOMING;
        m->fault.node = m->node[i].id;
        m->fault.statusword = m->node[i].statusword;
        m->fault.home_why = why;
        m->fault.home_method = h->cfg.method;
        m->fault.home_ms = h->periods * m->cfg.period_us / 1000;
        if (why == NCP_CH_WHY_SDO)
            memcpy(m->fault.text, h->why, sizeof m->fault.text);
    }
    /* back to CSP, so that the operator's reset finds a drive that
     * follows targets again */
    atomic_store_explicit(&h->phase_sw, 0, memory_order_relaxed);
    ask_mode(h, NCP_402_MODE_CSP);
    begin(h, NCP_CH_FAILED);
    return -1;
}

int ncp_co_home_start(struct ncp_co_master *m, size_t i)
{
    struct ncp_co_home *h = &m->home[i];
    if (i >= m->n || !h->cfg.on || m->mode != NCP_CO_RUN || h->phase != NCP_CH_IDLE)
        return -1;
    begin(h, NCP_CH_TO_HOMING);
    atomic_store_explicit(&h->phase_sw, 0, memory_order_relaxed);
    ask_mode(h, NCP_402_MODE_HOMING);
    return 0;
}

void ncp_co_home_abort(struct ncp_co_master *m, size_t i)
{
    struct ncp_co_home *h = &m->home[i];
    if (h->phase == NCP_CH_TO_HOMING || h->phase == NCP_CH_HOMING || h->phase == NCP_CH_TO_CSP) {
        atomic_store_explicit(&h->phase_sw, 0, memory_order_relaxed);
        ask_mode(h, NCP_402_MODE_CSP);
        begin(h, NCP_CH_ABORTING);
    }
}

void ncp_co_home_drop(struct ncp_co_master *m)
{
    for (size_t i = 0; i < m->n; i++) {
        struct ncp_co_home *h = &m->home[i];
        if (h->phase == NCP_CH_IDLE)
            continue;
        if (h->phase != NCP_CH_FAILED && h->phase != NCP_CH_HOMED) {
            atomic_store_explicit(&h->phase_sw, 0, memory_order_relaxed);
            ask_mode(h, NCP_402_MODE_CSP);
        }
        begin(h, NCP_CH_IDLE);
    }
}

int ncp_co_home_poll(struct ncp_co_master *m, size_t i)
{
    struct ncp_co_home *h = &m->home[i];
    switch (h->phase) {
    case NCP_CH_HOMED: begin(h, NCP_CH_IDLE); return 0;
    case NCP_CH_IDLE:
    case NCP_CH_FAILED: return -1;
    default: return 1;
    }
}

int ncp_co_home_step(struct ncp_co_master *m, size_t i)
{
    struct ncp_co_home *h = &m->home[i];
    const struct ncp_co_node *nd = &m->node[i];
    if (h->phase == NCP_CH_IDLE)
        return 0;
    /* the drive ignores targets in homing mode, and takes the one it has
     * the moment it is back in CSP: its actual position, no jump */
    m->target[i] = nd->actual;
    m->cw[i] = NCP_402_CW_ENABLE;
    h->periods++;
    switch (h->phase) {
    case NCP_CH_TO_HOMING:
        if (!answered(h))
            break;
        if (atomic_load_explicit(&h->failed, memory_order_relaxed))
            return fail(m, i, NCP_CH_WHY_SDO);
        begin(h, NCP_CH_HOMING);
        h->tpdos_at = nd->tpdos;
        h->under_way = 0;
        m->cw[i] |= NCP_402_CW_HOMING_START;
        break;
    case NCP_CH_HOMING:
        m->cw[i] |= NCP_402_CW_HOMING_START;
        if (nd->tpdos != h->tpdos_at && !(nd->statusword & NCP_402_SW_TARGET_REACHED))
            h->under_way = 1;
        if (h->under_way || nd->tpdos - h->tpdos_at >= NCP_CO_HOME_SETTLE_TPDOS) {
            if (nd->statusword & NCP_402_SW_HOMING_ERROR)
                return fail(m, i, NCP_CH_WHY_ERROR);
            uint16_t done = NCP_402_SW_HOMING_ATTAINED | NCP_402_SW_TARGET_REACHED;
            if ((nd->statusword & done) == done) {
                /* bit 4 down with this period's RPDO, CSP by SDO */
                m->cw[i] = NCP_402_CW_ENABLE;
                atomic_store_explicit(&h->phase_sw, nd->statusword, memory_order_relaxed);
                begin(h, NCP_CH_TO_CSP);
                ask_mode(h, NCP_402_MODE_CSP);
                break;
            }
        }
        if (h->periods > h->cfg.timeout_periods)
            return fail(m, i, NCP_CH_WHY_TIMEOUT);
        break;
    case NCP_CH_TO_CSP:
    case NCP_CH_ABORTING:
        if (!answered(h))
            break;
        if (atomic_load_explicit(&h->failed, memory_order_relaxed))
            return fail(m, i, NCP_CH_WHY_SDO);
        begin(h, h->phase == NCP_CH_TO_CSP ? NCP_CH_HOMED : NCP_CH_IDLE);
        break;
    default: break;
    }
    return 1;
}

/* ---- the worker's side: blocking SDO, never on the loop's thread ------ */

int ncp_co_home_serve(struct ncp_co_master *m, struct ncp_can_bus *bus, size_t i)
{
    struct ncp_co_home *h = &m->home[i];
    uint32_t a = atomic_load_explicit(&h->ask, memory_order_acquire);
    if (a == atomic_load_explicit(&h->done, memory_order_relaxed))
        return 0;
    int mode = atomic_load_explicit(&h->want, memory_order_relaxed);
    unsigned sw = atomic_load_explicit(&h->phase_sw, memory_order_relaxed);
    uint8_t node = m->node[i].id;
    int to = m->cfg.sdo_timeout_ms;
    struct ncp_co_sdo_step steps[8];
    size_t n = ncp_co_home_sdo_steps(&h->cfg, mode, steps, sizeof steps / sizeof steps[0]);
    struct ncp_diag d;
    int bad = 0;
    for (size_t k = 0; k < n && !bad; k++)
        bad = ncp_sdo_write(bus, node, steps[k].index, steps[k].sub, steps[k].value,
                            steps[k].size, to, NULL, &d) != NCP_OK;
    uint32_t v = 0;
    if (!bad && ncp_sdo_read(bus, node, 0x6061, 0, &v, to, NULL, &d) != NCP_OK)
        bad = 1;
    else if (!bad && v != (uint32_t)mode)
        bad = ncp_diag_set(&d, NCP_ERR_IO, 0, 0,
                           "node %u: modes of operation display 0x6061 = %u after 0x6060 = %d",
                           node, v, mode) != NCP_OK;
    if (m->log && bad)
        fprintf(m->log, "%s\n", d.msg);
    else if (m->log && mode == NCP_402_MODE_HOMING)
        fprintf(m->log, "node %u: homing mode (0x6060 = 6), method %d (0x6098)\n", node,
                h->cfg.method);
    else if (m->log && sw)
        fprintf(m->log, "node %u: homing attained (statusword 0x6041 = 0x%04X), cyclic "
                        "synchronous position again (0x6060 = 8)\n", node, sw);
    else if (m->log)
        fprintf(m->log, "node %u: cyclic synchronous position again (0x6060 = 8)\n", node);
    if (bad)
        memcpy(h->why, d.msg, sizeof h->why);
    atomic_store_explicit(&h->failed, bad, memory_order_relaxed);
    atomic_store_explicit(&h->done, a, memory_order_release);
    return 1;
}
