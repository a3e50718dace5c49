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

static void nap_ns(long ns)
{
    struct timespec ts = { 0, ns };
    nanosleep(&ts, NULL);
}

/* At rest with nothing queued: the next segment starts from rest. */
static int at_rest(struct nck_core *n)
{
    return nck_plan_idle(n) && nck_plan_queued(n) == 0;
}

/* END and SYNC both make the planner run what it has to a stop; after the
 * END setpoint the next job starts afresh (no blend with what went before). */
static void pull_segments(struct nck_core *n, int *finishing, uint32_t *stop_aux, int *aux_stop,
                          struct nck_seg_msg *jump)
{
    struct nck_seg_msg m;
    while (!*finishing && !nck_plan_full(n) && ncp_spsc_pop(&n->cross.segs, &m) == 0) {
        if (m.kind == NCK_MSG_SEG) {
            if (at_rest(n)) {
                n->plan->start_arrived_ns = ncp_mono_ns();
                n->plan->start_stepped = n->plan->start_moved = 0;
            }
            nck_plan_push(n, &m.seg);
        } else {
            *finishing = 1;
            *stop_aux = m.aux;
            *aux_stop = m.kind == NCK_MSG_AUX;
            jump->jump = m.jump;
            memcpy(jump->seg.end, m.seg.end, sizeof jump->seg.end);
            nck_plan_finish(n);
        }
    }
}

/* A start from rest (p->start_arrived_ns set): its first setpoint, its
 * first that moves (t: now). */
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
static int may_step(struct nck_core *n, int finishing, int64_t *wait_since)
{
    if (finishing || nck_plan_full(n)) {
        *wait_since = 0;
        return 1;
    }
    if (at_rest(n))
        return 0;
    if (n->setup.virtual_clock)
        return 0;
    if (!nck_plan_idle(n))
        return 1;
    int64_t now = ncp_mono_ns();
    if (!*wait_since)
        *wait_since = now;
    return now - *wait_since > START_WAIT_NS;
}

/* Parked (a drop in progress): the segment ring is emptied (its producer has
 * been stopped) and nothing is planned until the loop has rested and the
 * service thread says where. */
static void parked(struct nck_core *n, int *finishing, int *aux_stop)
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
    *finishing = 0;
    *aux_stop = 0;
    atomic_store_explicit(&n->cross.unpark_ack, atomic_load(&n->cross.unpark_req), memory_order_release);
}

void *nck_planner_main(void *arg)
{
    struct nck_core *n = arg;
    int finishing = 0, aux_stop = 0;
    uint32_t stop_aux = 0;
    int64_t wait_since = 0;
    struct nck_seg_msg jump;   /* the stop's jump, if it has one */
    memset(&jump, 0, sizeof jump);
    long nap = (long)(n->cfg->servo_period * nck_plan_stream_ratio(n->cfg) * 1e9 / 4) + 1000;
    int64_t last_step = 0;
    nck_sched_enter(n, 1);
    while (!atomic_load(&n->cross.quit)) {
        if (atomic_load_explicit(&n->cross.park_req, memory_order_acquire) !=
            atomic_load_explicit(&n->cross.park_ack, memory_order_relaxed)) {
            parked(n, &finishing, &aux_stop);
            jump.jump = 0;
            continue;
        }
        pull_segments(n, &finishing, &stop_aux, &aux_stop, &jump);
        if (ncp_spsc_count(&n->cross.sps) >= ncp_spsc_capacity(&n->cross.sps) ||
            !may_step(n, finishing, &wait_since)) {
            int idle = at_rest(n);
            if (n->setup.virtual_clock && !idle)
                sched_yield();
            else
                nap_ns(nap);
            continue;
        }
        struct ncp_setpoint sp;
        int64_t t0 = n->trace_rings ? ncp_mono_ns() : 0;
        int more = nck_plan_step(n, &sp);
        if (!more) {
            /* the stop's sample: the machine functions due there; an AUX
             * stop is no end of the job's motion */
            if (stop_aux > sp.aux)
                sp.aux = stop_aux;
            if (aux_stop)
                sp.flags &= ~(uint32_t)NCP_SP_END;
        }
        ncp_spsc_push(&n->cross.sps, &sp);
        if (n->plan->start_arrived_ns)
            note_start(n->plan, &sp, ncp_mono_ns());
        if (n->trace_rings) {
            /* response: one step's work; cycle: from one setpoint to the next */
            int64_t t1 = ncp_mono_ns();
            atomic_store_explicit(&n->cross.plan_resp_ns, t1 - t0, memory_order_relaxed);
            if (last_step)
                atomic_store_explicit(&n->cross.plan_cycle_ns, t1 - last_step, memory_order_relaxed);
            last_step = t1;
        }
        if (!more) {
            if (!aux_stop)
                atomic_fetch_add_explicit(&n->cross.ends_pushed, 1, memory_order_release);
            n->plan->start_arrived_ns = 0;   /* it ended without moving */
            nck_plan_restart(n);
            /* a synchronised run the position loop moves starts here: the
             * next segment is planned from its end */
            if (jump.jump)
                nck_plan_reset(n, jump.seg.end);
            jump.jump = 0;
            finishing = 0;
            aux_stop = 0;
        }
    }
    nck_sched_leave(n, 1);
    return NULL;
}
