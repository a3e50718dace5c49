/* The setpoint source of the planner thread: the ADCBI planner or the ADCAI
 * chain, chosen by [PLANNER] NCK, behind one set of calls. */
#include "nck_int.h"
#include "ncpar/adcai.h"

int nck_plan_new(struct nck *n)
{
    if (n->cfg->nck == NCP_NCK_ADCAI)
        n->adcai = ncp_adcai_new(n->cfg, n->start);
    else
        n->planner = ncp_planner_new(n->cfg, n->start);
    if (n->planner && n->be.plan_tap)
        ncp_planner_set_tap(n->planner, n->be.plan_tap, n->be.impl);
    else if (n->planner && n->setup.plan_tap)
        ncp_planner_set_tap(n->planner, n->setup.plan_tap, n->setup.plan_tap_ctx);
    if (n->adcai && n->be.adcai_tap)
        ncp_adcai_set_tap(n->adcai, n->be.adcai_tap, n->be.impl);
    else if (n->adcai && n->setup.adcai_tap)
        ncp_adcai_set_tap(n->adcai, n->setup.adcai_tap, n->setup.adcai_tap_ctx);
    if (n->planner && n->be.plan_journal)
        n->be.plan_journal(n->be.impl, NCP_PLAN_RESET, NULL, n->start);
    return n->adcai || n->planner ? 0 : -1;
}

void nck_plan_free(struct nck *n)
{
    ncp_planner_free(n->planner);
    ncp_adcai_free(n->adcai);
    n->planner = NULL;
    n->adcai = NULL;
}

int nck_plan_full(const struct nck *n)
{
    return n->adcai ? ncp_adcai_full(n->adcai) : ncp_planner_full(n->planner);
}

size_t nck_plan_queued(const struct nck *n)
{
    return n->adcai ? ncp_adcai_queued(n->adcai) : ncp_planner_queued(n->planner);
}

int nck_plan_idle(const struct nck *n)
{
    return n->adcai ? ncp_adcai_idle(n->adcai) : ncp_planner_idle(n->planner);
}

/* An HLC at ADCBI's DP2 hands every call on the planner on. */
static void journal(const struct nck *n, enum ncp_plan_call c, const struct ncp_seg *s,
                    const double *pos)
{
    if (n->planner && n->be.plan_journal)
        n->be.plan_journal(n->be.impl, c, s, pos);
}

void nck_plan_push(struct nck *n, const struct ncp_seg *s)
{
    journal(n, NCP_PLAN_PUSH, s, NULL);
    if (n->adcai)
        ncp_adcai_push(n->adcai, s);
    else
        ncp_planner_push(n->planner, s);
}

void nck_plan_finish(struct nck *n)
{
    journal(n, NCP_PLAN_FINISH, NULL, NULL);
    if (n->adcai)
        ncp_adcai_finish(n->adcai);
    else
        ncp_planner_finish(n->planner);
}

void nck_plan_restart(struct nck *n)
{
    journal(n, NCP_PLAN_RESTART, NULL, NULL);
    if (n->adcai)
        ncp_adcai_restart(n->adcai);
    else
        ncp_planner_restart(n->planner);
}

void nck_plan_reset(struct nck *n, const double pos[NCP_AXES])
{
    journal(n, NCP_PLAN_RESET, NULL, pos);
    if (n->adcai)
        ncp_adcai_reset(n->adcai, pos);
    else
        ncp_planner_reset(n->planner, pos);
}

int nck_plan_step(struct nck *n, struct ncp_setpoint *out)
{
    journal(n, NCP_PLAN_STEP, NULL, NULL);
    return n->adcai ? ncp_adcai_step(n->adcai, out) : ncp_planner_step(n->planner, out);
}

void nck_plan_stats(const struct nck *n, struct ncp_planner_stats *st)
{
    if (n->adcai)
        ncp_adcai_get_stats(n->adcai, st);
    else
        ncp_planner_get_stats(n->planner, st);
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
