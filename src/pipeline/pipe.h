/* One run of the parallel pipeline: rings and per-thread state shared by the
 * stage threads (module-internal header). */
#ifndef NCP_PIPELINE_PIPE_H
#define NCP_PIPELINE_PIPE_H

#include <stdalign.h>
#include <stdatomic.h>
#include <pthread.h>
#include <stdint.h>
#include "ncpar/pipeline.h"
#include "lex_ahead.h"
#include "rec_stream.h"
#include "ring.h"
#include "ncpar/blocks.h"

/* Stages of an executor's command ring: analyzer fills, executor completes in
 * place, output emits and hands the slot back. */
enum { NCP_CMD_STAGE_ANALYZER, NCP_CMD_STAGE_EXECUTOR, NCP_CMD_STAGE_OUTPUT,
       NCP_CMD_STAGES };

struct ncp_pipe;

/* What the feeder hands a lexer: a piece of the program text of about
 * NCP_CHUNK_BYTES that ends at a line end, and the line number it starts on.
 * Chunk k goes to LEX_(k mod n), which splits it into blocks itself: the
 * paper's string buffer with a chunk of blocks per cell instead of one block,
 * so the feeder's work and every ring hand-off is per chunk, not per block. */
struct ncp_chunk {
    uint64_t off, end;
    uint32_t line;
};
#define NCP_CHUNK_BYTES 4096u

/* Own cache line each: counters are bumped per item by their thread. */
struct ncp_pipe_worker {
    alignas(64) struct ncp_pipe *p;
    void *(*fn)(void *);         /* its stage's code */
    int index;
    uint64_t items;              /* written by this worker's thread only */
    double cpu_ms;               /* its thread's CPU time, set as it ends */
    double wall_ms;              /* its stage's span, set as it ends */
    double sys_ms;               /* its thread's kernel CPU time, set as it ends */
};

struct ncp_pipe {
    const struct ncp_source *src;
    const struct ncp_thread_map *map;
    const struct ncp_analyzer_cfg *acfg;
    const struct ncp_output *out;
    int n, m;                    /* lexers, command rings (one per executor, >= 1) */
    int exec_threads;            /* executors; 0: the output thread (or the analyzer) formats */
    unsigned out_stage;          /* the output's stage: of a slot ring (executors),
                                  * or the reader (1) of the packed ring */
    int inline_out;              /* the analyzer executes and emits (m == 0) */
    int packed_out;              /* no executors: the output thread executes packed commands */

    struct ncp_ring *strings;    /* n: feeder -> LEX_i, struct ncp_chunk */
    struct ncp_ring *parsed;     /* n: LEX_i -> analyzer, packed blocks in NCP_PACK_UNIT units */
    struct ncp_ring *cmds;       /* m: analyzer -> EXEC_j -> output, struct ncp_cmd;
                                  * packed_out: one ring of packed commands, 8-byte units */

    /* Fixed when the pipe is made; read per item by the analyzer and the
     * output thread, so nothing either of them writes may share their lines. */
    struct ncp_text_feed *text;  /* no lexer threads: the analyzer lexes the text ... */
    struct ncp_lex_ahead *ahead; /* ... or, with packed output, the output thread helps
                                  * (then text is NULL: this has a feed of its own) */
    struct ncp_cmd *an_cmd;      /* inline and packed output: the analyzer's own slot */
    struct ncp_cmd *out_cmd;     /* packed output: the output thread's slot it unpacks into */

    /* Lexers start once the string ring is full, or at EOF, or on timeout. */
    alignas(64) _Atomic uint32_t gate;
    uint64_t string_fill;        /* spans that fill the whole string ring */

    struct ncp_pipe_worker feeder, analyzer, output;
    struct ncp_pipe_worker lexer[NCP_MAX_LEXERS], executor[NCP_MAX_EXECUTORS];

    /* each lexer's own block, lexed in place before it is packed */
    struct ncp_lex_scratch { alignas(64) struct ncp_block b; } lex_block[NCP_MAX_LEXERS];

    /* analyzer thread only, read after join */
    alignas(64) uint64_t taken;  /* blocks handed to the analyzer */
    uint64_t chunk;              /* the chunk it reads, so ring chunk mod n */
    uint64_t next_id;
    int an_rc;
    int inline_stopped;          /* the inline output stopped */
    struct ncp_diag an_diag;     /* ncp_analyzer_new failure */
    struct ncp_block an_block;   /* the block it holds, unpacked */
    unsigned an_plain;           /* an_block's state for ncp_block_unpack_over */
    struct ncp_rec_writer cmd_out; /* packed output: its end of cmds[0] */
    struct ncp_rec_reader block_in[NCP_MAX_LEXERS]; /* its ends of parsed[] */

    /* output thread only (the analyzer's with inline output), read after join */
    alignas(64) struct ncp_diag err; /* first error slot, in program order */
    int emit_failed;
    double end_ms;               /* last slot out */
    double alloc_ms;             /* ring allocation (CPU time), part of the start-up cost */
};

/* Rings and workers for a map (src, acfg and out are set per run); NULL when
 * out of memory. */
struct ncp_pipe *ncp_pipe_new(const struct ncp_thread_map *map);
void ncp_pipe_free(struct ncp_pipe *p);
/* Back to the state of a new pipe for another run: only while no stage thread
 * is inside a stage. */
void ncp_pipe_reset(struct ncp_pipe *p);
/* The program, settings and output of the next run: before its threads start
 * (or, in a pool, are let go). */
void ncp_pipe_set_run(struct ncp_pipe *p, const struct ncp_source *src,
                      const struct ncp_analyzer_cfg *acfg, const struct ncp_output *out);
/* The paper's start rule for the lexers: the string ring full, EOF, or the
 * start timeout, whichever comes first. */
void ncp_pipe_wait_gate(struct ncp_pipe *p, int timeout_us);

#define NCP_PIPE_MAX_THREADS (NCP_MAX_LEXERS + NCP_MAX_EXECUTORS + 3)

/* One stage thread of a run: where it runs, its code and its worker. */
struct ncp_pipe_stage {
    const struct ncp_rt_place *spec;
    void *(*fn)(void *);
    struct ncp_pipe_worker *w;
    int is_lexer;                /* keeps the paper's start rule (the gate) */
};

/* The run's stage threads in the paper's start order (feeder, lexers,
 * analyzer, executors, output); returns how many. Sets each worker's fn. */
int ncp_pipe_stages(struct ncp_pipe *p, struct ncp_pipe_stage out[NCP_PIPE_MAX_THREADS]);
/* A stage thread's run: w->fn(w) between the output's thread hooks. */
void ncp_pipe_run_stage(struct ncp_pipe_worker *w);
void *ncp_pipe_stage_main(void *w);

/* The threads of one run and how their start went. */
struct ncp_starter {
    struct ncp_pipe *p;
    pthread_t tid[NCP_PIPE_MAX_THREADS];
    int started;
    int failed;
    uint32_t warnings;
    double setup_ms; /* CPU time of the starting thread in pthread_create and friends */
};

/* Start a thread running fn(arg) with spec's placement; its creation counts in
 * s->setup_ms. On failure s->failed is set and the pipe aborted. */
void ncp_pipe_start_thread(struct ncp_starter *s, const struct ncp_rt_place *spec,
                           void *(*fn)(void *), void *arg);

/* The run's result in the serial reference's precedence, and its statistics
 * (wall time from t0). Both after every stage of the run has ended. */
int ncp_pipe_result(const struct ncp_pipe *p, const struct ncp_starter *s, struct ncp_diag *d);
void ncp_pipe_fill_stats(const struct ncp_pipe *p, const struct ncp_starter *s, double t0,
                         struct ncp_run_stats *st);

void *ncp_pipe_feeder(void *arg);
void *ncp_pipe_prefaulter(void *arg);
void *ncp_pipe_lexer(void *arg);
void *ncp_pipe_analyzer(void *arg);
void *ncp_pipe_executor(void *arg);
void *ncp_pipe_output(void *arg);

/* Shut every ring down: blocked stages return, running ones stop at their next
 * ring operation. Safe from any thread, more than once. */
void ncp_pipe_abort(struct ncp_pipe *p);
void ncp_pipe_open_gate(struct ncp_pipe *p);

double ncp_pipe_now_ms(void);
/* CPU time of the calling thread so far; of it, in the kernel. */
double ncp_pipe_thread_cpu_ms(void);
double ncp_pipe_thread_sys_ms(void);

#endif
