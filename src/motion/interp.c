/* Rough interpolation of the planner's queue: the look-ahead's head segment
 * gets its profile frozen when it starts (the lazy forward pass) and goes to
 * the interpolator (exec.c), which samples it once per planning period (the
 * servo period unless [TRAJ] PLANNING_PERIOD is longer; the position loop
 * then fine-interpolates, see src/rt/scaler.c). */
#include "planner_int.h"

#include <math.h>
#include <string.h>

void ncp_la_profile(enum ncp_profile profile, const struct ncp_la *la, double v0,
                    struct ncp_accdec *rec)
{
    struct plan_seg ps;
    memset(&ps, 0, sizeof ps);
    ps.s = la->s;
    ps.vmax = la->vmax;
    ps.acc = la->acc;
    ps.acc_full = la->acc_full;
    ps.jerk = la->jerk;
    ps.a_eff = la->a_eff;
    ps.kappa = la->kappa;
    ps.a_cap = la->a_cap;
    memcpy(ps.box_a, la->box_a, sizeof ps.box_a);
    memcpy(ps.box_b, la->box_b, sizeof ps.box_b);
    ps.box_kappa = la->box_kappa;
    int scurve = profile == NCP_PROFILE_SCURVE;
    memset(rec, 0, sizeof *rec);
    rec->s = la->s;
    rec->blend = la->blend;
    rec->after_stop = la->after_stop;
    if (la->s.kind == NCP_SEG_DWELL) {
        rec->dur = la->s.dwell;
        return;
    }
    double ratio = ncp_seg_ratio(&la->s);
    if (ratio > 0 && !scurve) {
        /* an uneven corner parabola: the ramp from v0 to ratio v0 and nothing
         * else (the planner's entry caps keep the exit within what follows);
         * an entry at rest, never planned, would never end: a crawl instead */
        v0 = fmax(v0, 1e-3);
        ncp_trap_plan(&rec->trap, la->s.length, v0, ratio * v0, fmax(v0, ratio * v0), 1e-12);
        rec->dur = ncp_trap_duration(&rec->trap);
        return;
    }
    double v1 = fmin(la->v_end, ncp_plan_seg_reach(scurve, &ps, v0, la->s.length));
    double vmax = fmax(la->vmax, v0);
    if (scurve && la->jerk > 0 && isfinite(la->jerk))
        ncp_scurve_plan(&rec->trap, la->s.length, v0, v1, vmax, la->acc, la->jerk);
    else
        ncp_trap_plan(&rec->trap, la->s.length, v0, v1, vmax,
                      ncp_plan_seg_profile_acc(scurve, &ps, v0, v1, vmax));
    rec->dur = ncp_trap_duration(&rec->trap);
}

static int head_record(void *ctx, double v0, struct ncp_accdec *rec)
{
    struct ncp_planner *p = ctx;
    if (p->count == 0) {
        p->ended |= p->finished;
        return p->finished ? -1 : 0;
    }
    const struct plan_seg *ps = plan_at(p, 0);
    struct ncp_la la = {
        .s = ps->s, .vmax = ps->vmax, .acc = ps->acc, .acc_full = ps->acc_full,
        .jerk = ps->jerk, .a_eff = ps->a_eff, .kappa = ps->kappa, .a_cap = ps->a_cap,
        .box_a = { ps->box_a[0], ps->box_a[1], ps->box_a[2] },
        .box_b = { ps->box_b[0], ps->box_b[1], ps->box_b[2] }, .box_kappa = ps->box_kappa,
        .v_end = p->count > 1 ? plan_at(p, 1)->v_in : 0, .blend = (uint8_t)(ps->blend || ps->fitted),
        .after_stop = (uint8_t)p->ended,
    };
    p->ended = 0;
    ncp_la_profile(p->cfg.profile, &la, v0, rec);
    if (p->tap)
        p->tap(p->tap_ctx, &la, rec);
    return 1;
}

static void head_done(void *ctx)
{
    ncp_planner_pop(ctx);
}

void ncp_planner_set_tap(struct ncp_planner *p,
                         void (*tap)(void *ctx, const struct ncp_la *la,
                                     const struct ncp_accdec *rec),
                         void *ctx)
{
    p->tap = tap;
    p->tap_ctx = ctx;
}

int ncp_planner_step(struct ncp_planner *p, struct ncp_setpoint *out)
{
    const struct ncp_exec_source src = { head_record, head_done, p };
    ncp_planner_edge_low(p);
    int more = ncp_exec_step(&p->ex, &src, out);
    if (out->flags & NCP_SP_STARVED)
        p->st.starved++;
    return more;
}
