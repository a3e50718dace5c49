/* Look-ahead: per-segment speed and acceleration caps from the axis limits,
 * junction caps, and a backward pass that keeps every queued segment able to
 * stop at the end of the queue. The forward pass is done lazily, one segment at
 * a time, when the interpolator starts a segment (interp.c). */
#include "blend.h"
#include "planner_int.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* With fine interpolation (src/rt/scaler.c) the servo cycles between two
 * rough points follow a quintic through their positions, velocities and
 * accelerations (each point's acceleration that of the cubic through it and
 * the point before). Where the planned acceleration changes inside a
 * planning period the curve's acceleration overshoots it (a cubic's by up to
 * 2/3 when it reverses, a dip into a junction), so the plan keeps 3/5 of
 * each limit. A corner's velocity step is spread over the period instead of
 * one servo cycle, at most 4 dv / Tp, which the kink caps below keep within
 * their share when they take Tp / 4 as the period of the step (with the
 * S-curve the same caps keep the jerk of that spreading within the limit).
 * Its velocity strays from the plan by at most da Tp / 12 for an
 * acceleration change da (<= 2 a) inside the period: the velocity caps keep
 * that much room. tests/unit/test_motion_ipo.c checks the servo output. */
static void fine_ipo_margins(struct ncp_machine_cfg *c)
{
    int ratio = ncp_machine_cfg_ipo_ratio(c);
    if (ratio <= 1)
        return;
    double room = 0;
    for (int j = 0; j < NCP_AXES; j++) {
        c->axis[j].max_acc *= 0.6;
        double dv = 2 * c->axis[j].max_acc * c->planning_period / 12;
        c->axis[j].max_vel = fmax(0.5 * c->axis[j].max_vel, c->axis[j].max_vel - dv);
        room = fmax(room, dv);
    }
    c->max_linear_vel = fmax(0.5 * c->max_linear_vel, c->max_linear_vel - room);
    c->default_linear_acc *= 0.6;
    c->servo_period = c->planning_period / 4;
}

struct ncp_planner *ncp_planner_new(const struct ncp_machine_cfg *cfg,
                                    const double start[NCP_AXES])
{
    struct ncp_planner *p = calloc(1, sizeof *p);
    if (!p)
        return NULL;
    p->cfg = *cfg;
    ncp_edge_prepare();
    /* a blend arc's speed keeps its centripetal acceleration a_c below 0.95 of
     * its bound (arc_limits), at most 1.23 times the largest axis limit a (some
     * axis holds sqrt(2/3) of any plane), so a servo step's chord lies at most
     * a_c T^2 / 8 inside it; read at a fraction of a sample (after a rate
     * change, src/rt/scaler.c) a step across a sample cuts in up to twice
     * that again: 0.3 a T^2 covers both. G64 P is a distance in X Y Z, so
     * only their limits count: an axis the machine does not have keeps the
     * default 2000 mm/s^2 and would double the margin of one with 1000 */
    double a_max = 0;
    for (int j = 0; j < 3; j++)
        a_max = fmax(a_max, cfg->axis[j].max_acc);
    p->chord = 0.3 * a_max * cfg->servo_period * cfg->servo_period;
    /* an uneven corner parabola's acceleration vector may take every axis's
     * whole limit at once, more than those 1.23 a: twice its a T^2 / 8 */
    double a_all = 0;
    for (int j = 0; j < 3; j++)
        a_all += cfg->axis[j].max_acc * cfg->axis[j].max_acc;
    p->chord_all = 0.25 * sqrt(a_all) * cfg->servo_period * cfg->servo_period;
    fine_ipo_margins(&p->cfg);
    /* room for a blend arc per programmed segment: the window is LOOKAHEAD blocks */
    p->cap = 2 * (size_t)(cfg->lookahead > 1 ? cfg->lookahead : 1) + 2;
    /* a CAM chain held back for fairing takes at most a quarter of the window */
    p->fair_max = cfg->lookahead / 4 < PLAN_FAIR_MAX ? cfg->lookahead / 4 : PLAN_FAIR_MAX;
    p->q = calloc(p->cap, sizeof *p->q);
    if (!p->q) {
        free(p);
        return NULL;
    }
    ncp_exec_init(&p->ex, start, cfg->planning_period > 0 ? cfg->planning_period
                                                          : cfg->servo_period);
    return p;
}

void ncp_planner_free(struct ncp_planner *p)
{
    if (!p)
        return;
    free(p->q);
    free(p);
}

int ncp_planner_full(const struct ncp_planner *p)
{
    /* a push may add a blend arc too; blends do not count against the window,
     * a chain of lines held back for G64 Q counts as the one it will become,
     * lines held back for a moved vertex as themselves (a push may queue
     * them, with their blends) */
    return p->programmed + (p->chain_n > 0) + (size_t)p->fair_n + (size_t)p->edge_n >=
               (size_t)p->cfg.lookahead ||
           p->count + 2 + 2 * (size_t)p->edge_n > p->cap;
}

size_t ncp_planner_queued(const struct ncp_planner *p)
{
    return p->count;
}

int ncp_planner_idle(const struct ncp_planner *p)
{
    return !p->ex.active;
}

static void chain_flush(struct ncp_planner *p);
static void fair_flush(struct ncp_planner *p);

static void edge_release(struct ncp_planner *p);

void ncp_planner_finish(struct ncp_planner *p)
{
    chain_flush(p);
    fair_flush(p);
    edge_release(p);
    p->finished = 1;
}

void ncp_planner_restart(struct ncp_planner *p)
{
    p->finished = 0;
    p->have_last = 0;
}

void ncp_planner_reset(struct ncp_planner *p, const double pos[NCP_AXES])
{
    p->head = 0;
    p->count = 0;
    p->programmed = 0;
    p->finished = 0;
    p->have_last = 0;
    p->chain_n = 0;
    p->fair_n = 0;
    p->fair_out_n = 0;
    p->edge_n = 0;
    memset(&p->corner, 0, sizeof p->corner);
    /* the last block's line, machine functions and tool stay what the held
     * samples report */
    struct ncp_exec was = p->ex;
    ncp_exec_init(&p->ex, pos, was.period);
    p->ex.line = was.line;
    p->ex.aux = was.aux;
    p->ex.tool_z = was.tool_z;
}

void ncp_planner_get_stats(const struct ncp_planner *p, struct ncp_planner_stats *st)
{
    *st = p->st;
}

void ncp_planner_pop(struct ncp_planner *p)
{
    p->st.path_length += p->q[p->head].s.length;
    if (!p->q[p->head].blend)
        p->programmed--;
    p->head = (p->head + 1) % p->cap;
    p->count--;
}

static void line_limits(const struct ncp_planner *p, struct plan_seg *ps)
{
    const struct ncp_seg *s = &ps->s;
    /* a rotary-only move's path is in degrees: only its axes' limits apply */
    double vmax = s->angular ? s->feed : fmin(s->feed, p->cfg.max_linear_vel);
    double acc = INFINITY, jerk = INFINITY;
    for (int j = 0; j < NCP_AXES; j++) {
        double u = fabs(s->end[j] - s->start[j]) / s->length;
        if (u < 1e-12)
            continue;
        vmax = fmin(vmax, p->cfg.axis[j].max_vel / u);
        acc = fmin(acc, p->cfg.axis[j].max_acc / u);
        /* half: the other half is for the jerk a corner or a curvature step adds */
        if (p->cfg.axis[j].max_jerk > 0)
            jerk = fmin(jerk, 0.5 * p->cfg.axis[j].max_jerk / u);
    }
    ps->vmax = vmax;
    ps->acc = acc;
    ps->jerk = jerk;
}

/* S-curve on an arc, per axis, half of the jerk limit for the arc's own motion
 * (a sixth each for tangential jerk, the turning centripetal acceleration
 * v^3 k^2 and the turning tangential acceleration 3 v a k) and half for the
 * step of centripetal acceleration v^2 k at its ends, felt within one period. */
static void scurve_arc_caps(const struct ncp_planner *p, double jmax, double share, double km,
                            double *vmax, double *jerk)
{
    *jerk = fmin(*jerk, jmax / (6 * share));
    if (km > 1e-12) {
        *vmax = fmin(*vmax, cbrt(jmax / (6 * km * km)));
        *vmax = fmin(*vmax, sqrt(0.5 * jmax * p->cfg.servo_period / km));
    }
}

/* Along a helix the path acceleration is the tangential a_t along the tangent T
 * plus the centripetal a_n = v^2 kappa along the in-plane normal N, at right
 * angles: axis j feels a_t T_j + a_n N_j, at most sqrt(a_t^2 + a_n^2) times
 * sqrt(T_j^2 + N_j^2) (Cauchy-Schwarz), and T_j^2 + N_j^2 is at most
 * m^2 + f_a c (2 f_p m + f_a c) (m: axis j's share of the plane, c: of the
 * axis, f_p, f_a: the plane's and the axis's share of the motion; exactly m^2
 * on a plane arc). So every axis stays within its limit while the vector
 * stays within a_eff, the least limit over that bound; the cruise cap leaves
 * a_n at most an_share of it and the rest goes to a_t, as LinuxCNC's arcs
 * (0.866 / 0.5 at worst) rather than half of each axis's limit to either. */
static double arc_accel_bound(const struct ncp_planner *p, const struct ncp_seg *s,
                              double *kappa)
{
    double r = 0.5 * (s->r0 + s->r1);
    double f_plane = fabs(s->angle) * r / s->length, f_axis = fabs(s->axial) / s->length;
    double pitch = s->axial / fabs(s->angle);
    double a_eff = INFINITY;
    *kappa = r / (r * r + pitch * pitch);
    for (int j = 0; j < 3; j++) {  /* the arc's own axes: the others move as on a line */
        double m = sqrt(s->u[j] * s->u[j] + s->w[j] * s->w[j]), c = fabs(s->normal[j]);
        double b2 = m * m + f_axis * c * (2 * f_plane * m + f_axis * c);
        if (b2 > 1e-24)
            a_eff = fmin(a_eff, p->cfg.axis[j].max_acc / sqrt(b2));
    }
    return a_eff;
}

/* The most |kc cos(phi) + ks sin(phi) + d| reaches for phi between lo and
 * hi: at an end, or where the cosine about its phase peaks. */
static double sinusoid_abs_max(double kc, double ks, double d, double lo, double hi)
{
    double amp = hypot(kc, ks), psi = atan2(ks, kc);
    double best = fmax(fabs(kc * cos(lo) + ks * sin(lo) + d), fabs(kc * cos(hi) + ks * sin(hi) + d));
    if (amp < 1e-15)
        return best;
    if (hi - lo >= 2 * M_PI)
        return amp + fabs(d);
    for (double k = ceil((lo - psi) / M_PI); psi + k * M_PI <= hi; k++)
        best = fmax(best, fabs(amp * (fmod(fabs(k), 2) < 0.5 ? 1 : -1) + d));
    return best;
}

/* A short arc sweeps few directions: axis j sees at most nmax_j of the
 * centripetal acceleration and tmax_j of the tangential (their largest
 * shares over the sweep), so it stays within its limit while
 * a_n nmax_j + |a_t| tmax_j does, a box the disc a_eff lies within. Its
 * centripetal room min_j A_j / nmax_j may so exceed a_eff (up to sqrt 2
 * on a plane arc whose normal stays near a diagonal). */
static void arc_sweep_shares(const struct ncp_seg *s, double f_plane, double f_axis,
                             double nmax[3], double tmax[3])
{
    double lo = fmin(0, s->angle), hi = fmax(0, s->angle);
    double turn = s->angle < 0 ? -f_plane : f_plane, rise = s->axial < 0 ? -f_axis : f_axis;
    for (int j = 0; j < 3; j++) {
        nmax[j] = sinusoid_abs_max(s->u[j], s->w[j], 0, lo, hi);
        tmax[j] = sinusoid_abs_max(turn * s->w[j], -turn * s->u[j], rise * s->normal[j], lo, hi);
    }
}

static void arc_limits(const struct ncp_planner *p, struct plan_seg *ps, double an_share)
{
    const struct ncp_seg *s = &ps->s;
    double r = 0.5 * (s->r0 + s->r1);
    double f_plane = fabs(s->angle) * r / s->length, f_axis = fabs(s->axial) / s->length;
    double kappa, a_eff = arc_accel_bound(p, s, &kappa);
    double vmax = fmin(s->feed, p->cfg.max_linear_vel), acc_lin = INFINITY, jerk = INFINITY;
    /* the axes beyond X Y Z move linearly along the arc: a line's caps */
    for (int j = 3; j < NCP_AXES; j++) {
        double u = fabs(s->end[j] - s->start[j]) / s->length;
        if (u < 1e-12)
            continue;
        const struct ncp_axis_cfg *a = &p->cfg.axis[j];
        vmax = fmin(vmax, a->max_vel / u);
        acc_lin = fmin(acc_lin, a->max_acc / u);
        if (a->max_jerk > 0)
            jerk = fmin(jerk, 0.5 * a->max_jerk / u);
    }
    for (int j = 0; j < 3; j++) {
        double m = sqrt(s->u[j] * s->u[j] + s->w[j] * s->w[j]);
        double share = f_plane * m + f_axis * fabs(s->normal[j]);
        if (share < 1e-12)
            continue;
        const struct ncp_axis_cfg *a = &p->cfg.axis[j];
        vmax = fmin(vmax, a->max_vel / share);
        if (plan_scurve(p) && a->max_jerk > 0)
            scurve_arc_caps(p, a->max_jerk, share, kappa * m, &vmax, &jerk);
    }
    /* A fitted arc sweeps a few degrees (tiny's median 6): its cap and its
     * tangent read the box, where its normal near a diagonal leaves each axis
     * more than the disc would (bench/gen-planner.py's tiny 4.520 -> 4.382 s) */
    double room = a_eff;
    int box = kappa > 1e-12 && !plan_scurve(p) && ps->fitted;
    if (box) {
        double nmax[3], tmax[3];
        arc_sweep_shares(s, f_plane, f_axis, nmax, tmax);
        room = INFINITY;
        ps->box_kappa = kappa;
        for (int j = 0; j < 3; j++) {
            double a = p->cfg.axis[j].max_acc;
            if (nmax[j] > 1e-12)
                room = fmin(room, a / nmax[j]);
            ps->box_a[j] = tmax[j] > 1e-12 ? a / tmax[j] : INFINITY;
            ps->box_b[j] = tmax[j] > 1e-12 ? nmax[j] / tmax[j] : 0;
        }
    }
    if (kappa > 1e-12)
        vmax = fmin(vmax, sqrt(an_share * room / kappa));
    double an = vmax * vmax * kappa, acc = sqrt(fmax(0, a_eff * a_eff - an * an));
    if (box)
        acc = fmax(acc, plan_box_at(ps, an));
    ps->vmax = vmax;
    ps->acc = fmin(acc_lin, acc);
    ps->jerk = jerk;
    /* the S-curve's jerk caps assume the acceleration at the cruise cap */
    ps->a_eff = a_eff;
    ps->kappa = plan_scurve(p) ? 0 : kappa;
    ps->a_cap = acc_lin;
    /* tangential acceleration turns with the tangent: its jerk is 3 v a kappa */
    for (int j = 0; j < 3 && plan_scurve(p); j++) {
        double m = sqrt(s->u[j] * s->u[j] + s->w[j] * s->w[j]);
        if (p->cfg.axis[j].max_jerk > 0 && m > 1e-12 && vmax > 0)
            ps->acc = fmin(ps->acc, p->cfg.axis[j].max_jerk / (6 * 3 * vmax * kappa * m));
    }
}

/* A corner parabola (NCP_SEG_PARAB) at parameter speed v and acceleration
 * a_t: axis j moves at v g_j, g_j between the two lines' u1_j and u2_j, and
 * accelerates at v^2 k_j + a_t g_j, k_j = |u2_j - u1_j| / length (the
 * curve's constant second derivative). The cruise cap leaves v^2 k_j at
 * most share of the axis's limit and the tangent gets the rest at that cap.
 * S-curve: the acceleration steps from 0 to v^2 k_j where the curve meets a
 * line, within one period, so that step gets half of the jerk limit; the
 * tangential jerk j_t g_j and the turn of the tangential acceleration
 * (at most 3 v a_t k_j) a quarter each. */
static void parab_limits(const struct ncp_planner *p, struct plan_seg *ps, double share)
{
    const struct ncp_seg *s = &ps->s;
    double vmax = fmin(s->feed, p->cfg.max_linear_vel), acc = INFINITY, jerk = INFINITY;
    double g[NCP_AXES], k[NCP_AXES];
    ncp_seg_parab_rates(s, g, k);
    for (int j = 0; j < NCP_AXES; j++) {
        const struct ncp_axis_cfg *a = &p->cfg.axis[j];
        if (g[j] > 1e-12)
            vmax = fmin(vmax, a->max_vel / g[j]);
        if (k[j] > 1e-12)
            vmax = fmin(vmax, sqrt(share * a->max_acc / k[j]));
        if (k[j] > 1e-12 && plan_scurve(p) && a->max_jerk > 0)
            vmax = fmin(vmax, sqrt(0.5 * a->max_jerk * p->cfg.servo_period / k[j]));
    }
    for (int j = 0; j < NCP_AXES; j++) {
        const struct ncp_axis_cfg *a = &p->cfg.axis[j];
        if (g[j] > 1e-12)
            acc = fmin(acc, fmax(0, a->max_acc - vmax * vmax * k[j]) / g[j]);
        if (!plan_scurve(p) || a->max_jerk <= 0)
            continue;
        if (g[j] > 1e-12)
            jerk = fmin(jerk, 0.25 * a->max_jerk / g[j]);
        if (k[j] > 1e-12 && vmax > 0)
            acc = fmin(acc, a->max_jerk / (12 * vmax * k[j]));
    }
    ps->vmax = vmax;
    ps->acc = acc;
    ps->jerk = jerk;
    /* Below the cruise cap the turn takes less and the tangent may have
     * more, as on an arc (plan_acc_at): with a_n = v^2 |u2 - u1| / length
     * and h_j = |u2_j - u1_j| / |u2 - u1|, axis j feels a_t g_j + a_n h_j,
     * at most sqrt(a_t^2 + a_n^2) sqrt(g_j^2 + h_j^2) (Cauchy-Schwarz), so
     * the vector stays within the least a_j / sqrt(g_j^2 + h_j^2). The
     * S-curve keeps the cap's. */
    double du = 0, a_eff = INFINITY;
    for (int j = 0; j < NCP_AXES; j++)
        du += k[j] * k[j];
    du = sqrt(du);  /* |u2 - u1| / length */
    for (int j = 0; j < NCP_AXES && du > 0; j++) {
        double h = k[j] / du, b = sqrt(g[j] * g[j] + h * h);
        if (b > 1e-12)
            a_eff = fmin(a_eff, p->cfg.axis[j].max_acc / b);
    }
    ps->a_eff = a_eff;
    ps->kappa = plan_scurve(p) || !isfinite(a_eff) ? 0 : du;
    ps->a_cap = INFINITY;
}

/* An uneven corner parabola (ncp_seg_ratio): run only as the ramp from entry
 * v0 to ratio v0, on which axis j moves at most at v0 max(|u1_j|, ratio |u2_j|)
 * (its velocity turns linearly between the ends) and accelerates at
 * v0^2 curv_j; the feed holds at both ends and between. vmax is the highest
 * speed on it, the entry's cap that over max(1, ratio). */
static void ratio_limits(const struct ncp_planner *p, struct plan_seg *ps, double share)
{
    const struct ncp_seg *s = &ps->s;
    double ratio = ncp_seg_ratio(s), top = fmax(1, ratio);
    double v0 = fmin(s->feed, p->cfg.max_linear_vel) / top, g[NCP_AXES], k[NCP_AXES];
    ncp_seg_parab_rates(s, g, k);
    for (int j = 0; j < 3; j++) {
        const struct ncp_axis_cfg *a = &p->cfg.axis[j];
        double u1 = (s->center[j] - s->start[j]) / s->r0, u2 = (s->end[j] - s->center[j]) / s->r1;
        double vj = fmax(fabs(u1), ratio * fabs(u2));
        if (vj > 1e-12)
            v0 = fmin(v0, a->max_vel / vj);
        if (k[j] > 1e-12)
            v0 = fmin(v0, sqrt(share * a->max_acc / k[j]));
    }
    ps->vmax = v0 * top;
    ps->acc = v0 * v0 * fabs(ratio - 1) / (2 * s->r0);
    ps->jerk = INFINITY;
    ps->a_eff = INFINITY;
    ps->kappa = 0;
    ps->a_cap = INFINITY;
}

/* A corner parabola's turn loads each axis at a constant rate, exactly, so it
 * may take nearly all of the limit at the cruise cap: below the cap the
 * vector bound (parab_limits) leaves the tangent most of it again, and at
 * the cap the blend's speed need hardly change. The share is the turn's part
 * of each axis's acceleration limit; arcs keep a wider margin. Chosen with
 * bench-motion's programs, where a larger share made none slower
 * (bench/RESULTS.md, "Planner against LinuxCNC 2.9's"). */
#define PARAB_TURN_SHARE 0.99
/* An uneven parabola is only ever run as its ramp: its axes accelerate at
 * exactly v0^2 curv_j throughout, and the tangent needs nothing beside it. */
#define RATIO_TURN_SHARE 0.998

/* A corner parabola's caps, even or uneven. */
static void parabola_limits(const struct ncp_planner *p, struct plan_seg *ps)
{
    if (ncp_seg_ratio(&ps->s) > 0)
        ratio_limits(p, ps, RATIO_TURN_SHARE);
    else
        parab_limits(p, ps, PARAB_TURN_SHARE);
}

/* The exit speed a segment's profile reaches from entry v0, and the highest
 * entry from which it can end at v1: the same reach both ways, but for an
 * uneven parabola, whose exit is always ratio times its entry. */
static double exit_from(int scurve, const struct plan_seg *ps, double v0)
{
    double ratio = ncp_seg_ratio(&ps->s);
    return ratio > 0 ? ratio * v0 : ncp_plan_seg_reach(scurve, ps, v0, ps->s.length);
}

static double entry_for(int scurve, const struct plan_seg *ps, double v1)
{
    double ratio = ncp_seg_ratio(&ps->s);
    return ratio > 0 ? v1 / ratio : ncp_plan_seg_reach(scurve, ps, v1, ps->s.length);
}

/* Programmed arcs keep LinuxCNC's split (half the vector for a_t even at full
 * speed); a blend arc is so short that its speed hardly changes on it, so the
 * speed through the corner gets nearly all of it. */
#define ARC_AN_SHARE 0.866
#define BLEND_AN_SHARE 0.95
/* A fitted arc (fit.c) is short and runs into the next at the same speed:
 * its turn may take what a corner parabola's does (PARAB_TURN_SHARE) of the
 * room its sweep leaves the axes (arc_sweep_shares), and below the cruise cap
 * the tangent gets the rest (plan_acc_at). On bench/gen-planner.py's tiny,
 * of the disc a_eff, 0.866 gave 4.93 s, 0.95 4.79 and 0.99 4.73. */
#define FIT_AN_SHARE 0.99

/* A corner (kink) turns the velocity vector within one servo period. A servo
 * sample's second difference is a weighted mean of the continuous acceleration
 * plus the kink's velocity jump over one period, so the kink gets a share beta
 * of each axis's limit and the segments on both sides keep their continuous
 * acceleration within 1 - beta (halved: lines 0.5; arcs 0.5 tangential, and
 * kink_arc_cap keeps their centripetal part within 0.25 near the corner). */
static double kink_share(const struct ncp_seg *a, const struct ncp_seg *b)
{
    return a->kind == NCP_SEG_ARC || b->kind == NCP_SEG_ARC ? 0.25 : 0.5;
}

/* The speed at a kink into or out of an arc that keeps the arc's centripetal
 * acceleration within a quarter of its bound for the two samples around it. */
static double kink_arc_cap(const struct ncp_planner *p, const struct ncp_seg *s)
{
    double kappa, a_eff;
    if (s->kind != NCP_SEG_ARC)
        return INFINITY;
    a_eff = arc_accel_bound(p, s, &kappa);
    if (kappa <= 1e-12)
        return INFINITY;
    return fmax(0, sqrt(0.25 * a_eff / kappa) - 2 * a_eff * p->cfg.servo_period);
}

/* A kink whose velocity step at the segments' cruise speed needs at most
 * this share of any axis's acceleration (a CAM program's tangent moves
 * written with four decimals) is taken at that speed: the kink gets just the
 * share it needs and the segments keep the rest (kink_factor). */
#define KINK_SMALL 0.5

/* The share of its acceleration a segment keeps beside a kink that takes
 * beta of every axis's limit: a line 1 - beta; on an arc the centripetal
 * part stays at most c of the bound (c at its cruise cap) and the tangent
 * gets f with f^2 (1 - c^2) + c^2 <= (1 - beta)^2. Negative: none left. */
static double kink_factor(const struct plan_seg *ps, double beta)
{
    double c = ps->kappa > 0 && ps->a_eff > 0 ? fmin(1, ps->vmax * ps->vmax * ps->kappa / ps->a_eff)
                                              : 0;
    double room = (1 - beta) * (1 - beta) - c * c;
    return room > 0 && c < 1 ? sqrt(room / (1 - c * c)) : -1;
}

static double junction(const struct ncp_planner *p, const struct ncp_seg *prev,
                       const struct plan_seg *cur, double v_cruise, int *kink,
                       double *beta_small)
{
    *kink = 0;
    *beta_small = -1;
    if (prev->kind == NCP_SEG_DWELL || cur->s.kind == NCP_SEG_DWELL ||
        prev->term == NCP_TERM_STOP)
        return 0;
    double pos[NCP_AXES], t1[NCP_AXES], t2[NCP_AXES], dmax = 0, v = cur->vmax;
    double beta = kink_share(prev, &cur->s);
    double share_per_speed = 0;  /* the largest share of an axis's limit per mm/s */
    ncp_seg_eval(prev, prev->length, pos, t1);
    ncp_seg_eval(&cur->s, 0, pos, t2);
    for (int j = 0; j < NCP_AXES; j++) {
        double dj = fabs(t2[j] - t1[j]);
        dmax = fmax(dmax, dj);
        share_per_speed =
            fmax(share_per_speed, dj / (p->cfg.axis[j].max_acc * p->cfg.servo_period));
        if (dj > 1e-9)
            v = fmin(v, beta * p->cfg.axis[j].max_acc * p->cfg.servo_period / dj);
        /* S-curve: the velocity step of the corner, within one period, is a
         * jerk of dv / T^2: it gets the half the segments leave free */
        if (dj > 1e-9 && plan_scurve(p) && p->cfg.axis[j].max_jerk > 0)
            v = fmin(v, 0.5 * p->cfg.axis[j].max_jerk * p->cfg.servo_period *
                            p->cfg.servo_period / dj);
    }
    /* the joints turn their own corners under non-trivial kinematics */
    v = fmin(v, ncp_kins_junction_cap(&p->cfg, prev, &cur->s, beta, p->cfg.servo_period));
    if (dmax <= 1e-9)
        return v;
    if (prev->term == NCP_TERM_EXACT_PATH)
        return 0;
    *kink = 1;
    if (!plan_scurve(p) && v >= v_cruise) {
        double need = v_cruise * share_per_speed;
        if (need <= KINK_SMALL) {
            *beta_small = need;
            return v_cruise;
        }
    }
    return fmin(v, fmin(kink_arc_cap(p, prev), kink_arc_cap(p, &cur->s)));
}

/* Would lowering the tail's entry speed to v_tail (with the backward pass
 * carrying it towards the head) take an entry below the speed the executing
 * segment's frozen profile ends with? Stops as soon as a speed stays put. */
static int lowering_safe(const struct ncp_planner *p, double v_tail)
{
    if (!p->ex.active || p->count < 2)
        return p->count >= 1 && !(p->ex.active && p->count == 1);
    size_t k = p->count - 1;
    double v = v_tail;
    for (;;) {
        const struct plan_seg *ps = &p->q[(p->head + k) % p->cap];
        if (v >= ps->v_in)
            return 1;
        if (k == 1)
            return v >= p->ex.cur.trap.v1;
        k--;
        ps = &p->q[(p->head + k) % p->cap];
        v = fmin(ps->vjunc, entry_for(plan_scurve(p), ps, v));
    }
}

/* Time to leave a corner at v0 and cover len at acceleration acc, capped at
 * vmax: one side of a kink, its other end left out (the same either way). */
static double side_time(double len, double acc, double v0, double vmax)
{
    if (len <= 0)
        return 0;
    if (v0 >= vmax || acc <= 0)
        return vmax > 0 ? len / vmax : INFINITY;
    double d_acc = (vmax * vmax - v0 * v0) / (2 * acc);
    if (d_acc >= len)
        return (sqrt(v0 * v0 + 2 * acc * len) - v0) / acc;
    return (vmax - v0) / acc + (len - d_acc) / vmax;
}

/* Both sides of a kink taken at v with the share f of their acceleration. */
static double kink_sides_time(const struct plan_seg *prev, const struct plan_seg *cur, double v,
                              double f)
{
    return side_time(prev->s.length, fmin(prev->acc, f * prev->acc_full), v, prev->vmax) +
           side_time(cur->s.length, fmin(cur->acc, f * cur->acc_full), v, cur->vmax);
}

static void seg_limits(struct ncp_planner *p, struct plan_seg *ps)
{
    if (ps->s.kind == NCP_SEG_DWELL) {
        ps->vmax = 0;
        ps->acc = 1;
    } else if (ps->s.kind == NCP_SEG_ARC) {
        arc_limits(p, ps, ps->blend ? BLEND_AN_SHARE : ps->fitted ? FIT_AN_SHARE : ARC_AN_SHARE);
    } else if (ps->s.kind == NCP_SEG_PARAB) {
        parabola_limits(p, ps);
    } else {
        line_limits(p, ps);
    }
    if (p->cfg.default_linear_acc > 0) {
        ps->acc = fmin(ps->acc, p->cfg.default_linear_acc);
        ps->a_cap = fmin(ps->a_cap, p->cfg.default_linear_acc);
    }
    double acc_axes = ps->acc;
    ncp_kins_seg_caps(&p->cfg, &ps->s, &ps->vmax, &ps->acc);
    if (ps->acc < acc_axes)  /* the joints' limit: no speed-dependent share above it */
        ps->a_cap = fmin(ps->a_cap, ps->acc);
    ps->acc_full = ps->acc;
    ps->vjunc = 0;
    if (!p->have_last)
        return;
    int kink;
    double beta_small;
    /* a junction belongs to both segments: neither's cruise cap may be exceeded */
    double v_cruise = fmin(ps->vmax, p->last_vmax);
    double v = fmin(v_cruise, junction(p, &p->last_pushed, ps, v_cruise, &kink, &beta_small));
    double ratio = ncp_seg_ratio(&ps->s);
    if (ratio > 0)  /* its vmax is its exit's when that is the faster end */
        v = fmin(v, ps->vmax / fmax(1, ratio));
    if (kink) {
        /* The previous segment gives up acceleration for the kink, unless that
         * would cut into a profile already frozen: then stop at the corner.
         * Half each side, or for a small kink only what it needs. */
        struct plan_seg *prev = p->count ? plan_at(p, p->count - 1) : NULL;
        double f_cur = 0.5, f_prev = 0.5;
        if (prev && beta_small >= 0) {
            f_cur = kink_factor(ps, beta_small);
            f_prev = kink_factor(prev, beta_small);
            if (f_cur < 0.5 || f_prev < 0.5) {  /* not worth it: the usual caps */
                f_cur = f_prev = 0.5;
                v = fmin(v, fmin(kink_arc_cap(p, &p->last_pushed), kink_arc_cap(p, &ps->s)));
            }
        }
        /* a kink taken so slowly that stopping there loses less than the
         * halved acceleration of both sides (a near reversal): stop, and
         * the lines keep all of theirs (an arc's share is not only its
         * tangent's: left as it is) */
        if (prev && f_cur == 0.5 && f_prev == 0.5 && prev->s.kind == NCP_SEG_LINE &&
            ps->s.kind == NCP_SEG_LINE && kink_sides_time(prev, ps, 0, 1) <= kink_sides_time(prev, ps, v, 0.5))
            v = 0;
        if (v <= 0) {
            ps->vjunc = 0;
            return;
        }
        struct plan_seg cur_half = *ps, prev_half;
        cur_half.acc = fmin(ps->acc, f_cur * ps->acc_full);
        double exit_lb = fmin(v, exit_from(plan_scurve(p), &cur_half, 0));
        if (prev) {
            prev_half = *prev;
            prev_half.acc = fmin(prev->acc, f_prev * prev->acc_full);
        }
        if (!prev || !lowering_safe(p, fmin(prev->vjunc, entry_for(plan_scurve(p), &prev_half, exit_lb)))) {
            v = 0;
        } else {
            prev->acc = prev_half.acc;
            ps->acc = cur_half.acc;
        }
    }
    ps->vjunc = v;
}

/* The top speed x of ncp_plan_seg_reach in closed form, -1 where rounding
 * puts it on no branch. acc(x) = c max(acc_full, min(a_cap, S)), c = acc /
 * acc_full, S = sqrt(a_eff^2 - kappa^2 x^4): on the middle branch
 * (y - v^2)^2 = 4 len^2 c^2 (a_eff^2 - kappa^2 y^2) with y = x^2, a
 * quadratic in y; on the others the acceleration is constant. */
static double reach_closed(const struct plan_seg *ps, double v, double len)
{
    double c = ps->acc / ps->acc_full, v2 = v * v, k2 = ps->kappa * ps->kappa;
    double a2 = ps->a_eff * ps->a_eff;
    if (isfinite(ps->a_cap)) {
        double y = v2 + 2 * len * c * ps->a_cap;
        if (a2 - k2 * y * y >= ps->a_cap * ps->a_cap)
            return sqrt(y);
    }
    double q = 4 * len * len * c * c, k = 1 + q * k2;
    double d = v2 * v2 - k * (v2 * v2 - q * a2);
    if (d >= 0) {
        double y = (v2 + sqrt(d)) / k, sy = a2 - k2 * y * y;
        if (y >= v2 && sy >= ps->acc_full * ps->acc_full &&
            (!isfinite(ps->a_cap) || sy <= ps->a_cap * ps->a_cap))
            return sqrt(y);
    }
    double y = v2 + 2 * len * ps->acc;
    return a2 - k2 * y * y <= ps->acc_full * ps->acc_full ? sqrt(y) : -1;
}

double ncp_plan_seg_reach(int scurve, const struct plan_seg *ps, double v, double len)
{
    double lo = plan_reach(scurve, ps->acc, ps->jerk, v, len);
    /* every caller takes the least of this and a cap at or below vmax:
     * where the cruise cap's acceleration already reaches it, more is moot
     * (a chain of short arcs runs this in every backward pass) */
    if (ps->kappa <= 0 || scurve || lo >= ps->vmax)
        return lo;
    /* each root a hair below itself, so that rounding keeps it reachable */
    double xb = -1;
    if (ps->box_kappa > 0) {
        /* the box's lines are linear in x^2: each gives its root directly */
        double c = ps->acc / ps->acc_full, y = ps->vmax * ps->vmax;
        for (int j = 0; j < 3; j++)
            y = fmin(y, (v * v + 2 * len * c * ps->box_a[j]) /
                            (1 + 2 * len * c * ps->box_kappa * ps->box_b[j]));
        xb = sqrt(y) * (1 - 1e-12);
        if (!(xb >= lo && xb * xb <= v * v + 2 * len * plan_acc_at(ps, xb)))
            xb = -1;
        else if (y >= ps->vmax * ps->vmax)
            return xb;  /* the cap: the disc can give no more */
    }
    double x = reach_closed(ps, v, len) * (1 - 1e-12);
    if (x >= lo && x * x <= v * v + 2 * len * plan_acc_at(ps, x))
        return fmax(x, xb);
    if (xb >= lo)
        return xb;  /* the root wherever the box is what the arc reads there */
    /* the move's top speed x is the end reached: x^2 = v^2 + 2 len acc(x),
     * acc falling with x, so the largest such x is found by bisection
     * between the cruise cap's acceleration and the one at v */
    double hi = plan_reach(scurve, plan_acc_at(ps, v), ps->jerk, v, len);
    for (int i = 0; i < 40 && hi - lo > 1e-9 * hi; i++) {
        double mid = 0.5 * (lo + hi);
        if (mid * mid <= v * v + 2 * len * plan_acc_at(ps, mid))
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

/* The peak of a trapezoid from v0 to v1 over len at acceleration a. */
static double trap_peak(double a, double len, double v0, double v1, double vmax)
{
    double vp = fmin(vmax, sqrt(a * len + 0.5 * (v0 * v0 + v1 * v1)));
    return fmax(vp, fmax(v0, v1));
}

double ncp_plan_seg_profile_acc(int scurve, const struct plan_seg *ps, double v0, double v1,
                                double vmax)
{
    double len = ps->s.length;
    if (ps->kappa <= 0 || scurve || len <= 0)
        return ps->acc;
    double lo = ps->acc, hi = plan_acc_at(ps, fmax(v0, v1));
    if (hi <= plan_acc_at(ps, trap_peak(hi, len, v0, v1, vmax)))
        return hi;
    /* a harder acceleration reaches a higher peak, where less is left */
    for (int i = 0; i < 40 && hi - lo > 1e-9 * hi; i++) {
        double mid = 0.5 * (lo + hi);
        if (mid <= plan_acc_at(ps, trap_peak(mid, len, v0, v1, vmax)))
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

/* Raise entry speeds from the tail backwards until one does not change: the
 * segments before it were limited by their own caps, not by what follows. */
static void backward_pass(struct ncp_planner *p)
{
    size_t first = p->ex.active ? 1 : 0;
    double exit_v = 0;
    for (size_t k = p->count; k-- > first;) {
        struct plan_seg *ps = plan_at(p, k);
        double v = fmin(ps->vjunc, entry_for(plan_scurve(p), ps, exit_v));
        if (k + 1 < p->count && v == ps->v_in)
            break;
        if (k + 1 < p->count)
            p->st.replans++;
        ps->v_in = v;
        exit_v = v;
    }
}

static void push_one(struct ncp_planner *p, const struct ncp_seg *s, int blend)
{
    struct plan_seg *ps = &p->q[(p->head + p->count) % p->cap];
    memset(ps, 0, sizeof *ps);
    ps->s = *s;
    ps->blend = blend;
    ps->fitted = p->pushing_fit && !blend && s->kind == NCP_SEG_ARC;
    ps->faired = p->pushing_fair && !blend;
    seg_limits(p, ps);
    p->count++;
    p->programmed += !blend;
    p->last_pushed = *s;
    p->last_vmax = ps->vmax;
    p->have_last = 1;
    p->st.segments++;
    backward_pass(p);
}

/* A corner so slight that its kink speed does not slow the motion is left
 * sharp: the path stays exact and nothing is lost. */
static int kink_harmless(const struct ncp_planner *p, const struct ncp_seg *a,
                         const struct ncp_seg *b, double vmax)
{
    double pos[NCP_AXES], t1[NCP_AXES], t2[NCP_AXES];
    ncp_seg_eval(a, a->length, pos, t1);
    ncp_seg_eval(b, 0, pos, t2);
    for (int j = 0; j < NCP_AXES; j++) {
        double dj = fabs(t2[j] - t1[j]);
        if (dj > 1e-9 && kink_share(a, b) * p->cfg.axis[j].max_acc * p->cfg.servo_period / dj < vmax)
            return 0;
    }
    return 1;
}

/* A line's cruise cap at the feed its corners are blended for. */
static double blend_vmax(const struct ncp_planner *p, const struct ncp_seg *s)
{
    struct plan_seg ps;
    memset(&ps, 0, sizeof ps);
    ps.s = *s;
    if (s->blend_feed > 0)
        ps.s.feed = s->blend_feed;
    line_limits(p, &ps);
    return ps.vmax;
}

/* A blend's caps (an arc's or a parabola's). */
static void blend_limits(const struct ncp_planner *p, struct plan_seg *ps)
{
    if (ps->s.kind == NCP_SEG_PARAB)
        parabola_limits(p, ps);
    else
        arc_limits(p, ps, BLEND_AN_SHARE);
}

/* How fast a blend lets the corner be taken, feed aside. */
static double arc_speed(const struct ncp_planner *p, const struct ncp_seg *arc)
{
    struct plan_seg ps;
    memset(&ps, 0, sizeof ps);
    ps.s = *arc;
    ps.s.feed = INFINITY;
    blend_limits(p, &ps);
    return ps.vmax;
}

/* The part of G64 P tol a blend may use: the servo's chords across it cut
 * in by p->chord (at least a quarter stays). */
static double blend_tol(const struct ncp_planner *p, double tol)
{
    return fmax(0.25 * tol, tol - p->chord);
}

/* What an uneven parabola gives up of a blend's part of P beyond an even
 * one's: its chords may cut in by chord_all, more than chord. */
static double uneven_margin(const struct ncp_planner *p)
{
    return fmax(0, p->chord_all - p->chord);
}

/* The smallest trim (and so the smallest arc) whose speed reaches v_goal,
 * no more than the largest blend allowed: a blend departs from the
 * programmed corner only as far as the speed it buys needs. The arc's speed
 * grows with its radius, so a bisection finds it. */
static int size_blend(const struct ncp_planner *p, const struct ncp_seg *tol,
                      const struct ncp_seg *s, double v_goal, double max_trim, struct ncp_seg *arc,
                      double *d)
{
    if (!ncp_blend_corner(tol, s, max_trim, arc, d))
        return 0;
    if (arc_speed(p, arc) <= v_goal)
        return 1;
    double lo = 0, hi = *d;
    for (int i = 0; i < 40 && hi - lo > 1e-7 * hi; i++) {
        double mid = 0.5 * (lo + hi);
        if (ncp_blend_corner(tol, s, mid, arc, d) && arc_speed(p, arc) >= v_goal)
            hi = mid;
        else
            lo = mid;
    }
    return ncp_blend_corner(tol, s, hi, arc, d);
}

/* A line's path acceleration. */
static double line_acc(const struct ncp_planner *p, const struct ncp_seg *s)
{
    struct plan_seg ps;
    memset(&ps, 0, sizeof ps);
    ps.s = *s;
    line_limits(p, &ps);
    return ps.acc;
}

/* Time of a trapezoid from v0 to v1 over len at acceleration a, cruise cap
 * vmax; INFINITY where v1 cannot be reached from v0. */
static double trap_time(double len, double v0, double v1, double a, double vmax)
{
    if (len <= 0 || a <= 0)
        return len <= 0 && v0 == v1 ? 0 : INFINITY;
    if (fabs(v1 * v1 - v0 * v0) > 2 * a * len * (1 + 1e-9))
        return INFINITY;
    double vp = fmin(vmax, sqrt(a * len + 0.5 * (v0 * v0 + v1 * v1)));
    vp = fmax(vp, fmax(v0, v1));
    double d1 = (vp * vp - v0 * v0) / (2 * a), d3 = (vp * vp - v1 * v1) / (2 * a);
    return (vp - v0) / a + (vp - v1) / a + fmax(0, len - d1 - d3) / vp;
}

/* What a blend entered at v1 and left at v2, trimming t1 and t2 off the
 * lines, costs with the lines around it: the line before from v_n, the
 * blend (dur), the line after down to v_n, each at most at v_top. Only what
 * does not change with the feed override goes in (v_n: this corner's even
 * speed standing for its neighbours'; v_top: the feed at the largest
 * override), so the path cut never depends on it. */
static double corner_cost(double len1, double a1, double len2, double a2, double v_n,
                          double v_top, double v1, double v2, double t1, double t2, double dur)
{
    return trap_time(len1 - t1, v_n, v1, a1, v_top) + dur + trap_time(len2 - t2, v2, v_n, a2, v_top);
}

/* Uneven corner parabolas: the even one's constant acceleration points along
 * u2 - u1 and so loads one axis fully and the other less; entered slower and
 * left faster (or the other way) the vector turns, and at the right ratio
 * both axes give their limit (bench/corner-lp found the fastest motion over
 * servo samples taking corners so). Tried where the even blend holds the
 * corner below the feed, over ratios from 1/3 to 3, each as large as P and
 * the lines allow; kept when the simple cost above says it is faster. Its
 * profile is rigid (a ramp), so only where nothing else reshapes profiles:
 * trapezoids, trivial kinematics, no [TRAJ] DEFAULT_LINEAR_ACCELERATION.
 * A caller that only asks whether the corner costs at most `enough` (a
 * moved vertex against the one where it is) has the search end at the
 * first blend that does: the answer cannot change. */
#define RATIO_STEPS 24
/* what an uneven blend must save by the cost, s: where both are about as fast
 * (a corner between two axes, already at the per-axis floor) the even one stays */
#define RATIO_GAIN_MIN 1e-4
#define RATIO_MOVED_EVERY 2
static int uneven_blend(const struct ncp_planner *p, const struct ncp_seg *tol,
                        const struct plan_seg *prev, const struct ncp_seg *s, double v_goal,
                        const struct ncp_seg *even, double d, const struct plan_corner *corner,
                        double v_n, double enough, double *cost, struct ncp_seg *out,
                        double *d1, double *d2)
{
    *cost = INFINITY;
    if (plan_scurve(p) || ncp_kins_active(&p->cfg) || p->cfg.default_linear_acc > 0 ||
        tol->tolerance <= 0 || prev->s.kind != NCP_SEG_LINE || s->kind != NCP_SEG_LINE)
        return 0;
    /* the cost below reads the lines around the corner as lines: where blends
     * take most of them (tiny CAM chords) the even blend keeps its freedom */
    if (prev->s.length < 10 * d || s->length < 10 * d)
        return 0;
    double v_even = fmin(v_goal, arc_speed(p, even));
    if (v_even >= v_goal * (1 - 1e-9) || v_even <= 0)
        return 0;
    if (v_n <= 0)
        v_n = v_even;
    double a1 = line_acc(p, &prev->s), a2 = line_acc(p, s);
    double len1 = prev->s.length, len2 = s->length;
    struct ncp_seg tol_u = *tol;
    tol_u.tolerance -= uneven_margin(p);
    double best = corner_cost(len1, a1, len2, a2, v_n, v_goal, v_even, v_even, d, d, 2 * d / v_even);
    *cost = best;
    int found = 0, moved = corner && corner->shifted;
    for (int k = 0; k <= RATIO_STEPS; k++) {
        double rho = pow(3.0, -1 + 2.0 * k / RATIO_STEPS), t1, t2, hi;
        struct ncp_seg b;
        /* at a moved vertex each ratio is a search: every
         * RATIO_MOVED_EVERY-th one */
        if (fabs(rho - 1) < 1e-9 || (moved && k % RATIO_MOVED_EVERY))
            continue;
        /* at a moved vertex: the largest blend measured within P of the
         * programmed lines; elsewhere the largest within P of the lines */
        if (moved ? !ncp_edge_trims(&prev->s, s, corner, tol_u.tolerance, rho,
                                    fmin(0.2 * len1, 0.2 * len2 / rho), NULL, &hi) ||
                        !ncp_blend_corner_ratio_at(&prev->s, s, rho, hi, &b, &t1, &t2)
                  : !ncp_blend_corner_ratio(&tol_u, s, rho, &b, &t1, &t2))
            continue;
        if (t1 > 0.2 * len1 + 1e-12 || t2 > 0.2 * len2 + 1e-12)
            continue;
        /* beside a moved vertex the lines are not the programmed ones */
        if (corner && !moved &&
            !ncp_edge_within(&b, corner, tol_u.tolerance))
            continue;
        double v1 = fmin(v_goal, arc_speed(p, &b)) / fmax(1, rho);
        if (v1 <= 0)
            continue;
        double c = corner_cost(len1, a1, len2, a2, v_n, v_goal, v1, rho * v1, t1, t2, 2 * t1 / v1);
        if (c < best - RATIO_GAIN_MIN) {
            best = *cost = c;
            *out = b;
            *d1 = t1;
            *d2 = t2;
            found = 1;
            if (c <= enough)
                break;
        }
    }
    return found;
}

/* The same where an arc meets a line: the arc's cut is searched instead. */
static int size_arc_blend(const struct ncp_planner *p, const struct ncp_seg *tol,
                          const struct ncp_seg *s, double v_goal, struct ncp_seg *arc,
                          struct ncp_seg *prev_out, struct ncp_seg *cur_out)
{
    const struct ncp_seg *a = tol->kind == NCP_SEG_ARC ? tol : s;
    const struct ncp_seg *line = a == tol ? s : tol;
    double lo = 0, hi = 0.5 * a->length;
    /* a line leaving the arc's plane ends its blend with a slight kink
     * (blend.c), a velocity step that an S-curve would take as a jerk */
    if (plan_scurve(p) && line->length > 0 && ncp_blend_line_leaves(a, line))
        return 0;
    /* the largest cut within P: the deviation grows with the cut */
    if (!ncp_blend_arc_corner(tol, s, hi, arc, prev_out, cur_out)) {
        for (int i = 0; i < 40 && hi - lo > 1e-7 * hi; i++) {
            double mid = 0.5 * (lo + hi);
            if (ncp_blend_arc_corner(tol, s, mid, arc, prev_out, cur_out))
                lo = mid;
            else
                hi = mid;
        }
        hi = lo;
        if (hi <= 0 || !ncp_blend_arc_corner(tol, s, hi, arc, prev_out, cur_out))
            return 0;
    }
    if (arc_speed(p, arc) <= v_goal)
        return 1;
    lo = 0;
    for (int i = 0; i < 40 && hi - lo > 1e-7 * hi; i++) {
        double mid = 0.5 * (lo + hi);
        if (ncp_blend_arc_corner(tol, s, mid, arc, prev_out, cur_out) &&
            arc_speed(p, arc) >= v_goal)
            hi = mid;
        else
            lo = mid;
    }
    return ncp_blend_arc_corner(tol, s, hi, arc, prev_out, cur_out);
}

/* A segment's cruise cap at the feed its corners are blended for. */
static double blend_vmax_any(const struct ncp_planner *p, const struct ncp_seg *s)
{
    if (s->kind == NCP_SEG_LINE)
        return blend_vmax(p, s);
    struct plan_seg ps;
    memset(&ps, 0, sizeof ps);
    ps.s = *s;
    if (s->blend_feed > 0)
        ps.s.feed = s->blend_feed;
    arc_limits(p, &ps, ARC_AN_SHARE);
    return ps.vmax;
}

/* Blends the corner between the queued tail and s when the tail may still
 * change: not executing, and not lowering speeds a frozen profile counts on.
 * The blend's size follows from the feed at the largest override, never the
 * override in force, so the path cut is the same at any override. */
static int try_blend(struct ncp_planner *p, struct ncp_seg *s)
{
    if (!p->count || (p->ex.active && p->count == 1))
        return 0;
    struct plan_seg *prev = plan_at(p, p->count - 1);
    struct plan_seg arc;
    struct ncp_seg prev_out, cur_out;
    double d;
    memset(&arc, 0, sizeof arc);
    /* G64 P bounds what the servo gets: its chords across the arc too */
    struct ncp_seg tol = prev->s;
    if (tol.tolerance > 0)
        tol.tolerance = blend_tol(p, tol.tolerance);
    double v_goal = fmin(blend_vmax_any(p, &prev->s), blend_vmax_any(p, s));
    /* a moved vertex lies off the path: it is always cut off */
    if (!p->corner.shifted && kink_harmless(p, &prev->s, s, v_goal))
        return 0;
    if (prev->s.kind == NCP_SEG_LINE && s->kind == NCP_SEG_LINE) {
        double lo = 0, max_trim = INFINITY;
        struct ncp_seg tol_band = tol;
        if (p->corner.measured) {
            /* a line beside the corner left its programmed one (edge.c):
             * the trims whose blend stays within P of the programmed lines */
            double hi;
            if (!ncp_edge_trims(&prev->s, s, &p->corner, tol.tolerance, 1, INFINITY, &lo, &hi))
                return 0;  /* only where the vertex is on the path (edge_decide) */
            tol.tolerance = 0;
            max_trim = hi;
        } else if (prev->faired != p->pushing_fair && tol.tolerance > 0) {
            /* between a faired line and one as programmed neither is the
             * other's band: the blend passes within P of the corner point,
             * which a parabola within P cos(phi/2) of the lines does */
            double u1[3], u2[3];
            for (int i = 0; i < 3; i++) {
                u1[i] = (prev->s.end[i] - prev->s.start[i]) / prev->s.length;
                u2[i] = (s->end[i] - s->start[i]) / s->length;
            }
            tol.tolerance *= sqrt(fmax(0, 0.5 * (1 + dot3(u1, u2))));
        }
        if (!size_blend(p, &tol, s, v_goal, max_trim, &arc.s, &d))
            return 0;
        if (d < lo && !ncp_blend_corner(&tol, s, lo, &arc.s, &d))
            return 0;
        double d1 = d, d2 = d;
        struct ncp_seg uneven;
        /* uneven ones measured where a line beside the corner moved */
        double cost;
        if (uneven_blend(p, &tol_band, prev, s, v_goal, &arc.s, d,
                         p->corner.measured ? &p->corner : NULL, 0, -INFINITY, &cost, &uneven,
                         &d1, &d2))
            arc.s = uneven;
        prev_out = prev->s;
        prev_out.length -= d1;
        memcpy(prev_out.end, arc.s.start, sizeof prev_out.end);
        cur_out = *s;
        cur_out.length -= d2;
        memcpy(cur_out.start, arc.s.end, sizeof cur_out.start);
    } else if (!size_arc_blend(p, &tol, s, v_goal, &arc.s, &prev_out, &cur_out)) {
        return 0;
    }
    prev_out.tolerance = prev->s.tolerance;
    arc.blend = 1;
    blend_limits(p, &arc);
    arc.acc_full = arc.acc;
    double exit_lb = fmin(arc.vmax, exit_from(plan_scurve(p), &arc, 0));
    struct plan_seg cut = *prev;
    cut.s = prev_out;
    if (cut.s.kind == NCP_SEG_ARC) {
        arc_limits(p, &cut, ARC_AN_SHARE);
        cut.acc_full = cut.acc;
        cut.acc = fmin(prev->acc, cut.acc);
    }
    double vin = fmin(prev->vjunc, entry_for(plan_scurve(p), &cut, exit_lb));
    if (!lowering_safe(p, vin))
        return 0;
    prev->s = prev_out;
    p->last_pushed = prev->s;
    push_one(p, &arc.s, 1);
    *s = cur_out;
    p->st.segments--;  /* the arc is not a programmed segment */
    return 1;
}

/* Pieces a programmed arc's ends are cut into (push_arc), each: a middle
 * piece joins them, so an arc is queued as at most 2 ARC_END_PIECES + 1. */
#define ARC_END_PIECES 2
#define ARC_PIECES_MAX (2 * ARC_END_PIECES + 1)
/* Each piece at least this many times G64 P long: the blend into the line
 * after an arc may cut up to half of its last piece, and a corner turning by
 * 30 degrees or more needs at most 4 P / |u2 - u1| <= 8 P of it. */
#define ARC_PIECE_MIN_P 16
/* Cut only where the turn takes at least this share of the arc's
 * acceleration bound at its cruise cap: below it the tangent has most of it
 * already. */
#define ARC_PIECE_AN 0.5

/* The part of arc s from l0 to l1 of its parameter (eval_arc's l). */
static void arc_piece(const struct ncp_seg *s, double l0, double l1, struct ncp_seg *o)
{
    double tan[NCP_AXES], a = s->angle * l0, c = cos(a), sn = sin(a);
    *o = *s;
    for (int i = 0; i < 3; i++) {
        o->u[i] = c * s->u[i] + sn * s->w[i];
        o->w[i] = c * s->w[i] - sn * s->u[i];
        o->center[i] = s->center[i] + s->normal[i] * s->axial * l0;
    }
    o->axial = s->axial * (l1 - l0);
    o->angle = s->angle * (l1 - l0);
    o->r0 = s->r0 + (s->r1 - s->r0) * l0;
    o->r1 = s->r0 + (s->r1 - s->r0) * l1;
    o->length = s->length * (l1 - l0);
    ncp_seg_eval(s, s->length * l0, o->start, tan);
    if (l1 < 1)
        ncp_seg_eval(s, s->length * l1, o->end, tan);
}

/* Where arc s is cut (cut[0] = 0 < ... < cut[n] = 1, fractions of its
 * length); returns n, the number of pieces. An arc's tangent gets more of
 * its acceleration bound the slower it runs (plan_acc_at), but one
 * trapezoid runs at one constant acceleration, that of its top speed: an arc
 * braking from its cruise cap (where the turn leaves the tangent half the
 * bound) to a slow corner or a stop brakes at that half all the way. The
 * speed changes near the ends, within the braking distance d from the cap,
 * and a speed change's distance grows as the square of the speed: cut at
 * d (k / ARC_END_PIECES)^2 from each end, so that each end piece spans about
 * the same speed and brakes (or speeds up) at what its own top leaves. */
static int arc_cuts(const struct ncp_planner *p, const struct ncp_seg *s,
                    double cut[ARC_PIECES_MAX + 1])
{
    cut[0] = 0;
    cut[1] = 1;
    if (s->kind != NCP_SEG_ARC || plan_scurve(p) || s->length <= 0)
        return 1;
    double piece_min = 0;
    if (s->term == NCP_TERM_CONTINUOUS) {
        if (s->tolerance <= 0)
            return 1;  /* the blend after it may take up to half of the arc */
        piece_min = ARC_PIECE_MIN_P * s->tolerance;
    }
    struct plan_seg ps;
    memset(&ps, 0, sizeof ps);
    ps.s = *s;
    arc_limits(p, &ps, ARC_AN_SHARE);
    if (!(ps.kappa > 0) || !(ps.a_eff > 0) ||
        ps.vmax * ps.vmax * ps.kappa < ARC_PIECE_AN * ps.a_eff)
        return 1;
    double d = ps.vmax * ps.vmax / (2 * ps.a_eff), len = s->length;
    double from_end[ARC_END_PIECES] = { 0 };
    int m = 0;
    for (int k = 1; k <= ARC_END_PIECES; k++) {
        /* each piece piece_min or longer, the middle one included */
        double x = fmax(d * (double)(k * k) / (ARC_END_PIECES * ARC_END_PIECES),
                        (m ? from_end[m - 1] : 0) + piece_min);
        if (2 * x + piece_min > len)
            break;
        from_end[m++] = x;
    }
    /* room for them and for the next push (a blend and a segment) */
    while (m > 0 && p->count + (size_t)(2 * m + 1) + 2 > p->cap)
        m--;
    for (int k = 0; k < m; k++) {
        cut[1 + k] = from_end[k] / len;
        cut[2 * m - k] = 1 - from_end[k] / len;
    }
    cut[2 * m + 1] = 1;
    return 2 * m + 1;
}

/* Queues s, an arc in pieces (arc_cuts): they meet tangent with the same
 * curvature, so the path is the same and no corner is added. Each takes a
 * place in the look-ahead window (LOOKAHEAD counts segments; counted as one,
 * the window's blends would fill the ring and leave no room to cut). Only
 * the last keeps how s ends (an exact stop, single block). */
static void push_arc(struct ncp_planner *p, const struct ncp_seg *s)
{
    double cut[ARC_PIECES_MAX + 1];
    int n = arc_cuts(p, s, cut);
    if (n <= 1) {
        push_one(p, s, 0);
        return;
    }
    for (int k = 0; k < n; k++) {
        struct ncp_seg piece;
        arc_piece(s, cut[k], cut[k + 1], &piece);
        if (k + 1 < n)
            piece.term = NCP_TERM_CONTINUOUS;
        push_one(p, &piece, 0);
        if (k > 0)
            p->st.segments--;  /* the statistics count programmed segments */
    }
}

static void push_now(struct ncp_planner *p, const struct ncp_seg *s)
{
    struct ncp_seg cur = *s;
    try_blend(p, &cur);
    push_arc(p, &cur);
}

/* ---- vertices moved out to the band's outer edges (edge.c) ---------------- */

#define EDGE_OUT_ROUND 1e-6

/* A line whose end may move out: a G64 P feed line in X Y Z as programmed
 * (not faired, not joined by G64 Q), trivial kinematics. */
static int edge_may_hold(const struct ncp_planner *p, const struct ncp_seg *s)
{
    return s->kind == NCP_SEG_LINE && s->term == NCP_TERM_CONTINUOUS && s->tolerance > 0 &&
           !s->traverse && s->merge_tol <= 0 && s->length > 0 && !p->pushing_fair &&
           !p->pushing_fit && !ncp_seg_moves_other(s) && !ncp_kins_active(&p->cfg);
}

/* The blend between the queue's last line (tail) and held, with held's end
 * at `end`, as try_blend will measure it: is there one within P? */
static int edge_blend_fits(const struct ncp_planner *p, const struct ncp_seg *tail,
                           const struct ncp_seg *held, const double end[3],
                           const struct plan_corner *k)
{
    struct ncp_seg h = *held;
    memcpy(h.end, end, 3 * sizeof h.end[0]);
    h.length = dist3(h.start, h.end);
    return ncp_edge_trims(tail, &h, k, blend_tol(p, tail->tolerance), 1, INFINITY, NULL, NULL);
}

/* Whether the vertex between held lines h and cur moves out (k: its
 * programmed points): where the corner holds the speed below what the lines
 * are blended for, the blend at the moved vertex is within P and faster,
 * and the blend at h's start (k_start) still fits with h's end moved. The
 * blend at the moved vertex is measured here with cur's end where it is
 * programmed; should cur's end move in turn, that move is made only if this
 * blend still fits (this same check, one line on), so the vertex is never
 * left uncut. */
static void edge_decide(struct ncp_planner *p, const struct plan_corner *k_start,
                        struct ncp_seg *h, struct ncp_seg *cur, struct plan_corner *k)
{
    double tol = blend_tol(p, h->tolerance), moved[3], hi, d;
    if (h->tolerance != cur->tolerance || !ncp_edge_vertex(k->a, k->c, k->b, k->out, moved))
        return;
    /* the queue's last line is blended into h: as programmed there, or
     * measured where it moved too */
    const struct ncp_seg *tail = p->count ? &plan_at(p, p->count - 1)->s : NULL;
    int start_line = tail && tail->kind == NCP_SEG_LINE && tail->term == NCP_TERM_CONTINUOUS;
    if (start_line && !k_start->valid)
        return;
    double v_goal = fmin(blend_vmax(p, h), blend_vmax(p, cur));
    struct ncp_seg tl = *h, bl;
    tl.tolerance = tol;
    if (!ncp_blend_corner(&tl, cur, 0.5 * h->length, &bl, &d))
        return;
    double v_inner = arc_speed(p, &bl);
    if (v_inner >= v_goal)
        return;
    /* the fastest corner with the vertex where it is (even or uneven) and
     * moved (the same), by the simple cost of uneven_blend, the corner's
     * even speed standing for its neighbours' in both */
    struct plan_seg hp;
    struct ncp_seg uneven;
    double d1, d2, cost_in, cost_out;
    memset(&hp, 0, sizeof hp);
    hp.s = *h;
    double a1 = line_acc(p, h), a2 = line_acc(p, cur);
    if (!uneven_blend(p, &tl, &hp, cur, v_goal, &bl, d, NULL, v_inner, -INFINITY, &cost_in, &uneven,
                      &d1, &d2))
        cost_in = corner_cost(h->length, a1, cur->length, a2, v_inner, v_goal, v_inner, v_inner, d,
                              d, 2 * d / v_inner);
    struct ncp_seg h2 = *h, c2 = *cur;
    memcpy(h2.end, moved, sizeof moved);
    memcpy(c2.start, moved, sizeof moved);
    h2.length = dist3(h2.start, h2.end);
    c2.length = dist3(c2.start, c2.end);
    struct ncp_seg free_h2 = h2;
    free_h2.tolerance = 0;
    double d_out;
    if (!ncp_edge_trims(&h2, &c2, k, tol, 1, 0.5 * h2.length - 1e-3, NULL, &hi) ||
        !ncp_blend_corner(&free_h2, &c2, hi, &bl, &d_out))
        return;
    double v_out = fmin(v_goal, arc_speed(p, &bl));
    struct plan_corner km = *k;
    km.shifted = 1;
    hp.s = h2;
    if (!uneven_blend(p, &tl, &hp, &c2, v_goal, &bl, d_out, &km, v_inner,
                      cost_in - RATIO_GAIN_MIN, &cost_out, &uneven, &d1, &d2))
        cost_out = corner_cost(h2.length, a1, c2.length, a2, v_inner, v_goal, v_out, v_out, d_out,
                               d_out, 2 * d_out / v_out);
    if (cost_out > cost_in - RATIO_GAIN_MIN)
        return;
    if (start_line) {
        struct plan_corner ks = *k_start;
        ks.measured = 1;
        if (!edge_blend_fits(p, tail, h, moved, &ks))
            return;
    }
    h2.tolerance = h->tolerance;
    *h = h2;
    *cur = c2;
    k->shifted = 1;
}

/* Queues the first held line, its start corner measured where a line beside
 * it moved (the one before, this one, or the next one: `next_moved`). */
static void edge_pop(struct ncp_planner *p, int next_moved)
{
    p->corner = p->edge_start[0];
    p->corner.measured = p->corner.valid && (p->corner.shifted || p->corner.measured || next_moved);
    struct ncp_seg line = p->edge_line[0];
    if (--p->edge_n) {
        p->edge_line[0] = p->edge_line[1];
        p->edge_start[0] = p->edge_start[1];
        p->edge_start[0].measured |= p->corner.shifted;
    }
    push_now(p, &line);
    memset(&p->corner, 0, sizeof p->corner);
}

/* Queues every held line: the vertex between them stays (the segment after
 * them is no G64 P line, so the second line's end is no such corner). */
static void edge_release(struct ncp_planner *p)
{
    while (p->edge_n)
        edge_pop(p, 0);
}

/* The queue left to run before the held lines would be needed: below it
 * they go (their ends as programmed) rather than wait for what comes next,
 * so a moved vertex is always cut off by its blend while the line before it
 * is not yet running (try_blend blends no running tail). A virtual clock
 * steps with a full window, so only a starved real-time run gets here. */
#define EDGE_RELEASE_QUEUED 3

void ncp_planner_edge_low(struct ncp_planner *p)
{
    if (p->edge_n && p->count <= EDGE_RELEASE_QUEUED)
        edge_release(p);
}

static void push_line(struct ncp_planner *p, const struct ncp_seg *s)
{
    if (!edge_may_hold(p, s)) {
        edge_release(p);
        push_now(p, s);
        return;
    }
    if (p->edge_n == 2) {
        /* the second line's end turns into s, a G64 P line: the vertex
         * between the held two may move */
        struct plan_corner *k = &p->edge_start[1];
        edge_decide(p, &p->edge_start[0], &p->edge_line[0], &p->edge_line[1], k);
        edge_pop(p, k->shifted);
    }
    struct plan_corner k;
    memset(&k, 0, sizeof k);
    memcpy(k.c, s->start, sizeof k.c);
    if (p->edge_n) {
        k.valid = 1;
        /* the whole of P outside: straight lines there need no chord margin
         * (a blend's chords cut in), and the checks' rounding has 1 nm */
        k.out = fmax(0, p->edge_line[p->edge_n - 1].tolerance - EDGE_OUT_ROUND);
        memcpy(k.a, p->edge_start[p->edge_n - 1].c, sizeof k.a);
        memcpy(k.b, s->end, sizeof k.b);
    }
    p->edge_line[p->edge_n] = *s;
    p->edge_start[p->edge_n] = k;
    p->edge_n++;
}

/* Queues what fairing and arc fitting handed on: a fitted arc runs as a
 * feed (no G2/G3 in the trace), and the statistics count each programmed
 * line once however many pieces it became. */
static void fair_drain(struct ncp_planner *p)
{
    if (p->fair_out_n)
        edge_release(p);
    for (int i = 0; i < p->fair_out_n; i++) {
        p->pushing_fit = (p->fair_out_flags[i] & PLAN_OUT_FITTED) != 0;
        p->pushing_fair = 1;
        push_line(p, &p->fair_out[i]);
        p->pushing_fit = p->pushing_fair = 0;
        if (p->fair_out_flags[i] & PLAN_OUT_MORE)
            p->st.segments--;
    }
    p->fair_out_n = 0;
}

static void fair_flush(struct ncp_planner *p)
{
    ncp_fair_flush(p);
    fair_drain(p);
}

/* After G64 Q's joining: a short line of a CAM chain is held back to be
 * faired with its neighbours (fair.c), anything else ends the chain. */
static void push_blended(struct ncp_planner *p, const struct ncp_seg *s)
{
    if (!ncp_fair_takes(p, s)) {
        fair_flush(p);
        if (!ncp_fair_takes(p, s)) {
            push_line(p, s);
            return;
        }
    }
    ncp_fair_add(p, s);
    fair_drain(p);
}

static int chain_may_start(const struct ncp_seg *s)
{
    /* Q is a distance in X Y Z: lines that turn another axis are not joined */
    return s->kind == NCP_SEG_LINE && !s->traverse && s->term == NCP_TERM_CONTINUOUS &&
           s->merge_tol > 0 && s->length > 0 && !ncp_seg_moves_other(s);
}

/* May s join the chain? It must continue it with the same feed and mode,
 * with no machine function (M62, M67, ...) sent between them, and the line from the chain's start to s's end must pass within Q of every
 * point programmed so far. */
static int chain_takes(const struct ncp_planner *p, const struct ncp_seg *s)
{
    const struct ncp_seg *c = &p->chain;
    if (!chain_may_start(s) || p->chain_n >= PLAN_CHAIN_MAX || s->merge_tol != c->merge_tol ||
        s->feed != c->feed || s->blend_feed != c->blend_feed || s->tolerance != c->tolerance ||
        s->aux != c->aux)  /* a machine function between them keeps its place */
        return 0;
    for (int j = 0; j < NCP_AXES; j++)
        if (fabs(s->start[j] - c->end[j]) > 1e-9)
            return 0;
    for (int i = 0; i < p->chain_n; i++)
        if (plan_chord_dist(p->chain_pt[i], c->start, s->end, NCP_AXES) > s->merge_tol)
            return 0;
    return 1;
}

static void chain_add(struct ncp_planner *p, const struct ncp_seg *s)
{
    if (!p->chain_n)
        p->chain = *s;
    memcpy(p->chain.end, s->end, sizeof p->chain.end);
    p->chain.line = s->line;  /* the joined move is the last block's, as in LinuxCNC */
    double l2 = 0;
    for (int j = 0; j < NCP_AXES; j++)
        l2 += (p->chain.end[j] - p->chain.start[j]) * (p->chain.end[j] - p->chain.start[j]);
    p->chain.length = sqrt(l2);
    memcpy(p->chain_pt[p->chain_n++], s->end, sizeof p->chain_pt[0]);
}

static void chain_flush(struct ncp_planner *p)
{
    if (!p->chain_n)
        return;
    p->st.merged += (uint64_t)(p->chain_n - 1);
    p->chain_n = 0;
    if (p->chain.length > 1e-9)
        push_blended(p, &p->chain);
}

void ncp_planner_push(struct ncp_planner *p, const struct ncp_seg *s)
{
    if (ncp_planner_full(p))
        return;
    if (p->chain_n && chain_takes(p, s)) {
        chain_add(p, s);
        return;
    }
    chain_flush(p);
    if (chain_may_start(s))
        chain_add(p, s);
    else
        push_blended(p, s);
}
