/* The stage threads of the parallel pipeline. Data never gets copied between
 * stages: each one writes or reads its slot in place in the ring. */
#include "pipe.h"

#include "futex.h"
#include "ncpar/executor.h"
#include "ncpar/lex.h"

#include <stddef.h>
#include <time.h>

static double clock_ms(clockid_t clock)
{
    struct timespec ts;
    clock_gettime(clock, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec / 1e6;
}

double ncp_pipe_now_ms(void)
{
    return clock_ms(CLOCK_MONOTONIC);
}

double ncp_pipe_thread_cpu_ms(void)
{
    return clock_ms(CLOCK_THREAD_CPUTIME_ID);
}

/* Every stage thread ends here: nothing it holds back may keep another stage
 * asleep, and its CPU time goes into the run's statistics. */
static void *stage_done(void *arg)
{
    ncp_ring_wake_owed();
    ((struct ncp_pipe_worker *)arg)->cpu_ms = ncp_pipe_thread_cpu_ms();
    return NULL;
}

/* ---- prefetching -------------------------------------------------------- */

/* How far ahead the stages warm their next slots: enough to overlap a handful
 * of cache-to-cache transfers, small against any ring. */
#define PREFETCH_AHEAD 6u

/* The lines every command slot uses: header with error code, first op. */
static void prefetch_cmd(const struct ncp_cmd *cmd)
{
    if (!cmd)
        return;
    const char *c = (const char *)cmd;
    __builtin_prefetch(c, 1);
    __builtin_prefetch(c + offsetof(struct ncp_cmd, ops), 1);
    __builtin_prefetch(c + offsetof(struct ncp_cmd, ops) + 64, 1);
    __builtin_prefetch(c + offsetof(struct ncp_cmd, ops) + 128, 1);
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
    return stage_done(arg);
}

/* LEX_i lexes into a block of its own (hot in its cache) and passes it on
 * packed: only the used parts cross to the analyzer's core. */
static int put_packed(struct ncp_ring *out, const struct ncp_block *b)
{
    uint32_t units = (uint32_t)(ncp_block_packed_size(b) / NCP_PACK_UNIT);
    uint32_t to_end = ncp_ring_to_end(out, 0);
    if (units > to_end) { /* records never wrap: pad to the ring's end */
        void *pad = ncp_ring_reserve_n(out, to_end);
        if (!pad)
            return -1;
        ncp_block_pack_pad(pad);
        ncp_ring_commit_n(out, to_end);
    }
    void *dst = ncp_ring_reserve_n(out, units);
    if (!dst)
        return -1;
    ncp_block_pack(b, dst);
    ncp_ring_commit_n(out, units);
    return 0;
}

void *ncp_pipe_lexer(void *arg)
{
    struct ncp_pipe_worker *w = arg;
    struct ncp_pipe *p = w->p;
    struct ncp_ring *in = &p->strings[w->index], *out = &p->parsed[w->index];
    struct ncp_block *b = &p->lex_block[w->index].b;
    const struct ncp_span *sp;
    while ((sp = ncp_ring_peek(in)) != NULL) {
        /* the feeder has just read this text on its own core */
        const struct ncp_span *later = ncp_ring_stage_ahead(in, 1, PREFETCH_AHEAD * 2);
        if (later)
            __builtin_prefetch(p->src->text + later->off, 0);
        ncp_lex_block(p->src->text + sp->off, sp->len, sp->line, sp->off, b);
        ncp_ring_release(in);
        if (put_packed(out, b) != 0)
            break;
        w->items++;
    }
    ncp_ring_close(out);
    return stage_done(arg);
}

/* ---- the analyzer's feed and sink ---------------------------------------- */

/* Blocks come round-robin from the parsed columns, which is file order. The
 * analyzer holds one block at a time: each is unpacked into the pipe's own
 * block and its record given back at once. */
static const struct ncp_block *feed_next(void *ctx)
{
    struct ncp_pipe *p = ctx;
    struct ncp_ring *r = &p->parsed[p->taken % (uint64_t)p->n];
    for (;;) {
        const void *rec = ncp_ring_stage_peek(r, 1, 0);
        if (!rec)
            return NULL;
        if (ncp_block_packed_is_pad(rec)) {
            ncp_ring_stage_release_n(r, 1, ncp_ring_to_end(r, 1));
            continue;
        }
        uint32_t units = (uint32_t)ncp_block_packed_units(rec);
        if (units > 1 && !ncp_ring_stage_peek(r, 1, units - 1))
            return NULL;
        /* the lexer wrote the next records on its core: start their transfer */
        const char *later = ncp_ring_stage_ahead(r, 1, units + 1024 / NCP_PACK_UNIT);
        if (later) {
            __builtin_prefetch(later, 0);
            __builtin_prefetch(later + 64, 0);
            __builtin_prefetch(later + 128, 0);
        }
        ncp_block_unpack(rec, &p->an_block);
        ncp_ring_stage_release_n(r, 1, units);
        break;
    }
    p->taken++;
    return &p->an_block;
}

static void feed_release(void *ctx)
{
    (void)ctx; /* the record went back when it was unpacked */
}

/* Slot cmd_id lives in executor ring cmd_id mod m. */
static struct ncp_cmd *sink_acquire(void *ctx)
{
    struct ncp_pipe *p = ctx;
    struct ncp_ring *r = &p->cmds[p->next_id % (uint64_t)p->m];
    struct ncp_cmd *c = ncp_ring_reserve(r);
    if (!c)
        return NULL;
    prefetch_cmd(ncp_ring_reserve_ahead(r, PREFETCH_AHEAD / (uint32_t)p->m + 1));
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
    return stage_done(arg);
}

void *ncp_pipe_executor(void *arg)
{
    struct ncp_pipe_worker *w = arg;
    struct ncp_ring *r = &w->p->cmds[w->index];
    struct ncp_cmd *c;
    while ((c = ncp_ring_stage_peek(r, NCP_CMD_STAGE_EXECUTOR, 0)) != NULL) {
        prefetch_cmd(ncp_ring_stage_ahead(r, NCP_CMD_STAGE_EXECUTOR, PREFETCH_AHEAD));
        ncp_exec_cmd(c);
        ncp_ring_stage_release(r, NCP_CMD_STAGE_EXECUTOR);
        w->items++;
    }
    return stage_done(arg);
}

/* Slots in cmd_id order (executed here first when there are no executor
 * threads: on a machine with few cores a thread per stage only adds hand-offs);
 * the first error, the end of the program or a failed
 * emit stops the run, exactly where the serial reference stops. */
void *ncp_pipe_output(void *arg)
{
    struct ncp_pipe *p = ((struct ncp_pipe_worker *)arg)->p;
    for (uint64_t id = 0;; id++) {
        struct ncp_ring *r = &p->cmds[id % (uint64_t)p->m];
        struct ncp_cmd *c = ncp_ring_stage_peek(r, p->out_stage, 0);
        if (!c)
            break;
        prefetch_cmd(ncp_ring_stage_ahead(r, p->out_stage, PREFETCH_AHEAD / (uint32_t)p->m + 1));
        if (p->exec_threads == 0)
            ncp_exec_cmd(c);
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
        ncp_ring_stage_release(r, p->out_stage);
        if (stop)
            break;
    }
    p->end_ms = ncp_pipe_now_ms();
    ncp_pipe_abort(p);
    return stage_done(arg);
}
