/* Priorities of the NCK's soft-real-time tasks (the task-scheduling paper): the interpreter
 * pipeline's threads, the job thread and the planner (look-ahead, acc/dec,
 * rough interpolation), each fed by a ring, all below the position loop.
 *
 * static:   SCHED_FIFO by dependency distance from the position loop, fixed
 *           for the run: the planner one below the loop, the job one below that.
 * dataflow: a scheduler thread re-ranks the tasks every PERIOD_MS from their
 *           rings' fill: the task with the most input waiting and the least output
 *           ready goes to the top of the band, a task that cannot run (input
 *           empty or output full) to its bottom.
 * Both keep every task within [floor, ceiling], and the ceiling is below the
 * lowest position loop of the process, so the position loops stay on top.
 * The data-flow thread itself runs SCHED_FIFO just above its band (and
 * below the loops): a SCHED_OTHER scheduler would starve exactly when its
 * re-ranking matters, with FIFO tasks keeping every CPU busy. It wakes for a
 * few microseconds each period and never runs on the position loop's path. */
#ifndef NCPAR_SCHED_H
#define NCPAR_SCHED_H

#include <pthread.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

enum ncp_sched_strategy {
    NCP_SCHED_NONE = 0,   /* [RT]'s priorities as written (no [SCHED] STRATEGY) */
    NCP_SCHED_STATIC,
    NCP_SCHED_DATAFLOW
};

struct ncp_sched_cfg {         /* [SCHED] */
    enum ncp_sched_strategy strategy;  /* STRATEGY = static | dataflow */
    int period_ms;             /* PERIOD_MS: the data-flow scheduler's period (10) */
    int floor;                 /* PRIORITY_MIN: the band's bottom (1) */
    int trace_rings;           /* TRACE_RINGS = 1: ring and task columns in the trace */
};

void ncp_sched_cfg_default(struct ncp_sched_cfg *c);
/* One key of [SCHED]: 1 taken, 0 unknown key, -1 bad value (why says more). */
int ncp_sched_ini_key(struct ncp_sched_cfg *c, const char *k, const char *v, char *why,
                      size_t len);
const char *ncp_sched_strategy_name(enum ncp_sched_strategy s);

/* ---- the priority functions (pure) ------------------------------------------ */

/* A task's rings; a capacity of 0 means it has none on that side (a source
 * always has input, a sink never a full output). */
struct ncp_sched_fill {
    size_t in_fill, in_cap, out_fill, out_cap;
};

/* Tasks 0..n-1 from upstream to downstream, task n-1 feeding the position
 * loop: static priority of each, ceiling - distance, never below floor. */
void ncp_sched_static(int n, int floor, int ceiling, int *prio);
/* Data-flow priorities from the fills, within [floor, ceiling]; ties go to
 * the task nearer the position loop. */
void ncp_sched_dataflow(const struct ncp_sched_fill *f, int n, int floor, int ceiling,
                        int *prio);
/* The same for tasks in any order: rank[i] is task i's place in the chain
 * (higher: nearer the position loop), which breaks ties before the index. */
void ncp_sched_dataflow_ranked(const struct ncp_sched_fill *f, const int *rank, int n,
                               int floor, int ceiling, int *prio);

/* ---- the scheduler thread ----------------------------------------------------- */

/* the NCK's job and planner, and every thread an interpreter pipeline may run */
#define NCP_SCHED_TASKS 40

struct ncp_sched_task {
    const char *name;
    _Atomic int tid;            /* the task's Linux thread id while it runs, else 0:
                                 * only running tasks are ranked */
    int rank;                   /* place in the chain, higher nearer the position loop */
    /* its rings' fill and capacity, read without locks */
    size_t (*in_fill)(void *ctx), (*out_fill)(void *ctx);
    size_t in_cap, out_cap;
    /* or, where the rings come and go with the task, all four at once
     * (only called while tid is set) */
    void (*gauge)(void *ctx, struct ncp_sched_fill *f);
    void *ctx;
    /* written by the scheduler thread only */
    int prio, prio_min, prio_max;
    int applied_tid;            /* the thread prio was set on */
    uint64_t changes;
};

struct ncp_sched {
    struct ncp_sched_cfg cfg;
    int ceiling;                /* the band's top */
    int thread_priority;        /* the data-flow thread's (0: SCHED_OTHER) */
    int n;
    struct ncp_sched_task task[NCP_SCHED_TASKS];
    _Atomic int stop;
    _Atomic unsigned round_seq; /* odd while a data-flow round reads the tasks */
    int started, refused;
    pthread_t thread;
};

/* The ceiling of a process whose lowest position loop runs at loop_priority. */
int ncp_sched_ceiling(int loop_priority);
/* Registers the calling thread as task i (0 when it ends: call before
 * returning); the static strategy's priority is set on the attributes at
 * creation instead. */
void ncp_sched_enter(struct ncp_sched_task *t);
void ncp_sched_leave(struct ncp_sched_task *t);
/* Leave, then wait until no round can still be reading the task's rings (a
 * task whose rings are freed once it ends). */
void ncp_sched_leave_sync(struct ncp_sched *s, struct ncp_sched_task *t);
/* Starts the data-flow thread (no-op for the other strategies). 0 or errno. */
int ncp_sched_start(struct ncp_sched *s);
void ncp_sched_stop(struct ncp_sched *s);
/* One data-flow round, as the thread runs it: public for tests. Returns the
 * number of priority changes applied, -1 when SCHED_FIFO was refused. */
int ncp_sched_round(struct ncp_sched *s);

#endif
