/* The machine functions on the position loop: the simulated spindle (speed
 * ramps at [SPINDLE_0] MAX_ACCELERATION, angle kept for spindle-synchronised
 * motion), coolant, digital and analog outputs, input waits and the pauses
 * that wait for the operator. Packs of actions come from the job thread on
 * their own ring; each is applied when the position loop reaches the sample
 * that carries its number (see nck_int.h). While an action waits, the loop
 * holds the axes where they stand: the planner brought them to a stop there.
 * Real-time rules: no allocation, locks or system calls here. */
#include "nck_int.h"
#include "loop_state.h"

#include <math.h>
#include <string.h>

static double ramp(double from, double to, double step)
{
    if (step <= 0)
        return to;
    return to > from ? fmin(to, from + step) : fmax(to, from - step);
}

/* M19: brake to a stop, then turn (P0 clockwise = as M3, P1 the other way,
 * P2 the shorter way) to the angle at ORIENT_RPM at most, braking into it. */
static void orient_step(struct nck_core *n, double dt)
{
    struct nck_mach *m = &n->loop->mach;
    const struct ncp_io_cfg *io = &n->cfg->io;
    double acc = io->spindle_acc;
    if (m->orienting == 1) {
        m->rpm = ramp(m->rpm, 0, acc * dt);
        m->rev += m->rpm / 60 * dt;
        if (m->rpm != 0)
            return;
        double up = m->orient_to - (m->rev - floor(m->rev));
        up -= floor(up);          /* 0..1 turns the clockwise way */
        m->orient_sign = m->orient_dir == 1 ? -1 : m->orient_dir == 2 && up > 0.5 ? -1 : 1;
        m->orienting = 2;
    }
    double left = m->orient_to - (m->rev - floor(m->rev));
    left -= floor(left);
    if (m->orient_sign < 0)
        left = left > 0 ? 1 - left : 0;
    double v = io->orient_rpm / 60;   /* turns per second */
    if (acc > 0)
        v = fmin(v, sqrt(2 * acc / 60 * left));
    if (left <= v * dt || left < 1e-9) {
        m->rev = floor(m->rev) + m->orient_to;
        m->rpm = 0;
        m->orienting = 0;
        return;
    }
    m->rpm = m->orient_sign * v * 60;
    m->rev += m->orient_sign * v * dt;
}

static void spindle_step(struct nck_core *n)
{
    struct nck_mach *m = &n->loop->mach;
    double dt = n->cfg->servo_period;
    if (m->orienting) {
        orient_step(n, dt);
        return;
    }
    m->rpm = ramp(m->rpm, nck_spindle_target(n), n->cfg->io.spindle_acc * dt);
    m->rev += m->rpm / 60 * dt;
}

/* A pause for the operator: resume (tool: tool-changed) goes on; a batch run
 * goes on by itself after AUTO_RESUME_S unless that is negative (SIGUSR1,
 * which the batch turns into a resume). */
static int operator_wait(struct nck_core *n, int kind, uint32_t line, _Atomic uint64_t *go)
{
    struct nck_mach *m = &n->loop->mach;
    if (m->wait != kind) {
        m->waits++;
        m->wait = kind;
        m->wait_line = line;
        m->wait_since = n->loop->now_ns;
        m->resume_used = atomic_load_explicit(go, memory_order_acquire);
    }
    /* a pause lasts one cycle at least: the trace and the operator see it */
    if (n->loop->now_ns == m->wait_since)
        return 1;
    if (atomic_load_explicit(go, memory_order_acquire) > m->resume_used)
        return 0;
    double after = n->cfg->io.auto_resume_s;
    if (n->batch && after >= 0 && (double)(n->loop->now_ns - m->wait_since) * 1e-9 >= after - 1e-12)
        return 0;
    return 1;
}

static int input_wait(struct nck_core *n, const struct nck_aux *a)
{
    struct nck_mach *m = &n->loop->mach;
    if (a->a) {               /* analog: L0 only (the interpreter checks) */
        n->cross.m66_result = n->cfg->io.ain[a->idx];
        return 0;
    }
    int v = (int)((atomic_load_explicit(&n->ctl->din, memory_order_acquire) >> a->idx) & 1u);
    if (m->wait != NCK_WAIT_INPUT) {
        m->waits++;
        m->wait = NCK_WAIT_INPUT;
        m->wait_line = a->line;
        m->wait_since = n->loop->now_ns;
        m->in_last = v;
    }
    int done;
    switch (a->i) {
    case 1: done = !m->in_last && v; break;     /* rise */
    case 2: done = m->in_last && !v; break;     /* fall */
    case 3: done = v; break;                    /* high */
    case 4: done = !v; break;                   /* low */
    default: done = 1; break;                   /* immediate */
    }
    m->in_last = v;
    if (done) {
        n->cross.m66_result = v;
        return 0;
    }
    if ((double)(n->loop->now_ns - m->wait_since) * 1e-9 >= a->v) {
        n->cross.m66_result = -1;   /* timed out, as rs274 reports it */
        return 0;
    }
    return 1;
}

/* One action: 1 while it waits. */
static int act(struct nck_core *n, const struct nck_aux *a)
{
    struct nck_mach *m = &n->loop->mach;
    switch (a->kind) {
    case NCK_AUX_SPINDLE:
        m->rpm_cmd = a->v;
        m->orienting = 0;
        return 0;
    case NCK_AUX_ORIENT:
        if (m->wait != NCK_WAIT_ORIENT) {
            m->waits++;
            m->wait = NCK_WAIT_ORIENT;
            m->wait_line = a->line;
            m->rpm_cmd = 0;
            m->orienting = 1;
            m->orient_dir = a->i;
            m->orient_to = a->v / 360 - floor(a->v / 360);
        }
        return m->orienting != 0;
    case NCK_AUX_AT_SPEED:
        if (nck_spindle_at_speed(n))
            return 0;
        if (m->wait != NCK_WAIT_SPINDLE)
            m->waits++;
        m->wait = NCK_WAIT_SPINDLE;
        m->wait_line = a->line;
        return 1;
    case NCK_AUX_MIST: m->mist = a->i; return 0;
    case NCK_AUX_FLOOD: m->flood = a->i; return 0;
    case NCK_AUX_DOUT:
        if (a->i)
            m->dout |= 1ull << a->idx;
        else
            m->dout &= ~(1ull << a->idx);
        return 0;
    case NCK_AUX_AOUT: m->aout[a->idx] = a->v; return 0;
    case NCK_AUX_PREPARE:
        m->prepared = a->i;
        if (a->idx)         /* M61: job.c marks it in idx */
            m->tool = a->i;
        return 0;
    case NCK_AUX_ENABLE: m->en[a->i & 3] = a->v != 0; return 0;
    case NCK_AUX_PROBE: nck_probe_arm(n, a->i); return 0;
    case NCK_AUX_SYNC: return nck_sync_cycle(n);
    case NCK_AUX_WAIT_INPUT: return input_wait(n, a);
    case NCK_AUX_PAUSE:
        if (a->i == NCK_WAIT_M1 && !atomic_load_explicit(&n->ctl->optional_stop,
                                                          memory_order_relaxed))
            return 0;
        return operator_wait(n, a->i, a->line, &n->ctl->resume_go);
    case NCK_AUX_TOOL:
        if (operator_wait(n, NCK_WAIT_TOOL, a->line, &n->ctl->tool_go))
            return 1;
        m->tool = a->i;
        return 0;
    default:
        return 0;
    }
}

int nck_aux_cycle(struct nck_core *n)
{
    struct nck_mach *m = &n->loop->mach;
    /* once per instant: a virtual clock's retry is the same period again */
    if (!m->spun || m->spun_at != n->loop->now_ns) {
        spindle_step(n);
        m->spun = 1;
        m->spun_at = n->loop->now_ns;
    }
    for (;;) {
        if (!m->have_pack) {
            if (!m->have_ahead)
                m->have_ahead = ncp_spsc_pop(&n->cross.auxq, &m->ahead) == 0;
            if (!m->have_ahead || m->ahead.seq > m->seq_reached)
                return 0;
            m->pack = m->ahead;
            m->have_ahead = 0;
            m->have_pack = 1;
            m->at = 0;
        }
        while (m->at < m->pack.n) {
            int r = act(n, &m->pack.a[m->at]);
            if (r == 2)        /* a synchronised run: the stream is still on its way */
                return 0;
            if (r)
                return 1;
            m->wait = NCK_WAIT_NONE;
            m->at++;
        }
        m->have_pack = 0;
    }
}

/* A drop (stop, abort, E-stop, fault): what was queued is gone, and the
 * spindle and coolant go off, as LinuxCNC's abort turns them off. */
void nck_aux_discard(struct nck_core *n)
{
    struct nck_mach *m = &n->loop->mach;
    while (ncp_spsc_pop(&n->cross.auxq, &m->ahead) == 0)
        ;
    m->have_ahead = m->have_pack = 0;
    nck_sync_discard(n);
    m->wait = NCK_WAIT_NONE;
    m->rpm_cmd = 0;
    m->orienting = 0;
    m->mist = m->flood = 0;
}
