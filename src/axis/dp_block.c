/* ADCBI's DP3 (LAbuf) and DP2 (INTbuf) at the LLC. Records arrive, are
 * numbered, resent and flow-controlled as DP4's (llc.c); what differs is
 * what turns them into the interpolator's ACCDECbuf records:
 *  - DP3: the ACC/DEC stage (ncp_la_profile) on each look-ahead record, as
 *    the interpolator takes it, entered at the speed the last one ended
 *    with: the planner's own call, so the profile is the central one;
 *  - DP2: an own planner (the same INI), given the HLC's planner's calls in
 *    order and stepped between them exactly as often as the HLC's was (each
 *    record says after how many steps it came; NCP_HLC_STEPS says how far
 *    past the last one). Its tap fills `own`, which the interpolator runs.
 *    The HLC's planner steps on the real clock whenever its ring has room,
 *    so the windows its profiles saw depend on timing: replaying that
 *    interleaving is what makes this plan the central one bit for bit. */
#include "axis.h"

#include <string.h>

/* DP2: planner steps (or calls) per period at most: it catches up with the
 * HLC's, up to SETPOINT_RING periods ahead, within a few dozen periods
 * while costing the position loop little. */
#define PLAN_PER_PERIOD 64
/* room kept in `own`: the planner's tap can never be refused */
#define OWN_SPARE 64

static void own_tap(void *ctx, const struct ncp_la *la, const struct ncp_accdec *rec)
{
    (void)la;
    struct llc *l = ctx;
    union ncp_dist_rec u;
    u.a = *rec;
    ncp_dist_recs_put(&l->own, l->own_n++, &u);
}

int llc_blocks_init(struct llc *l)
{
    static const double origin[NCP_AXES];
    if (ncp_dist_recs_init(&l->own) != 0 || !(l->plan = ncp_planner_new(l->cfg, origin)))
        return -1;
    ncp_planner_set_tap(l->plan, own_tap, l);
    return 0;
}

void llc_on_la(struct llc *l, const uint8_t *p, size_t len)
{
    ncp_la_burst_t *b = &l->la_burst;
    if (ncp_la_burst_t_decode(p, 0, (int)len, b) != (int)len || b->sender != NCP_DIST_HLC_ID ||
        b->count < 0 || b->count > NCP_DIST_BURST)
        return;
    l->dp = 3;
    union ncp_dist_rec u;
    for (int i = 0; i < b->count; i++) {
        ncp_dist_la_decode(&b->recs[i], &u.la);
        ncp_dist_recs_put(&l->recs, b->first + i, &u);
    }
}

void llc_on_int(struct llc *l, const uint8_t *p, size_t len)
{
    ncp_int_burst_t *b = &l->int_burst;
    if (ncp_int_burst_t_decode(p, 0, (int)len, b) != (int)len || b->sender != NCP_DIST_HLC_ID ||
        b->count < 0 || b->count > NCP_DIST_BURST)
        return;
    l->dp = 2;
    union ncp_dist_rec u;
    for (int i = 0; i < b->count; i++) {
        ncp_dist_op_decode(&b->recs[i], &u.op);
        ncp_dist_recs_put(&l->recs, b->first + i, &u);
    }
}

void llc_on_steps(struct llc *l, const uint8_t *p, size_t len)
{
    ncp_plan_mark_t k;
    memset(&k, 0, sizeof k);
    if (ncp_plan_mark_t_decode(p, 0, (int)len, &k) != (int)len || k.sender != NCP_DIST_HLC_ID)
        return;
    /* a later mark never says less; an older one come late is ignored */
    if (k.steps > l->mark_steps) {
        l->mark_steps = k.steps;
        l->mark_records = k.records;
    }
    if (k.records > l->hlc_records)
        l->hlc_records = k.records;
}

static void apply(struct llc *l, const struct ncp_dist_op *o)
{
    switch (o->op) {
    case NCP_INT_REC_T_PUSH: ncp_planner_push(l->plan, &o->s); break;
    case NCP_INT_REC_T_FINISH: ncp_planner_finish(l->plan); break;
    case NCP_INT_REC_T_RESTART: ncp_planner_restart(l->plan); break;
    case NCP_INT_REC_T_RESET: ncp_planner_reset(l->plan, o->s.end); break;
    case NCP_INT_REC_T_DROP:
        /* what this planner made so far is the aborted job's: the
         * interpolator drops it at the HLC's period of the abort
         * (llc_scale.c); a RESET to where the HLC rested comes next */
        l->scale.drops++;
        l->scale.drop_own[(unsigned)l->scale.drops % LLC_DROPS] = l->own_n;
        break;
    default: break;   /* a newer HLC's call this LLC does not know */
    }
}

void llc_plan_advance(struct llc *l)
{
    union ncp_dist_rec u;
    for (int n = 0; n < PLAN_PER_PERIOD; n++) {
        int here = ncp_dist_recs_peek(&l->recs, &u);
        if (here && u.op.step <= l->plan_steps) {
            apply(l, &u.op);
            ncp_dist_recs_pop(&l->recs);
            continue;
        }
        /* a step is due before the next call, or past the last call sent
         * as far as the HLC's planner has gone */
        int may = here ? 1 : l->recs.next >= l->mark_records && l->plan_steps < l->mark_steps;
        if (!may || ncp_dist_recs_level(&l->own) > NCP_DIST_RECS - OWN_SPARE)
            return;
        struct ncp_setpoint sp;
        (void)ncp_planner_step(l->plan, &sp);
        l->plan_steps++;
    }
}

struct ncp_dist_recs *llc_exec_ring(struct llc *l)
{
    return l->dp == 2 || l->dp == 1 ? &l->own : &l->recs;
}

int llc_exec_head(struct llc *l, double v0, struct ncp_accdec *a)
{
    union ncp_dist_rec u;
    if (!ncp_dist_recs_peek(llc_exec_ring(l), &u))
        return 0;
    if (l->dp == 3)
        ncp_la_profile(l->cfg->profile, &u.la, v0, a);
    else
        *a = u.a;
    return 1;
}
