/* Drives CiA 402 servo drives (cnc-drive-sim or real) through the start-up a
 * CSP axis needs, then a position ramp over SYNC + PDO 1, the way the
 * socketcan backend will: SDO configuration, NMT start, device control to
 * Operation enabled (with fault reset), cyclic targets, and a controlled stop
 * with exit 3 on EMCY, heartbeat loss, a drive leaving Operation enabled or a
 * failed SDO.
 *   can-master-test IFACE NODE... [--cycles N] [--period-ms P] [--sdo-timeout-ms T]
 *   can-master-test --selftest          (frame and state-machine checks, no bus)
 * Exit: 0 ok, 1 usage or bus error, 3 drive fault (message on stderr). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "ncpar/can.h"

#define MAX_NODES 8
#define HB_PERIOD_MS 50
#define HB_TIMEOUT_MS 500 /* 10 periods: the TCG guest stalls for 100s of ms */

struct master {
    struct ncp_can_bus bus;
    struct ncp_co_node node[MAX_NODES];
    uint16_t cw[MAX_NODES];
    int32_t target[MAX_NODES];
    int enabled[MAX_NODES];
    size_t n;
    int period_ms, sdo_timeout_ms;
    int64_t started_ms;
    long cycle;
};

static int64_t now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000 + ts.tv_nsec / 1000000;
}

static void sleep_ms(int ms)
{
    struct timespec ts = {ms / 1000, (ms % 1000) * 1000000L};
    nanosleep(&ts, NULL);
}

/* ---- start-up over SDO ------------------------------------------------ */
struct sdo_step { uint16_t index; uint8_t sub; uint32_t value; unsigned size; };

static int configure(struct master *m, uint8_t node, struct ncp_diag *d)
{
    static const struct sdo_step steps[] = {
        {0x6060, 0, 8, 1},                       /* cyclic synchronous position */
        {0x60C2, 1, 1, 1}, {0x60C2, 2, 0xFD, 1}, /* interpolation period 1 * 10^-3 s */
        {0x1600, 0, 0, 1}, {0x1600, 1, 0x60400010, 4}, {0x1600, 2, 0x607A0020, 4},
        {0x1600, 0, 2, 1},                       /* RPDO1 = controlword + target */
        {0x1A00, 0, 0, 1}, {0x1A00, 1, 0x60410010, 4}, {0x1A00, 2, 0x60640020, 4},
        {0x1A00, 0, 2, 1},                       /* TPDO1 = statusword + actual */
        {0x1017, 0, HB_PERIOD_MS, 2},            /* heartbeat producer */
    };
    uint32_t v;
    int to = m->sdo_timeout_ms;
    if (ncp_sdo_read(&m->bus, node, 0x1000, 0, &v, to, NULL, d) != NCP_OK)
        return d->code;
    if ((v & 0xFFFFu) != 402)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                            "node %u: device type 0x%08X (object 0x1000) is not a CiA 402 drive",
                            node, v);
    for (size_t i = 0; i < sizeof steps / sizeof steps[0]; i++) {
        const struct sdo_step *s = &steps[i];
        if (ncp_sdo_write(&m->bus, node, s->index, s->sub, s->value, s->size, to, NULL, d))
            return d->code;
    }
    if (ncp_sdo_read(&m->bus, node, 0x6061, 0, &v, to, NULL, d) != NCP_OK)
        return d->code;
    if (v != 8)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                            "node %u: modes of operation display 0x6061 = %u, wanted 8 (CSP)",
                            node, v);
    printf("node %u: CiA 402 drive, CSP mode confirmed, PDO 1 mapped, heartbeat %d ms\n",
           node, HB_PERIOD_MS);
    return NCP_OK;
}

/* ---- one servo period ------------------------------------------------- */
static int send_cycle(struct master *m, struct ncp_diag *d)
{
    struct ncp_can_frame f;
    for (size_t i = 0; i < m->n; i++) {
        ncp_rpdo1_frame(&f, m->node[i].id, m->cw[i], m->target[i]);
        if (ncp_can_send(&m->bus, &f, d) != NCP_OK)
            return d->code;
    }
    ncp_sync_frame(&f);
    return ncp_can_send(&m->bus, &f, d);
}

static int collect_until(struct master *m, const uint32_t *want, int64_t deadline,
                         struct ncp_diag *d);

/* Takes in what arrived since the last period (late TPDOs, heartbeats, EMCY)
 * so that the next wait counts only answers to the next SYNC. */
static int drain(struct master *m, struct ncp_diag *d)
{
    uint32_t never[MAX_NODES] = {0};
    for (size_t i = 0; i < m->n; i++)
        never[i] = UINT32_MAX;
    return collect_until(m, never, now_ms(), d);
}

/* Waits for every node's TPDO1 of this SYNC; a missing one is not fatal
 * (the drive may drop frames): its actual stays that of the last TPDO. */
static int collect(struct master *m, struct ncp_diag *d)
{
    uint32_t want[MAX_NODES] = {0};
    for (size_t i = 0; i < m->n; i++)
        want[i] = m->node[i].tpdos + 1;
    return collect_until(m, want, now_ms() + m->period_ms + 100, d);
}

static int collect_until(struct master *m, const uint32_t *want, int64_t deadline,
                         struct ncp_diag *d)
{
    for (;;) {
        size_t done = 0;
        for (size_t i = 0; i < m->n; i++)
            done += m->node[i].tpdos >= want[i];
        int64_t left = deadline - now_ms();
        if (done == m->n)
            return NCP_OK;
        struct ncp_can_frame f;
        int r = ncp_can_recv(&m->bus, &f, left > 0 ? (int)left : 0, d);
        if (r < 0)
            return d->code;
        if (r == 0)
            return NCP_OK;
        if (ncp_co_track(m->node, m->n, &f, now_ms()) == NCP_CO_EMCY) {
            for (size_t i = 0; i < m->n; i++)
                if (m->node[i].id == (f.id & 0x7Fu)) {
                    char why[160];
                    ncp_emcy_describe(&m->node[i].emcy, why, sizeof why);
                    return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "node %u: EMCY (0x%03X): %s",
                                        m->node[i].id, (unsigned)f.id, why);
                }
        }
    }
}

static int check_faults(struct master *m, struct ncp_diag *d)
{
    int64_t t = now_ms();
    for (size_t i = 0; i < m->n; i++) {
        struct ncp_co_node *nd = &m->node[i];
        if (ncp_co_check_heartbeat(nd, t, m->started_ms, HB_TIMEOUT_MS, d) != NCP_OK)
            return d->code;
        enum ncp_cia402_state s = ncp_cia402_state(nd->statusword);
        if (m->enabled[i] && s != NCP_402_OPERATION_ENABLED) {
            uint32_t code = 0;
            struct ncp_diag d2;
            ncp_sdo_read(&m->bus, nd->id, 0x603F, 0, &code, m->sdo_timeout_ms, NULL, &d2);
            return ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                                "node %u: drive left Operation enabled: now %s "
                                "(statusword 0x6041 = 0x%04X, error code 0x603F = 0x%04X)",
                                nd->id, ncp_cia402_state_name(s), nd->statusword, code);
        }
    }
    return NCP_OK;
}

static int run_cycle(struct master *m, struct ncp_diag *d)
{
    int64_t t0 = now_ms();
    if (drain(m, d) || send_cycle(m, d) || collect(m, d) || check_faults(m, d))
        return d->code;
    m->cycle++;
    int64_t left = t0 + m->period_ms - now_ms();
    if (left > 0)
        sleep_ms((int)left);
    return NCP_OK;
}

/* ---- device control --------------------------------------------------- */
static int enable_all(struct master *m, struct ncp_diag *d)
{
    for (int k = 0; k < 200; k++) {
        size_t ready = 0;
        for (size_t i = 0; i < m->n; i++) {
            enum ncp_cia402_state s = ncp_cia402_state(m->node[i].statusword);
            if (m->node[i].tpdos > 0 && s == NCP_402_OPERATION_ENABLED && !m->enabled[i]) {
                m->enabled[i] = 1;
                m->target[i] = m->node[i].actual;
                printf("node %u: Operation enabled at %d counts\n", m->node[i].id,
                       m->node[i].actual);
            }
            ready += m->enabled[i];
            uint16_t next = m->node[i].tpdos ? ncp_cia402_step(s, m->cw[i]) : 0;
            if (next != m->cw[i] && !m->enabled[i])
                printf("node %u: %s -> controlword 0x%02X\n", m->node[i].id,
                       ncp_cia402_state_name(s), next);
            m->cw[i] = next;
        }
        if (ready == m->n)
            return NCP_OK;
        if (run_cycle(m, d) != NCP_OK)
            return d->code;
    }
    for (size_t i = 0; i < m->n; i++)
        if (!m->enabled[i])
            return ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                                "node %u: no Operation enabled after 200 cycles: still %s "
                                "(statusword 0x6041 = 0x%04X)",
                                m->node[i].id,
                                ncp_cia402_state_name(ncp_cia402_state(m->node[i].statusword)),
                                m->node[i].statusword);
    return NCP_OK;
}

/* Holds every axis where it is, then shuts the drives down. */
static void controlled_stop(struct master *m)
{
    struct ncp_diag d;
    for (size_t i = 0; i < m->n; i++)
        m->target[i] = m->node[i].actual;
    for (int k = 0; k < 5; k++)
        if (send_cycle(m, &d) || collect(m, &d))
            break;
    for (size_t i = 0; i < m->n; i++)
        m->cw[i] = NCP_402_CW_SHUTDOWN;
    send_cycle(m, &d);
    struct ncp_can_frame f;
    ncp_nmt_frame(&f, NCP_NMT_PRE_OPERATIONAL, 0);
    ncp_can_send(&m->bus, &f, &d);
}

static int ramp(struct master *m, long cycles, struct ncp_diag *d)
{
    int32_t start[MAX_NODES] = {0};
    long mismatches = 0, dropped = 0, lagging = 0;
    for (size_t i = 0; i < m->n; i++)
        start[i] = m->target[i];
    for (long k = 1; k <= cycles; k++) {
        for (size_t i = 0; i < m->n; i++)
            m->target[i] = start[i] + (int32_t)(k * 100 * (long)(i + 1));
        uint32_t before[MAX_NODES] = {0};
        for (size_t i = 0; i < m->n; i++)
            before[i] = m->node[i].tpdos;
        if (run_cycle(m, d) != NCP_OK)
            return d->code;
        /* The plant follows within one period, and a late or dropped TPDO
         * leaves the previous actual: one period's step is the tolerance. */
        for (size_t i = 0; i < m->n; i++) {
            long dev = labs((long)m->node[i].actual - m->target[i]);
            dropped += m->node[i].tpdos == before[i];
            lagging += dev != 0;
            mismatches += dev > 100 * (long)(i + 1);
        }
    }
    for (size_t i = 0; i < m->n; i++)
        printf("node %u: target %d actual %d (%u TPDOs, heartbeat state %s)\n",
               m->node[i].id, m->target[i], m->node[i].actual, m->node[i].tpdos,
               ncp_nmt_state_name(m->node[i].hb_state));
    printf("ramp: %ld cycles x %zu axes, %ld outside tolerance, %ld one period behind, "
           "%ld TPDOs missing\n", cycles, m->n, mismatches, lagging, dropped);
    if (mismatches)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                            "%ld actual positions more than one period behind the target",
                            mismatches);
    return NCP_OK;
}

/* ---- main ------------------------------------------------------------- */
int selftest(void);

static int run(struct master *m, long cycles, struct ncp_diag *d)
{
    for (size_t i = 0; i < m->n; i++)
        if (configure(m, m->node[i].id, d) != NCP_OK)
            return d->code;
    struct ncp_can_frame f;
    ncp_nmt_frame(&f, NCP_NMT_START, 0);
    if (ncp_can_send(&m->bus, &f, d) != NCP_OK)
        return d->code;
    m->started_ms = now_ms();
    if (enable_all(m, d) != NCP_OK)
        return d->code;
    return ramp(m, cycles, d);
}

int main(int argc, char **argv)
{
    setvbuf(stdout, NULL, _IOLBF, 0); /* interleaves sensibly with candump */
    if (argc == 2 && !strcmp(argv[1], "--selftest"))
        return selftest();
    static struct master m;
    long cycles = 200;
    m.period_ms = 4;
    m.sdo_timeout_ms = 200;
    const char *ifname = NULL;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--cycles") && i + 1 < argc)
            cycles = atol(argv[++i]);
        else if (!strcmp(argv[i], "--period-ms") && i + 1 < argc)
            m.period_ms = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--sdo-timeout-ms") && i + 1 < argc)
            m.sdo_timeout_ms = atoi(argv[++i]);
        else if (!ifname)
            ifname = argv[i];
        else if (m.n < MAX_NODES && atoi(argv[i]) >= 1 && atoi(argv[i]) <= NCP_CAN_NODE_MAX)
            ncp_co_node_init(&m.node[m.n++], (uint8_t)atoi(argv[i]));
        else
            return fprintf(stderr, "can-master-test: bad argument '%s'\n", argv[i]), 1;
    }
    if (!ifname || m.n == 0)
        return fputs("usage: can-master-test IFACE NODE... [--cycles N] [--period-ms P] "
                     "[--sdo-timeout-ms T] | --selftest\n", stderr), 1;
    struct ncp_diag d;
    uint32_t ids[4 * MAX_NODES];
    size_t nids = ncp_co_filter_ids(m.node, m.n, ids, sizeof ids / sizeof ids[0]);
    if (ncp_can_open(&m.bus, ifname, &d) != NCP_OK || ncp_can_filter(&m.bus, ids, nids, &d)) {
        fprintf(stderr, "can-master-test: %s\n", d.msg);
        return 1;
    }
    m.started_ms = now_ms();
    int rc = 0;
    if (run(&m, cycles, &d) != NCP_OK) {
        fprintf(stderr, "can-master-test: controlled stop after cycle %ld: %s\n", m.cycle,
                d.msg);
        controlled_stop(&m);
        rc = 3;
    }
    ncp_can_close(&m.bus);
    return rc;
}
