/* The pipeline's threads as a scheduler's tasks (struct ncp_pipe_hooks): who
 * they are and how full their rings are. Nothing here runs per item: the
 * hooks are called twice a thread and run, the gauges by the scheduler. */
#include "pipe.h"

static enum ncp_pipe_kind kind_of(const struct ncp_pipe_worker *w)
{
    const struct ncp_pipe *p = w->p;
    if (w == &p->feeder)
        return NCP_PIPE_FEEDER;
    if (w == &p->analyzer)
        return NCP_PIPE_ANALYZER;
    if (w == &p->output)
        return NCP_PIPE_OUTPUT;
    return w >= p->lexer && w < p->lexer + NCP_MAX_LEXERS ? NCP_PIPE_LEXER : NCP_PIPE_EXECUTOR;
}

void ncp_pipe_run_stage(struct ncp_pipe_worker *w)
{
    const struct ncp_output *out = w->p->out;
    const struct ncp_pipe_hooks *h = out ? out->threads : NULL;
    struct ncp_pipe_thread t = { kind_of(w), w->index, w->p };
    if (h && h->started)
        h->started(h->ctx, &t);
    /* the monotonic clock is read without a syscall, and only here */
    double t0 = ncp_pipe_now_ms();
    w->fn(w);
    w->wall_ms = ncp_pipe_now_ms() - t0;
    if (h && h->ended)
        h->ended(h->ctx, &t);
}

void *ncp_pipe_stage_main(void *w)
{
    ncp_pipe_run_stage(w);
    return NULL;
}

const char *ncp_pipe_kind_name(enum ncp_pipe_kind k)
{
    static const char *const name[NCP_PIPE_KINDS] = { "feeder", "lexer", "analyzer",
                                                      "executor", "output" };
    return (unsigned)k < NCP_PIPE_KINDS ? name[k] : "?";
}

/* Ring r as seen by stage s of it: what waits for s (from s - 1), or what s
 * has ready for the next (to s + 1). */
static void take_in(const struct ncp_ring *r, unsigned s, size_t *fill, size_t *cap)
{
    *fill += ncp_ring_between(r, s - 1);
    *cap += ncp_ring_cap(r);
}

static void give_out(const struct ncp_ring *r, unsigned s, size_t *fill, size_t *cap)
{
    *fill += ncp_ring_between(r, s);
    *cap += ncp_ring_cap(r);
}

void ncp_pipe_thread_fill(const struct ncp_pipe_thread *t, struct ncp_pipe_fill *f)
{
    const struct ncp_pipe *p = t->pipe;
    *f = (struct ncp_pipe_fill){ 0, 0, 0, 0 };
    switch (t->kind) {
    case NCP_PIPE_FEEDER:
        for (int i = 0; i < p->n; i++)
            give_out(&p->strings[i], 0, &f->out_fill, &f->out_cap);
        break;
    case NCP_PIPE_LEXER:
        take_in(&p->strings[t->index], 1, &f->in_fill, &f->in_cap);
        give_out(&p->parsed[t->index], 0, &f->out_fill, &f->out_cap);
        break;
    case NCP_PIPE_ANALYZER:
        for (int i = 0; i < p->n; i++)
            take_in(&p->parsed[i], 1, &f->in_fill, &f->in_cap);
        for (int j = 0; j < p->m; j++)
            give_out(&p->cmds[j], NCP_CMD_STAGE_ANALYZER, &f->out_fill, &f->out_cap);
        break;
    case NCP_PIPE_EXECUTOR:
        take_in(&p->cmds[t->index], NCP_CMD_STAGE_EXECUTOR, &f->in_fill, &f->in_cap);
        give_out(&p->cmds[t->index], NCP_CMD_STAGE_EXECUTOR, &f->out_fill, &f->out_cap);
        break;
    case NCP_PIPE_OUTPUT:
        for (int j = 0; j < p->m; j++)
            take_in(&p->cmds[j], p->out_stage, &f->in_fill, &f->in_cap);
        break;
    }
}
