/* The position cycle: the only code on the real-time thread. It takes the
 * period's setpoint from the scaler, steps the backend and hands the cycle on.
 * No allocation, locks or I/O: requests from other threads arrive as atomic
 * counters and are answered the same way. */
#include "nck_int.h"
#include "ncpar/clock.h"

#include <math.h>
#include <string.h>
#include <time.h>

#define SETTLE_CYCLES 100          /* batch: hold after the end so the plant settles */

/* Each servo's following error: per joint (the axes are joints under
 * trivkins, and keep their own FERROR there). */
static int check_ferror(struct nck *n)
{
    int kins = ncp_kins_active(n->cfg);
    for (int j = 0; j < NCP_AXES; j++) {
        double e = fabs(n->jcmd[j] - n->jact[j]);
        if (e > (kins ? n->cfg->joint[j].ferror : n->cfg->axis[j].ferror)) {
            n->fault_axis = j;
            n->fault_err = e;
            n->fault_line = n->cur.line;
            return 1;
        }
    }
    return 0;
}

/* The guard behind the check before motion: a joint commanded beyond its
 * limit (a path the sampling missed, a jog) stops the machine. */
static int check_joint_limits(struct nck *n)
{
    if (!ncp_kins_active(n->cfg))
        return 0;
    for (int j = 0; j < NCP_AXES; j++) {
        const struct ncp_joint_cfg *jc = &n->cfg->joint[j];
        if (!(n->cfg->axis_mask & NCP_AXIS_BIT(j)) || n->cfg->axis[j].wrapped)
            continue;
        /* the check before motion samples the path: allow its chord */
        if (n->jcmd[j] < jc->min_limit - 1e-3 || n->jcmd[j] > jc->max_limit + 1e-3) {
            n->fault_axis = j;
            n->fault_err = n->jcmd[j];
            n->fault_line = n->cur.line;
            return 1;
        }
    }
    return 0;
}

/* The servos drive joints: this period's and the next one's axes through
 * the inverse kinematics, the actual joints back through the forward one
 * (the probe, the trace's axes and the contour error see the tool tip). */
static int drive(struct nck *n, double act[NCP_AXES], int with_faults)
{
    const struct ncp_kins *k = &n->cfg->kins;
    ncp_kins_inverse(k, n->cur.tool_z, n->cur.pos, n->jcmd);
    ncp_kins_inverse(k, n->next.tool_z, n->next.pos, n->jnext);
    /* homing's offset between the joints and what the servos count from */
    double c[NCP_AXES], x[NCP_AXES], a[NCP_AXES];
    for (int j = 0; j < NCP_AXES; j++) {
        c[j] = n->jcmd[j] + n->home.off[j];
        x[j] = n->jnext[j] + n->home.off[j];
        a[j] = c[j];  /* a backend reports only the machine's joints */
    }
    /* timing faults act on what the servos get: the joints */
    int rc = with_faults ? nck_servo_cycle(n, c, x, a) : n->be.ops->cycle(&n->be, c, x, a);
    for (int j = 0; j < NCP_AXES; j++)
        n->jact[j] = a[j] - n->home.off[j];
    ncp_kins_forward(k, n->cur.tool_z, n->jact, act);
    return rc;
}

/* Live feed override relative to the override the plan was made at; feed hold
 * (and --for) bring it to 0. Above the planned override the plan's own caps
 * hold: a faster stream could exceed the acceleration limits. */
static double feed_rate(struct nck *n)
{
    /* M53 P0 turns the feed hold off (not the controlled stop) */
    int hold = n->mach.en[NCK_EN_FEED_HOLD] &&
               atomic_load_explicit(&n->ctl->hold, memory_order_relaxed);
    if (n->for_expired || hold || nck_probe_braking(n) || n->timing_stop ||
        atomic_load_explicit(&n->ctl->stop, memory_order_relaxed))
        return 0.0;
    /* a serving NCK's rapids follow the rapid override, as LinuxCNC's (a
     * batch run's --feed-override and live override apply to all motion) */
    if (!n->batch && (n->cur.flags & NCP_SP_RAPID))
        return fmin(1.0, atomic_load_explicit(&n->ctl->rapid_permille, memory_order_relaxed) /
                             1000.0);
    /* M48/M49/M50: with the override off the program's feed holds */
    double ov = n->mach.en[NCK_EN_FEED_OVERRIDE]
                    ? atomic_load_explicit(&n->ctl->override_permille, memory_order_relaxed) / 1000.0
                    : 1.0;
    double f = fmin(1.0, ov / n->plan_override);
    /* G95 (LinuxCNC's velocity mode): the feed per turn at the spindle's
     * actual speed; above the speed planned for, the plan's caps hold */
    if (n->cur.rev_rpm > 0)
        f *= fmin(1.0, fabs(n->mach.rpm) / n->cur.rev_rpm);
    return f;
}

/* The end of the stream is in the ring: running it down is no underrun. */
static int end_in_ring(const struct nck *n)
{
    return atomic_load_explicit(&n->ends_pushed, memory_order_acquire) >
           atomic_load_explicit(&n->ends_taken, memory_order_relaxed);
}

/* Real clock: when the ring holds fewer setpoints than a stop along the path
 * needs, slow the stream down (an underrun in the making); speed up again
 * once it has refilled. The virtual clock never needs to: it waits instead. */
static double rate_target(struct nck *n)
{
    double feed = feed_rate(n);
    if (feed <= 0 || n->setup.virtual_clock || end_in_ring(n))
        return feed;
    /* ramping the rate down to 0 reads half as many samples as cycles pass;
     * a ring too small for that still gets the attempt (see SETPOINT_RING) */
    double cap = (double)ncp_spsc_capacity(&n->sps);
    double need = fmin(0.5 * ncp_scaler_stop_cycles(&n->scaler) / n->scaler.ratio + 8, 0.75 * cap);
    double fill = (double)ncp_spsc_count(&n->sps);
    if (!n->slowing && fill < need) {
        n->slowing = 1;
        n->underruns += need > 8;  /* only in motion: at rest it just waits */
    } else if (n->slowing && fill >= fmin(2 * need, cap - 1)) {
        n->slowing = 0;
    }
    return n->slowing ? 0.0 : feed;
}

/* Motion the loop must wait for on the virtual clock: a job has motion open
 * that the loop has not reached the end of, the planner has not pushed that
 * end yet, and the job is not waiting for the operator (single block). */
static int stream_expected(const struct nck *n)
{
    return atomic_load_explicit(&n->marks_sent, memory_order_acquire) >
               atomic_load_explicit(&n->ends_taken, memory_order_relaxed) &&
           !end_in_ring(n) && !atomic_load_explicit(&n->job.waiting, memory_order_relaxed);
}

/* The servo sees one setpoint ahead (the command runs one period late), so
 * its feed-forward uses the velocity of the interval it is about to drive. */
static int take_setpoint(struct nck *n)
{
    /* a machine function waits (spindle, operator, input): hold where the
     * stream stopped for it */
    struct ncp_setpoint before = n->next;
    if (nck_aux_cycle(n)) {
        n->cur = before;   /* a synchronised run writes the next itself */
        return NCP_RT_CONTINUE;
    }
    if (!n->ended && n->setup.virtual_clock &&
        ncp_spsc_count(&n->sps) < ncp_scaler_wants(&n->scaler, ncp_spsc_capacity(&n->sps)) &&
        stream_expected(n))
        return NCP_RT_RETRY;
    n->cur = n->next;
    if (!n->ended && ncp_scaler_step(&n->scaler, rate_target(n), &n->sps, &n->next) != 0)
        n->dry++;
    if (n->next.aux > n->mach.seq_reached)
        n->mach.seq_reached = n->next.aux;
    if (n->scaler.ends != n->ends_seen) {
        atomic_fetch_add_explicit(&n->ends_taken, n->scaler.ends - n->ends_seen,
                                  memory_order_release);
        n->ends_seen = n->scaler.ends;
    }
    /* a batch run ends with the period that commands its END sample (a
     * queue buster's stop is one too, but more motion is expected after it) */
    n->end_seen = (n->cur.flags & NCP_SP_END) != 0;
    if (n->batch && n->end_seen && !n->ended &&
        atomic_load_explicit(&n->ends_taken, memory_order_relaxed) >=
            atomic_load_explicit(&n->marks_sent, memory_order_acquire)) {
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

/* A drop request: the planner is parked, so nothing more comes into the ring;
 * empty it and rest where the machine is. */
static void discard(struct nck *n, const double act[NCP_AXES])
{
    struct ncp_setpoint sp;
    while (ncp_spsc_pop(&n->sps, &sp) == 0)
        ;
    double at[NCP_AXES];
    memcpy(at, atomic_load_explicit(&n->discard_to_actual, memory_order_relaxed) ? act : n->cur.pos,
           sizeof at);
    memcpy(n->rest, at, sizeof n->rest);
    nck_aux_discard(n);
    n->probe.state = NCK_PROBE_OFF;
    ncp_scaler_rebase(&n->scaler, at);
    n->scaler.decel = n->decel_normal;
    memset(&n->cur, 0, sizeof n->cur);
    memcpy(n->cur.pos, at, sizeof n->cur.pos);
    n->next = n->cur;
    n->slowing = 0;
    n->end_seen = 0;
    n->ends_seen = n->scaler.ends;
    atomic_store_explicit(&n->ends_taken,
                          atomic_load_explicit(&n->ends_pushed, memory_order_acquire),
                          memory_order_relaxed);
    atomic_store_explicit(&n->discard_ack,
                          atomic_load_explicit(&n->discard_req, memory_order_relaxed),
                          memory_order_release);
}

/* TRACE_RINGS: the rings' fill as this cycle sees it and the tasks' last
 * times; the loop's own cycle is the actual time since its last wake-up
 * (clock_gettime is the vDSO's, no system call; the virtual clock's time is
 * the schedule itself). */
static void ring_columns(struct nck *n, int64_t now_ns, struct nck_fb *fb)
{
    fb->seg_fill = (uint32_t)ncp_spsc_count(&n->segs);
    fb->sp_fill = (uint32_t)ncp_spsc_count(&n->sps);
    fb->plan_resp_ns = atomic_load_explicit(&n->plan_resp_ns, memory_order_relaxed);
    fb->plan_cycle_ns = atomic_load_explicit(&n->plan_cycle_ns, memory_order_relaxed);
    fb->job_cycle_ns = atomic_load_explicit(&n->job_cycle_ns, memory_order_relaxed);
    int64_t t = n->setup.virtual_clock ? now_ns : ncp_mono_ns();
    fb->loop_cycle_ns = n->loop_last_ns ? t - n->loop_last_ns : 0;
    n->loop_last_ns = t;
}

static void push_cycle(struct nck *n, int64_t now_ns, const double act[NCP_AXES],
                       uint64_t home)
{
    struct nck_fb fb;
    fb.home = home;
    fb.t = (double)now_ns * 1e-9;
    fb.v = n->cur.v;
    fb.line = n->cur.line;
    fb.flags = n->cur.flags;
    memcpy(fb.cmd, n->cur.pos, sizeof fb.cmd);
    memcpy(fb.act, act, sizeof fb.act);
    fb.inj = n->inj_ev;
    memset(&n->inj_ev, 0, sizeof n->inj_ev);
    memcpy(fb.jcmd, n->jcmd, sizeof fb.jcmd);
    memcpy(fb.jact, n->jact, sizeof fb.jact);
    fb.tool_z = n->cur.tool_z;
    const struct nck_mach *m = &n->mach;
    fb.rpm = m->rpm;
    fb.rev = m->rev;
    fb.dout = m->dout;
    fb.mist = (uint8_t)m->mist;
    fb.flood = (uint8_t)m->flood;
    fb.wait = (uint8_t)m->wait;
    fb.waits = m->waits;
    fb.tool = m->tool;
    fb.wait_line = m->wait_line;
    if (n->trace_rings)
        ring_columns(n, now_ns, &fb);
    if (ncp_spsc_push(&n->fbs, &fb) != 0)
        n->fb_dropped++;
}

static void publish_stats(struct nck *n)
{
    atomic_store_explicit(&n->pub_misses, n->loop.stats.misses, memory_order_relaxed);
    atomic_store_explicit(&n->pub_lat_max_ns, n->loop.stats.lat_max_ns, memory_order_relaxed);
}

/* Nothing to do on a serving NCK's virtual clock: time goes on at the real
 * rate rather than racing ahead of the operator. */
static void idle_nap(const struct nck *n)
{
    struct timespec ts = { 0, (long)(n->cfg->servo_period * 1e9) };
    clock_nanosleep(CLOCK_MONOTONIC, 0, &ts, NULL);
}

/* E-stop or a fault: the setpoint stays where it was, the drives are off. */
static int frozen_cycle(struct nck *n, int64_t now_ns)
{
    if (n->drives_on && n->be.ops->enable) {
        n->be.ops->enable(&n->be, 0);
        n->drives_on = 0;
    }
    nck_home_cancel(n);
    double act[NCP_AXES];
    n->be.timing = NULL;
    n->next = n->cur;
    (void)drive(n, act, 0);
    nck_inject_clear(n);
    n->mach.rpm_cmd = 0;   /* E-stop and faults stop the spindle too */
    (void)nck_aux_cycle(n);
    if (atomic_load_explicit(&n->discard_req, memory_order_acquire) !=
        atomic_load_explicit(&n->discard_ack, memory_order_relaxed))
        discard(n, act);
    n->cur.v = 0;
    push_cycle(n, now_ns, act, 0);
    atomic_store_explicit(&n->at_rest, 1, memory_order_relaxed);
    if (n->setup.virtual_clock)
        idle_nap(n);
    return NCP_RT_CONTINUE;
}

int nck_position_cycle(void *ctx, int64_t now_ns)
{
    struct nck *n = ctx;
    atomic_store_explicit(&n->ctl->now_ns, now_ns, memory_order_release);
    int virt = n->setup.virtual_clock;
    if (virt && now_ns >= atomic_load_explicit(&n->ctl->pause_at_ns, memory_order_acquire))
        return NCP_RT_RETRY;
    n->now_ns = now_ns;
    if (virt && ncp_spsc_count(&n->fbs) >= ncp_spsc_capacity(&n->fbs))
        return NCP_RT_RETRY;
    publish_stats(n);
    if (atomic_load_explicit(&n->frozen, memory_order_acquire))
        return frozen_cycle(n, now_ns);
    if (!n->drives_on && n->be.ops->enable) {
        n->be.ops->enable(&n->be, 1);
        n->drives_on = 1;
    }
    n->scaler.decel = atomic_load_explicit(&n->full_decel, memory_order_relaxed)
                          ? n->decel_full : n->decel_normal;
    /* homing drives the axes itself, the planner's stream waits */
    if (!nck_home_take(n)) {
        if (atomic_load_explicit(&n->job_pending, memory_order_acquire)) {
            if (virt)
                return NCP_RT_RETRY;
            n->cur = n->next;
        } else if (take_setpoint(n) == NCP_RT_RETRY) {
            return NCP_RT_RETRY;
        }
    }
    uint64_t home = nck_home_phases(n);   /* the row shows the phase the period ran in */
    double act[NCP_AXES];
    int be_rc = drive(n, act, 1);
    nck_probe_cycle(n, act);
    nck_home_sense(n, act);
    track_blocks(n);
    push_cycle(n, now_ns, act, home);
    int rest = !nck_home_active(n) && n->cur.v == 0 && n->next.v == 0 &&
               (n->scaler.r == 0 || n->end_seen || ncp_spsc_count(&n->sps) == 0);
    atomic_store_explicit(&n->at_rest, rest, memory_order_relaxed);
    if (atomic_load_explicit(&n->discard_req, memory_order_acquire) !=
        atomic_load_explicit(&n->discard_ack, memory_order_relaxed))
        discard(n, act);
    /* A drive fault (EMCY, heartbeat, device state, bus) or a following error
     * ends motion: a batch run's loop stops (the backend's stop() then brings
     * every axis to a controlled stop); a serving NCK freezes its setpoints
     * and turns its drives off until reset, as LinuxCNC does. */
    int fault = be_rc != 0 ? NCK_LF_BACKEND : check_ferror(n) ? NCK_LF_FERROR
                : check_joint_limits(n) ? NCK_LF_JOINT : NCK_LF_NONE;
    if (fault) {
        if (fault == NCK_LF_BACKEND)
            n->fault_line = n->cur.line;
        atomic_store_explicit(&n->loop_fault, fault, memory_order_release);
        if (n->batch)
            return NCP_RT_STOP;
        atomic_store_explicit(&n->frozen, 1, memory_order_release);
        return NCP_RT_CONTINUE;
    }
    nck_inject_rest(n);
    if (n->batch) {
        if (n->for_s > 0 && (double)now_ns * 1e-9 >= n->for_s)
            n->for_expired = 1;
        int held = n->for_expired || n->timing_stop ||
                   atomic_load_explicit(&n->ctl->stop, memory_order_relaxed);
        int done = n->ended || (held && n->scaler.r == 0 && n->cur.v == 0);
        if (done && ++n->settle >= SETTLE_CYCLES)
            return NCP_RT_STOP;
    } else if (virt && n->setup.virtual_pace > 0 && !rest) {
        struct timespec ts = { 0, (long)(n->cfg->servo_period * 1e9 / n->setup.virtual_pace) };
        clock_nanosleep(CLOCK_MONOTONIC, 0, &ts, NULL);
    } else if (virt && rest &&
               (atomic_load_explicit(&n->ctl->hold, memory_order_relaxed) ||
                /* waiting for the operator or an input: at the real rate */
                (n->mach.wait != NCK_WAIT_NONE && n->mach.wait != NCK_WAIT_SPINDLE &&
                 n->mach.wait != NCK_WAIT_ORIENT && n->mach.wait != NCK_WAIT_INDEX) ||
                (!stream_expected(n) && ncp_spsc_count(&n->sps) == 0))) {
        idle_nap(n);
    }
    return NCP_RT_CONTINUE;
}
