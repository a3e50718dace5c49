/* CiA 402 drives in cyclic synchronous position mode over raw SocketCAN, one
 * drive per axis ([AXIS_n] NODE_ID, COUNTS_PER_MM), mastered by src/can/.
 *
 * start() (before the real-time loop; blocking): SDO configuration of every
 * drive, NMT start, the CiA 402 walk to Operation enabled with fault reset.
 * cycle() (the real-time path): take in what the drives sent (non-blocking
 * recv, at most POLL_MAX frames), check EMCY, heartbeats and device states,
 * then RPDO1 per drive with the next target and a SYNC (non-blocking send).
 * Nothing there allocates, locks, formats or sleeps; the only system calls
 * are those send()/recv() with MSG_DONTWAIT and the clock_gettime of the
 * vDSO. A drive's TPDO answers the previous period's SYNC: the actual
 * position is one servo period old.
 * stop() (after the loop): hold, shutdown, NMT pre-operational.
 * enable() (a serving NCK's E-stop, fault and reset, real-time): Quick Stop
 * on every drive then Disable Voltage at rest, or the walk back to
 * Operation enabled at the actual positions (src/can/seat.c).
 * drive_home() (real-time): an axis with HOME_METHOD = drive:N homes in its
 * drive's own homing mode (src/can/dhome.c); the mode switches are SDO
 * exchanges, which a worker thread serves outside the loop on a socket of
 * its own, polling every WORKER_NAP_MS for what the loop asked. */
#include "ncpar/backend.h"
#include "ncpar/can.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define POLL_MAX 64 /* frames taken in per period: a backlog drains over a few */
#define WORKER_NAP_MS 2

/* The master's nodes are the configured axes in order: node k drives axis
 * ax[k]. (With a joint layer these become the joints.) */
struct sc {
    struct ncp_co_master m;
    double cpm[NCP_AXES];
    int ax[NCP_AXES];
    int n;
    /* from start() to the loop: a thread runs the blocking cycle, holding
     * the drives where they stand */
    pthread_t idle;
    int idle_started;
    atomic_int idle_run;
    atomic_int idle_failed;
    /* for the seat's status: statusword | last EMCY code << 16, per node */
    atomic_uint pub[NCP_CO_MAX_NODES];
    /* the drives' own homing: the SDO worker and its socket (homes: how
     * many drives home themselves; 0: neither exists) */
    int homes;
    struct ncp_can_bus sdo;
    pthread_t worker;
    int worker_started;
    atomic_int worker_run;
};

static void *worker_main(void *arg)
{
    struct sc *s = arg;
    struct timespec nap = {0, WORKER_NAP_MS * 1000000L};
    while (atomic_load(&s->worker_run)) {
        int served = 0;
        for (int k = 0; k < s->n; k++)
            if (s->m.home[k].cfg.on)
                served |= ncp_co_home_serve(&s->m, &s->sdo, (size_t)k);
        if (!served)
            nanosleep(&nap, NULL);
    }
    return NULL;
}

static void worker_stop(struct sc *s)
{
    if (!s->worker_started)
        return;
    atomic_store(&s->worker_run, 0);
    pthread_join(s->worker, NULL);
    s->worker_started = 0;
}

static void *idle_main(void *arg)
{
    struct sc *s = arg;
    struct ncp_diag d;
    while (atomic_load(&s->idle_run))
        if (ncp_co_master_cycle(&s->m, &d) != NCP_OK) {
            atomic_store(&s->idle_failed, 1);
            break;
        }
    return NULL;
}

static void idle_stop(struct sc *s)
{
    if (!s->idle_started)
        return;
    atomic_store(&s->idle_run, 0);
    pthread_join(s->idle, NULL);
    s->idle_started = 0;
}

static void sc_live(struct ncp_backend *b)
{
    idle_stop(b->impl);
}

static int sc_start(struct ncp_backend *b, double pos[NCP_AXES])
{
    struct sc *s = b->impl;
    struct ncp_diag d;
    if (ncp_co_master_startup(&s->m, &d) != NCP_OK) {
        if (s->m.fault.kind == NCP_CO_FAULT_NONE) {
            s->m.fault.kind = NCP_CO_FAULT_START;
            memcpy(s->m.fault.text, d.msg, sizeof s->m.fault.text);
        }
        return -1;
    }
    for (int k = 0; k < s->n; k++) {
        s->m.cw[k] = NCP_402_CW_ENABLE;
        pos[s->ax[k]] = ncp_counts_to_mm(s->m.node[k].actual, s->cpm[k]);
    }
    atomic_store(&s->idle_run, 1);
    atomic_store(&s->idle_failed, 0);
    s->idle_started = pthread_create(&s->idle, NULL, idle_main, s) == 0;
    if (s->homes) {
        atomic_store(&s->worker_run, 1);
        s->worker_started = pthread_create(&s->worker, NULL, worker_main, s) == 0;
    }
    return 0;
}

static int sc_cycle(struct ncp_backend *b, const double cmd[NCP_AXES], const double next[NCP_AXES],
                    double act[NCP_AXES])
{
    (void)cmd;
    struct sc *s = b->impl;
    struct ncp_co_master *m = &s->m;
    int64_t now = ncp_co_now_ms();
    /* a fault while the drives were held before the loop (fault recorded) */
    int bad = atomic_load(&s->idle_failed) || ncp_co_master_poll(m, now, POLL_MAX) ||
              ncp_co_master_check(m, now);
    for (int k = 0; k < s->n; k++) {
        const struct ncp_co_node *nd = &m->node[k];
        act[s->ax[k]] = ncp_counts_to_mm(nd->actual, s->cpm[k]);
        atomic_store_explicit(&s->pub[k], (unsigned)nd->statusword | (unsigned)nd->emcy.code << 16,
                              memory_order_relaxed);
    }
    if (m->mode == NCP_CO_RUN && bad)
        return -1;
    /* E-stopped or being reset: the drives hear their controlwords every
     * period, faults or not, and the NCK's frozen setpoints are not theirs */
    int seat = ncp_co_master_seat_step(m);
    for (int k = 0; seat == 0 && k < s->n; k++) {
        /* a drive homing itself gets the homing's controlword and target */
        int h = s->homes ? ncp_co_home_step(m, (size_t)k) : 0;
        if (h < 0)
            bad = 1;
        if (h != 0)
            continue;
        if (ncp_mm_to_counts(next[s->ax[k]], s->cpm[k], &m->target[k]))
            return -1; /* cannot happen within the checked soft limits */
    }
    int rc = ncp_co_master_send(m);
    return bad || seat < 0 || rc ? -1 : 0;
}

static void sc_enable(struct ncp_backend *b, int on)
{
    struct sc *s = b->impl;
    ncp_co_master_seat(&s->m, on);
}

static int sc_drives(const struct ncp_backend *b, struct ncp_drive_info *out, int max)
{
    struct sc *s = b->impl;
    int n = 0;
    for (; n < s->n && n < max; n++) {
        unsigned v = atomic_load_explicit(&s->pub[n], memory_order_relaxed);
        out[n] = (struct ncp_drive_info){ s->ax[n], s->m.node[n].id, (uint16_t)(v & 0xFFFFu),
                                          (uint16_t)(v >> 16) };
    }
    return n;
}

static int sc_drive_home(struct ncp_backend *b, int axis, int go)
{
    struct sc *s = b->impl;
    for (int k = 0; k < s->n; k++) {
        if (s->ax[k] != axis)
            continue;
        if (go > 0)
            return ncp_co_home_start(&s->m, (size_t)k);
        if (go < 0) {
            ncp_co_home_abort(&s->m, (size_t)k);
            return 0;
        }
        return ncp_co_home_poll(&s->m, (size_t)k);
    }
    return -1;
}

static void sc_stop(struct ncp_backend *b)
{
    struct sc *s = b->impl;
    idle_stop(s);
    worker_stop(s);
    ncp_co_master_stop(&s->m);
}

static void sc_describe(const struct ncp_backend *b, char *buf, size_t len)
{
    const struct sc *s = b->impl;
    /* a homing's fault names the axis too: the operator homed an axis,
     * not a node */
    int at = 0;
    for (int k = 0; k < s->n && s->m.fault.kind == NCP_CO_FAULT_HOMING; k++)
        if (s->m.node[k].id == s->m.fault.node)
            at = snprintf(buf, len, "homing %c: ", NCP_AXIS_LETTERS[s->ax[k]]);
    if (at < 0 || (size_t)at >= len)
        at = 0;
    ncp_co_fault_describe(&s->m.fault, s->m.bus.ifname, buf + at, len - (size_t)at);
}

static void sc_close(struct ncp_backend *b)
{
    struct sc *s = b->impl;
    worker_stop(s);
    ncp_can_close(&s->sdo);
    ncp_co_master_close(&s->m);
    free(s);
    b->impl = NULL;
}

static int sc_home_switch(const struct ncp_backend *b, int axis)
{
    const struct sc *s = b->impl;
    for (int k = 0; k < s->n; k++)
        if (s->ax[k] == axis)
            return !s->m.cfg.map_din || s->m.node[k].dins == 0
                       ? -1
                       : (s->m.node[k].din & NCP_402_DIN_HOME_SWITCH) != 0;
    return -1;
}

static const struct ncp_backend_ops sc_ops = {
    "socketcan", sc_start, sc_cycle, sc_stop, sc_describe, sc_close, sc_enable, sc_live, sc_drives,
    sc_home_switch, NULL, sc_drive_home, NULL,
};

/* Counts per second from mm per second, within what 0x6099/0x609A hold. */
static uint32_t per_s(double mm, double cpm)
{
    double c = fabs(mm) * cpm;
    return c >= 1 && c < 4e9 ? (uint32_t)c : 0;
}

/* The homing mode's parameters of every drive that homes itself, and the
 * worker's own socket, which sees only the SDO answers. */
static int open_homing(struct sc *s, const struct ncp_machine_cfg *cfg, struct ncp_diag *d)
{
    uint32_t ids[NCP_CO_MAX_NODES];
    for (int k = 0; k < s->n; k++) {
        const struct ncp_axis_cfg *a = &cfg->axis[s->ax[k]];
        if (!a->home_drive)
            continue;
        double travel = a->max_limit - a->min_limit, cpm = s->cpm[k];
        /* long enough to cross 1.5 travels searching and one latching,
         * a minute for a speed left to the drive */
        double t = 10 + (a->home_search_vel != 0 ? 1.5 * travel / fabs(a->home_search_vel) : 60) +
                   (a->home_latch_vel != 0 ? travel / fabs(a->home_latch_vel) : 60);
        int32_t off = 0;
        (void)ncp_mm_to_counts(a->home_offset, cpm, &off);
        s->m.home[k].cfg = (struct ncp_co_home_cfg){
            .on = 1, .method = a->home_method,
            .search = per_s(a->home_search_vel, cpm), .latch = per_s(a->home_latch_vel, cpm),
            .acc = per_s(a->max_acc, cpm), .offset = off,
            .timeout_periods = (long)(t / cfg->servo_period),
        };
        ids[s->homes++] = NCP_COB_SDO_TX + s->m.node[k].id;
    }
    if (!s->homes)
        return NCP_OK;
    if (ncp_can_open(&s->sdo, cfg->can.interface, d) != NCP_OK)
        return d->code;
    return ncp_can_filter(&s->sdo, ids, (size_t)s->homes, d);
}

int ncp_backend_open_socketcan(struct ncp_backend *b, const struct ncp_machine_cfg *cfg,
                               FILE *log, struct ncp_diag *d)
{
    if (ncp_socketcan_check_cfg(cfg, d) != NCP_OK)
        return d->code;
    struct sc *s = calloc(1, sizeof *s);
    if (!s)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "out of memory for the CAN master");
    uint8_t nodes[NCP_AXES];
    for (int j = 0; j < NCP_AXES; j++) {
        if (!(cfg->axis_mask & NCP_AXIS_BIT(j)))
            continue;
        nodes[s->n] = (uint8_t)cfg->axis[j].node_id;
        s->cpm[s->n] = cfg->axis[j].counts_per_mm;
        s->ax[s->n++] = j;
    }
    struct ncp_co_master_cfg mc = {
        .period_us = (long)(cfg->servo_period * 1e6 + 0.5),
        .sdo_timeout_ms = cfg->can.sdo_timeout_ms,
        .hb_period_ms = cfg->can.heartbeat_period_ms,
        .hb_timeout_ms = cfg->can.heartbeat_timeout_ms,
        .master_node = (uint8_t)cfg->can.master_node,
        .hb_consumer_ms = cfg->can.hb_consumer_ms,
        .rpdo_timeout_ms = cfg->can.rpdo_timeout_ms,
        .abort_option = cfg->can.abort_option,
        .fault_reaction = cfg->can.fault_reaction,
    };
    /* the NCK's homing search reads the drive's home switch (0x60FD in
     * TPDO2); a drive that homes itself reads its own */
    for (int k = 0; k < s->n; k++)
        mc.map_din |= cfg->axis[s->ax[k]].home_search_vel != 0 && !cfg->axis[s->ax[k]].home_drive;
    s->sdo.fd = -1;
    if (ncp_co_master_open(&s->m, cfg->can.interface, nodes, s->n, &mc, d) != NCP_OK) {
        free(s);
        return d->code;
    }
    s->m.log = log;
    if (open_homing(s, cfg, d) != NCP_OK) {
        ncp_can_close(&s->sdo);
        ncp_co_master_close(&s->m);
        free(s);
        return d->code;
    }
    for (int i = 0; i < s->n; i++) {
        double dec = cfg->axis[s->ax[i]].max_acc * s->cpm[i];
        s->m.quick_stop_dec[i] = dec >= 1 && dec < 4e9 ? (uint32_t)dec : 0;
    }
    memset(b, 0, sizeof *b);
    b->ops = &sc_ops;
    b->impl = s;
    b->real_clock_only = 1;
    return NCP_OK;
}
