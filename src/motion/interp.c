/* Rough interpolator: samples the planned profile once per planning period
 * (the servo period unless [TRAJ] PLANNING_PERIOD is longer; the position loop
 * then fine-interpolates, see src/rt/scaler.c). A segment's
 * profile is frozen when it starts (the lazy forward pass); time left over at
 * its end carries into the next segment so the path speed has no gaps, except
 * at a stop, where the end point itself is the sample (exact stop). */
#include "planner_int.h"

#include <math.h>
#include <string.h>

static void start_head(struct ncp_planner *p)
{
    struct plan_seg *ps = plan_at(p, 0);
    double v0 = p->v_now;
    if (ps->s.kind == NCP_SEG_DWELL) {
        memset(&p->trap, 0, sizeof p->trap);
        p->dur = ps->s.dwell;
    } else {
        double next = p->count > 1 ? plan_at(p, 1)->v_in : 0;
        double v1 = fmin(next, ncp_plan_seg_reach(p, ps, v0, ps->s.length));
        double vmax = fmax(ps->vmax, v0);
        if (plan_scurve(p) && ps->jerk > 0 && isfinite(ps->jerk))
            ncp_scurve_plan(&p->trap, ps->s.length, v0, v1, vmax, ps->acc, ps->jerk);
        else
            ncp_trap_plan(&p->trap, ps->s.length, v0, v1, vmax,
                          ncp_plan_seg_profile_acc(p, ps, v0, v1, vmax));
        p->dur = ncp_trap_duration(&p->trap);
    }
    p->active = 1;
    p->line = ps->s.line;
    p->aux = ps->s.aux;
    p->tool_z = ps->s.tool_z;
}

static void sample(struct ncp_planner *p, struct ncp_setpoint *out)
{
    const struct plan_seg *ps = plan_at(p, 0);
    double v = 0;
    if (ps->s.kind == NCP_SEG_DWELL) {
        memcpy(p->pos, ps->s.end, sizeof p->pos);
        memset(out->dir, 0, sizeof out->dir);
    } else {
        double s = ncp_trap_eval(&p->trap, p->t, &v);
        ncp_seg_eval(&ps->s, s, p->pos, out->dir);
        /* a blend arc is part of the feed path around a corner, not a G2/G3 */
        if (ps->s.traverse)
            out->flags |= NCP_SP_RAPID;
        else if (ps->s.kind == NCP_SEG_ARC && !ps->blend)
            out->flags |= NCP_SP_ARC;
    }
    p->v_now = v;
    out->v = v;
    out->rev_rpm = ps->s.rev_rpm;
}

static void hold(struct ncp_planner *p, struct ncp_setpoint *out)
{
    memset(out->dir, 0, sizeof out->dir);
    out->v = 0;
    out->rev_rpm = 0;
    p->v_now = 0;
}

int ncp_planner_step(struct ncp_planner *p, struct ncp_setpoint *out)
{
    int stopped_at_end = 0;
    out->flags = 0;
    if (!p->active) {
        if (p->count == 0) {
            hold(p, out);
            memcpy(out->pos, p->pos, sizeof out->pos);
            out->line = p->line;
            out->aux = p->aux;
            out->tool_z = p->tool_z;
            if (p->finished) {
                out->flags = NCP_SP_END;
                return 0;
            }
            out->flags = NCP_SP_STARVED;
            p->st.starved++;
            return 1;
        }
        start_head(p);
        p->t = 0;
    }
    p->t += p->cfg.planning_period > 0 ? p->cfg.planning_period : p->cfg.servo_period;
    while (p->t >= p->dur) {
        if (p->trap.v1 <= 1e-9 || p->count < 2) {
            p->t = p->dur;
            stopped_at_end = 1;
            break;
        }
        double left = p->t - p->dur;
        p->v_now = p->trap.v1;
        ncp_planner_pop(p);
        start_head(p);
        p->t = left;
    }
    sample(p, out);
    memcpy(out->pos, p->pos, sizeof out->pos);
    out->line = p->line;
    out->aux = p->aux;
    out->tool_z = p->tool_z;
    if (stopped_at_end) {
        ncp_planner_pop(p);
        p->active = 0;
        p->v_now = 0;
        out->v = 0;
    }
    return 1;
}
