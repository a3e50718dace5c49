/* The LLC's side of the common time base ([LCM] CLOCK).
 *
 * A thread of its own (SCHED_OTHER, its own socket) probes the HLC's clock
 * and keeps the estimate (src/dist/clock.c) in atomics; the position loop
 * only reads them. The probes' four times must be taken when the datagrams
 * leave and arrive: the loop reads its socket once a period, which would
 * add up to a period of one-sided delay to every answer, and a thread that
 * blocks in poll() has no place in the loop (llc.c).
 *
 * The loop maps its own clock onto the HLC's: under CLOCK = probe by the
 * estimate (stepped before the grid is known, then slewed a little each
 * period, so the grid never jumps in motion); under monotonic (one host) and
 * ptp (CLOCK_REALTIME kept by phc2sys on every host) the clocks are taken to
 * be the same and the estimate is only reported, and checked: clocks further
 * apart than CLOCK_TOLERANCE_US stop the axis. */
#include "axis.h"

#include <poll.h>
#include <stdlib.h>
#include <string.h>

#define PROBE_FAST_NS 5000000LL    /* until the estimate stands */
/* The estimate stands with a full window whose best round trip is this
 * short, or after this many answers whatever it is: a host busy starting
 * its loops delays whole windows of answers by milliseconds. */
#define GOOD_RTT_NS 500000LL
#define SETTLE_ANSWERS 60
#define PROBE_SLOW_NS 50000000LL   /* then: drift is slow, probes cost bandwidth */
/* Under CLOCK = probe the grid follows the estimate within this much and
 * slews at most this much a period: 1 us per 1 ms period is 1000 ppm, far
 * more than two crystals drift apart, and a few us of estimate scatter do
 * not move the grid at all. */
#define DEADBAND_NS 20000LL
#define SLEW_NS 1000LL

int64_t llc_clock_local(const struct llc_clock *c, int64_t mono_ns)
{
    return mono_ns + c->base_ns + c->skew_ns +
           (int64_t)(c->drift_ppm * 1e-6 * (double)(mono_ns - c->mono0));
}

int64_t llc_hlc_time(const struct llc *l, int64_t mono_ns)
{
    return llc_clock_local(&l->clk, mono_ns) + l->clk.applied;
}

static void probe(struct llc *l)
{
    struct llc_clock *c = &l->clk;
    ncp_clock_probe_t q = { c->seq, (int16_t)(l->axis + 1), 0, c->seq, 0, 0, 0 };
    c->seq++;
    uint8_t buf[64];
    q.t1_ns = llc_clock_local(c, llc_now());
    int n = ncp_clock_probe_t_encode(buf, 0, sizeof buf, &q);
    if (n > 0 && ncp_msg_publish(c->io.msg, c->channel, buf, (size_t)n) == 0)
        atomic_fetch_add(&c->sent, 1);
}

static void answered(struct llc *l, const uint8_t *p, size_t len, int64_t t4)
{
    struct llc_clock *c = &l->clk;
    ncp_clock_probe_t a;
    memset(&a, 0, sizeof a);
    /* any answer of ours will do: it carries its own t1 (a late one has a
     * long round trip and is outweighed) */
    if (ncp_clock_probe_t_decode(p, 0, (int)len, &a) != (int)len || a.sender != NCP_DIST_HLC_ID ||
        a.peer != l->axis + 1 || ncp_dist_clock_add(&c->win, a.t1_ns, a.t2_ns, a.t3_ns, t4) != 0)
        return;
    struct ncp_dist_clock_est e;
    if (ncp_dist_clock_estimate(&c->win, &e) != 0)
        return;
    unsigned long long n = atomic_fetch_add(&c->answers, 1) + 1;
    atomic_store(&c->est_rtt, e.rtt_ns);
    atomic_store(&c->est_jitter, e.jitter_ns);
    atomic_store(&c->est_offset, e.offset_ns);
    atomic_store(&c->probes, e.probes);
    if (e.probes == NCP_DIST_CLOCK_WINDOW && (e.rtt_ns <= GOOD_RTT_NS || n >= SETTLE_ANSWERS))
        atomic_store(&c->ready, 1);
}

static void *clock_main(void *arg)
{
    struct llc *l = arg;
    struct llc_clock *c = &l->clk;
    struct pollfd pfd = { .fd = ncp_msg_fd(c->io.msg), .events = POLLIN };
    while (atomic_load(&c->io.run)) {
        int64_t due = llc_now() + (atomic_load(&c->ready) ? PROBE_SLOW_NS : PROBE_FAST_NS);
        probe(l);
        for (int64_t left; (left = due - llc_now()) > 0 && atomic_load(&c->io.run);) {
            if (poll(&pfd, 1, (int)(left / 1000000 + 1)) <= 0)
                continue;
            int sub;
            const uint8_t *p;
            size_t len;
            /* t4 as each is read (see lcm_clock.c) */
            while (ncp_msg_take(c->io.msg, llc_now(), &sub, &p, &len) == 1)
                answered(l, p, len, llc_clock_local(c, llc_now()));
        }
    }
    return NULL;
}

int llc_clock_start(struct llc *l, const char *url, struct ncp_diag *d)
{
    struct llc_clock *c = &l->clk;
    const struct ncp_machine_cfg *cfg = l->cfg;
    c->mode = cfg->lcm.clock;
    c->tolerance_ns = cfg->lcm.clock_tolerance_us * 1000LL;
    c->mono0 = llc_now();
    if (c->mode == NCP_LCM_CLOCK_PTP)
        c->base_ns = ncp_dist_realtime_offset();
    ncp_dist_clock_init(&c->win);
    ncp_dist_ax_channel(c->channel, sizeof c->channel, l->axis, NCP_DIST_AX_CLOCK);
    int rc = ncp_dist_probe_io_open(&c->io, &cfg->lcm, url,
                                    (uint64_t)cfg->lcm.inject_seed + 1001u + (uint64_t)l->axis, d);
    if (rc != NCP_OK)
        return rc;
    ncp_msg_subscribe(c->io.msg, NCP_DIST_CH_CLOCK);
    return ncp_dist_probe_io_run(&c->io, clock_main, l, d);
}

void llc_clock_stop(struct llc *l)
{
    ncp_dist_probe_io_close(&l->clk.io);
}

int llc_clock_known(const struct llc *l)
{
    return atomic_load_explicit(&l->clk.ready, memory_order_relaxed);
}

int llc_clock_cycle(struct llc *l, int grid_known)
{
    struct llc_clock *c = &l->clk;
    if (!llc_clock_known(l))
        return 0;
    int64_t est = atomic_load_explicit(&c->est_offset, memory_order_relaxed);
    if (c->mode != NCP_LCM_CLOCK_PROBE) {
        /* apart for certain: even where the best probe's round trip was all
         * one way (a loaded host at start-up), not only by the estimate */
        c->applied = 0;
        int64_t rtt = atomic_load_explicit(&c->est_rtt, memory_order_relaxed);
        return llabs(est) - rtt / 2 > c->tolerance_ns ? -1 : 0;
    }
    if (!grid_known)
        c->applied = est;
    else if (llabs(est - c->applied) > DEADBAND_NS || c->slewing) {
        /* slews all the way once it starts, then rests in the dead band */
        int64_t to = ncp_dist_clock_slew(c->applied, est, SLEW_NS);
        c->slewed += llabs(to - c->applied);
        c->applied = to;
        c->slewing = to != est;
    }
    return 0;
}

void llc_clock_status(const struct llc *l, ncp_ax_status_t *s)
{
    const struct llc_clock *c = &l->clk;
    s->clock_mode = (int8_t)c->mode;
    if (!llc_clock_known(l))
        return;
    s->clock_offset_ns = atomic_load_explicit(&c->est_offset, memory_order_relaxed);
    s->clock_rtt_ns = (int32_t)atomic_load_explicit(&c->est_rtt, memory_order_relaxed);
    s->clock_jitter_ns = (int32_t)atomic_load_explicit(&c->est_jitter, memory_order_relaxed);
}

void llc_clock_report(const struct llc *l)
{
    const struct llc_clock *c = &l->clk;
    char ax = NCP_AXIS_LETTERS[l->axis];
    fprintf(stderr, "cnc-axis %c: clock %s: %llu probes, %llu answered", ax,
            ncp_lcm_clock_name(c->mode),
            (unsigned long long)atomic_load(&c->sent), (unsigned long long)atomic_load(&c->answers));
    if (llc_clock_known(l))
        fprintf(stderr, "; the HLC's clock ahead of this one by %+.3f ms (round trip %.1f us, "
                        "jitter %.1f us); the grid ran %+.3f ms off this clock, slewed %.1f us",
                (double)atomic_load(&c->est_offset) * 1e-6, (double)atomic_load(&c->est_rtt) * 1e-3,
                (double)atomic_load(&c->est_jitter) * 1e-3, (double)c->applied * 1e-6,
                (double)c->slewed * 1e-3);
    if (c->skew_ns || c->drift_ppm != 0) {
        int64_t m = llc_now();
        fprintf(stderr, "; this clock simulated %+.1f ppm off CLOCK_MONOTONIC, now %+.3f ms",
                c->drift_ppm, (double)(llc_clock_local(c, m) - m - c->base_ns) * 1e-6);
    }
    fputc('\n', stderr);
}
