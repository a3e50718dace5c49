/* ACCDECbuf records on the wire, and an LLC's ring of block-level records
 * (any point's: they are kept decoded). The record keeps the
 * doubles as the planner froze them: an LLC at DP4 must compute exactly the
 * central run's samples, and any rounding here would show as a path
 * deviation there. */
#include "ncpar/dist.h"
#include "seg_fields.h"

#include <stdlib.h>
#include <string.h>

void ncp_dist_rec_encode(const struct ncp_accdec *a, ncp_accdec_rec_t *r)
{
    const struct ncp_seg *s = &a->s;
    memset(r, 0, sizeof *r);
    NCP_DIST_SEG_ENCODE(s, r);
    r->flags = (int8_t)((a->blend ? NCP_ACCDEC_REC_T_FLAG_BLEND : 0) |
                        (a->after_stop ? NCP_ACCDEC_REC_T_FLAG_AFTER_STOP : 0));
    const struct ncp_trap *t = &a->trap;
    const double tr[12] = { t->v0, t->vp, t->v1, t->a,      t->t1, t->t2,
                            t->t3, t->d1, t->d2, t->length, t->j,  a->dur };
    memcpy(r->trap, tr, sizeof tr);
}

void ncp_dist_rec_decode(const ncp_accdec_rec_t *r, struct ncp_accdec *a)
{
    struct ncp_seg *s = &a->s;
    memset(a, 0, sizeof *a);
    NCP_DIST_SEG_DECODE(r, s);
    a->blend = (r->flags & NCP_ACCDEC_REC_T_FLAG_BLEND) != 0;
    a->after_stop = (r->flags & NCP_ACCDEC_REC_T_FLAG_AFTER_STOP) != 0;
    struct ncp_trap *t = &a->trap;
    t->v0 = r->trap[0];
    t->vp = r->trap[1];
    t->v1 = r->trap[2];
    t->a = r->trap[3];
    t->t1 = r->trap[4];
    t->t2 = r->trap[5];
    t->t3 = r->trap[6];
    t->d1 = r->trap[7];
    t->d2 = r->trap[8];
    t->length = r->trap[9];
    t->j = r->trap[10];
    a->dur = r->trap[11];
}

int ncp_dist_recs_init(struct ncp_dist_recs *q)
{
    memset(q, 0, sizeof *q);
    for (int i = 0; i < NCP_DIST_RECS; i++)
        q->num[i] = -1;
    q->rec = calloc(NCP_DIST_RECS, sizeof *q->rec);
    return q->rec ? 0 : -1;
}

void ncp_dist_recs_free(struct ncp_dist_recs *q)
{
    free(q->rec);
    q->rec = NULL;
}

void ncp_dist_recs_put(struct ncp_dist_recs *q, int32_t num, const union ncp_dist_rec *r)
{
    if (num < q->next) {
        q->stale++;
        return;
    }
    if (num - q->next >= NCP_DIST_RECS) {
        q->early++;
        return;
    }
    unsigned k = (unsigned)num % NCP_DIST_RECS;
    if (q->num[k] == num) {
        q->duplicate++;
        return;
    }
    if (num > q->top)
        q->gaps++;   /* the ones between were lost (or come out of order) */
    q->num[k] = num;
    q->rec[k] = *r;
    if (num >= q->top)
        q->top = num + 1;
    while (q->num[(unsigned)q->have % NCP_DIST_RECS] == q->have)
        q->have++;
}

int ncp_dist_recs_peek(const struct ncp_dist_recs *q, union ncp_dist_rec *r)
{
    unsigned k = (unsigned)q->next % NCP_DIST_RECS;
    if (q->num[k] != q->next)
        return 0;
    *r = q->rec[k];
    return 1;
}

void ncp_dist_recs_pop(struct ncp_dist_recs *q)
{
    /* the record stays in its place until a later one takes it: an LLC may
     * take back a step of its interpolator (q->next with it) */
    if (q->num[(unsigned)q->next % NCP_DIST_RECS] == q->next)
        q->next++;
}

void ncp_dist_recs_skip(struct ncp_dist_recs *q, int32_t num)
{
    if (num > q->next)
        q->next = num;
    if (num > q->top)
        q->top = num;
    if (num > q->have)
        q->have = num;
    while (q->num[(unsigned)q->have % NCP_DIST_RECS] == q->have)
        q->have++;
}
