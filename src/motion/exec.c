/* The interpolator on its own: runs segments whose profiles are frozen
 * (ncp_accdec, the distributed-NCK paper's ACCDECbuf), one sample per planning period. Time
 * left over at a segment's end carries into the next so the path speed has no
 * gaps, except at a stop, where the end point itself is the sample (exact
 * stop). The planner feeds it as each segment starts (interp.c); an LLC at
 * ADCBI's DP4 feeds it the records it received, and its samples equal the
 * central run's bit for bit because this is the same code on the same
 * doubles. Real-time safe: no allocation, no locks. */
#include "ncpar/motion.h"

#include <string.h>

void ncp_exec_init(struct ncp_exec *e, const double start[NCP_AXES], double period)
{
    memset(e, 0, sizeof *e);
    e->period = period;
    if (start)
        memcpy(e->pos, start, sizeof e->pos);
}

static void take(struct ncp_exec *e)
{
    e->line = e->cur.s.line;
    e->aux = e->cur.s.aux;
    e->tool_z = e->cur.s.tool_z;
}

static void sample(struct ncp_exec *e, struct ncp_setpoint *out)
{
    const struct ncp_accdec *r = &e->cur;
    double v = 0;
    if (r->s.kind == NCP_SEG_DWELL) {
        memcpy(e->pos, r->s.end, sizeof e->pos);
        memset(out->dir, 0, sizeof out->dir);
    } else {
        double s = ncp_trap_eval(&r->trap, e->t, &v);
        ncp_seg_eval(&r->s, s, e->pos, out->dir);
        /* a blend arc is part of the feed path around a corner, not a G2/G3 */
        if (r->s.traverse)
            out->flags |= NCP_SP_RAPID;
        else if (r->s.kind == NCP_SEG_ARC && !r->blend)
            out->flags |= NCP_SP_ARC;
    }
    e->v_now = v;
    out->v = v;
    out->rev_rpm = r->s.rev_rpm;
}

static void fill(const struct ncp_exec *e, struct ncp_setpoint *out)
{
    memcpy(out->pos, e->pos, sizeof out->pos);
    out->line = e->line;
    out->aux = e->aux;
    out->tool_z = e->tool_z;
}

int ncp_exec_step(struct ncp_exec *e, const struct ncp_exec_source *src, struct ncp_setpoint *out)
{
    out->flags = 0;
    if (!e->active) {
        int got = src->next(src->ctx, 0, &e->cur);
        if (got <= 0) {
            memset(out->dir, 0, sizeof out->dir);
            out->v = 0;
            out->rev_rpm = 0;
            e->v_now = 0;
            fill(e, out);
            out->flags = got < 0 ? NCP_SP_END : NCP_SP_STARVED;
            return got < 0 ? 0 : 1;
        }
        e->active = 1;
        e->t = 0;
        take(e);
    }
    e->t += e->period;
    int stopped = 0, ended = 0;
    while (e->t >= e->cur.dur) {
        if (e->cur.trap.v1 <= 1e-9) {
            e->t = e->cur.dur;
            stopped = 1;
            break;
        }
        double left = e->t - e->cur.dur;
        e->v_now = e->cur.trap.v1;
        src->done(src->ctx);
        struct ncp_accdec next;
        if (src->next(src->ctx, e->v_now, &next) <= 0) {
            /* the record ended at speed and none follows: a source that
             * cannot keep up (never the planner, whose look-ahead ends every
             * queue at rest); stop on its end point and say so */
            e->t = e->cur.dur;
            stopped = ended = 1;
            out->flags |= NCP_SP_STARVED;
            break;
        }
        e->cur = next;
        take(e);
        e->t = left;
    }
    sample(e, out);
    fill(e, out);
    if (stopped) {
        if (!ended)
            src->done(src->ctx);
        e->active = 0;
        e->v_now = 0;
        out->v = 0;
    }
    return 1;
}
