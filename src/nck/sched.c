/* [SCHED] for one NCK: the soft-RT tasks of the task-scheduling paper's chain (the
 * interpreter pipeline's threads, the job thread that hands its commands on,
 * the planner), their priorities below the position loop, and what they ran
 * at for the summary. The position loop itself is never touched. */
#include "nck_int.h"

#include <sched.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

enum { TASK_JOB = 0, TASK_PLANNER = 1, TASK_PIPE = 2 };

/* The chain, upstream first: receive (feeder), interpret (lexers, analyzer),
 * discrete (executors), the commands in order (output, then the job thread's
 * segment ring), look-ahead and rough interpolation (planner). */
enum { RANK_FEEDER, RANK_LEXER, RANK_ANALYZER, RANK_EXECUTOR, RANK_OUTPUT, RANK_JOB,
       RANK_PLANNER, RANKS };

/* Task slot of each pipeline thread: one per kind and index. */
static int pipe_slot(const struct ncp_pipe_thread *t)
{
    static const int base[NCP_PIPE_KINDS] = { 0, 1, 1 + NCP_MAX_LEXERS, 2 + NCP_MAX_LEXERS,
                                              2 + NCP_MAX_LEXERS + NCP_MAX_EXECUTORS };
    int max = t->kind == NCP_PIPE_LEXER ? NCP_MAX_LEXERS
              : t->kind == NCP_PIPE_EXECUTOR ? NCP_MAX_EXECUTORS : 1;
    int slot = TASK_PIPE + base[t->kind] + t->index;
    return t->index >= 0 && t->index < max && slot < NCP_SCHED_TASKS ? slot : -1;
}

static size_t segs_fill(void *ctx)
{
    return ncp_spsc_count(&((struct nck_core *)ctx)->cross.segs);
}

static size_t sps_fill(void *ctx)
{
    return ncp_spsc_count(&((struct nck_core *)ctx)->cross.sps);
}

/* Where the strategy applies: a real-clock position loop on SCHED_FIFO
 * (the virtual clock's threads spin and never run SCHED_FIFO). */
static int applies(const struct nck_core *n)
{
    return n->cfg->sched.strategy != NCP_SCHED_NONE && !n->setup.virtual_clock;
}

/* Static: by distance from the position loop along the whole chain, the
 * planner just below the loop. */
static int static_prio(const struct nck_core *n, int rank)
{
    int prio[RANKS];
    ncp_sched_static(RANKS, n->cfg->sched.floor, n->cross.sched.ceiling, prio);
    return prio[rank];
}

static void pipe_gauge(void *ctx, struct ncp_sched_fill *f)
{
    struct ncp_pipe_fill pf;
    ncp_pipe_thread_fill(ctx, &pf);
    *f = (struct ncp_sched_fill){ pf.in_fill, pf.in_cap, pf.out_fill, pf.out_cap };
}

void nck_sched_setup(struct nck_core *n)
{
    const struct ncp_machine_cfg *c = n->cfg;
    n->cross.job_place = c->interp;
    n->cross.planner_place = c->planner;
    memset(&n->cross.sched, 0, sizeof n->cross.sched);
    n->cross.sched.cfg = c->sched;
    int loop = n->setup.loop_priority_min > 0 && n->setup.loop_priority_min < c->position.priority
                   ? n->setup.loop_priority_min
                   : c->position.priority;
    n->cross.sched.ceiling = ncp_sched_ceiling(loop);
    if (c->sched.strategy == NCP_SCHED_DATAFLOW) {
        /* the scheduler thread just below the loops, its band below it */
        n->cross.sched.thread_priority = n->cross.sched.ceiling;
        n->cross.sched.ceiling--;
    }
    n->cross.sched.n = NCP_SCHED_TASKS;
    n->cross.sched.task[TASK_JOB] = (struct ncp_sched_task){ .name = "job", .rank = RANK_JOB,
                                                       .out_fill = segs_fill,
                                                       .out_cap = ncp_spsc_capacity(&n->cross.segs),
                                                       .ctx = n };
    n->cross.sched.task[TASK_PLANNER] = (struct ncp_sched_task){
        .name = "planner", .rank = RANK_PLANNER, .in_fill = segs_fill,
        .in_cap = ncp_spsc_capacity(&n->cross.segs), .out_fill = sps_fill,
        .out_cap = ncp_spsc_capacity(&n->cross.sps), .ctx = n
    };
    /* the pipeline's slots stay empty (tid 0, never ranked) until a thread
     * of that kind and index starts */
    for (int i = TASK_PIPE; i < NCP_SCHED_TASKS; i++)
        n->cross.sched.task[i] = (struct ncp_sched_task){ .name = "pipeline", .gauge = pipe_gauge,
                                                    .ctx = &n->cross.pipe_thread[i] };
    if (!applies(n))
        return;
    /* both strategies start from the static ranks; data flow moves them */
    n->cross.job_place = (struct ncp_rt_place){ c->interp.cpu, SCHED_FIFO, static_prio(n, RANK_JOB) };
    n->cross.planner_place = (struct ncp_rt_place){ c->planner.cpu, SCHED_FIFO,
                                              static_prio(n, RANK_PLANNER) };
}

/* A pipeline thread starting a run: it takes its slot and its static
 * priority (the map placed it; only its priority changes); data flow moves
 * it from there like the others. */
static void pipe_started(void *ctx, const struct ncp_pipe_thread *t)
{
    struct nck_core *n = ctx;
    int slot = pipe_slot(t);
    if (slot < 0)
        return;
    static const int rank[NCP_PIPE_KINDS] = { RANK_FEEDER, RANK_LEXER, RANK_ANALYZER,
                                              RANK_EXECUTOR, RANK_OUTPUT };
    struct ncp_sched_task *task = &n->cross.sched.task[slot];
    n->cross.pipe_thread[slot] = *t;
    task->name = ncp_pipe_kind_name(t->kind);
    task->rank = rank[t->kind];
    struct sched_param sp = { .sched_priority = static_prio(n, task->rank) };
    if (pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp) == 0)
        atomic_store(&n->cross.prio_seen[slot], sp.sched_priority);
    ncp_sched_enter(task);
}

static void pipe_ended(void *ctx, const struct ncp_pipe_thread *t)
{
    struct nck_core *n = ctx;
    int slot = pipe_slot(t);
    if (slot >= 0)
        ncp_sched_leave_sync(&n->cross.sched, &n->cross.sched.task[slot]);
}

const struct ncp_pipe_hooks *nck_sched_pipe_hooks(struct nck_core *n)
{
    if (!applies(n))
        return NULL;
    n->cross.pipe_hooks = (struct ncp_pipe_hooks){ n, pipe_started, pipe_ended };
    return &n->cross.pipe_hooks;
}

int nck_sched_start(struct nck_core *n)
{
    return applies(n) ? ncp_sched_start(&n->cross.sched) : 0;
}

/* Called by the task's own thread as it starts: it registers with the
 * scheduler and notes the priority it really got. */
void nck_sched_enter(struct nck_core *n, int task)
{
    ncp_sched_enter(&n->cross.sched.task[task]);
    if (!applies(n))
        return;
    int policy;
    struct sched_param sp;
    if (pthread_getschedparam(pthread_self(), &policy, &sp) == 0)
        atomic_store(&n->cross.prio_seen[task], policy == SCHED_FIFO ? sp.sched_priority : 0);
}

void nck_sched_leave(struct nck_core *n, int task)
{
    ncp_sched_leave(&n->cross.sched.task[task]);
}

/* The pipeline's threads for the summary: " pipeline feeder 74, lexers
 * 75, ..." (static: what each kind got) or their data-flow range. */
static void pipe_summary(const struct nck_core *n, int dataflow, char *buf, size_t len)
{
    size_t at = strlen(buf);
    int lo = 0, hi = 0, threads = 0, kind_prio[NCP_PIPE_KINDS] = { 0 };
    unsigned long long changes = 0;
    for (int i = TASK_PIPE; i < NCP_SCHED_TASKS; i++) {
        const struct ncp_sched_task *t = &n->cross.sched.task[i];
        int seen = atomic_load(&n->cross.prio_seen[i]);
        if (!seen)
            continue;
        threads++;
        kind_prio[n->cross.pipe_thread[i].kind] = seen;
        int a = t->changes ? (t->prio_min < seen ? t->prio_min : seen) : seen;
        int b = t->changes ? (t->prio_max > seen ? t->prio_max : seen) : seen;
        lo = threads == 1 || a < lo ? a : lo;
        hi = threads == 1 || b > hi ? b : hi;
        changes += t->changes;
    }
    if (!threads || at >= len)
        return;
    if (dataflow) {
        snprintf(buf + at, len - at, ", pipeline %d threads %d..%d (%llu changes)", threads, lo,
                 hi, changes);
        return;
    }
    for (int k = 0; k < NCP_PIPE_KINDS; k++) {
        at = strlen(buf);
        if (kind_prio[k] && at < len)
            snprintf(buf + at, len - at, ", %s %d", ncp_pipe_kind_name((enum ncp_pipe_kind)k),
                     kind_prio[k]);
    }
}

void nck_sched_summary(const struct nck_core *n, char *buf, size_t len)
{
    buf[0] = '\0';
    const struct ncp_machine_cfg *c = n->cfg;
    if (c->sched.strategy == NCP_SCHED_NONE)
        return;
    const char *name = ncp_sched_strategy_name(c->sched.strategy);
    if (!applies(n)) {
        snprintf(buf, len, "%s: not applied on the virtual clock", name);
        return;
    }
    if (!n->cross.rt.fifo || n->cross.sched.refused) {
        snprintf(buf, len, "%s: SCHED_FIFO not permitted, the tasks ran without priorities",
                 name);
        return;
    }
    if (c->sched.strategy == NCP_SCHED_STATIC) {
        snprintf(buf, len, "static: position loop %d, planner %d, job %d", c->position.priority,
                 atomic_load(&n->cross.prio_seen[TASK_PLANNER]), atomic_load(&n->cross.prio_seen[TASK_JOB]));
        pipe_summary(n, 0, buf, len);
        return;
    }
    const struct ncp_sched_task *p = &n->cross.sched.task[TASK_PLANNER], *j = &n->cross.sched.task[TASK_JOB];
    snprintf(buf, len,
             "dataflow every %d ms: position loop %d, planner %d..%d (%llu changes), "
             "job %d..%d (%llu changes), band %d..%d, scheduler %d",
             c->sched.period_ms, c->position.priority, p->prio_min, p->prio_max,
             (unsigned long long)p->changes, j->prio_min, j->prio_max,
             (unsigned long long)j->changes, c->sched.floor, n->cross.sched.ceiling,
             n->cross.sched.thread_priority);
    pipe_summary(n, 1, buf, len);
}
