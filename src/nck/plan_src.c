/* The setpoint source of the planner thread: the ADCBI planner or the ADCAI
 * chain, chosen by [PLANNER] NCK, behind one set of calls. */
#include "nck_int.h"
#include "planner_state.h"
#include "ncpar/adcai.h"

int nck_plan_new(struct nck_core *n)
{
    if (n->cfg->nck == NCP_NCK_ADCAI)
        n->plan->adcai = ncp_adcai_new(n->cfg, n->start);
    else
        n->plan->planner = ncp_planner_new(n->cfg, n->start);
    if (n->plan->planner && n->cross.be.plan_tap)
        ncp_planner_set_tap(n->plan->planner, n->cross.be.plan_tap, n->cross.be.impl);
    else if (n->plan->planner && n->setup.plan_tap)
        ncp_planner_set_tap(n->plan->planner, n->setup.plan_tap, n->setup.plan_tap_ctx);
    if (n->plan->adcai && n->cross.be.adcai_tap)
        ncp_adcai_set_tap(n->plan->adcai, n->cross.be.adcai_tap, n->cross.be.impl);
    else if (n->plan->adcai && n->setup.adcai_tap)
        ncp_adcai_set_tap(n->plan->adcai, n->setup.adcai_tap, n->setup.adcai_tap_ctx);
    if (n->plan->planner && n->cross.be.plan_journal)
        n->cross.be.plan_journal(n->cross.be.impl, NCP_PLAN_RESET, NULL, n->start);
    return n->plan->adcai || n->plan->planner ? 0 : -1;
}

void nck_plan_free(struct nck_core *n)
{
    ncp_planner_free(n->plan->planner);
    ncp_adcai_free(n->plan->adcai);
    n->plan->planner = NULL;
    n->plan->adcai = NULL;
}

int nck_plan_full(const struct nck_core *n)
{
    return n->plan->adcai ? ncp_adcai_full(n->plan->adcai) : ncp_planner_full(n->plan->planner);
}

size_t nck_plan_queued(const struct nck_core *n)
{
    return n->plan->adcai ? ncp_adcai_queued(n->plan->adcai) : ncp_planner_queued(n->plan->planner);
}

int nck_plan_idle(const struct nck_core *n)
{
    return n->plan->adcai ? ncp_adcai_idle(n->plan->adcai) : ncp_planner_idle(n->plan->planner);
}

/* An HLC at ADCBI's DP2 hands every call on the planner on. */
static void journal(const struct nck_core *n, enum ncp_plan_call c, const struct ncp_seg *s,
                    const double *pos)
{
    if (n->plan->planner && n->cross.be.plan_journal)
        n->cross.be.plan_journal(n->cross.be.impl, c, s, pos);
}

void nck_plan_push(struct nck_core *n, const struct ncp_seg *s)
{
    journal(n, NCP_PLAN_PUSH, s, NULL);
    if (n->plan->adcai)
        ncp_adcai_push(n->plan->adcai, s);
    else
        ncp_planner_push(n->plan->planner, s);
}

void nck_plan_finish(struct nck_core *n)
{
    journal(n, NCP_PLAN_FINISH, NULL, NULL);
    if (n->plan->adcai)
        ncp_adcai_finish(n->plan->adcai);
    else
        ncp_planner_finish(n->plan->planner);
}

void nck_plan_restart(struct nck_core *n)
{
    journal(n, NCP_PLAN_RESTART, NULL, NULL);
    if (n->plan->adcai)
        ncp_adcai_restart(n->plan->adcai);
    else
        ncp_planner_restart(n->plan->planner);
}

void nck_plan_dropped(const struct nck_core *n)
{
    journal(n, NCP_PLAN_DROP, NULL, NULL);
}

void nck_plan_reset(struct nck_core *n, const double pos[NCP_AXES])
{
    journal(n, NCP_PLAN_RESET, NULL, pos);
    if (n->plan->adcai)
        ncp_adcai_reset(n->plan->adcai, pos);
    else
        ncp_planner_reset(n->plan->planner, pos);
}

int nck_plan_step(struct nck_core *n, struct ncp_setpoint *out)
{
    journal(n, NCP_PLAN_STEP, NULL, NULL);
    return n->plan->adcai ? ncp_adcai_step(n->plan->adcai, out) : ncp_planner_step(n->plan->planner, out);
}

void nck_plan_stats(const struct nck_core *n, struct ncp_planner_stats *st)
{
    if (n->plan->adcai)
        ncp_adcai_get_stats(n->plan->adcai, st);
    else
        ncp_planner_get_stats(n->plan->planner, st);
}

/* ADCAI interpolates down to the servo period itself. Its stream is already
 * acc/dec-filtered per axis, so the position loop's time scaling (feed
 * override, feed hold, a late planner) slows the filtered path along
 * itself: the machinist sees a hold or an override change brake and
 * resume along the rounded corners ADCAI cuts, never leave them. */
int nck_plan_stream_ratio(const struct ncp_machine_cfg *c)
{
    return c->nck == NCP_NCK_ADCAI ? 1 : ncp_machine_cfg_ipo_ratio(c);
}
