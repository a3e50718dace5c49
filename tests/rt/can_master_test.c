/* Drives CiA 402 servo drives (cnc-drive-sim or real) through the start-up a
 * CSP axis needs, then a position ramp over SYNC + PDO 1, the way the
 * socketcan backend will: SDO configuration, NMT start, device control to
 * Operation enabled (with fault reset), cyclic targets, and a controlled stop
 * with exit 3 on EMCY, heartbeat loss, a drive leaving Operation enabled or a
 * failed SDO.
 *   can-master-test IFACE NODE... [--cycles N] [--period-ms P] [--sdo-timeout-ms T]
 *                   [--hb-timeout-ms T] [--lenient]
 * --lenient is for software emulation (qemu TCG), where a drive's answer may
 * come many periods late: the ramp then checks the values and order of the
 * TPDOs and that every axis reaches its target, not that they keep pace, and
 * the SDO and heartbeat timeouts default to 2 s instead of 200 / 500 ms.
 *   can-master-test --selftest          (frame and state-machine checks, no bus)
 * Exit: 0 ok, 1 usage or bus error, 3 drive fault (message on stderr). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "ncpar/can.h"
#include "ramp_check.h"

#define MAX_NODES 8
#define HB_PERIOD_MS 50
#define HB_TIMEOUT_MS 500 /* 10 periods */
#define LENIENT_TIMEOUT_MS 2000 /* a loaded TCG guest stalls for up to seconds */

struct master {
    struct ncp_can_bus bus;
    struct ncp_co_node node[MAX_NODES];
    uint16_t cw[MAX_NODES];
    int32_t target[MAX_NODES];
    int enabled[MAX_NODES];
    size_t n;
    int period_ms, sdo_timeout_ms, hb_timeout_ms, lenient;
    int64_t started_ms;
    long cycle;
    struct ncp_ramp_axis *ramp; /* while the ramp runs: judges each TPDO */
    long ramp_k, ramp_cycles;
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

/* A drive that left Operation enabled holds its position: check_faults
 * reports that, so only the TPDOs of enabled drives are judged here. */
static void judge_tpdo(struct master *m, unsigned id)
{
    for (size_t i = 0; m->ramp && i < m->n; i++) {
        const struct ncp_co_node *nd = &m->node[i];
        if (nd->id == id && ncp_cia402_state(nd->statusword) == NCP_402_OPERATION_ENABLED)
            ncp_ramp_axis_tpdo(&m->ramp[i], nd->actual, m->ramp_k, m->ramp_cycles);
    }
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
        enum ncp_co_event ev = ncp_co_track(m->node, m->n, &f, now_ms());
        if (ev == NCP_CO_TPDO)
            judge_tpdo(m, f.id & 0x7Fu);
        if (ev == NCP_CO_EMCY) {
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
        if (ncp_co_check_heartbeat(nd, t, m->started_ms, m->hb_timeout_ms, d) != NCP_OK)
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

static int settled(const struct master *m, const struct ncp_ramp_axis *ax, long cycles)
{
    for (size_t i = 0; i < m->n; i++)
        if (ax[i].last_j != cycles)
            return 0;
    return 1;
}

/* Counts what breaks the ramp and names the first cause in d. */
static long ramp_faults(const struct master *m, const struct ncp_ramp_axis *ax, long cycles,
                        long late, struct ncp_diag *d)
{
    long faults = 0;
    for (size_t i = 0; i < m->n; i++) {
        const struct ncp_ramp_axis *a = &ax[i];
        unsigned id = m->node[i].id;
        if (a->bad && !faults)
            ncp_diag_set(d, NCP_ERR_IO, 0, 0, "node %u: %ld wrong TPDOs, first: %s", id, a->bad,
                         a->why);
        faults += a->bad;
        if (a->last_j != cycles && !faults++)
            ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                         "node %u: actual %d never reached the final target %d", id,
                         m->node[i].actual, m->target[i]);
        /* A drive may drop TPDOs (CAN is best effort), not most of them. */
        if (cycles - a->seen > cycles / 4 && !faults++)
            ncp_diag_set(d, NCP_ERR_IO, 0, 0, "node %u: %ld of %ld TPDOs missing", id,
                         cycles - a->seen, cycles);
    }
    if (!m->lenient && late && !faults)
        ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                     "%ld actual positions more than one period behind the target", late);
    return faults + (m->lenient ? 0 : late);
}

static int ramp(struct master *m, long cycles, struct ncp_diag *d)
{
    struct ncp_ramp_axis ax[MAX_NODES];
    long lagging = 0, late = 0, missing = 0, worst = 0, extra = 0;
    for (size_t i = 0; i < m->n; i++)
        ncp_ramp_axis_init(&ax[i], m->target[i], 100 * (int32_t)(i + 1));
    m->ramp = ax;
    m->ramp_cycles = cycles;
    int rc = NCP_OK;
    for (long k = 1; k <= cycles && rc == NCP_OK; k++) {
        for (size_t i = 0; i < m->n; i++)
            m->target[i] = ax[i].start + (int32_t)k * ax[i].step;
        m->ramp_k = k;
        rc = run_cycle(m, d);
        for (size_t i = 0; i < m->n && rc == NCP_OK; i++) {
            long lag = ncp_ramp_axis_lag(&ax[i], k);
            lagging += lag != 0;
            late += lag > 1; /* a dropped TPDO leaves the actual one period old */
        }
    }
    /* Late answers still on their way: hold the final target until they are in. */
    for (long max = m->lenient ? 250 : 3; rc == NCP_OK && extra < max && !settled(m, ax, cycles);
         extra++)
        rc = run_cycle(m, d);
    m->ramp = NULL;
    if (rc != NCP_OK)
        return rc;
    for (size_t i = 0; i < m->n; i++) {
        printf("node %u: target %d actual %d (%u TPDOs, heartbeat state %s)\n",
               m->node[i].id, m->target[i], m->node[i].actual, m->node[i].tpdos,
               ncp_nmt_state_name(m->node[i].hb_state));
        missing += cycles - ax[i].seen;
        worst = ax[i].max_lag > worst ? ax[i].max_lag : worst;
    }
    long faults = ramp_faults(m, ax, cycles, late, d);
    printf("ramp: %ld cycles x %zu axes, %ld outside tolerance, %ld one period behind, "
           "%ld TPDOs missing\n", cycles, m->n, faults, lagging, missing);
    printf("ramp check %s: worst lag %ld periods, %ld settling cycles\n",
           m->lenient ? "lenient (software emulation: late TPDOs tolerated, values and order "
                        "checked)"
                      : "strict (each TPDO within one period)",
           worst, extra);
    return faults ? NCP_ERR_IO : NCP_OK;
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
    m.sdo_timeout_ms = m.hb_timeout_ms = -1;
    const char *ifname = NULL;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--cycles") && i + 1 < argc)
            cycles = atol(argv[++i]);
        else if (!strcmp(argv[i], "--period-ms") && i + 1 < argc)
            m.period_ms = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--sdo-timeout-ms") && i + 1 < argc)
            m.sdo_timeout_ms = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--hb-timeout-ms") && i + 1 < argc)
            m.hb_timeout_ms = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--lenient"))
            m.lenient = 1;
        else if (!ifname)
            ifname = argv[i];
        else if (m.n < MAX_NODES && atoi(argv[i]) >= 1 && atoi(argv[i]) <= NCP_CAN_NODE_MAX)
            ncp_co_node_init(&m.node[m.n++], (uint8_t)atoi(argv[i]));
        else
            return fprintf(stderr, "can-master-test: bad argument '%s'\n", argv[i]), 1;
    }
    if (!ifname || m.n == 0)
        return fputs("usage: can-master-test IFACE NODE... [--cycles N] [--period-ms P] "
                     "[--sdo-timeout-ms T] [--hb-timeout-ms T] [--lenient] | --selftest\n",
                     stderr), 1;
    if (m.sdo_timeout_ms <= 0)
        m.sdo_timeout_ms = m.lenient ? LENIENT_TIMEOUT_MS : 200;
    if (m.hb_timeout_ms <= 0)
        m.hb_timeout_ms = m.lenient ? LENIENT_TIMEOUT_MS : HB_TIMEOUT_MS;
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
