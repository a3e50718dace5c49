/* The NCK runtime's threads: interpreter -> planner/interpolator -> position
 * loop, joined by SPSC rings. Only the position cycle runs on the real-time
 * thread: it takes a setpoint, steps the backend and hands the cycle on. */
#include "nck_int.h"

#include "ncpar/executor.h"

#include <math.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define SEG_RING 1024
#define FB_RING 65536
#define SETTLE_CYCLES 100          /* hold after the end so the plant settles */
#define START_WAIT_NS 20000000LL   /* real clock: wait this long for a full window at rest */

static void nap_us(long us)
{
    struct timespec ts = { 0, us * 1000 };
    nanosleep(&ts, NULL);
}

static int64_t mono_ns(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (int64_t)t.tv_sec * 1000000000LL + t.tv_nsec;
}

/* ---- interpreter thread ------------------------------------------------------- */

static int push_wait(struct nck *n, struct ncp_spsc *ring, const void *item)
{
    while (ncp_spsc_push(ring, item) != 0) {
        if (atomic_load(&n->abort))
            return -1;
        nap_us(100);
    }
    return 0;
}

static int emit_segments(void *ctx, const struct ncp_cmd *cmd)
{
    struct nck *n = ctx;
    struct nck_seg_msg m;
    memset(&m, 0, sizeof m);
    /* as the interpreter reaches them, ahead of the motion, as in LinuxCNC */
    if (cmd->text_used)
        (void)ncp_exec_write_prints(cmd, stderr);
    for (unsigned i = 0; i < cmd->n_ops; i++) {
        int rc = ncp_canon_map_op(&n->map, &cmd->ops[i], cmd->line, &m.seg, &n->map_diag);
        if (rc < 0) {
            n->map_failed = 1;
            return 1;
        }
        while (rc == 1) {
            if (push_wait(n, &n->segs, &m))
                return 1;
            rc = ncp_canon_map_more(&n->map, &m.seg, &n->map_diag);
        }
        if (rc < 0) {
            n->map_failed = 1;
            return 1;
        }
    }
    return 0;
}

static void *interp_main(void *arg)
{
    struct nck *n = arg;
    struct ncp_output out = { .ctx = n, .emit = emit_segments };
    memset(&n->interp_diag, 0, sizeof n->interp_diag);
    n->interp_rc = n->o->interpret(n->o->interp_ctx, &out, &n->interp_diag);
    struct nck_seg_msg end;
    memset(&end, 0, sizeof end);
    end.kind = NCK_MSG_END;
    push_wait(n, &n->segs, &end);
    return NULL;
}

/* ---- soft limits, before any motion ---------------------------------------------- */

struct precheck {
    struct ncp_canon_map map;
    struct ncp_diag d;
    int failed;
};

static int emit_check(void *ctx, const struct ncp_cmd *cmd)
{
    struct precheck *pc = ctx;
    struct ncp_seg s;
    for (unsigned i = 0; i < cmd->n_ops; i++) {
        int rc = ncp_canon_map_op(&pc->map, &cmd->ops[i], cmd->line, &s, &pc->d);
        while (rc == 1)
            rc = ncp_canon_map_more(&pc->map, &s, &pc->d);
        if (rc < 0) {
            pc->failed = pc->d.code == NCP_ERR_LIMIT;
            return 1;
        }
    }
    return 0;
}

/* The program is interpreted once without motion: a soft-limit violation
 * anywhere stops the run before the machine moves. Program errors are left to
 * the real run, which moves up to the last good block. */
static int precheck_limits(const struct ncp_nck_opts *o, const double start[NCP_AXES],
                           struct ncp_diag *d)
{
    struct precheck *pc = calloc(1, sizeof *pc);
    if (!pc)
        return -1;
    ncp_canon_map_init(&pc->map, o->cfg, start, o->feed_override);
    struct ncp_output out = { .ctx = pc, .emit = emit_check };
    struct ncp_diag ignored;
    o->interpret(o->interp_ctx, &out, &ignored);
    int failed = pc->failed;
    if (failed)
        *d = pc->d;
    free(pc);
    return failed;
}

/* ---- planner + interpolator thread ------------------------------------------------ */

static void pull_segments(struct nck *n, int *finished)
{
    struct nck_seg_msg m;
    while (!*finished && !ncp_planner_full(n->planner) && ncp_spsc_pop(&n->segs, &m) == 0) {
        if (m.kind == NCK_MSG_END) {
            *finished = 1;
            ncp_planner_finish(n->planner);
        } else {
            ncp_planner_push(n->planner, &m.seg);
        }
    }
}

/* Virtual clock: the window is always full (or the program ended) before a
 * step, so runs are deterministic. Real clock: only a start from rest waits
 * (briefly) for the window; in motion the planner never holds the loop up. */
static int may_step(struct nck *n, int finished, int64_t *wait_since)
{
    if (finished || ncp_planner_full(n->planner)) {
        *wait_since = 0;
        return 1;
    }
    if (n->o->virtual_clock)
        return 0;
    if (!ncp_planner_idle(n->planner))
        return 1;
    int64_t now = mono_ns();
    if (!*wait_since)
        *wait_since = now;
    return ncp_planner_queued(n->planner) && now - *wait_since > START_WAIT_NS;
}

static void *planner_main(void *arg)
{
    struct nck *n = arg;
    int finished = 0, more = 1;
    int64_t wait_since = 0;
    long nap = (long)(n->cfg->servo_period * ncp_machine_cfg_ipo_ratio(n->cfg) * 1e6 / 4) + 1;
    while (more && !atomic_load(&n->abort)) {
        pull_segments(n, &finished);
        if (ncp_spsc_count(&n->sps) >= ncp_spsc_capacity(&n->sps) ||
            !may_step(n, finished, &wait_since)) {
            if (n->o->virtual_clock)
                sched_yield();
            else
                nap_us(nap);
            continue;
        }
        struct ncp_setpoint sp;
        more = ncp_planner_step(n->planner, &sp);
        ncp_spsc_push(&n->sps, &sp);
    }
    atomic_store(&n->planner_done, 1);
    return NULL;
}

/* ---- position cycle (real-time path: no allocation, locks or I/O) -------------------- */

static int check_ferror(struct nck *n, const double act[NCP_AXES])
{
    for (int j = 0; j < NCP_AXES; j++) {
        double e = fabs(n->cur.pos[j] - act[j]);
        if (e > n->cfg->axis[j].ferror) {
            n->fault = 1;
            n->fault_axis = j;
            n->fault_err = e;
            n->fault_line = n->cur.line;
            return 1;
        }
    }
    return 0;
}

/* Real clock: when the ring holds fewer setpoints than a stop along the path
 * needs, slow the stream down (an underrun in the making); speed up again
 * once it has refilled. The virtual clock never needs to: it waits instead. */
/* Live feed override relative to the override the plan was made at; feed hold
 * (and --for) bring it to 0. Above the planned override the plan's own caps
 * hold: a faster stream could exceed the acceleration limits. */
static double feed_rate(struct nck *n)
{
    if (n->for_expired || atomic_load_explicit(&n->ctl->hold, memory_order_relaxed))
        return 0.0;
    double ov = atomic_load_explicit(&n->ctl->override_permille, memory_order_relaxed) / 1000.0;
    double planned = n->o->feed_override > 0 ? n->o->feed_override : 1.0;
    return fmin(1.0, ov / planned);
}

static double rate_target(struct nck *n)
{
    double feed = feed_rate(n);
    if (feed <= 0 || n->o->virtual_clock || atomic_load(&n->planner_done))
        return feed;
    /* ramping the rate down to 0 reads half as many samples as cycles pass;
     * a ring too small for that still gets the attempt (see SETPOINT_RING) */
    double cap = (double)ncp_spsc_capacity(&n->sps);
    double need = fmin(0.5 * nck_scaler_stop_cycles(&n->scaler) / n->scaler.ratio + 8, 0.75 * cap);
    double fill = (double)ncp_spsc_count(&n->sps);
    if (!n->slowing && fill < need) {
        n->slowing = 1;
        n->underruns += need > 8;  /* only in motion: at rest it just waits */
    } else if (n->slowing && fill >= fmin(2 * need, cap - 1)) {
        n->slowing = 0;
    }
    return n->slowing ? 0.0 : feed;
}

/* The servo sees one setpoint ahead (the command runs one period late), so
 * its feed-forward uses the velocity of the interval it is about to drive. */
static int take_setpoint(struct nck *n)
{
    if (!n->ended && n->o->virtual_clock &&
        ncp_spsc_count(&n->sps) < nck_scaler_wants(&n->scaler, ncp_spsc_capacity(&n->sps)) &&
        !atomic_load(&n->planner_done))
        return NCP_RT_RETRY;
    n->cur = n->next;
    if (!n->ended && nck_scaler_step(&n->scaler, rate_target(n), &n->sps, &n->next) != 0)
        n->dry++;
    if ((n->cur.flags & NCP_SP_END) && !n->ended) {
        n->ended = 1;
        n->end_ns = n->now_ns;
    }
    return NCP_RT_CONTINUE;
}

/* The line of the setpoint changes when its block's motion is complete. */
static void track_blocks(struct nck *n)
{
    if (n->cur.line != n->line_now) {
        n->line_done = n->line_now;
        n->line_now = n->cur.line;
    }
}

static int position_cycle(void *ctx, int64_t now_ns)
{
    struct nck *n = ctx;
    atomic_store_explicit(&n->ctl->now_ns, now_ns, memory_order_release);
    if (n->o->virtual_clock && now_ns >= atomic_load_explicit(&n->ctl->pause_at_ns,
                                                              memory_order_acquire))
        return NCP_RT_RETRY;
    n->now_ns = now_ns;
    if (n->o->virtual_clock && ncp_spsc_count(&n->fbs) >= ncp_spsc_capacity(&n->fbs))
        return NCP_RT_RETRY;
    if (take_setpoint(n) == NCP_RT_RETRY)
        return NCP_RT_RETRY;
    struct nck_fb fb;
    int be_rc = n->be->ops->cycle(n->be, n->cur.pos, n->next.pos, fb.act);
    track_blocks(n);
    fb.t = (double)now_ns * 1e-9;
    fb.v = n->cur.v;
    fb.line = n->cur.line;
    fb.flags = n->cur.flags;
    memcpy(fb.cmd, n->cur.pos, sizeof fb.cmd);
    if (ncp_spsc_push(&n->fbs, &fb) != 0)
        n->fb_dropped++;
    /* A drive fault (EMCY, heartbeat, device state, bus) ends the loop; the
     * backend's stop() then brings every axis to a controlled stop. */
    if (be_rc != 0) {
        n->backend_fault = 1;
        n->fault_line = n->cur.line;
        return NCP_RT_STOP;
    }
    /* A following-error fault stops the loop: the servo is disabled where it
     * stands (as LinuxCNC does), and the run reports the commanding line. */
    if (check_ferror(n, fb.act))
        return NCP_RT_STOP;
    if (n->o->for_s > 0 && fb.t >= n->o->for_s)
        n->for_expired = 1;
    int at_rest = n->ended || (n->for_expired && n->scaler.r == 0 && n->cur.v == 0);
    if (at_rest && ++n->settle >= SETTLE_CYCLES)
        return NCP_RT_STOP;
    return NCP_RT_CONTINUE;
}

/* ---- live controls ---------------------------------------------------------------- */

void ncp_nck_ctl_init(struct ncp_nck_ctl *c, double feed_override)
{
    atomic_store(&c->override_permille, (int)lround(fmin(2.0, fmax(0.0, feed_override)) * 1000));
    atomic_store(&c->hold, 0);
    atomic_store(&c->now_ns, 0);
    atomic_store(&c->pause_at_ns, INT64_MAX);
}

void ncp_nck_set_feed_override(struct ncp_nck_ctl *c, double ov)
{
    atomic_store(&c->override_permille, (int)lround(fmin(2.0, fmax(0.0, ov)) * 1000));
}

void ncp_nck_feed_hold(struct ncp_nck_ctl *c, int hold)
{
    atomic_store(&c->hold, hold != 0);
}

/* ---- set-up and results ---------------------------------------------------------- */

static int init(struct nck *n, const struct ncp_nck_opts *o, const double start[NCP_AXES],
                struct ncp_backend *be)
{
    n->o = o;
    n->be = be;
    n->cfg = o->cfg;
    n->ctl = o->ctl;
    if (!n->ctl) {
        ncp_nck_ctl_init(&n->own_ctl, o->feed_override);
        n->ctl = &n->own_ctl;
    }
    ncp_canon_map_init(&n->map, o->cfg, start, o->feed_override);
    memcpy(n->next.pos, start, sizeof n->next.pos);
    double a_min = o->cfg->axis[0].max_acc;
    for (int j = 1; j < NCP_AXES; j++)
        a_min = fmin(a_min, o->cfg->axis[j].max_acc);
    /* half the weakest axis: the stream may itself be accelerating meanwhile */
    nck_scaler_init(&n->scaler, start, 0.5 * a_min, o->cfg->servo_period);
    int ratio = ncp_machine_cfg_ipo_ratio(o->cfg);
    if (ratio < 1)
        return -1;
    nck_scaler_set_ratio(&n->scaler, ratio);
    nck_scaler_limits(&n->scaler, o->cfg);
    n->planner = ncp_planner_new(o->cfg, start);
    if (!n->planner || ncp_spsc_init(&n->segs, sizeof(struct nck_seg_msg), SEG_RING) ||
        ncp_spsc_init(&n->sps, sizeof(struct ncp_setpoint), (size_t)o->cfg->setpoint_ring) ||
        ncp_spsc_init(&n->fbs, sizeof(struct nck_fb), FB_RING))
        return -1;
    n->loop.cfg = (struct ncp_rt_loop_cfg){ (int64_t)llround(o->cfg->servo_period * 1e9),
                                            o->cfg->position.priority, o->cfg->position.cpu,
                                            o->virtual_clock };
    n->loop.cycle = position_cycle;
    n->loop.ctx = n;
    return 0;
}

static void fini(struct nck *n)
{
    ncp_spsc_destroy(&n->segs);
    ncp_spsc_destroy(&n->sps);
    ncp_spsc_destroy(&n->fbs);
    ncp_planner_free(n->planner);
}

/* "node 2: EMCY (0x082): ... (last completed block: line 7)", at the line
 * of the block in progress. */
static void backend_diag(const struct nck *n, struct ncp_nck_result *res)
{
    char why[NCP_DIAG_MSG_MAX];
    n->be->ops->describe_fault(n->be, why, sizeof why);
    char done[48] = "none";
    if (n->line_done)
        snprintf(done, sizeof done, "line %u", n->line_done);
    ncp_diag_set(&res->diag, NCP_ERR_IO, n->fault_line, 0, "%.*s (last completed block: %s)",
                 (int)(sizeof res->diag.msg - 40), why, done);
    res->status = NCP_NCK_FAULT;
}

static void collect(const struct nck *n, const struct nck_summary *s, struct ncp_nck_result *res)
{
    struct ncp_planner_stats ps;
    ncp_planner_get_stats(n->planner, &ps);
    res->program_time = n->ended ? (double)n->end_ns * 1e-9 : s->t;
    res->path_length = s->path;
    res->segments = ps.segments;
    res->starved = ps.starved;
    res->replans = ps.replans;
    res->ferr_max = s->ferr_max;
    res->ferr_avg = s->moving ? s->ferr_sum / (double)s->moving : 0;
    _Static_assert(NCP_AXES == sizeof res->ferr_axis_max / sizeof res->ferr_axis_max[0],
                   "result arrays follow the axis count");
    for (int j = 0; j < NCP_AXES; j++)
        res->ferr_axis_max[j] = s->ferr_axis_max[j];
    res->contour_max = s->contour_max;
    res->contour_avg = s->moving ? s->contour_sum / (double)s->moving : 0;
    res->underruns = n->underruns;
    res->dry = n->dry;
    res->trace_dropped = n->fb_dropped;
    res->fifo = n->loop.fifo;
    memcpy(res->warning, n->loop.warning, sizeof res->warning);
    res->lat = n->loop.stats;
    res->for_expired = n->for_expired;
    if (n->backend_fault) {
        backend_diag(n, res);
    } else if (n->fault) {
        res->fault = 1;
        res->fault_axis = n->fault_axis;
        res->fault_err = n->fault_err;
        res->fault_line = n->fault_line;
        res->status = NCP_NCK_FAULT;
    } else if (n->for_expired) {
        /* the interpreter was cut short by us: its "stopped" is no program error */
    } else if (n->map_failed || n->interp_rc != NCP_OK) {
        res->diag = n->map_failed ? n->map_diag : n->interp_diag;
        res->status = res->diag.code == NCP_ERR_LIMIT ? NCP_NCK_FAULT : NCP_NCK_PROGRAM_ERROR;
    }
}

static int run_threads(struct nck *n, struct nck_summary *s)
{
    pthread_t interp, plan;
    const struct ncp_machine_cfg *c = n->cfg;
    if (ncp_rt_spawn(&interp, interp_main, n, c->interp.priority, c->interp.cpu, NULL))
        return -1;
    if (ncp_rt_spawn(&plan, planner_main, n, c->planner.priority, c->planner.cpu, NULL)) {
        atomic_store(&n->abort, 1);
        pthread_join(interp, NULL);
        return -1;
    }
    int rc = ncp_rt_loop_start(&n->loop);
    if (rc == 0) {
        if (n->loop.warning[0] && n->o->progress)
            fprintf(n->o->progress, "warning: %s\n", n->loop.warning);
        nck_drain(n, s);
        ncp_rt_loop_join(&n->loop);
    }
    atomic_store(&n->abort, 1);
    pthread_join(plan, NULL);
    pthread_join(interp, NULL);
    return rc ? -1 : 0;
}

/* Brings the backend up before anything moves; a failure there (SDO, state
 * machine, no drive) is a fault with no line: nothing has run. */
static int start_backend(const struct ncp_nck_opts *o, struct ncp_backend *be,
                         double start[NCP_AXES], struct ncp_nck_result *res)
{
    if (ncp_backend_open(be, o->cfg, o->progress ? o->progress : stderr, &res->diag) != NCP_OK) {
        res->diag.code = NCP_ERR_IO;
        return -1;
    }
    if (be->real_clock_only && o->virtual_clock) {
        ncp_diag_set(&res->diag, NCP_ERR_IO, 0, 0,
                     "the %s backend drives real hardware: it needs the real clock",
                     be->ops->name);
        be->ops->close(be);
        return -1;
    }
    if (be->ops->start(be, start) != 0) {
        char why[NCP_DIAG_MSG_MAX];
        be->ops->describe_fault(be, why, sizeof why);
        ncp_diag_set(&res->diag, NCP_ERR_IO, 0, 0, "%s", why);
        be->ops->stop(be);
        be->ops->close(be);
        return -1;
    }
    return 0;
}

int ncp_nck_run(const struct ncp_nck_opts *o, struct ncp_nck_result *res)
{
    double start[NCP_AXES] = { 0 };
    memset(res, 0, sizeof res[0]);
    ncp_rt_stats_reset(&res->lat);
    struct ncp_backend be;
    if (start_backend(o, &be, start, res))
        return res->status = NCP_NCK_FAULT;
    int lim = precheck_limits(o, start, &res->diag);
    if (lim) {
        res->limit_violation = lim > 0;
        be.ops->stop(&be);
        be.ops->close(&be);
        return res->status = NCP_NCK_FAULT;
    }
    struct nck *n = calloc(1, sizeof *n);
    struct nck_summary *s = calloc(1, sizeof *s);
    if (!n || !s || init(n, o, start, &be) || run_threads(n, s)) {
        snprintf(res->diag.msg, sizeof res->diag.msg, "cannot set up the runtime");
        res->status = NCP_NCK_FAULT;
        be.ops->stop(&be);
    } else {
        /* after the loop, fault or not: the drives stop under control */
        be.ops->stop(&be);
        collect(n, s, res);
    }
    be.ops->close(&be);
    if (n)
        fini(n);
    free(n);
    free(s);
    return res->status;
}
