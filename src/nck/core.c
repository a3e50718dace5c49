/* Bringing an NCK up and down: the backend, the rings, the planner thread and
 * the position loop; and the steps of dropping what is queued. */
#include "nck_int.h"
#include "job_state.h"
#include "loop_state.h"
#include "planner_state.h"
#include "service_state.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define SEG_RING 1024
#define FB_RING 65536

/* The threads' parts in one block, so a core is two allocations at most
 * and none after start. */
struct nck_parts {
    struct nck_loop loop;
    struct nck_planner plan;
    struct nck_job job;
    struct nck_service svc;
};

int nck_core_alloc(struct nck_core *n)
{
    struct nck_parts *p = calloc(1, sizeof *p);
    if (!p)
        return -1;
    n->loop = &p->loop;
    n->plan = &p->plan;
    n->job = &p->job;
    n->svc = &p->svc;
    return 0;
}

void nck_core_free(struct nck_core *n)
{
    /* the loop's part is the block's first member: its address is the block's */
    free(n->loop);
    n->loop = NULL;
    n->plan = NULL;
    n->job = NULL;
    n->svc = NULL;
}

/* Brings the backend up before anything moves; a failure there (SDO, state
 * machine, no drive) is a fault with no line: nothing has run. */
static int start_backend(struct nck_core *n, struct ncp_diag *d)
{
    if (ncp_backend_open(&n->cross.be, n->cfg, stderr, d) != NCP_OK) {
        d->code = NCP_ERR_IO;
        return -1;
    }
    n->svc->be_open = 1;
    if (n->cross.be.real_clock_only && n->setup.virtual_clock) {
        ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                     "the %s backend drives real hardware: it needs the real clock",
                     n->cross.be.ops->name);
        return -1;
    }
    /* the backend reports its joints; the machine starts from the tool tip
     * they put in the work (no tool length yet). A joint no drive reports
     * (CAN drives for X Y Z only) starts at 0, not at what the stack held:
     * the first move would turn that joint too and lose its corner's blend. */
    double joints[NCP_AXES] = { 0 };
    if (n->cross.be.ops->start(&n->cross.be, joints) != 0) {
        char why[NCP_DIAG_MSG_MAX];
        n->cross.be.ops->describe_fault(&n->cross.be, why, sizeof why);
        ncp_diag_set(d, NCP_ERR_IO, 0, 0, "%s", why);
        n->cross.be.ops->stop(&n->cross.be);
        return -1;
    }
    ncp_kins_forward(&n->cfg->kins, 0.0, joints, n->start);
    n->svc->be_started = 1;
    n->loop->drives_on = n->cross.be.ops->enable == NULL;
    return 0;
}

/* The backend hands the machine over to the position loop. */
static void backend_live(void *ctx)
{
    struct nck_core *n = ctx;
    if (n->svc->be_started && n->cross.be.ops->live)
        n->cross.be.ops->live(&n->cross.be);
}

static int init_motion(struct nck_core *n)
{
    const struct ncp_machine_cfg *c = n->cfg;
    ncp_canon_map_init(&n->job->map, c, n->start, n->plan_override);
    memcpy(n->loop->next.pos, n->start, sizeof n->loop->next.pos);
    memcpy(n->loop->probe.last, n->start, sizeof n->loop->probe.last);
    n->loop->cur = n->loop->next;
    double a_min = INFINITY;
    for (int j = 0; j < NCP_AXES; j++)
        if (c->axis_mask & NCP_AXIS_BIT(j))
            a_min = fmin(a_min, c->axis[j].max_acc);
    /* half the weakest axis: the stream may itself be accelerating meanwhile;
     * an abort brakes with all of it */
    n->loop->decel_normal = 0.5 * a_min;
    n->loop->decel_full = a_min;
    ncp_scaler_init(&n->loop->scaler, n->start, n->loop->decel_normal, c->servo_period);
    n->loop->read_k_next = -2;   /* a and b: the start, before the first sample */
    int ratio = nck_plan_stream_ratio(c);
    if (ratio < 1)
        return -1;
    ncp_scaler_set_ratio(&n->loop->scaler, ratio);
    ncp_scaler_limits(&n->loop->scaler, c);
    if (nck_plan_new(n) || ncp_spsc_init(&n->cross.segs, sizeof(struct nck_seg_msg), SEG_RING) ||
        ncp_spsc_init(&n->cross.sps, sizeof(struct ncp_setpoint), (size_t)c->setpoint_ring) ||
        ncp_spsc_init(&n->cross.fbs, sizeof(struct nck_fb), FB_RING) ||
        ncp_spsc_init(&n->cross.auxq, sizeof(struct nck_aux_pack), NCK_AUX_RING) ||
        ncp_spsc_init(&n->cross.syncq, sizeof(struct nck_sync_run), NCK_SYNC_RING))
        return -1;
    for (int k = 0; k < 4; k++)
        n->loop->mach.en[k] = 1;
    atomic_store(&n->ctl->din, c->io.din);
    n->cross.rt.cfg = (struct ncp_rt_loop_cfg){ (int64_t)llround(c->servo_period * 1e9),
                                            c->position.priority, c->position.cpu,
                                            n->setup.virtual_clock, 0 };
    n->cross.rt.cycle = nck_position_cycle;
    n->cross.rt.ctx = n;
    n->cross.rt.handover = backend_live;
    return 0;
}

int nck_start(struct nck_core *n, const struct ncp_nck_setup *s, int batch, struct ncp_diag *d)
{
    n->setup = *s;
    n->cfg = s->cfg;
    n->batch = batch;
    if (n->plan_override <= 0)
        n->plan_override = 1.0;
    if (!n->ctl) {
        ncp_nck_ctl_init(&n->own_ctl, n->plan_override);
        n->ctl = &n->own_ctl;
    }
    pthread_mutex_init(&n->cross.ev_lock, NULL);
    if (start_backend(n, d))
        return -1;
    if (init_motion(n)) {
        ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot set up the runtime (out of memory?)");
        return -1;
    }
    nck_inject_setup(n);
    n->svc->sum.inject_col = n->cfg->inject.kinds != 0;
    n->trace_rings = s->trace_rings || n->cfg->sched.trace_rings;
    n->svc->sum.rings = n->trace_rings;
    n->svc->sum.seg_cap = (uint32_t)ncp_spsc_capacity(&n->cross.segs);
    n->svc->sum.sp_cap = (uint32_t)ncp_spsc_capacity(&n->cross.sps);
    nck_sched_setup(n);
    if (ncp_rt_start(&n->svc->planner_thread, &n->cross.planner_place, nck_planner_main, n, NULL)) {
        ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot start the planner thread");
        return -1;
    }
    n->svc->planner_started = 1;
    if (nck_sched_start(n)) {
        ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot start the scheduler thread");
        return -1;
    }
    return 0;
}

int nck_start_loop(struct nck_core *n, struct ncp_diag *d)
{
    int rc = ncp_rt_loop_start(&n->cross.rt);
    if (rc)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot start the position loop: %s",
                            strerror(rc)), -1;
    n->svc->loop_started = 1;
    return 0;
}

/* Everything down, in the order the data flows: the job, the planner, the
 * loop, then the backend's controlled stop. */
void nck_finish(struct nck_core *n)
{
    ncp_sched_stop(&n->cross.sched);
    atomic_store(&n->job->abort, 1);
    nck_job_join(n);
    atomic_store(&n->cross.quit, 1);
    if (n->svc->planner_started)
        pthread_join(n->svc->planner_thread, NULL);
    n->svc->planner_started = 0;
    if (n->svc->loop_started) {
        atomic_store(&n->cross.rt.stop, 1);
        ncp_rt_loop_join(&n->cross.rt);
        n->svc->loop_started = 0;
    }
    /* after the loop, fault or not: the drives stop under control */
    if (n->svc->be_started)
        n->cross.be.ops->stop(&n->cross.be);
    n->svc->be_started = 0;
}

void nck_release(struct nck_core *n)
{
    if (n->svc->be_open)
        n->cross.be.ops->close(&n->cross.be);
    n->svc->be_open = 0;
    ncp_spsc_destroy(&n->cross.segs);
    ncp_spsc_destroy(&n->cross.sps);
    ncp_spsc_destroy(&n->cross.fbs);
    ncp_spsc_destroy(&n->cross.auxq);
    ncp_spsc_destroy(&n->cross.syncq);
    nck_plan_free(n);
    pthread_mutex_destroy(&n->cross.ev_lock);
}

void nck_park_planner(struct nck_core *n)
{
    atomic_fetch_add_explicit(&n->cross.park_req, 1, memory_order_release);
}

int nck_planner_parked(const struct nck_core *n)
{
    return atomic_load_explicit(&n->cross.park_ack, memory_order_acquire) ==
           atomic_load_explicit(&n->cross.park_req, memory_order_relaxed);
}

void nck_discard(struct nck_core *n, int to_actual)
{
    atomic_store_explicit(&n->cross.discard_to_actual, to_actual, memory_order_relaxed);
    atomic_fetch_add_explicit(&n->cross.discard_req, 1, memory_order_release);
}

int nck_discarded(const struct nck_core *n)
{
    return atomic_load_explicit(&n->cross.discard_ack, memory_order_acquire) ==
           atomic_load_explicit(&n->cross.discard_req, memory_order_relaxed);
}

/* The loop rested at n->cross.rest: plan from there, and so does the map. */
void nck_unpark_planner(struct nck_core *n)
{
    atomic_store(&n->cross.marks_sent, atomic_load(&n->cross.ends_taken));
    memcpy(n->job->map.pos, n->cross.rest, sizeof n->job->map.pos);
    atomic_fetch_add_explicit(&n->cross.unpark_req, 1, memory_order_release);
}

int nck_planner_unparked(const struct nck_core *n)
{
    return atomic_load_explicit(&n->cross.unpark_ack, memory_order_acquire) ==
           atomic_load_explicit(&n->cross.unpark_req, memory_order_relaxed);
}

int nck_motion_done(const struct nck_core *n)
{
    return atomic_load_explicit(&n->cross.ends_taken, memory_order_acquire) >=
           atomic_load_explicit(&n->cross.marks_sent, memory_order_relaxed);
}

/* ---- live controls ---------------------------------------------------------------- */

void ncp_nck_ctl_init(struct ncp_nck_ctl *c, double feed_override)
{
    atomic_store(&c->override_permille, (int)lround(fmin(2.0, fmax(0.0, feed_override)) * 1000));
    atomic_store(&c->hold, 0);
    atomic_store(&c->now_ns, 0);
    atomic_store(&c->pause_at_ns, INT64_MAX);
    atomic_store(&c->rapid_permille, 1000);
    atomic_store(&c->stop, 0);
    atomic_store(&c->resume_go, 0);
    atomic_store(&c->tool_go, 0);
    atomic_store(&c->optional_stop, 1);
    atomic_store(&c->spindle_permille, 1000);
    atomic_store(&c->din, 0);
}

void ncp_nck_set_feed_override(struct ncp_nck_ctl *c, double ov)
{
    atomic_store(&c->override_permille, (int)lround(fmin(2.0, fmax(0.0, ov)) * 1000));
}

void ncp_nck_feed_hold(struct ncp_nck_ctl *c, int hold)
{
    atomic_store(&c->hold, hold != 0);
}
