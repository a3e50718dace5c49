/* Spindle-synchronised motion on the position loop (G33, G76's passes,
 * G33.1), as LinuxCNC's position-synchronised mode: the run waits until the
 * spindle is at speed and then for its index (the angle crossing a whole
 * turn), so every pass of a thread starts at the same spindle angle and cuts
 * the same groove. From there the run's distance along its path is meant to
 * be pitch x the turns since the index. The axes start from rest while the
 * spindle is already turning, so they catch up within their acceleration
 * and then lock: each period the speed is the spindle's (times the pitch)
 * plus a correction that brings the remaining error to zero no faster than
 * it can still be braked (sqrt(2 a e)), and no more than the error itself
 * (no overshoot from one period to the next). A thread brakes into its end
 * as LinuxCNC's does (that part is cut out of sync; programs run the thread
 * out past the part). A rigid tap (G33.1) follows the spindle in, reverses
 * it at the bottom and follows it back out (overshooting the bottom while
 * the spindle brakes), reverses it again at the top and, once it turns the
 * tap's way again, moves back to where the tap started.
 * Real-time rules: no allocation, locks or system calls here. */
#include "nck_int.h"
#include "loop_state.h"

#include <math.h>
#include <string.h>

/* A share of the path acceleration for the catch-up's braking curve: the
 * rest keeps each period's step within the limit. */
#define CATCH_UP_SHARE 0.5

/* The path's acceleration and speed caps: every axis within its own. */
static void run_limits(struct nck_core *n)
{
    struct nck_sync_state *st = &n->loop->sync;
    const struct nck_sync_run *r = &st->run;
    const double *from = r->start;
    st->acc = INFINITY;
    st->vmax = n->cfg->max_linear_vel;
    st->total = 0;
    for (int i = 0; i < r->n; i++) {
        for (int j = 0; j < NCP_AXES; j++) {
            double u = fabs(r->l[i].end[j] - from[j]) / r->l[i].len;
            if (u < 1e-12)
                continue;
            st->acc = fmin(st->acc, n->cfg->axis[j].max_acc / u);
            st->vmax = fmin(st->vmax, n->cfg->axis[j].max_vel / u);
        }
        st->total += r->l[i].len;
        from = r->l[i].end;
    }
    if (!isfinite(st->acc))
        st->acc = 1.0;
}

/* Distance along the run the spindle's turns u (since the index, the
 * spindle's way) stand for, and the pitch there. Before the start and past
 * the end the first and last lines go on straight (a tap's overshoots). */
static double turns_to_dist(const struct nck_sync_run *r, double u, double *pitch)
{
    double s = 0;
    for (int i = 0; i < r->n; i++) {
        double span = r->l[i].len / r->l[i].pitch;
        *pitch = r->l[i].pitch;
        if (u <= span || i == r->n - 1)
            return s + u * r->l[i].pitch;
        u -= span;
        s += r->l[i].len;
    }
    return s;
}

/* The axes at distance s along the run, its direction there and the line. */
static void run_point(const struct nck_sync_run *r, double s, double pos[NCP_AXES],
                      double dir[NCP_AXES], uint32_t *line)
{
    const double *from = r->start;
    int i = 0;
    while (i < r->n - 1 && s > r->l[i].len) {
        s -= r->l[i].len;
        from = r->l[i].end;
        i++;
    }
    const struct nck_sync_line *l = &r->l[i];
    for (int j = 0; j < NCP_AXES; j++) {
        dir[j] = (l->end[j] - from[j]) / l->len;
        pos[j] = from[j] + dir[j] * s;
    }
    *line = l->line;
}

/* One period's speed towards target (where the run should be at the end of
 * the period), which moves at vt. */
static double follow(const struct nck_sync_state *st, double target, double vt, double T)
{
    double e = target - (st->s + vt * T);
    double ac = CATCH_UP_SHARE * st->acc;
    double fix = fmin(sqrt(2 * ac * fabs(e)), fabs(e) / T);
    return vt + copysign(fix, e);
}

/* The speed after this period: v within the acceleration and speed limits. */
static double limit(const struct nck_sync_state *st, double v, double T)
{
    double dv = st->acc * T;
    v = fmax(st->v - dv, fmin(st->v + dv, v));
    return fmax(-st->vmax, fmin(st->vmax, v));
}

/* A thread's end: brake so as to stop on it. */
static double brake(const struct nck_sync_state *st, double v, double T)
{
    double left = fmax(0.0, st->total - st->s);
    return fmin(v, fmin(sqrt(2 * CATCH_UP_SHARE * st->acc * left), left / T));
}

static void write_next(struct nck_core *n)
{
    struct nck_sync_state *st = &n->loop->sync;
    run_point(&st->run, st->s, n->loop->next.pos, n->loop->next.dir, &n->loop->next.line);
    n->loop->next.v = fabs(st->v);
    n->loop->next.flags = NCP_SP_SYNC;
    n->loop->next.rev_rpm = 0;
    if (st->v < 0)
        for (int j = 0; j < NCP_AXES; j++)
            n->loop->next.dir[j] = -n->loop->next.dir[j];
}

static void begin_wait(struct nck_core *n, int kind)
{
    struct nck_mach *m = &n->loop->mach;
    if (m->wait != kind) {
        m->waits++;
        m->wait = kind;
        m->wait_line = n->loop->sync.run.l[0].line;
    }
}

/* The spindle's turns since the index, counted the way it turned at the
 * start, and their rate (turns per second), at the instant the setpoint
 * being made is commanded: one period on (the loop runs a setpoint ahead). */
static double turns(const struct nck_core *n, double *rate)
{
    const struct nck_sync_state *st = &n->loop->sync;
    *rate = st->sgn * n->loop->mach.rpm / 60.0;
    return st->sgn * (n->loop->mach.rev - st->index) + *rate * n->cfg->servo_period;
}

/* The motion of one period once locked on to the index. */
static void move(struct nck_core *n)
{
    struct nck_sync_state *st = &n->loop->sync;
    struct nck_mach *m = &n->loop->mach;
    double T = n->cfg->servo_period, rate, pitch = 0;
    double u = turns(n, &rate);
    double target = turns_to_dist(&st->run, u, &pitch), vt = pitch * rate;
    if (st->phase == NCK_SYNC_PLACE) {
        target = 0;
        vt = 0;
    }
    double v = follow(st, target, vt, T);
    if (st->phase == NCK_SYNC_FOLLOW)
        v = brake(st, v, T);
    st->v = limit(st, v, T);
    st->s += st->v * T;
    switch (st->phase) {
    case NCK_SYNC_FOLLOW:
        if (st->total - st->s < 1e-9 && fabs(st->v) <= st->acc * T) {
            st->s = st->total;
            st->v = 0;
            st->phase = NCK_SYNC_DONE;
        }
        break;
    case NCK_SYNC_TAP_IN:        /* the bottom: reverse the spindle */
        if (st->s >= st->total) {
            m->rpm_cmd = -st->rpm_cmd;
            st->phase = NCK_SYNC_TAP_OUT;
        }
        break;
    case NCK_SYNC_TAP_OUT:       /* back at the top: the spindle turns the tap's way again */
        if (st->s <= 0 && st->v < 0) {
            m->rpm_cmd = st->rpm_cmd;
            st->phase = NCK_SYNC_TAP_TURN;
        }
        break;
    case NCK_SYNC_TAP_TURN:      /* followed out until the spindle has turned round */
        if (st->sgn * m->rpm >= 0)
            st->phase = NCK_SYNC_PLACE;
        break;
    case NCK_SYNC_PLACE:
        if (fabs(st->s) < 1e-9 && fabs(st->v) <= st->acc * T) {
            st->s = 0;
            st->v = 0;
            st->phase = NCK_SYNC_DONE;
        }
        break;
    default:
        break;
    }
}

/* The run the loop is about to start: off the sync ring. 0, or -1 when
 * the ring has none (a dropped queue): nothing to do. */
static int begin(struct nck_core *n)
{
    struct nck_sync_state *st = &n->loop->sync;
    if (ncp_spsc_pop(&n->cross.syncq, &st->run) != 0 || st->run.n <= 0)
        return -1;
    run_limits(n);
    st->s = st->v = 0;
    st->rpm_cmd = n->loop->mach.rpm_cmd;
    st->sgn = n->loop->mach.rpm_cmd < 0 ? -1 : 1;
    st->phase = NCK_SYNC_ARRIVE;
    return 0;
}

/* The stream sits at the run's start: it is the stop the planner made for
 * it (a machine function due a sample early waits for the landing). */
static int arrived(const struct nck_core *n)
{
    for (int j = 0; j < NCP_AXES; j++)
        if (fabs(n->loop->next.pos[j] - n->loop->sync.run.start[j]) > 1e-6)
            return 0;
    return n->loop->next.v == 0;
}

/* The run has ended away from where it started: the stream the planner made
 * after it starts there, so what the scaler holds of before moves too. */
static void hand_back(struct nck_core *n)
{
    struct nck_sync_state *st = &n->loop->sync;
    double end[NCP_AXES], dir[NCP_AXES], delta[NCP_AXES];
    uint32_t line;
    run_point(&st->run, st->s, end, dir, &line);
    for (int j = 0; j < NCP_AXES; j++)
        delta[j] = end[j] - st->run.start[j];
    ncp_scaler_jump(&n->loop->scaler, delta);
    n->loop->next.v = 0;
    n->loop->next.flags = 0;
    memset(n->loop->next.dir, 0, sizeof n->loop->next.dir);
    memcpy(n->loop->next.pos, end, sizeof end);
}

int nck_sync_cycle(struct nck_core *n)
{
    struct nck_sync_state *st = &n->loop->sync;
    if (st->phase == NCK_SYNC_IDLE && begin(n) != 0)
        return 0;
    switch (st->phase) {
    case NCK_SYNC_ARRIVE:
        if (!arrived(n))
            return 2;
        st->phase = NCK_SYNC_AT_SPEED;
        /* fall through */
    case NCK_SYNC_AT_SPEED:
        if (!nck_spindle_at_speed(n)) {
            begin_wait(n, NCK_WAIT_SPINDLE);
            return 1;
        }
        st->phase = NCK_SYNC_INDEX;
        st->rev_last = n->loop->mach.rev;
        begin_wait(n, NCK_WAIT_INDEX);
        return 1;
    case NCK_SYNC_INDEX: {
        double now = n->loop->mach.rev, last = st->rev_last;
        st->rev_last = now;
        if (floor(now) == floor(last)) {
            begin_wait(n, NCK_WAIT_INDEX);
            return 1;
        }
        /* the whole turn crossed: the index, exactly where it lies */
        st->index = now > last ? floor(now) : floor(last);
        n->loop->mach.wait = NCK_WAIT_NONE;
        st->phase = st->run.tap ? NCK_SYNC_TAP_IN : NCK_SYNC_FOLLOW;
        move(n);
        write_next(n);
        return 1;
    }
    case NCK_SYNC_DONE:
        hand_back(n);
        st->phase = NCK_SYNC_IDLE;
        return 0;
    default:
        move(n);
        write_next(n);
        return 1;
    }
}

void nck_sync_discard(struct nck_core *n)
{
    struct nck_sync_run r;
    while (ncp_spsc_pop(&n->cross.syncq, &r) == 0)
        ;
    n->loop->sync.phase = NCK_SYNC_IDLE;
}
