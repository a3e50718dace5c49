/* The position cycle: the only code on the real-time thread. It takes the
 * period's setpoint from the scaler, steps the backend and hands the cycle on.
 * No allocation, locks or I/O: requests from other threads arrive as atomic
 * counters and are answered the same way. */
#include "nck_int.h"
#include "loop_state.h"
#include "ncpar/clock.h"

#include <math.h>
#include <string.h>
#include <time.h>

#define SETTLE_CYCLES 100          /* batch: hold after the end so the plant settles */

/* Each servo's following error: per joint (the axes are joints under
 * trivkins, and keep their own FERROR there). */
static int check_ferror(struct nck_core *n)
{
    int kins = ncp_kins_active(n->cfg);
    for (int j = 0; j < NCP_AXES; j++) {
        /* a drive homing itself moves on its own and, at its home, starts
         * counting from the home offset: its own monitoring watches it */
        if (n->loop->home.ax[j].phase == NCK_HP_DRIVE)
            continue;
        double e = fabs(n->loop->jcmd[j] - n->loop->jact[j]);
        if (e > (kins ? n->cfg->joint[j].ferror : n->cfg->axis[j].ferror)) {
            n->cross.fault_axis = j;
            n->cross.fault_err = e;
            n->cross.fault_line = n->loop->cur.line;
            return 1;
        }
    }
    return 0;
}

/* The guard behind the check before motion: a joint commanded beyond its
 * limit (a path the sampling missed, a jog) stops the machine. */
static int check_joint_limits(struct nck_core *n)
{
    if (!ncp_kins_active(n->cfg))
        return 0;
    for (int j = 0; j < NCP_AXES; j++) {
        const struct ncp_joint_cfg *jc = &n->cfg->joint[j];
        if (!(n->cfg->axis_mask & NCP_AXIS_BIT(j)) || n->cfg->axis[j].wrapped)
            continue;
        /* the check before motion samples the path: allow its chord */
        if (n->loop->jcmd[j] < jc->min_limit - 1e-3 || n->loop->jcmd[j] > jc->max_limit + 1e-3) {
            n->cross.fault_axis = j;
            n->cross.fault_err = n->loop->jcmd[j];
            n->cross.fault_line = n->loop->cur.line;
            return 1;
        }
    }
    return 0;
}

/* The servos drive joints: this period's and the next one's axes through
 * the inverse kinematics, the actual joints back through the forward one
 * (the probe, the trace's axes and the contour error see the tool tip). */
static int drive(struct nck_core *n, double act[NCP_AXES], int with_faults)
{
    const struct ncp_kins *k = &n->cfg->kins;
    ncp_kins_inverse(k, n->loop->cur.tool_z, n->loop->cur.pos, n->loop->jcmd);
    ncp_kins_inverse(k, n->loop->next.tool_z, n->loop->next.pos, n->loop->jnext);
    /* homing's offset between the joints and what the servos count from */
    double c[NCP_AXES], x[NCP_AXES], a[NCP_AXES];
    for (int j = 0; j < NCP_AXES; j++) {
        c[j] = n->loop->jcmd[j] + n->loop->home.off[j];
        x[j] = n->loop->jnext[j] + n->loop->home.off[j];
        a[j] = c[j];  /* a backend reports only the machine's joints */
        n->cross.be.home_off[j] = n->loop->home.off[j];
    }
    /* timing faults act on what the servos get: the joints */
    int rc = with_faults ? nck_servo_cycle(n, c, x, a) : n->cross.be.ops->cycle(&n->cross.be, c, x, a);
    for (int j = 0; j < NCP_AXES; j++)
        n->loop->jact[j] = a[j] - n->loop->home.off[j];
    ncp_kins_forward(k, n->loop->cur.tool_z, n->loop->jact, act);
    return rc;
}

/* Live feed override relative to the override the plan was made at; feed hold
 * (and --for) bring it to 0. Above the planned override the plan's own caps
 * hold: a faster stream could exceed the acceleration limits. */
static double feed_rate(struct nck_core *n)
{
    /* M53 P0 turns the feed hold off (not the controlled stop) */
    int hold = n->loop->mach.en[NCK_EN_FEED_HOLD] &&
               atomic_load_explicit(&n->ctl->hold, memory_order_relaxed);
    if (n->loop->for_expired || hold || nck_probe_braking(n) || n->loop->timing_stop ||
        atomic_load_explicit(&n->ctl->stop, memory_order_relaxed))
        return 0.0;
    /* a serving NCK's rapids follow the rapid override, as LinuxCNC's (a
     * batch run's --feed-override and live override apply to all motion) */
    if (!n->batch && (n->loop->cur.flags & NCP_SP_RAPID))
        return fmin(1.0, atomic_load_explicit(&n->ctl->rapid_permille, memory_order_relaxed) /
                             1000.0);
    /* M48/M49/M50: with the override off the program's feed holds */
    double ov = n->loop->mach.en[NCK_EN_FEED_OVERRIDE]
                    ? atomic_load_explicit(&n->ctl->override_permille, memory_order_relaxed) / 1000.0
                    : 1.0;
    double f = fmin(1.0, ov / n->plan_override);
    /* G95 (LinuxCNC's velocity mode): the feed per turn at the spindle's
     * actual speed; above the speed planned for, the plan's caps hold */
    if (n->loop->cur.rev_rpm > 0)
        f *= fmin(1.0, fabs(n->loop->mach.rpm) / n->loop->cur.rev_rpm);
    return f;
}

/* The end of the stream is in the ring: running it down is no underrun. */
static int end_in_ring(const struct nck_core *n)
{
    return atomic_load_explicit(&n->cross.ends_pushed, memory_order_acquire) >
           atomic_load_explicit(&n->cross.ends_taken, memory_order_relaxed);
}

/* Real clock: when the ring holds fewer setpoints than a stop along the path
 * needs, slow the stream down (an underrun in the making); speed up again
 * once it has refilled. The virtual clock never needs to: it waits instead. */
static double rate_target(struct nck_core *n)
{
    double feed = feed_rate(n);
    if (feed <= 0 || n->setup.virtual_clock || end_in_ring(n))
        return feed;
    /* ramping the rate down to 0 reads half as many samples as cycles pass;
     * a ring too small for that still gets the attempt (see SETPOINT_RING) */
    double cap = (double)ncp_spsc_capacity(&n->cross.sps);
    double need = fmin(0.5 * ncp_scaler_stop_cycles(&n->loop->scaler) / n->loop->scaler.ratio + 8, 0.75 * cap);
    double fill = (double)ncp_spsc_count(&n->cross.sps);
    if (!n->loop->slowing && fill < need) {
        n->loop->slowing = 1;
        n->loop->underruns += need > 8;  /* only in motion: at rest it just waits */
    } else if (n->loop->slowing && fill >= fmin(2 * need, cap - 1)) {
        n->loop->slowing = 0;
    }
    return n->loop->slowing ? 0.0 : feed;
}

/* Motion the loop must wait for on the virtual clock: a job has motion open
 * that the loop has not reached the end of, the planner has not pushed that
 * end yet, and the job is not waiting for the operator (single block). */
static int stream_expected(const struct nck_core *n)
{
    return atomic_load_explicit(&n->cross.marks_sent, memory_order_acquire) >
               atomic_load_explicit(&n->cross.ends_taken, memory_order_relaxed) &&
           !end_in_ring(n) && !atomic_load_explicit(&n->cross.job_waiting, memory_order_relaxed);
}

/* The servo sees one setpoint ahead (the command runs one period late), so
 * its feed-forward uses the velocity of the interval it is about to drive. */
static int take_setpoint(struct nck_core *n)
{
    /* a machine function waits (spindle, operator, input): hold where the
     * stream stopped for it */
    struct ncp_setpoint before = n->loop->next;
    if (nck_aux_cycle(n)) {
        n->loop->cur = before;   /* a synchronised run writes the next itself */
        nck_loop_take_read(n);
        return NCP_RT_CONTINUE;
    }
    if (!n->loop->ended && n->setup.virtual_clock &&
        ncp_spsc_count(&n->cross.sps) < ncp_scaler_wants(&n->loop->scaler, ncp_spsc_capacity(&n->cross.sps)) &&
        stream_expected(n))
        return NCP_RT_RETRY;
    n->loop->cur = n->loop->next;
    nck_loop_take_read(n);
    if (!n->loop->ended && ncp_scaler_step(&n->loop->scaler, rate_target(n), &n->cross.sps, &n->loop->next) != 0)
        n->loop->dry++;
    if (!n->loop->ended) {
        n->loop->adv_next = n->loop->scaler.adv;
        nck_loop_note_read(n);
    }
    if (n->loop->next.aux > n->loop->mach.seq_reached)
        n->loop->mach.seq_reached = n->loop->next.aux;
    if (n->loop->scaler.ends != n->loop->ends_seen) {
        /* the END is commanded next period (the servo runs one late): a
         * serving NCK's program time ends there, as a batch run's does. Set
         * before the count the service reads it by (release) */
        atomic_store_explicit(&n->cross.end_ns, n->loop->now_ns + n->cross.rt.cfg.period_ns,
                              memory_order_relaxed);
        atomic_fetch_add_explicit(&n->cross.ends_taken, n->loop->scaler.ends - n->loop->ends_seen,
                                  memory_order_release);
        n->loop->ends_seen = n->loop->scaler.ends;
    }
    /* a batch run ends with the period that commands its END sample (a
     * queue buster's stop is one too, but more motion is expected after it) */
    n->loop->end_seen = (n->loop->cur.flags & NCP_SP_END) != 0;
    if (n->batch && n->loop->end_seen && !n->loop->ended &&
        atomic_load_explicit(&n->cross.ends_taken, memory_order_relaxed) >=
            atomic_load_explicit(&n->cross.marks_sent, memory_order_acquire)) {
        n->loop->ended = 1;
        n->loop->end_ns = n->loop->now_ns;
    }
    return NCP_RT_CONTINUE;
}

/* The line of the setpoint changes when its block's motion is complete. */
static void track_blocks(struct nck_core *n)
{
    if (n->loop->cur.line != n->loop->line_now) {
        n->loop->line_done = n->loop->line_now;
        n->loop->line_now = n->loop->cur.line;
    }
}

/* A drop request: the planner is parked, so nothing more comes into the ring;
 * empty it and rest where the machine is. */
static void discard(struct nck_core *n, const double act[NCP_AXES])
{
    struct ncp_setpoint sp;
    while (ncp_spsc_pop(&n->cross.sps, &sp) == 0)
        ;
    double at[NCP_AXES];
    memcpy(at, atomic_load_explicit(&n->cross.discard_to_actual, memory_order_relaxed) ? act : n->loop->cur.pos,
           sizeof at);
    memcpy(n->cross.rest, at, sizeof n->cross.rest);
    nck_aux_discard(n);
    n->loop->probe.state = NCK_PROBE_OFF;
    ncp_scaler_rebase(&n->loop->scaler, at);
    n->loop->adv_next = 0;
    nck_loop_note_read(n);
    n->cross.be.drop_k = n->loop->read_k_next + 2;
    n->cross.be.discards++;
    n->loop->scaler.decel = n->loop->decel_normal;
    memset(&n->loop->cur, 0, sizeof n->loop->cur);
    memcpy(n->loop->cur.pos, at, sizeof n->loop->cur.pos);
    n->loop->next = n->loop->cur;
    n->loop->slowing = 0;
    n->loop->end_seen = 0;
    n->loop->ends_seen = n->loop->scaler.ends;
    atomic_store_explicit(&n->cross.ends_taken,
                          atomic_load_explicit(&n->cross.ends_pushed, memory_order_acquire),
                          memory_order_relaxed);
    atomic_store_explicit(&n->cross.discard_ack,
                          atomic_load_explicit(&n->cross.discard_req, memory_order_relaxed),
                          memory_order_release);
}

/* TRACE_RINGS: the rings' fill as this cycle sees it and the tasks' last
 * times; the loop's own cycle is the actual time since its last wake-up
 * (clock_gettime is the vDSO's, no system call; the virtual clock's time is
 * the schedule itself). */
static void ring_columns(struct nck_core *n, int64_t now_ns, struct nck_fb *fb)
{
    fb->seg_fill = (uint32_t)ncp_spsc_count(&n->cross.segs);
    fb->sp_fill = (uint32_t)ncp_spsc_count(&n->cross.sps);
    fb->plan_resp_ns = atomic_load_explicit(&n->cross.plan_resp_ns, memory_order_relaxed);
    fb->plan_cycle_ns = atomic_load_explicit(&n->cross.plan_cycle_ns, memory_order_relaxed);
    fb->job_cycle_ns = atomic_load_explicit(&n->cross.job_cycle_ns, memory_order_relaxed);
    int64_t t = n->setup.virtual_clock ? now_ns : ncp_mono_ns();
    fb->loop_cycle_ns = n->loop->loop_last_ns ? t - n->loop->loop_last_ns : 0;
    n->loop->loop_last_ns = t;
}

static void push_cycle(struct nck_core *n, int64_t now_ns, const double act[NCP_AXES],
                       uint64_t home)
{
    struct nck_fb fb;
    fb.home = home;
    fb.t = (double)now_ns * 1e-9;
    fb.v = n->loop->cur.v;
    fb.adv = n->cross.be.adv;
    fb.line = n->loop->cur.line;
    fb.flags = n->loop->cur.flags;
    memcpy(fb.cmd, n->loop->cur.pos, sizeof fb.cmd);
    memcpy(fb.act, act, sizeof fb.act);
    fb.inj = n->loop->inj_ev;
    memset(&n->loop->inj_ev, 0, sizeof n->loop->inj_ev);
    memcpy(fb.jcmd, n->loop->jcmd, sizeof fb.jcmd);
    memcpy(fb.jact, n->loop->jact, sizeof fb.jact);
    fb.tool_z = n->loop->cur.tool_z;
    const struct nck_mach *m = &n->loop->mach;
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
    if (ncp_spsc_push(&n->cross.fbs, &fb) != 0)
        n->loop->fb_dropped++;
}

static void publish_stats(struct nck_core *n)
{
    atomic_store_explicit(&n->cross.pub_misses, n->cross.rt.stats.misses, memory_order_relaxed);
    atomic_store_explicit(&n->cross.pub_lat_max_ns, n->cross.rt.stats.lat_max_ns, memory_order_relaxed);
}

/* Nothing to do on a serving NCK's virtual clock: time goes on at the real
 * rate rather than racing ahead of the operator. */
static void idle_nap(const struct nck_core *n)
{
    struct timespec ts = { 0, (long)(n->cfg->servo_period * 1e9) };
    clock_nanosleep(CLOCK_MONOTONIC, 0, &ts, NULL);
}

/* Below this speed on every axis, for NCK_STILL_PERIODS in a row, an axis
 * whose drive is off has stopped coasting. */
#define NCK_STILL_MM_S 0.1
#define NCK_STILL_PERIODS 10
/* After this long frozen the actual position is taken however it moves: a
 * drive that never settles is its following-error check's to catch. */
#define NCK_STILL_GIVE_UP_S 5.0

/* The axes stand: a drop to the actual position (a reset, the end of an
 * E-stop's drop) takes it only then, or the setpoint would stay behind
 * where they stop and the drives would pull back when they come on. */
static int plant_still(struct nck_core *n, const double act[NCP_AXES])
{
    struct nck_loop *lp = n->loop;
    double step = NCK_STILL_MM_S * n->cfg->servo_period;
    int moved = 0;
    for (int j = 0; j < NCP_AXES; j++) {
        moved |= fabs(act[j] - lp->frozen_prev[j]) > step;
        lp->frozen_prev[j] = act[j];
    }
    lp->still_periods = moved ? 0 : lp->still_periods + 1;
    lp->frozen_periods++;
    return lp->still_periods >= NCK_STILL_PERIODS ||
           lp->frozen_periods * n->cfg->servo_period >= NCK_STILL_GIVE_UP_S;
}

/* E-stop or a fault: the setpoint stays where it was, the drives are off. */
static int frozen_cycle(struct nck_core *n, int64_t now_ns)
{
    if (n->loop->drives_on && n->cross.be.ops->enable) {
        n->cross.be.ops->enable(&n->cross.be, 0);
        n->loop->drives_on = 0;
    }
    if (n->loop->frozen_periods == 0)
        memcpy(n->loop->frozen_prev, n->loop->cur.pos, sizeof n->loop->frozen_prev);
    nck_home_cancel(n);
    double act[NCP_AXES];
    n->cross.be.timing = NULL;
    n->cross.be.adv = 0;
    n->loop->next = n->loop->cur;
    (void)drive(n, act, 0);
    nck_inject_clear(n);
    n->loop->mach.rpm_cmd = 0;   /* E-stop and faults stop the spindle too */
    (void)nck_aux_cycle(n);
    int still = plant_still(n, act);
    if (atomic_load_explicit(&n->cross.discard_req, memory_order_acquire) !=
            atomic_load_explicit(&n->cross.discard_ack, memory_order_relaxed) &&
        (still || !atomic_load_explicit(&n->cross.discard_to_actual, memory_order_relaxed)))
        discard(n, act);
    n->loop->cur.v = 0;
    push_cycle(n, now_ns, act, 0);
    atomic_store_explicit(&n->cross.at_rest, 1, memory_order_relaxed);
    if (n->setup.virtual_clock)
        idle_nap(n);
    return NCP_RT_CONTINUE;
}

int nck_position_cycle(void *ctx, int64_t now_ns)
{
    struct nck_core *n = ctx;
    atomic_store_explicit(&n->ctl->now_ns, now_ns, memory_order_release);
    int virt = n->setup.virtual_clock;
    if (virt && now_ns >= atomic_load_explicit(&n->ctl->pause_at_ns, memory_order_acquire))
        return NCP_RT_RETRY;
    n->loop->now_ns = now_ns;
    if (virt && ncp_spsc_count(&n->cross.fbs) >= ncp_spsc_capacity(&n->cross.fbs))
        return NCP_RT_RETRY;
    publish_stats(n);
    if (atomic_load_explicit(&n->cross.frozen, memory_order_acquire))
        return frozen_cycle(n, now_ns);
    n->loop->frozen_periods = 0;
    n->loop->still_periods = 0;
    if (!n->loop->drives_on && n->cross.be.ops->enable) {
        n->cross.be.ops->enable(&n->cross.be, 1);
        n->loop->drives_on = 1;
    }
    n->loop->scaler.decel = atomic_load_explicit(&n->cross.full_decel, memory_order_relaxed)
                          ? n->loop->decel_full : n->loop->decel_normal;
    /* homing drives the axes itself, the planner's stream waits */
    if (!nck_home_take(n)) {
        if (atomic_load_explicit(&n->cross.job_pending, memory_order_acquire)) {
            if (virt)
                return NCP_RT_RETRY;
            n->loop->cur = n->loop->next;
            nck_loop_take_read(n);
        } else if (take_setpoint(n) == NCP_RT_RETRY) {
            return NCP_RT_RETRY;
        }
        n->cross.be.homing = 0;
    } else {
        n->cross.be.adv = 0;
        n->cross.be.homing = 1;
    }
    uint64_t home = nck_home_phases(n);   /* the row shows the phase the period ran in */
    double act[NCP_AXES];
    int be_rc = drive(n, act, 1);
    nck_probe_cycle(n, act);
    nck_home_sense(n, act);
    track_blocks(n);
    push_cycle(n, now_ns, act, home);
    int rest = !nck_home_active(n) && n->loop->cur.v == 0 && n->loop->next.v == 0 &&
               (n->loop->scaler.r == 0 || n->loop->end_seen || ncp_spsc_count(&n->cross.sps) == 0);
    atomic_store_explicit(&n->cross.at_rest, rest, memory_order_relaxed);
    if (atomic_load_explicit(&n->cross.discard_req, memory_order_acquire) !=
        atomic_load_explicit(&n->cross.discard_ack, memory_order_relaxed))
        discard(n, act);
    /* A drive fault (EMCY, heartbeat, device state, bus) or a following error
     * ends motion: a batch run's loop stops (the backend's stop() then brings
     * every axis to a controlled stop); a serving NCK freezes its setpoints
     * and turns its drives off until reset, as LinuxCNC does. */
    int fault = be_rc != 0 ? NCK_LF_BACKEND : check_ferror(n) ? NCK_LF_FERROR
                : check_joint_limits(n) ? NCK_LF_JOINT : NCK_LF_NONE;
    if (fault) {
        if (fault == NCK_LF_BACKEND)
            n->cross.fault_line = n->loop->cur.line;
        atomic_store_explicit(&n->cross.loop_fault, fault, memory_order_release);
        if (n->batch)
            return NCP_RT_STOP;
        atomic_store_explicit(&n->cross.frozen, 1, memory_order_release);
        return NCP_RT_CONTINUE;
    }
    nck_inject_rest(n);
    if (n->batch) {
        if (n->for_s > 0 && (double)now_ns * 1e-9 >= n->for_s)
            n->loop->for_expired = 1;
        int held = n->loop->for_expired || n->loop->timing_stop ||
                   atomic_load_explicit(&n->ctl->stop, memory_order_relaxed);
        int done = n->loop->ended || (held && n->loop->scaler.r == 0 && n->loop->cur.v == 0);
        if (done && ++n->loop->settle >= SETTLE_CYCLES)
            return NCP_RT_STOP;
    } else if (virt && n->setup.virtual_pace > 0 && !rest) {
        struct timespec ts = { 0, (long)(n->cfg->servo_period * 1e9 / n->setup.virtual_pace) };
        clock_nanosleep(CLOCK_MONOTONIC, 0, &ts, NULL);
    } else if (virt && rest &&
               (atomic_load_explicit(&n->ctl->hold, memory_order_relaxed) ||
                /* waiting for the operator or an input: at the real rate */
                (n->loop->mach.wait != NCK_WAIT_NONE && n->loop->mach.wait != NCK_WAIT_SPINDLE &&
                 n->loop->mach.wait != NCK_WAIT_ORIENT && n->loop->mach.wait != NCK_WAIT_INDEX) ||
                (!stream_expected(n) && ncp_spsc_count(&n->cross.sps) == 0))) {
        idle_nap(n);
    }
    return NCP_RT_CONTINUE;
}

void nck_loop_report(const struct nck_core *n, struct nck_loop_report *r)
{
    const struct nck_loop *l = n->loop;
    *r = (struct nck_loop_report){ l->underruns, l->dry, l->fb_dropped, l->ended,
                                   l->for_expired, l->end_ns, l->line_done };
}
