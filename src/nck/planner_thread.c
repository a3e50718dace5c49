/* The planner/interpolator thread: segments in, one setpoint per planning
 * period out. It lives as long as the NCK; between jobs it waits. */
#include "nck_int.h"
#include "planner_state.h"
#include "ncpar/clock.h"

#include <math.h>
#include <sched.h>
#include <string.h>
#include <time.h>

#define START_WAIT_NS 20000000LL   /* real clock: wait this long for a full window at rest */

/* The thread's loop state between iterations. */
struct plan_run {
    int finishing, aux_stop;
    uint32_t stop_aux;
    int64_t wait_since;        /* real clock: when a start from rest began waiting */
    int64_t last_step;
    int64_t period_ns;         /* one setpoint of the stream */
    struct nck_seg_msg jump;   /* the stop's jump, if it has one */
};

/* Real clock, in motion: the setpoint ring's least lead, the steps restore
 * it after a pull. The position loop slows the stream down (an underrun)
 * below half its stop's setpoints plus 8 (loop.c's rate_target, at half the
 * weakest axis's acceleration); this keeps twice that at the machine's top
 * path speed, as the loop refills to before it speeds up again. */
static size_t lead_min(const struct ncp_machine_cfg *c, double period, size_t cap)
{
    double a_min = INFINITY, j_min = INFINITY, v2 = 0;
    for (int j = 0; j < NCP_AXES; j++)
        if (c->axis_mask & NCP_AXIS_BIT(j)) {
            a_min = fmin(a_min, c->axis[j].max_acc);
            v2 += c->axis[j].max_vel * c->axis[j].max_vel;
            if (c->profile == NCP_PROFILE_SCURVE && c->axis[j].max_jerk > 0)
                j_min = fmin(j_min, c->axis[j].max_jerk);
        }
    double v = c->max_linear_vel > 0 ? fmin(c->max_linear_vel, sqrt(v2)) : sqrt(v2);
    double a = 0.5 * a_min, t = a > 0 && isfinite(a) ? v / a : 0;
    if (isfinite(j_min))
        t += a / (0.25 * j_min);
    double need = fmin(0.5 * t / period + 8, 0.75 * (double)cap);
    double lead = fmin(2 * need, (double)cap - 1);
    return lead > 1 ? (size_t)lead : 1;
}

static void nap_ns(long ns)
{
    struct timespec ts = { 0, ns };
    nanosleep(&ts, NULL);
}

/* Real clock: until when pulling segments may hold up the next step. A
 * start from rest waits START_WAIT_NS from its first segment for the window
 * (INT64_MIN: that segment sets it); in motion, half the time the setpoint
 * ring still holds, so the position loop keeps a lead however long the
 * corners take to plan. 0: no bound (the virtual clock fills the window
 * before every step, so runs stay deterministic). */
static int64_t pull_deadline(struct nck_core *n, const struct plan_run *r)
{
    if (n->setup.virtual_clock)
        return 0;
    if (nck_plan_idle(n)) {
        if (r->wait_since)
            return r->wait_since + START_WAIT_NS;
        return nck_plan_queued(n) ? ncp_mono_ns() + START_WAIT_NS : INT64_MIN;
    }
    return ncp_mono_ns() + (int64_t)ncp_spsc_count(&n->cross.sps) * r->period_ns / 2;
}

/* END and SYNC both make the planner run what it has to a stop; after the
 * END setpoint the next job starts afresh (no blend with what went before).
 * A deadline (pull_deadline) is checked between pushes: a corner's blend
 * search can take most of a millisecond, and a window's worth of them
 * would hold the step up for a tenth of a second. */
static void pull_segments(struct nck_core *n, struct plan_run *r, int64_t deadline)
{
    struct nck_seg_msg m;
    while (!r->finishing && !nck_plan_full(n) && ncp_spsc_pop(&n->cross.segs, &m) == 0) {
        if (m.kind == NCK_MSG_SEG) {
            if (nck_plan_idle(n) && nck_plan_queued(n) == 0) {
                n->plan->start_arrived_ns = ncp_mono_ns();
                n->plan->start_stepped = 0;
                if (!n->setup.virtual_clock)
                    r->wait_since = n->plan->start_arrived_ns;
                if (deadline == INT64_MIN)
                    deadline = n->plan->start_arrived_ns + START_WAIT_NS;
            }
            nck_plan_push(n, &m.seg);
            if (deadline && ncp_mono_ns() >= deadline)
                break;
        } else {
            r->finishing = 1;
            r->stop_aux = m.aux;
            r->aux_stop = m.kind == NCK_MSG_AUX;
            r->jump.jump = m.jump;
            memcpy(r->jump.seg.end, m.seg.end, sizeof r->jump.seg.end);
            nck_plan_finish(n);
        }
    }
}

/* A start from rest: its first setpoint, its first that moves (t: now). */
static void note_start(struct nck_planner *p, const struct ncp_setpoint *sp, int64_t t)
{
    if (!p->start_stepped) {
        p->start_stepped = 1;
        p->starts++;
        if (t - p->start_arrived_ns > p->start_sp_max_ns)
            p->start_sp_max_ns = t - p->start_arrived_ns;
    }
    if (sp->v > 0) {
        if (t - p->start_arrived_ns > p->start_move_max_ns)
            p->start_move_max_ns = t - p->start_arrived_ns;
        p->start_arrived_ns = 0;
    }
}

void nck_planner_starts(const struct nck_core *n, uint64_t *starts, int64_t *sp_max_ns,
                        int64_t *move_max_ns)
{
    *starts = n->plan->starts;
    *sp_max_ns = n->plan->start_sp_max_ns;
    *move_max_ns = n->plan->start_move_max_ns;
}

/* Virtual clock: the window is always full (or a stop is due) before a step,
 * so runs are deterministic. Real clock: only a start from rest waits
 * (briefly) for the window; in motion the planner never holds the loop up.
 * Nothing queued and nothing due: no step (idle setpoints would only delay
 * the next job's motion by the ring's length). */
static int may_step(struct nck_core *n, struct plan_run *r)
{
    if (r->finishing || nck_plan_full(n)) {
        r->wait_since = 0;
        return 1;
    }
    if (nck_plan_idle(n) && nck_plan_queued(n) == 0)
        return 0;
    if (n->setup.virtual_clock)
        return 0;
    if (!nck_plan_idle(n))
        return 1;
    int64_t now = ncp_mono_ns();
    if (!r->wait_since)
        r->wait_since = now;
    return now - r->wait_since >= START_WAIT_NS;
}

/* One setpoint into the ring; 0 once it was the stop's. */
static int step(struct nck_core *n, struct plan_run *r)
{
    struct ncp_setpoint sp;
    int64_t t0 = n->trace_rings ? ncp_mono_ns() : 0;
    int more = nck_plan_step(n, &sp);
    if (!more) {
        /* the stop's sample: the machine functions due there; an AUX
         * stop is no end of the job's motion */
        if (r->stop_aux > sp.aux)
            sp.aux = r->stop_aux;
        if (r->aux_stop)
            sp.flags &= ~(uint32_t)NCP_SP_END;
    }
    ncp_spsc_push(&n->cross.sps, &sp);
    if (n->plan->start_arrived_ns)
        note_start(n->plan, &sp, ncp_mono_ns());
    if (n->trace_rings) {
        /* response: one step's work; cycle: from one setpoint to the next */
        int64_t t1 = ncp_mono_ns();
        atomic_store_explicit(&n->cross.plan_resp_ns, t1 - t0, memory_order_relaxed);
        if (r->last_step)
            atomic_store_explicit(&n->cross.plan_cycle_ns, t1 - r->last_step, memory_order_relaxed);
        r->last_step = t1;
    }
    if (!more) {
        if (!r->aux_stop)
            atomic_fetch_add_explicit(&n->cross.ends_pushed, 1, memory_order_release);
        n->plan->start_arrived_ns = 0;   /* it ended without moving */
        nck_plan_restart(n);
        /* a synchronised run the position loop moves starts here: the
         * next segment is planned from its end */
        if (r->jump.jump)
            nck_plan_reset(n, r->jump.seg.end);
        r->jump.jump = 0;
        r->finishing = 0;
        r->aux_stop = 0;
    }
    return more;
}

/* Parked (a drop in progress): the segment ring is emptied (its producer has
 * been stopped) and nothing is planned until the loop has rested and the
 * service thread says where. */
static void parked(struct nck_core *n, struct plan_run *r)
{
    struct nck_seg_msg m;
    while (ncp_spsc_pop(&n->cross.segs, &m) == 0)
        ;
    atomic_store_explicit(&n->cross.park_ack, atomic_load(&n->cross.park_req), memory_order_release);
    while (!atomic_load(&n->cross.quit) &&
           atomic_load_explicit(&n->cross.unpark_req, memory_order_acquire) ==
               atomic_load_explicit(&n->cross.unpark_ack, memory_order_relaxed))
        nap_ns(200000);
    n->plan->start_arrived_ns = 0;
    nck_plan_dropped(n);
    nck_plan_reset(n, n->cross.rest);
    r->finishing = 0;
    r->aux_stop = 0;
    r->wait_since = 0;
    r->jump.jump = 0;
    atomic_store_explicit(&n->cross.unpark_ack, atomic_load(&n->cross.unpark_req), memory_order_release);
}

void *nck_planner_main(void *arg)
{
    struct nck_core *n = arg;
    struct plan_run r;
    memset(&r, 0, sizeof r);
    r.period_ns = (int64_t)(n->cfg->servo_period * nck_plan_stream_ratio(n->cfg) * 1e9 + 0.5);
    long nap = (long)(r.period_ns / 4) + 1000;
    size_t cap = ncp_spsc_capacity(&n->cross.sps);
    size_t lead = lead_min(n->cfg, n->cfg->servo_period * nck_plan_stream_ratio(n->cfg), cap);
    nck_sched_enter(n, 1);
    while (!atomic_load(&n->cross.quit)) {
        if (atomic_load_explicit(&n->cross.park_req, memory_order_acquire) !=
            atomic_load_explicit(&n->cross.park_ack, memory_order_relaxed)) {
            parked(n, &r);
            continue;
        }
        size_t had = ncp_spsc_count(&n->cross.sps);
        pull_segments(n, &r, pull_deadline(n, &r));
        if (ncp_spsc_count(&n->cross.sps) >= cap || !may_step(n, &r)) {
            int idle = nck_plan_idle(n) && nck_plan_queued(n) == 0;
            if (n->setup.virtual_clock && !idle)
                sched_yield();
            else
                nap_ns(nap);
            continue;
        }
        if (!step(n, &r) || n->setup.virtual_clock)
            continue;
        /* Real clock: what the pull cost the ring, and a lead to grow from,
         * stepped at once; the window refills over the next pulls, each
         * bounded by the lead this leaves. */
        size_t target = had * 2 > lead ? had * 2 : lead;
        if (target > cap)
            target = cap;
        while (ncp_spsc_count(&n->cross.sps) < target && may_step(n, &r) && step(n, &r))
            ;
    }
    nck_sched_leave(n, 1);
    return NULL;
}
