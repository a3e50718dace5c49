/* The servo's part of the position cycle when timing faults are injected or
 * miss limits are set: the period's faults are drawn, the setpoint policy
 * decides what the servo runs on when its setpoint is late or lost, the
 * simulated plant is told the period's timing, and every miss (injected,
 * late, lost, or the real clock's) counts against [RT]'s limits. Without
 * any of it the backend is stepped as it always was. Real-time path: no
 * allocation, locks or system calls. */
#include "nck_int.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define TIMED_KINDS (NCP_INJ_LATENCY | NCP_INJ_IO | NCP_INJ_JITTER | NCP_INJ_LOSE_FB | \
                     NCP_INJ_DELAY_FB)

void nck_inject_setup(struct nck *n)
{
    const struct ncp_inject_cfg *c = &n->cfg->inject;
    n->inj_on = c->kinds || c->max_consecutive > 0 || c->max_ratio > 0;
    n->inj_timed = (c->kinds & TIMED_KINDS) != 0;
    n->sum.inject_col = c->kinds != 0;
    ncp_inject_init(&n->inj, c, n->cfg->servo_period);
    ncp_inject_rx_init(&n->rx, c->policy);
    for (int j = 0; j < NCP_AXES; j++)
        ncp_inject_rx_init(&n->rx_axis[j], c->policy);
    ncp_inject_guard_init(&n->guard, c);
    memset(&n->inj_rep, 0, sizeof n->inj_rep);
}

static void trip(struct nck *n, int why, uint64_t k)
{
    if (n->timing_stop)
        return;
    n->timing_stop = why;
    n->inj_rep.trip = why;
    n->inj_rep.trip_cycle = k;
    n->inj_rep.trip_line = n->cur.line;
    n->inj_rep.trip_run = n->guard.consecutive;
    n->inj_rep.trip_in_window = n->guard.in_window;
}

int nck_servo_cycle(struct nck *n, const double cmd[NCP_AXES], const double next[NCP_AXES],
                    double act[NCP_AXES])
{
    if (!n->inj_on)
        return n->be.ops->cycle(&n->be, cmd, next, act);
    uint64_t k = (uint64_t)llround((double)n->now_ns / (double)n->loop.cfg.period_ns);
    struct ncp_inject_ev *ev = &n->inj_ev;
    ncp_inject_period(&n->inj, k, ev);
    if (n->cfg->inject.per_axis) {
        /* a frame per drive: only the machine's own axes have one */
        ev->miss_axes &= n->cfg->axis_mask;
        ev->lose_axes &= n->cfg->axis_mask;
        if (!ev->miss_axes)
            ev->what &= ~(uint32_t)NCP_INJ_MISS;
        if (!ev->lose_axes)
            ev->what &= ~(uint32_t)NCP_INJ_LOSE_SP;
    }
    uint64_t real = n->loop.stats.misses;
    int real_miss = real != n->real_misses_seen;
    n->real_misses_seen = real;
    for (int b = 0; b < NCP_INJ_KINDS; b++)
        n->inj_rep.count[b] += (ev->what >> b) & 1u;
    int arrived = !(ev->what & (NCP_INJ_MISS | NCP_INJ_LOSE_SP));
    double use[NCP_AXES], use_next[NCP_AXES];
    double frac = ev->sample_s / n->cfg->servo_period;
    if (n->cfg->inject.per_axis) {
        /* each drive keeps its own history of what reached it */
        uint32_t gone = ev->miss_axes | ev->lose_axes;
        for (int j = 0; j < NCP_AXES; j++)
            ncp_inject_rx_take(&n->rx_axis[j], (int64_t)k, !(gone >> j & 1), &cmd[j],
                               &next[j], frac, 1, &use[j], &use_next[j]);
    } else {
        ncp_inject_rx_take(&n->rx, (int64_t)k, arrived, cmd, next, frac, NCP_AXES,
                           use, use_next);
    }
    n->be.timing = n->inj_timed ? ev : NULL;
    int rc = n->be.ops->cycle(&n->be, use, use_next, act);
    int missed = !arrived || (ev->what & NCP_INJ_LATE) || real_miss;
    n->inj_rep.misses += (uint64_t)missed;
    int why = ncp_inject_guard_add(&n->guard, missed);
    if (why != NCP_TRIP_NONE)
        trip(n, why, k);
    return rc;
}

void nck_inject_rest(struct nck *n)
{
    if (!n->timing_stop || n->batch || n->cur.v != 0 || n->scaler.r != 0 ||
        atomic_load_explicit(&n->loop_fault, memory_order_relaxed) != NCK_LF_NONE)
        return;
    n->fault_line = n->inj_rep.trip_line;
    atomic_store_explicit(&n->loop_fault, NCK_LF_TIMING, memory_order_release);
    atomic_store_explicit(&n->frozen, 1, memory_order_release);
}

/* After a reset the limits count afresh. */
void nck_inject_clear(struct nck *n)
{
    if (!n->timing_stop)
        return;
    n->timing_stop = 0;
    ncp_inject_guard_init(&n->guard, &n->cfg->inject);
}

void nck_inject_describe(const struct nck *n, char *buf, size_t len)
{
    char why[200];
    ncp_inject_trip_text(&n->cfg->inject, &n->inj_rep, n->cfg->servo_period, why, sizeof why);
    snprintf(buf, len, "%s (line %u); drives off", why, n->inj_rep.trip_line);
}
