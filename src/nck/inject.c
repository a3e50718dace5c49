/* The servo's part of the position cycle when timing faults are injected or
 * miss limits are set: the period's faults are drawn, the setpoint policy
 * decides what the servo runs on when its setpoint is late or lost, the
 * simulated plant is told the period's timing, and every miss (injected,
 * late, lost, or the real clock's) counts against [RT]'s limits. Without
 * any of it the backend is stepped as it always was. Real-time path: no
 * allocation, locks or system calls. */
#include "nck_int.h"
#include "loop_state.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define TIMED_KINDS (NCP_INJ_LATENCY | NCP_INJ_IO | NCP_INJ_JITTER | NCP_INJ_LOSE_FB | \
                     NCP_INJ_DELAY_FB)

void nck_inject_setup(struct nck_core *n)
{
    const struct ncp_inject_cfg *c = &n->cfg->inject;
    n->loop->inj_on = c->kinds || c->max_consecutive > 0 || c->max_ratio > 0;
    n->loop->inj_timed = (c->kinds & TIMED_KINDS) != 0;
    ncp_inject_init(&n->loop->inj, c, n->cfg->servo_period);
    ncp_inject_rx_init(&n->loop->rx, c->policy);
    for (int j = 0; j < NCP_AXES; j++)
        ncp_inject_rx_init(&n->loop->rx_axis[j], c->policy);
    ncp_inject_guard_init(&n->loop->guard, c);
    memset(&n->cross.inj_rep, 0, sizeof n->cross.inj_rep);
}

static void trip(struct nck_core *n, int why, uint64_t k)
{
    if (n->loop->timing_stop)
        return;
    n->loop->timing_stop = why;
    n->cross.inj_rep.trip = why;
    n->cross.inj_rep.trip_cycle = k;
    n->cross.inj_rep.trip_line = n->loop->cur.line;
    n->cross.inj_rep.trip_run = n->loop->guard.consecutive;
    n->cross.inj_rep.trip_in_window = n->loop->guard.in_window;
}

int nck_servo_cycle(struct nck_core *n, const double cmd[NCP_AXES], const double next[NCP_AXES],
                    double act[NCP_AXES])
{
    if (!n->loop->inj_on)
        return n->cross.be.ops->cycle(&n->cross.be, cmd, next, act);
    uint64_t k = (uint64_t)llround((double)n->loop->now_ns / (double)n->cross.rt.cfg.period_ns);
    struct ncp_inject_ev *ev = &n->loop->inj_ev;
    ncp_inject_period(&n->loop->inj, k, ev);
    if (n->cfg->inject.per_axis) {
        /* a frame per drive: only the machine's own axes have one */
        ev->miss_axes &= n->cfg->axis_mask;
        ev->lose_axes &= n->cfg->axis_mask;
        if (!ev->miss_axes)
            ev->what &= ~(uint32_t)NCP_INJ_MISS;
        if (!ev->lose_axes)
            ev->what &= ~(uint32_t)NCP_INJ_LOSE_SP;
    }
    uint64_t real = n->cross.rt.stats.misses;
    int real_miss = real != n->loop->real_misses_seen;
    n->loop->real_misses_seen = real;
    for (int b = 0; b < NCP_INJ_KINDS; b++)
        n->cross.inj_rep.count[b] += (ev->what >> b) & 1u;
    int arrived = !(ev->what & (NCP_INJ_MISS | NCP_INJ_LOSE_SP));
    double use[NCP_AXES], use_next[NCP_AXES];
    double frac = ev->sample_s / n->cfg->servo_period;
    if (n->cfg->inject.per_axis) {
        /* each drive keeps its own history of what reached it */
        uint32_t gone = ev->miss_axes | ev->lose_axes;
        for (int j = 0; j < NCP_AXES; j++)
            ncp_inject_rx_take(&n->loop->rx_axis[j], (int64_t)k, !(gone >> j & 1), &cmd[j],
                               &next[j], frac, 1, &use[j], &use_next[j]);
    } else {
        ncp_inject_rx_take(&n->loop->rx, (int64_t)k, arrived, cmd, next, frac, NCP_AXES,
                           use, use_next);
    }
    n->cross.be.timing = n->loop->inj_timed ? ev : NULL;
    int rc = n->cross.be.ops->cycle(&n->cross.be, use, use_next, act);
    int missed = !arrived || (ev->what & NCP_INJ_LATE) || real_miss;
    n->cross.inj_rep.misses += (uint64_t)missed;
    int why = ncp_inject_guard_add(&n->loop->guard, missed);
    if (why != NCP_TRIP_NONE)
        trip(n, why, k);
    return rc;
}

void nck_inject_rest(struct nck_core *n)
{
    if (!n->loop->timing_stop || n->batch || n->loop->cur.v != 0 || n->loop->scaler.r != 0 ||
        atomic_load_explicit(&n->cross.loop_fault, memory_order_relaxed) != NCK_LF_NONE)
        return;
    n->cross.fault_line = n->cross.inj_rep.trip_line;
    atomic_store_explicit(&n->cross.loop_fault, NCK_LF_TIMING, memory_order_release);
    atomic_store_explicit(&n->cross.frozen, 1, memory_order_release);
}

/* After a reset the limits count afresh. */
void nck_inject_clear(struct nck_core *n)
{
    if (!n->loop->timing_stop)
        return;
    n->loop->timing_stop = 0;
    ncp_inject_guard_init(&n->loop->guard, &n->cfg->inject);
}

void nck_inject_describe(const struct nck_core *n, char *buf, size_t len)
{
    char why[200];
    ncp_inject_trip_text(&n->cfg->inject, &n->cross.inj_rep, n->cfg->servo_period, why, sizeof why);
    snprintf(buf, len, "%s (line %u); drives off", why, n->cross.inj_rep.trip_line);
}
