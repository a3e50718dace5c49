/* ncp_pipeline_run: sets up the rings, starts the stage threads in the paper's
 * order (feeder first, the rest once the string ring is full, at EOF or after
 * the start timeout), joins them and reports exactly what the serial reference
 * would. */
#include "pipe.h"

#include "cmd_pack.h"
#include "futex.h"

#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static struct ncp_ring *rings_new(int count)
{
    struct ncp_ring *r = aligned_alloc(64, sizeof *r * (size_t)count);
    if (r)
        memset(r, 0, sizeof *r * (size_t)count);
    return r;
}

static void rings_free(struct ncp_ring *r, int count)
{
    if (!r)
        return;
    for (int i = 0; i < count; i++)
        ncp_ring_destroy(&r[i]);
    free(r);
}

void ncp_pipe_free(struct ncp_pipe *p)
{
    if (!p)
        return;
    rings_free(p->strings, p->n);
    rings_free(p->parsed, p->n);
    rings_free(p->cmds, p->m);
    free(p->an_cmd);
    free(p->out_cmd);
    free(p->text);
    if (p->ahead)
        ncp_lex_ahead_destroy(p->ahead);
    free(p->ahead);
    free(p);
}

static int clamp(int v, int lo, int hi)
{
    return v < lo ? lo : v > hi ? hi : v;
}

/* A ring of packed records (blocks, commands) in 8-byte units: rows of
 * row_bytes, and never less than two of the largest records (one always fits
 * after the padding at the wrap point). A CAM block packs to 64 bytes (rows of
 * 256), a plain command to 144 (rows of 4 KB per command slot, below). */
static uint32_t record_ring_units(uint32_t rows, size_t row_bytes, size_t record_max)
{
    uint64_t units = (uint64_t)rows * (row_bytes / NCP_PACK_UNIT);
    uint64_t least = 2 * (record_max / NCP_PACK_UNIT + 1);
    if (units < least)
        units = least;
    return units > NCP_RING_MAX_CAPACITY ? NCP_RING_MAX_CAPACITY : (uint32_t)units;
}

static void workers_reset(struct ncp_pipe *p);

/* More stage threads than CPUs: a stage that polls an empty or full ring
 * holds a CPU that the stage it waits for may need, so it sleeps at once.
 * Without lexer threads the first thread is the prefaulter, done in the
 * first milliseconds: it does not count (-j 0 keeps its polling). */
static void set_spin(struct ncp_pipe *p)
{
    struct ncp_pipe_stage st[NCP_PIPE_MAX_THREADS];
    int threads = ncp_pipe_stages(p, st) - (p->n == 0 ? 1 : 0);
    long cpus = sysconf(_SC_NPROCESSORS_ONLN);
    if (cpus < 1 || threads <= cpus)
        return;
    for (int i = 0; i < p->n; i++) {
        ncp_ring_set_spin(&p->strings[i], 0);
        ncp_ring_set_spin(&p->parsed[i], 0);
    }
    for (int j = 0; j < p->m; j++)
        ncp_ring_set_spin(&p->cmds[j], 0);
}

struct ncp_pipe *ncp_pipe_new(const struct ncp_thread_map *map)
{
    struct ncp_pipe *p = aligned_alloc(64, (sizeof *p + 63) / 64 * 64);
    if (!p)
        return NULL;
    memset(p, 0, sizeof *p);
    p->map = map;
    p->n = clamp(map->n_lexers, 0, NCP_MAX_LEXERS);
    p->exec_threads = clamp(map->n_executors, 0, NCP_MAX_EXECUTORS);
    p->inline_out = map->inline_output && p->exec_threads == 0;
    p->packed_out = p->exec_threads == 0 && !p->inline_out;
    p->m = p->exec_threads > 0 ? p->exec_threads : p->inline_out ? 0 : 1;
    p->out_stage = p->exec_threads > 0 ? NCP_CMD_STAGE_OUTPUT : NCP_CMD_STAGE_EXECUTOR;
    atomic_init(&p->gate, 0);
    /* No lexer threads: no feeder either, the analyzer reads the text itself */
    p->strings = p->n > 0 ? rings_new(p->n) : NULL;
    p->parsed = p->n > 0 ? rings_new(p->n) : NULL;
    /* no lexer threads: the analyzer's own feed, or with packed output the
     * lexing-ahead one (which has a feed of its own) */
    int lex_ahead = p->n == 0 && p->packed_out && map->lex_ahead_bytes > 0;
    p->text = p->n == 0 && !lex_ahead ? malloc(sizeof *p->text) : NULL;
    p->cmds = p->m > 0 ? rings_new(p->m) : NULL;
    /* Without executor threads the analyzer fills a slot of its own (inline
     * or packed output). aligned_alloc wants a multiple of the alignment. */
    size_t cmd_bytes = (sizeof(struct ncp_cmd) + 63) / 64 * 64;
    p->an_cmd = p->exec_threads == 0 ? aligned_alloc(64, cmd_bytes) : NULL;
    p->out_cmd = p->packed_out ? aligned_alloc(64, cmd_bytes) : NULL;
    if (lex_ahead) {
        size_t ahead_bytes = (sizeof *p->ahead + 63) / 64 * 64;
        p->ahead = aligned_alloc(64, ahead_bytes);
        if (p->ahead && ncp_lex_ahead_init(p->ahead, (uint64_t)map->lex_ahead_bytes) != 0) {
            ncp_lex_ahead_destroy(p->ahead);
            free(p->ahead);
            p->ahead = NULL;
        }
        if (!p->ahead) {
            ncp_pipe_free(p);
            return NULL;
        }
    }
    if ((p->n > 0 && (!p->strings || !p->parsed)) || (p->n == 0 && !p->text && !p->ahead) ||
        (p->m > 0 && !p->cmds) ||
        (p->exec_threads == 0 && !p->an_cmd) || (p->packed_out && !p->out_cmd)) {
        ncp_pipe_free(p);
        return NULL;
    }
    uint32_t g = (uint32_t)clamp(map->string_rows, 1, NCP_RING_MAX_CAPACITY);
    uint32_t h = (uint32_t)clamp(map->parsed_rows, 1, NCP_RING_MAX_CAPACITY);
    uint32_t s = (uint32_t)clamp(map->cmd_slots, 1, NCP_RING_MAX_CAPACITY);
    int bad = 0;
    for (int i = 0; i < p->n; i++) {
        bad |= ncp_ring_init(&p->strings[i], sizeof(struct ncp_chunk), g);
        bad |= ncp_ring_init(&p->parsed[i], NCP_PACK_UNIT,
                             record_ring_units(h, 256, NCP_BLOCK_PACK_MAX));
        if (!bad) /* publish about every 4 KB of records, not every 32 units */
            ncp_ring_set_batch(&p->parsed[i], 4096 / NCP_PACK_UNIT);
    }
    if (p->packed_out) {
        /* cmd_slots of 4 KB (a few dozen plain commands each), never less
         * than two of the largest. Lexing ahead lets the analyzer run through
         * up to NCP_AHEAD_SLOTS chunks of ready blocks faster than the output
         * thread keeps up: a ring that holds fewer commands than that fills,
         * and the analyzer sleeps until half of it is free. Rows smaller
         * than 4 KB only add wake-ups. */
        bad |= ncp_ring_init(&p->cmds[0], NCP_PACK_UNIT,
                             record_ring_units(s, 4096, NCP_CMD_PACK_MAX));
        if (!bad)
            ncp_ring_set_batch(&p->cmds[0], 4096 / NCP_PACK_UNIT);
    } else {
        for (int j = 0; j < p->m; j++)
            bad |= ncp_ring_init_staged(&p->cmds[j], sizeof(struct ncp_cmd), s,
                                        NCP_CMD_STAGES);
    }
    if (bad) {
        ncp_pipe_free(p);
        return NULL;
    }
    set_spin(p);
    p->string_fill = p->n > 0 ? (uint64_t)ncp_ring_cap(&p->strings[0]) * (uint64_t)p->n : 0;
    workers_reset(p);
    return p;
}

/* The counters start again; a worker keeps its stage's code (a pool's
 * threads run it again in the next run). */
static void worker_reset(struct ncp_pipe *p, struct ncp_pipe_worker *w, int index)
{
    *w = (struct ncp_pipe_worker){ .p = p, .fn = w->fn, .index = index };
}

static void workers_reset(struct ncp_pipe *p)
{
    for (int i = 0; i < NCP_MAX_LEXERS; i++)
        worker_reset(p, &p->lexer[i], i);
    for (int j = 0; j < NCP_MAX_EXECUTORS; j++)
        worker_reset(p, &p->executor[j], j);
    worker_reset(p, &p->feeder, 0);
    worker_reset(p, &p->analyzer, 0);
    worker_reset(p, &p->output, 0);
}

void ncp_pipe_reset(struct ncp_pipe *p)
{
    for (int i = 0; i < p->n; i++) {
        ncp_ring_reset(&p->strings[i]);
        ncp_ring_reset(&p->parsed[i]);
    }
    for (int j = 0; j < p->m; j++)
        ncp_ring_reset(&p->cmds[j]);
    atomic_store(&p->gate, 0);
    workers_reset(p);
    p->taken = 0;
    p->chunk = 0;
    p->next_id = 0;
    p->an_rc = NCP_OK;
    memset(&p->an_diag, 0, sizeof p->an_diag);
    memset(&p->err, 0, sizeof p->err);
    p->emit_failed = 0;
    p->inline_stopped = 0;
    p->end_ms = 0;
    p->alloc_ms = 0;
}

void ncp_pipe_set_run(struct ncp_pipe *p, const struct ncp_source *src,
                      const struct ncp_analyzer_cfg *acfg, const struct ncp_output *out)
{
    p->src = src;
    p->acfg = acfg;
    p->out = out;
    /* here, not in the analyzer: the output thread may look for lexing work
     * before the analyzer has started */
    if (p->ahead)
        ncp_lex_ahead_start(p->ahead, src);
}

/* The paper's start rule: the lexers wait for a full string ring, EOF, or
 * the start timeout, whichever comes first. */
void ncp_pipe_wait_gate(struct ncp_pipe *p, int timeout_us)
{
    double deadline = ncp_pipe_now_ms() + timeout_us / 1e3;
    while (atomic_load(&p->gate) == 0) {
        double left = deadline - ncp_pipe_now_ms();
        if (left <= 0)
            return;
        long long ns = (long long)(left * 1e6);
        struct timespec ts = { (time_t)(ns / 1000000000LL), (long)(ns % 1000000000LL) };
        ncp_futex_wait(&p->gate, 0, &ts);
    }
}

void ncp_pipe_start_thread(struct ncp_starter *s, const struct ncp_rt_place *spec,
                           void *(*fn)(void *), void *arg)
{
    if (s->failed)
        return;
    int pin = s->p->map->mode == NCP_MODE_ATT;
    /* CPU time, not wall time: a new thread may preempt its creator, and
     * that time is the pipeline's work, not start-up. */
    double t0 = ncp_pipe_thread_cpu_ms();
    struct ncp_rt_place at = *spec;
    if (!pin)
        at.cpu = -1;
    int rc = ncp_rt_start(&s->tid[s->started], &at, fn, arg, &s->warnings);
    s->setup_ms += ncp_pipe_thread_cpu_ms() - t0;
    if (rc != 0) {
        s->failed = 1;
        ncp_pipe_abort(s->p);
        return;
    }
    s->started++;
}

int ncp_pipe_stages(struct ncp_pipe *p, struct ncp_pipe_stage out[NCP_PIPE_MAX_THREADS])
{
    const struct ncp_thread_map *map = p->map;
    int k = 0;
    out[k++] = (struct ncp_pipe_stage){ &map->feeder,
                                        p->n > 0 ? ncp_pipe_feeder : ncp_pipe_prefaulter,
                                        &p->feeder, 0 };
    for (int i = 0; i < p->n; i++)
        out[k++] = (struct ncp_pipe_stage){ &map->lexer[i], ncp_pipe_lexer, &p->lexer[i], 1 };
    out[k++] = (struct ncp_pipe_stage){ &map->analyzer, ncp_pipe_analyzer, &p->analyzer, 0 };
    for (int j = 0; j < p->exec_threads; j++)
        out[k++] = (struct ncp_pipe_stage){ &map->executor[j], ncp_pipe_executor,
                                            &p->executor[j], 0 };
    if (!p->inline_out)
        out[k++] = (struct ncp_pipe_stage){ &map->output, ncp_pipe_output, &p->output, 0 };
    for (int i = 0; i < k; i++)
        out[i].w->fn = out[i].fn;
    return k;
}

/* The paper's order: the feeder first, the rest once the gate opened. */
static void start_all(struct ncp_starter *s)
{
    struct ncp_pipe_stage st[NCP_PIPE_MAX_THREADS];
    int n = ncp_pipe_stages(s->p, st);
    for (int k = 0; k < n; k++) {
        if (k == 1 && s->p->n > 0 && !s->failed)
            ncp_pipe_wait_gate(s->p, s->p->map->start_timeout_us);
        ncp_pipe_start_thread(s, st[k].spec, ncp_pipe_stage_main, st[k].w);
    }
}

static void stage_stats(struct ncp_stage_stats *st, const struct ncp_pipe_worker *w)
{
    memset(st, 0, sizeof *st);
    if (w) {
        st->items = w->items;
        st->cpu_ms = w->cpu_ms;
        st->wall_ms = w->wall_ms;
        st->sys_ms = w->sys_ms;
    }
}

static void add_waits(struct ncp_stage_stats *st, const struct ncp_ring *r, unsigned s,
                      int full)
{
    if (full)
        st->full_waits += ncp_ring_waits(r, s);
    else
        st->empty_waits += ncp_ring_waits(r, s);
    st->sleeps += ncp_ring_sleeps(r, s);
}

void ncp_pipe_fill_stats(const struct ncp_pipe *p, const struct ncp_starter *s, double t0,
                         struct ncp_run_stats *st)
{
    st->blocks = 0;
    st->commands = p->output.items;
    st->wall_ms = (p->end_ms > 0 ? p->end_ms : ncp_pipe_now_ms()) - t0;
    st->threads = s->started;
    st->warnings = s->warnings;
    st->setup_ms = s->setup_ms + p->alloc_ms;
    stage_stats(&st->feeder, &p->feeder);
    stage_stats(&st->analyzer, &p->analyzer);
    st->analyzer.items = p->taken;
    st->lexed_ahead = p->ahead ? p->ahead->h_blocks : 0;
    st->ahead_waits = p->ahead ? p->ahead->a_waits : 0;
    st->ahead_sleeps = p->ahead ? p->ahead->a_slept : 0;
    if (p->n == 0)
        st->blocks = p->taken;
    stage_stats(&st->output, &p->output);
    for (int i = 0; i < NCP_MAX_LEXERS; i++)
        stage_stats(&st->lexer[i], i < p->n ? &p->lexer[i] : NULL);
    for (int j = 0; j < NCP_MAX_EXECUTORS; j++)
        stage_stats(&st->executor[j], j < p->exec_threads ? &p->executor[j] : NULL);
    for (int i = 0; i < p->n; i++) {
        st->blocks += p->lexer[i].items;
        add_waits(&st->feeder, &p->strings[i], 0, 1);
        add_waits(&st->lexer[i], &p->strings[i], 1, 0);
        add_waits(&st->lexer[i], &p->parsed[i], 0, 1);
        add_waits(&st->analyzer, &p->parsed[i], 1, 0);
    }
    for (int j = 0; j < p->m; j++) {
        add_waits(&st->analyzer, &p->cmds[j], NCP_CMD_STAGE_ANALYZER, 1);
        if (p->exec_threads > 0)
            add_waits(&st->executor[j], &p->cmds[j], NCP_CMD_STAGE_EXECUTOR, 0);
        add_waits(&st->output, &p->cmds[j], p->out_stage, 0);
    }
}

/* Same precedence as the serial reference: the first error slot, then a failed
 * write, then an analyzer that stopped without a diagnostic. */
int ncp_pipe_result(const struct ncp_pipe *p, const struct ncp_starter *s, struct ncp_diag *d)
{
    if (p->err.code != NCP_OK) {
        *d = p->err;
        return d->code;
    }
    if (p->emit_failed)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot write output");
    if (s->failed)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "cannot start the pipeline threads");
    if (p->an_diag.code != NCP_OK) {
        *d = p->an_diag;
        return d->code;
    }
    if (p->an_rc != NCP_OK && p->an_rc != NCP_END) {
        ncp_diag_set(d, (enum ncp_status)p->an_rc, 0, 0,
                     "interpreter stopped without a diagnostic");
        return p->an_rc;
    }
    return NCP_OK;
}

int ncp_pipeline_run(const struct ncp_source *src, const struct ncp_thread_map *map,
                     const struct ncp_analyzer_cfg *acfg, const struct ncp_output *out,
                     struct ncp_run_stats *stats, struct ncp_diag *d)
{
    if (map->mode == NCP_MODE_SERIAL)
        return ncp_serial_run(src, acfg, out, stats, d);
    double t0 = ncp_pipe_now_ms(), cpu0 = ncp_pipe_thread_cpu_ms();
    memset(d, 0, sizeof *d);
    struct ncp_pipe *p = ncp_pipe_new(map);
    if (!p)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "out of memory for the pipeline rings");
    p->alloc_ms = ncp_pipe_thread_cpu_ms() - cpu0;
    ncp_pipe_set_run(p, src, acfg, out);

    struct ncp_starter s;
    memset(&s, 0, sizeof s);
    s.p = p;
    start_all(&s);
    for (int t = 0; t < s.started; t++)
        pthread_join(s.tid[t], NULL);

    int rc = ncp_pipe_result(p, &s, d);
    if (stats)
        ncp_pipe_fill_stats(p, &s, t0, stats);
    ncp_pipe_free(p);
    return rc;
}

const char *ncp_run_warning_next(uint32_t *w)
{
    if (*w & NCP_WARN_NO_FIFO) {
        *w &= ~(uint32_t)NCP_WARN_NO_FIFO;
        return "SCHED_FIFO not permitted (needs root or CAP_SYS_NICE): threads ran "
               "SCHED_OTHER";
    }
    if (*w & NCP_WARN_NO_CPU) {
        *w &= ~(uint32_t)NCP_WARN_NO_CPU;
        return "a CPU of the thread map is not available here: its thread was pinned "
               "to another CPU";
    }
    *w = 0;
    return NULL;
}
