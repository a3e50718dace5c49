/* Rough interpolation of the planner's queue: the look-ahead's head segment
 * gets its profile frozen when it starts (the lazy forward pass) and goes to
 * the interpolator (exec.c), which samples it once per planning period (the
 * servo period unless [TRAJ] PLANNING_PERIOD is longer; the position loop
 * then fine-interpolates, see src/rt/scaler.c). */
#include "planner_int.h"

#include <math.h>
#include <string.h>

static int head_record(void *ctx, double v0, struct ncp_accdec *rec)
{
    struct ncp_planner *p = ctx;
    if (p->count == 0)
        return p->finished ? -1 : 0;
    struct plan_seg *ps = plan_at(p, 0);
    memset(rec, 0, sizeof *rec);
    rec->s = ps->s;
    rec->blend = (uint8_t)ps->blend;
    if (ps->s.kind == NCP_SEG_DWELL) {
        rec->dur = ps->s.dwell;
    } else {
        double next = p->count > 1 ? plan_at(p, 1)->v_in : 0;
        double v1 = fmin(next, ncp_plan_seg_reach(p, ps, v0, ps->s.length));
        double vmax = fmax(ps->vmax, v0);
        if (plan_scurve(p) && ps->jerk > 0 && isfinite(ps->jerk))
            ncp_scurve_plan(&rec->trap, ps->s.length, v0, v1, vmax, ps->acc, ps->jerk);
        else
            ncp_trap_plan(&rec->trap, ps->s.length, v0, v1, vmax,
                          ncp_plan_seg_profile_acc(p, ps, v0, v1, vmax));
        rec->dur = ncp_trap_duration(&rec->trap);
    }
    if (p->tap)
        p->tap(p->tap_ctx, rec);
    return 1;
}

static void head_done(void *ctx)
{
    ncp_planner_pop(ctx);
}

void ncp_planner_set_tap(struct ncp_planner *p,
                         void (*tap)(void *ctx, const struct ncp_accdec *rec), void *ctx)
{
    p->tap = tap;
    p->tap_ctx = ctx;
}

int ncp_planner_step(struct ncp_planner *p, struct ncp_setpoint *out)
{
    const struct ncp_exec_source src = { head_record, head_done, p };
    int more = ncp_exec_step(&p->ex, &src, out);
    if (out->flags & NCP_SP_STARVED)
        p->st.starved++;
    return more;
}
