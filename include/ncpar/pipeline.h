/* The parallel interpreter pipeline (feeder -> n lexers -> analyzer -> m executors
 * -> in-order output) and its serial reference. Both produce byte-identical
 * output and identical errors for every configuration. */
#ifndef NCPAR_PIPELINE_H
#define NCPAR_PIPELINE_H

#include <stddef.h>
#include <stdint.h>
#include "ncpar/analyzer.h"
#include "ncpar/rt.h"
#include "ncpar/canon.h"
#include "ncpar/diag.h"
#include "ncpar/feeder.h"

#define NCP_MAX_LEXERS 16
#define NCP_MAX_EXECUTORS 16

enum ncp_thread_mode { NCP_MODE_SERIAL, NCP_MODE_DET, NCP_MODE_ATT };

/* Placement of one thread. cpu < 0: let the OS place it (DET). */

/* Thread map (an INI in rt-config/): which thread runs where, ring sizes. */
struct ncp_thread_map {
    enum ncp_thread_mode mode;
    /* n_lexers 0: no feeder and lexer threads, the analyzer lexes the text
     * itself; n_executors 0: the output thread executes (arcs, text) */
    int n_lexers, n_executors;
    /* 1 (only with n_executors 0): the analyzer executes and writes each
     * command itself, as the serial reference does: no command ring and no
     * output thread. On two cores the pipeline is then two busy threads,
     * feeder + lexer on one core and analyzer on the other, with one
     * hand-off between them. */
    int inline_output;
    int string_rows;  /* g: rows of the string ring (each row = n chunks of ~4 KB of text) */
    int parsed_rows;  /* h: rows of the parsed ring */
    int cmd_slots;    /* commands ring capacity per executor */
    int start_timeout_us; /* lexers start when the string ring is full or after this */
    /* n_lexers 0 and n_executors 0: the output thread, when it has no command
     * to write, lexes chunks of about this many bytes of text ahead of the
     * analyzer (it balances the two threads); 0: never */
    int lex_ahead_bytes;
    struct ncp_rt_place feeder, analyzer, output;
    struct ncp_rt_place lexer[NCP_MAX_LEXERS];
    struct ncp_rt_place executor[NCP_MAX_EXECUTORS];
};

/* "serial", "det" or "att" (any case) -> *mode; returns 0, or -1 if unknown. */
int ncp_thread_mode_parse(const char *name, enum ncp_thread_mode *mode);
/* The name ncp_thread_mode_parse() accepts for m. */
const char *ncp_thread_mode_name(enum ncp_thread_mode m);

/* Defaults for a mode and thread counts (ATT: feeder on CPU0, lexers, analyzer
 * and executors round-robin over the CPUs present from CPU1, output beside the
 * analyzer, or with no executors on the next CPU). */
void ncp_thread_map_default(struct ncp_thread_map *m, enum ncp_thread_mode mode,
                            int n_lexers, int n_executors);
/* The layout for a program of `bytes` bytes of text on `cpus` CPUs when the
 * user names none: serial below ncp_auto_parallel_bytes(cpus), where starting
 * threads costs more than they save, det threads from there on. */
void ncp_thread_map_auto(struct ncp_thread_map *m, size_t bytes, int cpus);
/* Program size from which ncp_thread_map_auto runs threads; SIZE_MAX: never. */
size_t ncp_auto_parallel_bytes(int cpus);
/* CPUs this process may run on (its affinity mask), at least 1. */
int ncp_cpus_usable(void);
/* Load an INI thread map; fills d (file:line) on error. */
int ncp_thread_map_load(struct ncp_thread_map *m, const char *path, struct ncp_diag *d);

/* The pipeline's threads as tasks of the task-scheduling paper's chain, for a scheduler that
 * ranks them (the NCK's [SCHED]): each thread is announced on itself as it
 * starts a run and again as it ends it, with what it is and a handle to read
 * its rings' fill without locks while it runs. */
enum ncp_pipe_kind {
    NCP_PIPE_FEEDER,     /* the feeder (without lexers: a thread with nothing to do) */
    NCP_PIPE_LEXER,
    NCP_PIPE_ANALYZER,
    NCP_PIPE_EXECUTOR,
    NCP_PIPE_OUTPUT      /* hands the commands on in order (emit): the chain's next task */
};
#define NCP_PIPE_KINDS 5

struct ncp_pipe;
struct ncp_pipe_thread {
    enum ncp_pipe_kind kind;
    int index;                   /* among the threads of its kind */
    const struct ncp_pipe *pipe;
};

/* Elements waiting in the thread's input rings and ready in its output rings
 * (summed over the rings of its kind), with their capacities; a capacity of 0
 * means no ring on that side (the feeder's input, the output's output). Only
 * between the started and ended calls. */
struct ncp_pipe_fill {
    size_t in_fill, in_cap, out_fill, out_cap;
};
void ncp_pipe_thread_fill(const struct ncp_pipe_thread *t, struct ncp_pipe_fill *f);
const char *ncp_pipe_kind_name(enum ncp_pipe_kind k);

struct ncp_pipe_hooks {
    void *ctx;
    void (*started)(void *ctx, const struct ncp_pipe_thread *t);
    /* the thread is done with the run's rings: after this returns they may go */
    void (*ended)(void *ctx, const struct ncp_pipe_thread *t);
};

/* Receives completed slots in cmd_id order on the output thread. Return non-zero
 * to stop the run (e.g. write error). */
struct ncp_output {
    void *ctx;
    int (*emit)(void *ctx, const struct ncp_cmd *cmd);
    /* Optional, both or neither: room for NCP_CMD_OUT_MAX bytes of text
     * (NULL when there is none, e.g. after a failed write), where the thread
     * that formats a command (serial, inline or packed output) writes it, and
     * the call that then takes the command with its cmd->out_len bytes
     * written there, in place of emit. Spares copying every line. commit
     * may read the command's head, calls and text, and its diag with
     * NCP_CMD_F_ERROR, nothing else: the output thread hands it commands
     * where they stand in its ring, which end there. */
    char *(*reserve)(void *ctx);
    int (*commit)(void *ctx, const struct ncp_cmd *cmd);
    /* Optional: the output is a machine, which the analyzer waits for at a
     * queue buster (see ncp_machine_sync in analyzer.h). Called on the
     * analyzer's thread once every command before the buster has been handed
     * on (the pipeline publishes what its stages hold back first), so it
     * may wait until emit has taken them. NULL: rs274 -g's stand-ins. */
    ncp_machine_sync_fn sync;
    /* Optional: told of every pipeline thread of the run (the serial
     * reference has none) */
    const struct ncp_pipe_hooks *threads;
};

/* Per-stage counters, each written by its own thread only (read after join). */
struct ncp_stage_stats {
    uint64_t items;       /* blocks fed / lexed / analyzed, slots executed / emitted */
    uint64_t full_waits;  /* times the output ring was full when the stage wanted to write */
    uint64_t empty_waits; /* times the input ring was empty when the stage wanted to read */
    uint64_t sleeps;      /* futex sleeps (a wait that outlasted the short spin) */
    double cpu_ms;        /* CPU time of the stage's thread (shows the load balance) */
    double wall_ms;       /* from the thread entering its stage to leaving it: cpu_ms
                           * against it is how busy the thread was */
    double sys_ms;        /* of cpu_ms, in the kernel (writing the text out, futexes) */
};

/* ncp_run_stats.warnings bits: the run went on with a weaker setting. */
enum ncp_run_warning {
    NCP_WARN_NO_FIFO = NCP_RT_WARN_NO_FIFO, /* SCHED_FIFO not permitted: ran SCHED_OTHER */
    NCP_WARN_NO_CPU = NCP_RT_WARN_NO_CPU    /* a map's cpu is not available: placed on another */
};

struct ncp_run_stats {
    uint64_t blocks;        /* blocks lexed */
    uint64_t commands;      /* slots emitted */
    double wall_ms;         /* pipeline start (thread creation incl.) to last slot out */
    int threads;            /* threads used in total */
    /* additive (pipeline): filled by ncp_pipeline_run only */
    uint32_t warnings;      /* enum ncp_run_warning bits */
    double setup_ms;        /* of wall_ms: the starting thread's CPU time for ring
                               allocation (prefaulted) and thread creation (0 for
                               serial); wall_ms - setup_ms approximates the run of
                               a pre-started pool */
    struct ncp_stage_stats feeder, analyzer, output;
    uint64_t lexed_ahead;   /* blocks the output thread lexed for the analyzer */
    uint64_t ahead_waits, ahead_sleeps; /* the analyzer found a chunk the output
                               thread was still lexing; of those, it slept */
    struct ncp_stage_stats lexer[NCP_MAX_LEXERS];
    struct ncp_stage_stats executor[NCP_MAX_EXECUTORS];
};

/* One line of text per warning bit set in w (for the CLI to print once), or NULL
 * when no bit is set; *w loses the bit returned. */
const char *ncp_run_warning_next(uint32_t *w);

/* Run the interpreter over src. The error (if any) is returned in *d in program
 * order, exactly as the serial reference reports it. Returns NCP_OK or d->code. */
int ncp_pipeline_run(const struct ncp_source *src, const struct ncp_thread_map *map,
                     const struct ncp_analyzer_cfg *acfg, const struct ncp_output *out,
                     struct ncp_run_stats *stats, struct ncp_diag *d);

/* A pre-started pipeline: the map's threads are created (and its rings
 * allocated and prefaulted) once, then run one program after another; each run
 * behaves exactly like ncp_pipeline_run without the start-up (stats->setup_ms
 * is 0, stats->wall_ms runs from the start of the run to the last command out).
 * A serial map keeps no threads: its runs are ncp_serial_run. Runs of one pool
 * must not overlap. */
struct ncp_pipeline_pool;
struct ncp_pipeline_pool *ncp_pipeline_pool_new(const struct ncp_thread_map *map,
                                                struct ncp_diag *d);
int ncp_pipeline_pool_run(struct ncp_pipeline_pool *pool, const struct ncp_source *src,
                          const struct ncp_analyzer_cfg *acfg, const struct ncp_output *out,
                          struct ncp_run_stats *stats, struct ncp_diag *d);
/* enum ncp_run_warning bits from starting the pool's threads. */
uint32_t ncp_pipeline_pool_warnings(const struct ncp_pipeline_pool *pool);
void ncp_pipeline_pool_free(struct ncp_pipeline_pool *pool);

/* The same stages in the calling thread, no rings. */
int ncp_serial_run(const struct ncp_source *src, const struct ncp_analyzer_cfg *acfg,
                   const struct ncp_output *out, struct ncp_run_stats *stats,
                   struct ncp_diag *d);

#endif
