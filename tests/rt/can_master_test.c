/* Drives CiA 402 servo drives (cnc-drive-sim or real) through the start-up a
 * CSP axis needs, then a position ramp over SYNC + PDO 1, the way the
 * socketcan backend does, with the backend's own master (src/can/master*.c):
 * SDO configuration, NMT start, device control to Operation enabled (with
 * fault reset), cyclic targets, and a controlled stop with exit 3 on EMCY,
 * heartbeat loss, a drive leaving Operation enabled or a failed SDO. The
 * ramp checks every TPDO's value against the targets sent (ramp_check.c).
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

#include "ncpar/can.h"
#include "ramp_check.h"

#define HB_PERIOD_MS 50
#define HB_TIMEOUT_MS 500 /* 10 periods */
#define LENIENT_TIMEOUT_MS 2000 /* a loaded TCG guest stalls for up to seconds */

struct ramp_run {
    struct ncp_co_master *m;
    struct ncp_ramp_axis *ax;
    long k, cycles;
};

/* A drive that left Operation enabled holds its position: the master's fault
 * check reports that, so only the TPDOs of enabled drives are judged here. */
static void judge_tpdo(void *ctx, size_t i)
{
    struct ramp_run *r = ctx;
    const struct ncp_co_node *nd = &r->m->node[i];
    if (ncp_cia402_state(nd->statusword) == NCP_402_OPERATION_ENABLED)
        ncp_ramp_axis_tpdo(&r->ax[i], nd->actual, r->k, r->cycles);
}

static int settled(const struct ncp_co_master *m, const struct ncp_ramp_axis *ax, long cycles)
{
    for (size_t i = 0; i < m->n; i++)
        if (ax[i].last_j != cycles)
            return 0;
    return 1;
}

/* Counts what breaks the ramp and names the first cause in d. */
static long ramp_faults(const struct ncp_co_master *m, const struct ncp_ramp_axis *ax,
                        long cycles, long late, int lenient, struct ncp_diag *d)
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
    if (!lenient && late && !faults)
        ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                     "%ld actual positions more than one period behind the target", late);
    return faults + (lenient ? 0 : late);
}

static int ramp(struct ncp_co_master *m, long cycles, int lenient, struct ncp_diag *d)
{
    struct ncp_ramp_axis ax[NCP_CO_MAX_NODES];
    long lagging = 0, late = 0, missing = 0, worst = 0, extra = 0;
    for (size_t i = 0; i < m->n; i++)
        ncp_ramp_axis_init(&ax[i], m->target[i], 100 * (int32_t)(i + 1));
    struct ramp_run r = {m, ax, 0, cycles};
    m->on_tpdo = judge_tpdo;
    m->on_tpdo_ctx = &r;
    int rc = NCP_OK;
    for (long k = 1; k <= cycles && rc == NCP_OK; k++) {
        for (size_t i = 0; i < m->n; i++)
            m->target[i] = ax[i].start + (int32_t)k * ax[i].step;
        r.k = k;
        rc = ncp_co_master_cycle(m, d);
        for (size_t i = 0; i < m->n && rc == NCP_OK; i++) {
            long lag = ncp_ramp_axis_lag(&ax[i], k);
            lagging += lag != 0;
            late += lag > 1; /* a dropped TPDO leaves the actual one period old */
        }
    }
    /* Late answers still on their way: hold the final target until they are in. */
    for (long max = lenient ? 250 : 3; rc == NCP_OK && extra < max && !settled(m, ax, cycles);
         extra++)
        rc = ncp_co_master_cycle(m, d);
    m->on_tpdo = NULL;
    if (rc != NCP_OK)
        return rc;
    for (size_t i = 0; i < m->n; i++) {
        printf("node %u: target %d actual %d (%u TPDOs, heartbeat state %s)\n",
               m->node[i].id, m->target[i], m->node[i].actual, m->node[i].tpdos,
               ncp_nmt_state_name(m->node[i].hb_state));
        missing += cycles - ax[i].seen;
        worst = ax[i].max_lag > worst ? ax[i].max_lag : worst;
    }
    long faults = ramp_faults(m, ax, cycles, late, lenient, d);
    printf("ramp: %ld cycles x %zu axes, %ld outside tolerance, %ld one period behind, "
           "%ld TPDOs missing\n", cycles, m->n, faults, lagging, missing);
    printf("ramp check %s: worst lag %ld periods, %ld settling cycles\n",
           lenient ? "lenient (software emulation: late TPDOs tolerated, values and order "
                     "checked)"
                   : "strict (each TPDO within one period)",
           worst, extra);
    return faults ? NCP_ERR_IO : NCP_OK;
}

/* ---- main ------------------------------------------------------------- */
int selftest(void);

int main(int argc, char **argv)
{
    setvbuf(stdout, NULL, _IOLBF, 0); /* interleaves sensibly with candump */
    if (argc == 2 && !strcmp(argv[1], "--selftest"))
        return selftest();
    static struct ncp_co_master m;
    /* no guarding: this master stops and starts drives at will */
    struct ncp_co_master_cfg cfg = {.period_us = 4000, .sdo_timeout_ms = -1,
                                    .hb_period_ms = HB_PERIOD_MS, .hb_timeout_ms = -1};
    uint8_t nodes[NCP_CO_MAX_NODES];
    size_t n = 0;
    long cycles = 200;
    int lenient = 0;
    const char *ifname = NULL;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--cycles") && i + 1 < argc)
            cycles = atol(argv[++i]);
        else if (!strcmp(argv[i], "--period-ms") && i + 1 < argc)
            cfg.period_us = 1000L * atoi(argv[++i]);
        else if (!strcmp(argv[i], "--sdo-timeout-ms") && i + 1 < argc)
            cfg.sdo_timeout_ms = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--hb-timeout-ms") && i + 1 < argc)
            cfg.hb_timeout_ms = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--lenient"))
            lenient = 1;
        else if (!ifname)
            ifname = argv[i];
        else if (n < NCP_CO_MAX_NODES && atoi(argv[i]) >= 1 && atoi(argv[i]) <= NCP_CAN_NODE_MAX)
            nodes[n++] = (uint8_t)atoi(argv[i]);
        else
            return fprintf(stderr, "can-master-test: bad argument '%s'\n", argv[i]), 1;
    }
    if (!ifname || n == 0 || cfg.period_us <= 0)
        return fputs("usage: can-master-test IFACE NODE... [--cycles N] [--period-ms P] "
                     "[--sdo-timeout-ms T] [--hb-timeout-ms T] [--lenient] | --selftest\n",
                     stderr), 1;
    if (cfg.sdo_timeout_ms <= 0)
        cfg.sdo_timeout_ms = lenient ? LENIENT_TIMEOUT_MS : 200;
    if (cfg.hb_timeout_ms <= 0)
        cfg.hb_timeout_ms = lenient ? LENIENT_TIMEOUT_MS : HB_TIMEOUT_MS;
    struct ncp_diag d;
    if (ncp_co_master_open(&m, ifname, nodes, n, &cfg, &d) != NCP_OK) {
        fprintf(stderr, "can-master-test: %s\n", d.msg);
        return 1;
    }
    m.log = stdout;
    int rc = 0;
    if (ncp_co_master_startup(&m, &d) != NCP_OK || ramp(&m, cycles, lenient, &d) != NCP_OK) {
        long cycle = m.cycle;
        ncp_co_master_stop(&m);
        /* a drive fault: the master's own description, completed by the stop */
        if (m.fault.kind != NCP_CO_FAULT_NONE)
            ncp_co_fault_describe(&m.fault, m.bus.ifname, d.msg, sizeof d.msg);
        fprintf(stderr, "can-master-test: controlled stop after cycle %ld: %s\n", cycle, d.msg);
        rc = 3;
    }
    ncp_co_master_close(&m);
    return rc;
}
