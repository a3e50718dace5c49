/* The stage threads of the parallel pipeline. Data never gets copied between
 * stages: each one writes or reads its slot in place in the ring. */
#include "pipe.h"

#include "futex.h"
#include "ncpar/executor.h"
#include "ncpar/lex.h"

#include <time.h>

double ncp_pipe_now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec / 1e6;
}

void ncp_pipe_open_gate(struct ncp_pipe *p)
{
    if (atomic_exchange(&p->gate, 1) == 0)
        ncp_futex_wake_all(&p->gate);
}

void ncp_pipe_abort(struct ncp_pipe *p)
{
    for (int i = 0; i < p->n; i++) {
        ncp_ring_abort(&p->strings[i]);
        ncp_ring_abort(&p->parsed[i]);
    }
    for (int j = 0; j < p->m; j++)
        ncp_ring_abort(&p->cmds[j]);
    ncp_pipe_open_gate(p);
}

/* Block b goes to column b mod n (the paper's i + k*n). */
void *ncp_pipe_feeder(void *arg)
{
    struct ncp_pipe *p = ((struct ncp_pipe_worker *)arg)->p;
    uint64_t off = p->src->begin;
    uint32_t line = p->src->begin_line;
    uint64_t k = 0;
    struct ncp_span sp;
    while (ncp_source_span(p->src, off, line, &sp) == 0) {
        struct ncp_span *slot = ncp_ring_reserve(&p->strings[k % (uint64_t)p->n]);
        if (!slot)
            break;
        *slot = sp;
        ncp_ring_commit(&p->strings[k % (uint64_t)p->n]);
        off = sp.next;
        line++;
        if (++k == p->string_fill)
            ncp_pipe_open_gate(p);
    }
    p->feeder.items = k;
    for (int i = 0; i < p->n; i++)
        ncp_ring_close(&p->strings[i]);
    ncp_pipe_open_gate(p);
    ncp_ring_wake_owed();
    return NULL;
}

/* LEX_i lexes straight into its reserved slot of parsed column i. */
void *ncp_pipe_lexer(void *arg)
{
    struct ncp_pipe_worker *w = arg;
    struct ncp_pipe *p = w->p;
    struct ncp_ring *in = &p->strings[w->index], *out = &p->parsed[w->index];
    const struct ncp_span *sp;
    while ((sp = ncp_ring_peek(in)) != NULL) {
        struct ncp_block *b = ncp_ring_reserve(out);
        if (!b)
            break;
        ncp_lex_block(p->src->text + sp->off, sp->len, sp->line, sp->off, b);
        ncp_ring_commit(out);
        ncp_ring_release(in);
        w->items++;
    }
    ncp_ring_close(out);
    ncp_ring_wake_owed();
    return NULL;
}

/* ---- the analyzer's feed and sink ---------------------------------------- */

/* Blocks come round-robin from the parsed columns, which is file order. The
 * analyzer may hold several blocks at once; they are given back in order. */
static const struct ncp_block *feed_next(void *ctx)
{
    struct ncp_pipe *p = ctx;
    int c = (int)(p->taken % (uint64_t)p->n);
    const struct ncp_block *b = ncp_ring_stage_peek(&p->parsed[c], 1, p->held[c]);
    if (!b)
        return NULL;
    p->held[c]++;
    p->taken++;
    return b;
}

static void feed_release(void *ctx)
{
    struct ncp_pipe *p = ctx;
    if (p->released == p->taken)
        return;
    int c = (int)(p->released % (uint64_t)p->n);
    ncp_ring_release(&p->parsed[c]);
    p->held[c]--;
    p->released++;
}

/* Slot cmd_id lives in executor ring cmd_id mod m. */
static struct ncp_cmd *sink_acquire(void *ctx)
{
    struct ncp_pipe *p = ctx;
    struct ncp_cmd *c = ncp_ring_reserve(&p->cmds[p->next_id % (uint64_t)p->m]);
    if (!c)
        return NULL;
    ncp_cmd_reset_header(c, p->next_id);
    return c;
}

static void sink_publish(void *ctx, struct ncp_cmd *cmd)
{
    struct ncp_pipe *p = ctx;
    (void)cmd;
    ncp_ring_commit(&p->cmds[p->next_id % (uint64_t)p->m]);
    p->next_id++;
    p->analyzer.items++;
}

void *ncp_pipe_analyzer(void *arg)
{
    struct ncp_pipe *p = ((struct ncp_pipe_worker *)arg)->p;
    struct ncp_analyzer *an = ncp_analyzer_new(p->acfg, &p->an_diag);
    if (!an) {
        if (p->an_diag.code == NCP_OK)
            ncp_diag_set(&p->an_diag, NCP_ERR_IO, 0, 0, "out of memory");
        p->an_rc = p->an_diag.code;
    } else {
        struct ncp_block_feed feed = { p, feed_next, feed_release, p->src };
        struct ncp_cmd_sink sink = { p, sink_acquire, sink_publish };
        p->an_rc = ncp_analyzer_run(an, &feed, &sink);
        ncp_analyzer_free(an);
    }
    for (int j = 0; j < p->m; j++)
        ncp_ring_close(&p->cmds[j]);
    /* The program may have ended before the file did (M2, an error): the
     * feeder and lexers working ahead are of no use any more. */
    for (int i = 0; i < p->n; i++) {
        ncp_ring_abort(&p->strings[i]);
        ncp_ring_abort(&p->parsed[i]);
    }
    ncp_ring_wake_owed();
    return NULL;
}

void *ncp_pipe_executor(void *arg)
{
    struct ncp_pipe_worker *w = arg;
    struct ncp_ring *r = &w->p->cmds[w->index];
    struct ncp_cmd *c;
    while ((c = ncp_ring_stage_peek(r, NCP_CMD_STAGE_EXECUTOR, 0)) != NULL) {
        ncp_exec_cmd(c);
        ncp_ring_stage_release(r, NCP_CMD_STAGE_EXECUTOR);
        w->items++;
    }
    ncp_ring_wake_owed();
    return NULL;
}

/* Slots in cmd_id order; the first error, the end of the program or a failed
 * emit stops the run, exactly where the serial reference stops. */
void *ncp_pipe_output(void *arg)
{
    struct ncp_pipe *p = ((struct ncp_pipe_worker *)arg)->p;
    for (uint64_t id = 0;; id++) {
        struct ncp_ring *r = &p->cmds[id % (uint64_t)p->m];
        const struct ncp_cmd *c = ncp_ring_stage_peek(r, NCP_CMD_STAGE_OUTPUT, 0);
        if (!c)
            break;
        p->output.items++;
        int stop = 0;
        if (p->out && p->out->emit(p->out->ctx, c) != 0) {
            p->emit_failed = 1;
            stop = 1;
        }
        if (c->flags & NCP_CMD_F_ERROR) {
            p->err = c->diag;
            stop = 1;
        }
        if (c->flags & NCP_CMD_F_END)
            stop = 1;
        ncp_ring_stage_release(r, NCP_CMD_STAGE_OUTPUT);
        if (stop)
            break;
    }
    p->end_ms = ncp_pipe_now_ms();
    ncp_pipe_abort(p);
    ncp_ring_wake_owed();
    return NULL;
}
