/* Homing on the position loop, as LinuxCNC's motion controller homes its
 * joints: each axis of a request moves on its own (the planner is idle),
 * the axes of one HOME_SEQUENCE together, the sequences in ascending order.
 * Per axis: off the switch if it is pressed already, search at
 * HOME_SEARCH_VEL until it is pressed, back off it when HOME_LATCH_VEL has
 * the search's sign, latch at HOME_LATCH_VEL (onto the switch, or off it
 * for the opposite sign), where the machine position becomes HOME_OFFSET,
 * then to HOME at HOME_FINAL_VEL. Every event is seen on the actual
 * position, once per servo period, and each phase ends in a stop at the
 * axis's MAX_ACCELERATION. The switch is the drive's input where the
 * backend reads one (CiA 402 drives: 0x60FD bit 2); the simulated switch is
 * pressed on the search's side of [SIM] HOME_SWITCH_<axis> (HOME_OFFSET
 * without it).
 * An axis with HOME_METHOD = drive:N is homed by its drive instead (the
 * backend's drive_home): its command follows the actual position while
 * the drive homes, and once the drive is homed its counts are the machine
 * position (the drive's position at home is HOME_OFFSET, 0x607C), so the
 * axis stands latched there and goes on to HOME as any other.
 * The loop functions are on the real-time path: no allocation, locks or
 * system calls. */
#include "nck_int.h"
#include "loop_state.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SEARCH_TRAVEL 1.5   /* a search gives up after this many times the axis's travel */

int nck_home_seq(const struct ncp_machine_cfg *c, int axis)
{
    for (int j = 0; j < NCP_AXES; j++)
        if ((c->axis_mask & NCP_AXIS_BIT(j)) && c->axis[j].have_home_sequence)
            return c->axis[axis].have_home_sequence ? abs(c->axis[axis].home_sequence) : 0;
    return axis == 2 ? 0 : 1;
}

unsigned nck_home_all_mask(const struct ncp_machine_cfg *c)
{
    unsigned with = 0;
    for (int j = 0; j < NCP_AXES; j++)
        if ((c->axis_mask & NCP_AXIS_BIT(j)) && c->axis[j].have_home_sequence)
            with |= NCP_AXIS_BIT(j);
    return with ? with : c->axis_mask;
}

static double switch_at(const struct ncp_axis_cfg *a)
{
    return a->have_home_switch ? a->home_switch : a->home_offset;
}

static int pressed(const struct nck_core *n, int j, double act)
{
    /* a drive's own switch input (CAN: 0x60FD) where the backend reads one */
    const struct ncp_backend *be = &n->cross.be;
    int sw = be->ops->home_switch ? be->ops->home_switch(be, j) : -1;
    if (sw >= 0)
        return sw;
    const struct ncp_axis_cfg *a = &n->cfg->axis[j];
    double phys = act + n->loop->home.off[j];
    return (phys - switch_at(a)) * (a->home_search_vel > 0 ? 1 : -1) >= 0;
}

/* The machine position of axis j becomes `at` where the simulated machine
 * stands at phys: what is commanded moves along, so nothing jumps. */
static void set_position(struct nck_core *n, int j, double phys, double at)
{
    struct nck_homing *h = &n->loop->home;
    double d = h->off[j] - (phys - at);
    h->off[j] = phys - at;
    h->ax[j].pos += d;
    h->ax[j].from += d;
    n->loop->next.pos[j] += d;
    n->loop->probe.last[j] += d;
}

static void begin_phase(struct nck_homing *h, int j, int phase)
{
    h->ax[j].phase = phase;
    h->ax[j].stopping = 0;
    h->ax[j].from = h->ax[j].pos;
}

static void stop_all(struct nck_core *n, int result, int axis);

static void begin_axis(struct nck_core *n, int j)
{
    struct nck_homing *h = &n->loop->home;
    const struct ncp_axis_cfg *a = &n->cfg->axis[j];
    h->ax[j].queued = 0;
    if (a->home_drive) {
        struct ncp_backend *be = &n->cross.be;
        begin_phase(h, j, NCK_HP_DRIVE);
        if (!be->ops->drive_home || be->ops->drive_home(be, j, 1) != 0) {
            h->ax[j].phase = NCK_HP_NONE;
            stop_all(n, NCK_HOME_NO_DRIVE, j);
        }
        return;
    }
    if (a->home_search_vel == 0) {
        /* no switch: the axis is homed where it stands */
        double phys = n->loop->probe.last[j] + h->off[j];
        n->cross.home.latched[j] = phys;
        set_position(n, j, phys, a->home_offset);
        begin_phase(h, j, NCK_HP_FINAL);
        return;
    }
    begin_phase(h, j, pressed(n, j, n->loop->probe.last[j]) ? NCK_HP_OFF_SWITCH : NCK_HP_SEARCH);
}

/* The velocity each phase runs at (0 once its event came). */
static double phase_vel(const struct ncp_axis_cfg *a, const struct nck_home_axis *x)
{
    if (x->stopping)
        return 0;
    switch (x->phase) {
    case NCK_HP_OFF_SWITCH:
    case NCK_HP_BACK_OFF: return -a->home_search_vel;
    case NCK_HP_SEARCH: return a->home_search_vel;
    case NCK_HP_LATCH: return a->home_latch_vel;
    default: return 0;
    }
}

/* One period towards `to`, never faster than vmax nor harder than a: 1 when
 * there. The speed allowed at distance d is the one that stops on `to` in
 * whole periods of a * dt less each (d = a dt^2 n (n + 1) / 2 at n a dt),
 * so the last period lands without a jump. */
static int approach(struct nck_home_axis *x, double to, double vmax, double a, double dt)
{
    double d = to - x->pos;
    double stop = a * dt * (sqrt(2 * fabs(d) / (a * dt * dt) + 0.25) - 0.5);
    double want = copysign(fmin(vmax, stop), d);
    double v = fmin(fmax(want, x->v - a * dt), x->v + a * dt);
    if (fabs(d) <= fabs(v) * dt || (fabs(d) < 1e-9 && fabs(x->v) <= a * dt)) {
        x->pos = to;
        x->v = 0;
        return 1;
    }
    x->pos += v * dt;
    x->v = v;
    return 0;
}

/* The group's synchronised axes (negative HOME_SEQUENCE) start their final
 * moves together, once every one of them has latched and stopped. */
static int group_latched(const struct nck_core *n, int seq)
{
    const struct nck_homing *h = &n->loop->home;
    for (int j = 0; j < NCP_AXES; j++)
        if ((n->cross.home.mask & NCP_AXIS_BIT(j)) && n->cfg->axis[j].home_sequence < 0 &&
            nck_home_seq(n->cfg, j) == seq &&
            (h->ax[j].phase != NCK_HP_LATCHED || h->ax[j].v != 0 || h->ax[j].queued))
            return 0;
    return 1;
}

static void next_phase(struct nck_core *n, int j)
{
    struct nck_homing *h = &n->loop->home;
    const struct ncp_axis_cfg *a = &n->cfg->axis[j];
    struct nck_home_axis *x = &h->ax[j];
    if (n->cross.home.result != NCK_HOME_OK) {
        x->phase = NCK_HP_NONE;
        return;
    }
    switch (x->phase) {
    case NCK_HP_OFF_SWITCH: begin_phase(h, j, NCK_HP_SEARCH); break;
    case NCK_HP_SEARCH:
        begin_phase(h, j, a->home_latch_vel * a->home_search_vel > 0 ? NCK_HP_BACK_OFF
                                                                     : NCK_HP_LATCH);
        break;
    case NCK_HP_BACK_OFF: begin_phase(h, j, NCK_HP_LATCH); break;
    case NCK_HP_LATCHED:
        if (a->home_sequence >= 0 || group_latched(n, nck_home_seq(n->cfg, j)))
            begin_phase(h, j, NCK_HP_FINAL);
        break;
    default: x->phase = NCK_HP_NONE; break;
    }
}

static void stop_all(struct nck_core *n, int result, int axis)
{
    struct nck_homing *h = &n->loop->home;
    struct nck_home_req *r = &n->cross.home;
    if (r->result == NCK_HOME_OK) {
        r->result = result;
        r->fail_axis = axis;
    }
    for (int j = 0; j < NCP_AXES; j++) {
        h->ax[j].queued = 0;
        if (h->ax[j].phase != NCK_HP_NONE)
            h->ax[j].stopping = 1;
    }
}

static void finish(struct nck_core *n)
{
    struct nck_homing *h = &n->loop->home;
    h->active = 0;
    n->loop->next.v = 0;
    memcpy(n->cross.home.final, n->loop->next.pos, sizeof n->cross.home.final);
    ncp_scaler_rebase(&n->loop->scaler, n->loop->next.pos);
    nck_loop_note_read(n);
    n->loop->ends_seen = n->loop->scaler.ends;
    atomic_store_explicit(&n->cross.home.done, h->taken, memory_order_release);
}

/* Starts the next HOME_SEQUENCE when the last one is over: 1 while any
 * axis homes. */
static int start_group(struct nck_core *n)
{
    struct nck_homing *h = &n->loop->home;
    int seq = -1;
    for (int j = 0; j < NCP_AXES; j++) {
        if (h->ax[j].phase != NCK_HP_NONE)
            return 1;
        if (h->ax[j].queued && (seq < 0 || nck_home_seq(n->cfg, j) < seq))
            seq = nck_home_seq(n->cfg, j);
    }
    if (seq < 0)
        return 0;
    for (int j = 0; j < NCP_AXES; j++)
        if (h->ax[j].queued && nck_home_seq(n->cfg, j) == seq)
            begin_axis(n, j);
    return 1;
}

static void step_axis(struct nck_core *n, int j, double dt)
{
    struct nck_homing *h = &n->loop->home;
    const struct ncp_axis_cfg *a = &n->cfg->axis[j];
    struct nck_home_axis *x = &h->ax[j];
    if (x->phase == NCK_HP_DRIVE) {
        /* the drive moves; the command follows it (nck_home_sense) */
        struct ncp_backend *be = &n->cross.be;
        if (x->stopping && !x->aborted) {
            be->ops->drive_home(be, j, -1);
            x->aborted = 1;
        }
        return;
    }
    if (x->phase == NCK_HP_FINAL && !x->stopping) {
        double vf = a->home_final_vel > 0 ? a->home_final_vel : a->max_vel;
        if (approach(x, a->home, vf, a->max_acc, dt))
            x->phase = NCK_HP_NONE;
        return;
    }
    double vt = phase_vel(a, x), dv = a->max_acc * dt;
    x->v = fmin(fmax(vt, x->v - dv), x->v + dv);
    x->pos += x->v * dt;
    if (x->v == 0 && (x->stopping || x->phase == NCK_HP_LATCHED))
        next_phase(n, j);
    else if (!x->stopping && x->phase != NCK_HP_LATCHED &&
             fabs(x->pos - x->from) > SEARCH_TRAVEL * (a->max_limit - a->min_limit))
        stop_all(n, NCK_HOME_NOT_FOUND, j);
}

int nck_home_take(struct nck_core *n)
{
    struct nck_homing *h = &n->loop->home;
    if (!h->active) {
        uint32_t req = atomic_load_explicit(&n->cross.home.req, memory_order_acquire);
        if (req == h->taken)
            return 0;
        h->taken = req;
        h->active = 1;
        n->cross.home.result = NCK_HOME_OK;
        n->cross.home.fail_axis = -1;
        for (int j = 0; j < NCP_AXES; j++) {
            struct nck_home_axis *x = &h->ax[j];
            memset(x, 0, sizeof *x);
            n->cross.home.latched[j] = 0;
            x->pos = n->loop->next.pos[j];
            x->queued = (n->cross.home.mask & n->cfg->axis_mask & NCP_AXIS_BIT(j)) != 0;
        }
    }
    n->loop->cur = n->loop->next;
    if ((atomic_load_explicit(&n->ctl->hold, memory_order_relaxed) ||
         atomic_load_explicit(&n->ctl->stop, memory_order_relaxed)))
        stop_all(n, NCK_HOME_STOPPED, -1);
    if (!start_group(n)) {
        finish(n);
        return 1;
    }
    double v2 = 0;
    for (int j = 0; j < NCP_AXES; j++) {
        if (h->ax[j].phase == NCK_HP_NONE)
            continue;
        step_axis(n, j, n->cfg->servo_period);
        n->loop->next.pos[j] = h->ax[j].pos;
        v2 += h->ax[j].v * h->ax[j].v;
    }
    n->loop->next.v = sqrt(v2);
    n->loop->next.flags = 0;
    n->loop->next.line = 0;
    return 1;
}

/* An axis its drive homes: the command is the actual position, so that
 * nothing jumps when the drive follows it again; once homed, the drive's
 * counts are the machine position. */
static void drive_sense(struct nck_core *n, int j, double act)
{
    struct nck_homing *h = &n->loop->home;
    struct nck_home_axis *x = &h->ax[j];
    struct ncp_backend *be = &n->cross.be;
    x->pos = act;
    int r = be->ops->drive_home(be, j, 0);
    if (r == 1)
        return;
    x->v = 0;
    x->stopping = 0;
    /* The command followed the drive two periods late (this period's was
     * taken from the actual of two before), and the following error is
     * checked again from this period on. The drive jumps to its home
     * offset at home and may be back in CSP a period later (its TPDOs
     * bunched in one late period, the mode switch quick): compared with a
     * command from before the jump, that is a following error of the whole
     * offset. The drive got its own actual as target all along, so the
     * command of this period and the next is its actual. */
    n->loop->jcmd[j] = n->loop->jact[j];
    n->loop->next.pos[j] = act;
    if (r < 0 || n->cross.home.result != NCK_HOME_OK) {
        /* aborted, or failed (the backend's fault stops the loop) */
        if (n->cross.home.result == NCK_HOME_OK)
            stop_all(n, NCK_HOME_STOPPED, j);
        x->phase = NCK_HP_NONE;
        return;
    }
    double phys = act + h->off[j];
    n->cross.home.latched[j] = phys;
    set_position(n, j, phys, phys);
    /* the drive's home is HOME_OFFSET: latched, then on to HOME */
    x->phase = NCK_HP_LATCHED;
}

void nck_home_sense(struct nck_core *n, const double act[NCP_AXES])
{
    struct nck_homing *h = &n->loop->home;
    if (!h->active)
        return;
    for (int j = 0; j < NCP_AXES; j++) {
        struct nck_home_axis *x = &h->ax[j];
        if (x->phase == NCK_HP_DRIVE) {
            drive_sense(n, j, act[j]);
            continue;
        }
        if (x->stopping || x->phase < NCK_HP_OFF_SWITCH || x->phase > NCK_HP_LATCH)
            continue;
        const struct ncp_axis_cfg *a = &n->cfg->axis[j];
        int on = pressed(n, j, act[j]);
        int onto = a->home_latch_vel * a->home_search_vel > 0;
        switch (x->phase) {
        case NCK_HP_OFF_SWITCH:
        case NCK_HP_BACK_OFF: x->stopping = !on; break;
        case NCK_HP_SEARCH: x->stopping = on; break;
        default:
            if (on == onto) {
                /* the latch: here the machine position becomes HOME_OFFSET */
                n->cross.home.latched[j] = act[j] + h->off[j];
                set_position(n, j, n->cross.home.latched[j], a->home_offset);
                x->phase = NCK_HP_LATCHED;
            }
            break;
        }
    }
}

void nck_home_cancel(struct nck_core *n)
{
    struct nck_homing *h = &n->loop->home;
    if (!h->active)
        return;
    stop_all(n, NCK_HOME_STOPPED, -1);
    for (int j = 0; j < NCP_AXES; j++) {
        h->ax[j].phase = NCK_HP_NONE;
        h->ax[j].v = 0;
    }
    finish(n);
}

int nck_home_active(const struct nck_core *n)
{
    return n->loop->home.active;
}

uint64_t nck_home_phases(const struct nck_core *n)
{
    uint64_t p = 0;
    if (!n->loop->home.active)
        return 0;
    for (int j = 0; j < NCP_AXES; j++)
        p |= (uint64_t)n->loop->home.ax[j].phase << (4 * j);
    return p;
}

/* ---- the caller's thread ------------------------------------------------------------- */

void nck_home_request(struct nck_core *n, unsigned mask)
{
    n->cross.home.mask = mask;
    atomic_fetch_add_explicit(&n->cross.home.req, 1, memory_order_release);
}

int nck_home_finished(const struct nck_core *n)
{
    return atomic_load_explicit(&n->cross.home.done, memory_order_acquire) ==
           atomic_load_explicit(&n->cross.home.req, memory_order_relaxed);
}

int nck_home_report(const struct nck_core *n, char *buf, size_t len)
{
    const struct nck_home_req *h = &n->cross.home;
    size_t at = 0;
    buf[0] = 0;
    if (h->result == NCK_HOME_NOT_FOUND) {
        const struct ncp_axis_cfg *a = &n->cfg->axis[h->fail_axis];
        snprintf(buf, len, "homing %c: no home switch within %.4f mm of travel at "
                           "HOME_SEARCH_VEL %.4f mm/s (switch at %.4f); the machine is not homed",
                 NCP_AXIS_LETTERS[h->fail_axis],
                 SEARCH_TRAVEL * (a->max_limit - a->min_limit), a->home_search_vel, switch_at(a));
        return -1;
    }
    if (h->result == NCK_HOME_NO_DRIVE) {
        snprintf(buf, len, "homing %c: HOME_METHOD = drive:%d has the axis's drive home itself, "
                           "and this backend has no drive that does (CiA 402 drives: --backend "
                           "socketcan, with a NODE_ID for the axis); the machine is not homed",
                 NCP_AXIS_LETTERS[h->fail_axis], n->cfg->axis[h->fail_axis].home_method);
        return -1;
    }
    if (h->result == NCK_HOME_STOPPED) {
        snprintf(buf, len, "homing stopped before it was complete; the machine is not homed");
        return -1;
    }
    for (int j = 0; j < NCP_AXES && at < len; j++) {
        if (!(h->mask & n->cfg->axis_mask & NCP_AXIS_BIT(j)))
            continue;
        const struct ncp_axis_cfg *a = &n->cfg->axis[j];
        int k = a->home_drive
                    ? snprintf(buf + at, len - at, "%shomed %c by its drive (node %d, homing "
                               "method %d): position HOME_OFFSET %.4f where the drive found "
                               "home, now at %.4f, then to HOME %.4f", at ? "\n" : "",
                               NCP_AXIS_LETTERS[j], a->node_id, a->home_method, a->home_offset,
                               h->latched[j], a->home)
                : a->home_search_vel == 0
                    ? snprintf(buf + at, len - at, "%shomed %c: no switch, position set to "
                               "HOME_OFFSET %.4f where it stood, then to HOME %.4f",
                               at ? "\n" : "", NCP_AXIS_LETTERS[j], a->home_offset, a->home)
                    : snprintf(buf + at, len - at, "%shomed %c: switch at %.4f latched at %.4f "
                               "(%+.4f mm), position set to HOME_OFFSET %.4f there, then to "
                               "HOME %.4f", at ? "\n" : "", NCP_AXIS_LETTERS[j], switch_at(a),
                               h->latched[j], h->latched[j] - switch_at(a), a->home_offset,
                               a->home);
        if (k < 0)
            break;
        at += (size_t)k;
    }
    return 0;
}
