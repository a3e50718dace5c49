/* Bringing an NCK up and down: the backend, the rings, the planner thread and
 * the position loop; and the steps of dropping what is queued. */
#include "nck_int.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define SEG_RING 1024
#define FB_RING 65536

/* Brings the backend up before anything moves; a failure there (SDO, state
 * machine, no drive) is a fault with no line: nothing has run. */
static int start_backend(struct nck *n, struct ncp_diag *d)
{
    if (ncp_backend_open(&n->be, n->cfg, stderr, d) != NCP_OK) {
        d->code = NCP_ERR_IO;
        return -1;
    }
    n->be_open = 1;
    if (n->be.real_clock_only && n->setup.virtual_clock) {
        ncp_diag_set(d, NCP_ERR_IO, 0, 0,
                     "the %s backend drives real hardware: it needs the real clock",
                     n->be.ops->name);
        return -1;
    }
    /* the backend reports its joints; the machine starts from the tool tip
     * they put in the work (no tool length yet). A joint no drive reports
     * (CAN drives for X Y Z only) starts at 0, not at what the stack held:
     * the first move would turn that joint too and lose its corner's blend. */
    double joints[NCP_AXES] = { 0 };
    if (n->be.ops->start(&n->be, joints) != 0) {
        char why[NCP_DIAG_MSG_MAX];
        n->be.ops->describe_fault(&n->be, why, sizeof why);
        ncp_diag_set(d, NCP_ERR_IO, 0, 0, "%s", why);
        n->be.ops->stop(&n->be);
        return -1;
    }
    ncp_kins_forward(&n->cfg->kins, 0.0, joints, n->start);
    n->be_started = 1;
    n->drives_on = n->be.ops->enable == NULL;
    return 0;
}

/* The backend hands the machine over to the position loop. */
static void backend_live(void *ctx)
{
    struct nck *n = ctx;
    if (n->be_started && n->be.ops->live)
        n->be.ops->live(&n->be);
}

static int init_motion(struct nck *n)
{
    const struct ncp_machine_cfg *c = n->cfg;
    ncp_canon_map_init(&n->map, c, n->start, n->plan_override);
    memcpy(n->next.pos, n->start, sizeof n->next.pos);
    memcpy(n->probe.last, n->start, sizeof n->probe.last);
    n->cur = n->next;
    double a_min = INFINITY;
    for (int j = 0; j < NCP_AXES; j++)
        if (c->axis_mask & NCP_AXIS_BIT(j))
            a_min = fmin(a_min, c->axis[j].max_acc);
    /* half the weakest axis: the stream may itself be accelerating meanwhile;
     * an abort brakes with all of it */
    n->decel_normal = 0.5 * a_min;
    n->decel_full = a_min;
    ncp_scaler_init(&n->scaler, n->start, n->decel_normal, c->servo_period);
    int ratio = nck_plan_stream_ratio(c);
    if (ratio < 1)
        return -1;
    ncp_scaler_set_ratio(&n->scaler, ratio);
    ncp_scaler_limits(&n->scaler, c);
    if (nck_plan_new(n) || ncp_spsc_init(&n->segs, sizeof(struct nck_seg_msg), SEG_RING) ||
        ncp_spsc_init(&n->sps, sizeof(struct ncp_setpoint), (size_t)c->setpoint_ring) ||
        ncp_spsc_init(&n->fbs, sizeof(struct nck_fb), FB_RING) ||
        ncp_spsc_init(&n->auxq, sizeof(struct nck_aux_pack), NCK_AUX_RING) ||
        ncp_spsc_init(&n->syncq, sizeof(struct nck_sync_run), NCK_SYNC_RING))
        return -1;
    for (int k = 0; k < 4; k++)
        n->mach.en[k] = 1;
    atomic_store(&n->ctl->din, c->io.din);
    n->loop.cfg = (struct ncp_rt_loop_cfg){ (int64_t)llround(c->servo_period * 1e9),
                                            c->position.priority, c->position.cpu,
                                            n->setup.virtual_clock, 0 };
    n->loop.cycle = nck_position_cycle;
    n->loop.ctx = n;
    n->loop.handover = backend_live;
    return 0;
}

int nck_start(struct nck *n, const struct ncp_nck_setup *s, int batch, struct ncp_diag *d)
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
    pthread_mutex_init(&n->ev_lock, NULL);
    if (start_backend(n, d))
        return -1;
    if (init_motion(n)) {
        ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot set up the runtime (out of memory?)");
        return -1;
    }
    nck_inject_setup(n);
    n->trace_rings = s->trace_rings || n->cfg->sched.trace_rings;
    n->sum.rings = n->trace_rings;
    n->sum.seg_cap = (uint32_t)ncp_spsc_capacity(&n->segs);
    n->sum.sp_cap = (uint32_t)ncp_spsc_capacity(&n->sps);
    nck_sched_setup(n);
    if (ncp_rt_start(&n->planner_thread, &n->planner_place, nck_planner_main, n, NULL)) {
        ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot start the planner thread");
        return -1;
    }
    n->planner_started = 1;
    if (nck_sched_start(n)) {
        ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot start the scheduler thread");
        return -1;
    }
    return 0;
}

int nck_start_loop(struct nck *n, struct ncp_diag *d)
{
    int rc = ncp_rt_loop_start(&n->loop);
    if (rc)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot start the position loop: %s",
                            strerror(rc)), -1;
    n->loop_started = 1;
    return 0;
}

/* Everything down, in the order the data flows: the job, the planner, the
 * loop, then the backend's controlled stop. */
void nck_finish(struct nck *n)
{
    ncp_sched_stop(&n->sched);
    atomic_store(&n->job.abort, 1);
    nck_job_join(n);
    atomic_store(&n->quit, 1);
    if (n->planner_started)
        pthread_join(n->planner_thread, NULL);
    n->planner_started = 0;
    if (n->loop_started) {
        atomic_store(&n->loop.stop, 1);
        ncp_rt_loop_join(&n->loop);
        n->loop_started = 0;
    }
    /* after the loop, fault or not: the drives stop under control */
    if (n->be_started)
        n->be.ops->stop(&n->be);
    n->be_started = 0;
}

void nck_release(struct nck *n)
{
    if (n->be_open)
        n->be.ops->close(&n->be);
    n->be_open = 0;
    ncp_spsc_destroy(&n->segs);
    ncp_spsc_destroy(&n->sps);
    ncp_spsc_destroy(&n->fbs);
    ncp_spsc_destroy(&n->auxq);
    ncp_spsc_destroy(&n->syncq);
    nck_plan_free(n);
    pthread_mutex_destroy(&n->ev_lock);
}

void nck_park_planner(struct nck *n)
{
    atomic_fetch_add_explicit(&n->park_req, 1, memory_order_release);
}

int nck_planner_parked(const struct nck *n)
{
    return atomic_load_explicit(&n->park_ack, memory_order_acquire) ==
           atomic_load_explicit(&n->park_req, memory_order_relaxed);
}

void nck_discard(struct nck *n, int to_actual)
{
    atomic_store_explicit(&n->discard_to_actual, to_actual, memory_order_relaxed);
    atomic_fetch_add_explicit(&n->discard_req, 1, memory_order_release);
}

int nck_discarded(const struct nck *n)
{
    return atomic_load_explicit(&n->discard_ack, memory_order_acquire) ==
           atomic_load_explicit(&n->discard_req, memory_order_relaxed);
}

/* The loop rested at n->rest: plan from there, and so does the map. */
void nck_unpark_planner(struct nck *n)
{
    atomic_store(&n->marks_sent, atomic_load(&n->ends_taken));
    memcpy(n->map.pos, n->rest, sizeof n->map.pos);
    atomic_fetch_add_explicit(&n->unpark_req, 1, memory_order_release);
}

int nck_planner_unparked(const struct nck *n)
{
    return atomic_load_explicit(&n->unpark_ack, memory_order_acquire) ==
           atomic_load_explicit(&n->unpark_req, memory_order_relaxed);
}

int nck_motion_done(const struct nck *n)
{
    return atomic_load_explicit(&n->ends_taken, memory_order_acquire) >=
           atomic_load_explicit(&n->marks_sent, memory_order_relaxed);
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
