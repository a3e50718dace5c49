/* ADCBI DP2 (INTbuf) at the HLC: every call on its planner becomes a record
 * numbered in the same sequence, with the count of planner steps taken
 * before it. An LLC that makes the same calls between the same steps gets
 * the same look-ahead: on the real clock the HLC's planner steps whenever
 * the setpoint ring has room, window full or not, so the blocks a segment's
 * profile saw depend on timing; replaying the interleaving, not just the
 * blocks, is what makes each LLC's plan the central one exactly.
 *
 * Steps themselves are not sent: a record says how far the LLC may step
 * before it, and after the last one sent a mark (NCP_HLC_STEPS) says how far
 * the HLC's planner has got. */
#include "lcm_tx.h"

#include <string.h>

#define MARK_MIN 5    /* periods between marks while the steps grow */
#define MARK_MAX 20   /* and at most between two (a lost one is no stall) */

void lcm_dp2_journal(struct lcm_tx *x, struct lcm_dp2 *d, enum ncp_plan_call c,
                     const struct ncp_seg *s, const double *pos)
{
    if (c == NCP_PLAN_STEP) {
        atomic_store_explicit(&d->steps, ++d->steps_own, memory_order_release);
        return;
    }
    struct ncp_dist_op o;
    memset(&o, 0, sizeof o);
    o.op = c == NCP_PLAN_PUSH     ? NCP_INT_REC_T_PUSH
           : c == NCP_PLAN_FINISH ? NCP_INT_REC_T_FINISH
           : c == NCP_PLAN_RESTART ? NCP_INT_REC_T_RESTART
           : c == NCP_PLAN_DROP    ? NCP_INT_REC_T_DROP
                                   : NCP_INT_REC_T_RESET;
    o.step = d->steps_own;
    if (s)
        o.s = *s;
    if (pos)
        memcpy(o.s.end, pos, sizeof o.s.end);
    lcm_tx_push(x, &o);
}

void lcm_dp2_mark(const struct lcm_tx *x, struct lcm_dp2 *d, struct ncp_msg *m, int32_t steps,
                  int64_t t, int64_t period)
{
    /* a record not sent yet may be due before some of those steps */
    if (x->sent < x->next) {
        const struct ncp_dist_op *o = lcm_tx_rec(x, x->sent);
        if (o->step < steps)
            steps = o->step;
    }
    int64_t since = t - d->last_mark;
    if (!(steps != d->last_steps && since >= MARK_MIN * period) && since < MARK_MAX * period)
        return;
    d->last_mark = t;
    d->last_steps = steps;
    ncp_plan_mark_t k = { d->mark_seq++, NCP_DIST_HLC_ID, x->sent, steps };
    uint8_t buf[64];
    int n = ncp_plan_mark_t_encode(buf, 0, sizeof buf, &k);
    if (n > 0)
        (void)ncp_msg_publish(m, NCP_DIST_CH_STEPS, buf, (size_t)n);
}
