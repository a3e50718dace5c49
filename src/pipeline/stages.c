/* The stage threads of the parallel pipeline. Data never gets copied between
 * stages: each one writes or reads its slot in place in the ring. */
#include "pipe.h"

#include "cmd_pack.h"
#include "emit.h"
#include "futex.h"
#include "ncpar/executor.h"
#include "ncpar/lex.h"

#include <stddef.h>

/* Every stage thread ends here: nothing it holds back may keep another stage
 * asleep, and its CPU time goes into the run's statistics. */
static void *stage_done(void *arg)
{
    ncp_ring_wake_owed();
    ((struct ncp_pipe_worker *)arg)->cpu_ms = ncp_pipe_thread_cpu_ms();
    ((struct ncp_pipe_worker *)arg)->sys_ms = ncp_pipe_thread_sys_ms();
    return NULL;
}

/* ---- prefetching -------------------------------------------------------- */

/* How far ahead the stages warm their next slots: enough to overlap a handful
 * of cache-to-cache transfers, small against any ring. */
#define PREFETCH_AHEAD 6u

/* The lines of a command slot a stage touches next: the analyzer fills the
 * header and the first calls, an executing stage reads those and writes the
 * text, the output reads the text. Written lines are claimed for writing. */
enum slot_use { SLOT_FILL, SLOT_EXECUTE, SLOT_EMIT };

static void prefetch_slot(const struct ncp_cmd *cmd, enum slot_use use)
{
    if (!cmd)
        return;
    const char *c = (const char *)cmd;
    const char *ops = c + offsetof(struct ncp_cmd, ops), *out = c + offsetof(struct ncp_cmd, out);
    if (use == SLOT_FILL) {
        ncp_prefetch_w(c);
        ncp_prefetch_w(ops);
        ncp_prefetch_w(ops + 64);
        ncp_prefetch_w(ops + 128);
        return;
    }
    __builtin_prefetch(c, 0);
    if (use == SLOT_EXECUTE) {
        __builtin_prefetch(ops, 0);
        __builtin_prefetch(ops + 64, 0);
        ncp_prefetch_w(out);
        ncp_prefetch_w(out + 64);
    } else {
        __builtin_prefetch(out, 0);
        __builtin_prefetch(out + 64, 0);
    }
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

/* Chunk k goes to column k mod n (the paper's i + k*n, a chunk of blocks per
 * cell). Counting its line ends gives the next chunk's first line number; it
 * also brings the text into the cache before a lexer reads it. */
void *ncp_pipe_feeder(void *arg)
{
    struct ncp_pipe *p = ((struct ncp_pipe_worker *)arg)->p;
    const struct ncp_source *src = p->src;
    uint64_t off = src->begin;
    uint32_t line = src->begin_line;
    uint64_t k = 0;
    int col = 0;
    /* the lexers read behind the feeder, at most a full string ring */
    struct ncp_source_window win;
    ncp_source_window_start(&win, src, p->string_fill * NCP_CHUNK_BYTES + NCP_SOURCE_WINDOW_LAG);
    while (off < src->end) {
        ncp_source_window_at(&win, off);
        uint64_t end = ncp_source_chunk_end(src, off, NCP_CHUNK_BYTES);
        struct ncp_ring *r = &p->strings[col];
        struct ncp_chunk *slot = ncp_ring_reserve(r);
        if (!slot)
            break;
        *slot = (struct ncp_chunk){ off, end, line };
        ncp_ring_commit(r);
        line += (uint32_t)ncp_source_count_newlines(src, off, end);
        off = end;
        if (++col == p->n)
            col = 0;
        if (++k == p->string_fill)
            ncp_pipe_open_gate(p);
    }
    p->feeder.items = k;
    for (int i = 0; i < p->n; i++)
        ncp_ring_close(&p->strings[i]);
    ncp_pipe_open_gate(p);
    return stage_done(arg);
}

/* Without lexer threads (-j 0) this thread used to read one byte of every
 * page of a mapped program ahead of the analyzer, when the first touch of a
 * page cost microseconds in these guests. It now does nothing: touching the
 * whole program ahead would make the process hold all of it, and the
 * analyzer's window (ncp_source_window) brings the text in as it goes. It
 * stays a stage so that the layouts keep their threads and statistics. */
void *ncp_pipe_prefaulter(void *arg)
{
    return stage_done(arg);
}

/* ---- rings of packed records ------------------------------------------- */

/* Blocks (lexer -> analyzer) and, without executor threads, commands
 * (analyzer -> output) cross in rings of 8-byte units as records of their
 * own size (rec_stream.h). What differs between the two is how a record
 * marks a pad and tells its size. */

/* A chunk's end mark is one unit, without a block header to read. */
static size_t block_record_units(const void *src)
{
    return ncp_block_packed_is_end_mark(src) ? 1 : ncp_block_packed_units(src);
}

static const struct ncp_record_kind block_stream = {
    ncp_block_pack_pad, ncp_block_packed_is_pad, block_record_units
};
static const struct ncp_record_kind cmd_stream = {
    ncp_cmd_pack_pad, ncp_cmd_packed_is_pad, ncp_cmd_packed_units
};

/* LEX_i lexes into a block of its own (hot in its cache) and passes it on
 * packed: only the used parts cross to the analyzer's core. */
static int put_packed(struct ncp_rec_writer *out, const struct ncp_block *b)
{
    uint32_t units = (uint32_t)(ncp_block_packed_size(b) / NCP_PACK_UNIT);
    void *dst = ncp_rec_reserve(out, units);
    if (!dst)
        return -1;
    ncp_block_pack(b, dst);
    ncp_rec_commit(out, units);
    return 0;
}

/* The analyzer moves on to the next column when it meets this. */
static int put_end_mark(struct ncp_rec_writer *out)
{
    void *dst = ncp_rec_reserve(out, 1);
    if (!dst)
        return -1;
    ncp_block_pack_end_mark(dst);
    ncp_rec_commit(out, 1);
    return 0;
}

/* Every block of the chunk, in order, then the chunk's end mark. */
static int lex_chunk(struct ncp_pipe_worker *w, const struct ncp_chunk *c,
                     struct ncp_rec_writer *out, struct ncp_block *b)
{
    const char *text = w->p->src->text;
    uint32_t line = c->line;
    for (uint64_t off = c->off; off < c->end; line++) {
        size_t next;
        ncp_lex_line(text + off, c->end - off, line, off, b, &next);
        if (put_packed(out, b) != 0)
            return -1;
        w->items++;
        off += next;
    }
    return put_end_mark(out);
}

void *ncp_pipe_lexer(void *arg)
{
    struct ncp_pipe_worker *w = arg;
    struct ncp_pipe *p = w->p;
    struct ncp_ring *in = &p->strings[w->index];
    struct ncp_rec_writer out;
    ncp_rec_writer_start(&out, &p->parsed[w->index], &block_stream);
    struct ncp_block *b = &p->lex_block[w->index].b;
    const struct ncp_chunk *slot;
    while ((slot = ncp_ring_peek(in)) != NULL) {
        struct ncp_chunk c = *slot;
        ncp_ring_release(in);
        if (lex_chunk(w, &c, &out, b) != 0)
            break;
    }
    ncp_ring_close(&p->parsed[w->index]);
    return stage_done(arg);
}

/* ---- the analyzer's feed and sink ---------------------------------------- */

/* Blocks come round-robin from the parsed columns, which is file order. The
 * analyzer holds one block at a time: each is unpacked into the pipe's own
 * block and its record given back at once. */
static const struct ncp_block *feed_next(void *ctx)
{
    struct ncp_pipe *p = ctx;
    struct ncp_rec_reader *in = &p->block_in[p->chunk % (uint64_t)p->n];
    for (;;) {
        uint32_t units;
        const void *rec = ncp_rec_take_as(in, &block_stream, &units);
        if (!rec)
            return NULL;
        if (ncp_block_packed_is_end_mark(rec)) {
            ncp_rec_release(in, 1);
            p->chunk++;
            in = &p->block_in[p->chunk % (uint64_t)p->n];
            continue;
        }
        ncp_block_unpack_over(rec, &p->an_block, &p->an_plain);
        ncp_rec_release(in, units);
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
    prefetch_slot(ncp_ring_reserve_ahead(r, PREFETCH_AHEAD / (uint32_t)p->m + 1), SLOT_FILL);
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

/* Inline output: each command executed and written the moment the analyzer
 * publishes it, stopping where the output thread (and the serial reference)
 * would stop. */
static struct ncp_cmd *inline_acquire(void *ctx)
{
    struct ncp_pipe *p = ctx;
    if (p->inline_stopped)
        return NULL;
    ncp_cmd_reset_header(p->an_cmd, p->next_id);
    return p->an_cmd;
}

static void inline_publish(void *ctx, struct ncp_cmd *c)
{
    struct ncp_pipe *p = ctx;
    p->next_id++;
    p->analyzer.items++;
    p->output.items++;
    if (ncp_exec_emit_cmd(c, p->out, &p->err, &p->emit_failed))
        p->inline_stopped = 1;
}

/* Packed output (no executor threads): the analyzer hands each command to
 * the output thread packed, which executes it (arc geometry, which may still
 * turn it into an error, then the text) and writes it, as an executor and the
 * output thread would. Executing is about a third of the analyzer's work on
 * CAM programs; on two cores it then runs on the other core, which has time
 * to spare. */
/* The slot is room for a whole command in the ring itself: the analyzer
 * writes it where its record goes, and publishing only makes it a record
 * (cmd_pack.h). */
#define CMD_IN_PLACE_UNITS ((uint32_t)((NCP_CMD_IN_PLACE_BYTES + NCP_PACK_UNIT - 1) / NCP_PACK_UNIT))

static struct ncp_cmd *packed_acquire(void *ctx)
{
    struct ncp_pipe *p = ctx;
    if (ncp_ring_aborted(&p->cmds[0]))
        return NULL;
    struct ncp_cmd *c = ncp_rec_reserve(&p->cmd_out, CMD_IN_PLACE_UNITS);
    if (!c)
        return NULL;
    ncp_cmd_reset_header(c, p->next_id);
    return c;
}

static void packed_publish(void *ctx, struct ncp_cmd *c)
{
    struct ncp_pipe *p = ctx;
    p->next_id++;
    p->analyzer.items++;
    ncp_rec_commit(&p->cmd_out, (uint32_t)(ncp_cmd_pack_in_place(c) / NCP_PACK_UNIT));
}

/* A queue buster: the commands before it must reach the machine, so the
 * positions this thread holds back in its rings are published first; the
 * executors and the output thread then run them out while it waits. */
static int pipe_sync(void *ctx, struct ncp_machine_sync *ms)
{
    const struct ncp_pipe *p = ctx;
    ncp_ring_wake_owed();
    return p->out->sync(p->out->ctx, ms);
}

void *ncp_pipe_analyzer(void *arg)
{
    struct ncp_pipe *p = ((struct ncp_pipe_worker *)arg)->p;
    struct ncp_analyzer *an = p->acfg && p->acfg->instance
                                  ? p->acfg->instance
                                  : ncp_analyzer_new(p->acfg, &p->an_diag);
    if (!an) {
        if (p->an_diag.code == NCP_OK)
            ncp_diag_set(&p->an_diag, NCP_ERR_IO, 0, 0, "out of memory");
        p->an_rc = p->an_diag.code;
    } else {
        struct ncp_block_feed feed = { p, feed_next, feed_release, p->src };
        p->an_plain = 0;
        for (int i = 0; i < p->n; i++)
            ncp_rec_reader_start(&p->block_in[i], &p->parsed[i], &block_stream);
        if (p->ahead) { /* started with the run (ncp_pipe_set_run) */
            feed = (struct ncp_block_feed){ p->ahead, ncp_lex_ahead_next, ncp_text_feed_release,
                                            p->src };
        } else if (p->n == 0) {
            ncp_text_feed_start(p->text, p->src);
            feed = (struct ncp_block_feed){ p->text, ncp_text_feed_next, ncp_text_feed_release,
                                            p->src };
        }
        struct ncp_cmd_sink sink = { p, sink_acquire, sink_publish };
        if (p->inline_out)
            sink = (struct ncp_cmd_sink){ p, inline_acquire, inline_publish };
        else if (p->packed_out) {
            ncp_rec_writer_start(&p->cmd_out, &p->cmds[0], &cmd_stream);
            sink = (struct ncp_cmd_sink){ p, packed_acquire, packed_publish };
        }
        ncp_analyzer_set_sync(an, p->out && p->out->sync ? pipe_sync : NULL, p);
        p->an_rc = ncp_analyzer_run(an, &feed, &sink);
        ncp_analyzer_set_sync(an, NULL, NULL);
        if (p->ahead) {
            ncp_lex_ahead_finish(p->ahead);
            p->taken = p->ahead->feed.blocks;
        } else if (p->n == 0) {
            p->taken = p->text->blocks;
        }
        if (!p->acfg || an != p->acfg->instance)
            ncp_analyzer_free(an);
    }
    if (p->inline_out)
        p->end_ms = ncp_pipe_now_ms();
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
        prefetch_slot(ncp_ring_stage_ahead(r, NCP_CMD_STAGE_EXECUTOR, PREFETCH_AHEAD), SLOT_EXECUTE);
        ncp_exec_cmd(c);
        ncp_ring_stage_release(r, NCP_CMD_STAGE_EXECUTOR);
        w->items++;
    }
    return stage_done(arg);
}

/* One packed command executed and handed to the output; 1 when the run stops
 * after it. A calls-only record (every CAM command) is executed where it
 * stands, its text formatted straight into the output's buffer: nothing of it
 * is copied (cmd_pack.h says why it may be read as a slot). An error found
 * while executing it goes to this thread's own slot, the record's head and
 * calls follow it there, and the command is emitted from there. Any other
 * record, or an output without a buffer of its own (emit reads the whole
 * slot), is unpacked into that slot first. */
static int exec_emit_record(struct ncp_pipe *p, const void *rec)
{
    const struct ncp_output *out = p->out;
    struct ncp_cmd *own = p->out_cmd;
    char *dst;
    if (!ncp_cmd_packed_calls_only(rec) || !out || !out->reserve ||
        (dst = out->reserve(out->ctx)) == NULL) {
        ncp_cmd_unpack(rec, own);
        return ncp_exec_emit_cmd(own, out, &p->err, &p->emit_failed);
    }
    /* the reader's to write: the writer is done with it until it is released */
    struct ncp_cmd *c = (struct ncp_cmd *)rec;
    if (ncp_exec_cmd_into_diag(c, dst, &own->diag) != NCP_OK) {
        ncp_cmd_copy_calls(c, own);
        c = own;
    }
    return ncp_emit_stop(c, out->commit(out->ctx, c) != 0, &p->err, &p->emit_failed);
}

/* Without executor threads: each packed command executed here. With no
 * command waiting, the thread lexes ahead for the analyzer instead of waiting
 * (lex_ahead.h), having first published what it has taken, so the analyzer
 * does not find the ring full while this thread is busy elsewhere. */
static void output_packed(struct ncp_pipe *p)
{
    struct ncp_lex_ahead *ahead = p->ahead;
    struct ncp_rec_reader in;
    ncp_rec_reader_start(&in, &p->cmds[0], &cmd_stream);
    for (;;) {
        if (ahead && ncp_rec_poll(&in) == 0) {
            ncp_ring_wake_owed();
            if (ncp_lex_ahead_help(ahead))
                continue;
        }
        uint32_t units;
        const void *rec = ncp_rec_take_as(&in, &cmd_stream, &units);
        if (!rec)
            break;
        p->output.items++;
        int stop = exec_emit_record(p, rec);
        ncp_rec_release(&in, units);
        if (stop)
            break;
    }
}

/* With executor threads: the slots they completed, round-robin over their
 * rings, which is cmd_id order. */
static void output_slots(struct ncp_pipe *p)
{
    for (uint64_t id = 0;; id++) {
        struct ncp_ring *r = &p->cmds[id % (uint64_t)p->m];
        struct ncp_cmd *c = ncp_ring_stage_peek(r, p->out_stage, 0);
        if (!c)
            break;
        prefetch_slot(ncp_ring_stage_ahead(r, p->out_stage, PREFETCH_AHEAD / (uint32_t)p->m + 1),
                      SLOT_EMIT);
        p->output.items++;
        int stop = ncp_emit_cmd(c, p->out, &p->err, &p->emit_failed);
        ncp_ring_stage_release(r, p->out_stage);
        if (stop)
            break;
    }
}

/* Commands leave in cmd_id order; the first error, the end of the program or a
 * failed emit stops the run, exactly where the serial reference stops. */
void *ncp_pipe_output(void *arg)
{
    struct ncp_pipe *p = ((struct ncp_pipe_worker *)arg)->p;
    if (p->packed_out)
        output_packed(p);
    else
        output_slots(p);
    p->end_ms = ncp_pipe_now_ms();
    ncp_pipe_abort(p);
    return stage_done(arg);
}
