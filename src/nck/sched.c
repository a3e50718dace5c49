/* [SCHED] for one NCK: the job thread and the planner as the soft-RT tasks
 * of seed 000's chain, their priorities below the position loop, and what
 * they ran at for the summary. The position loop itself is never touched. */
#include "nck_int.h"

#include <sched.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

enum { TASK_JOB = 0, TASK_PLANNER = 1 };

static size_t segs_fill(void *ctx)
{
    return ncp_spsc_count(&((struct nck *)ctx)->segs);
}

static size_t sps_fill(void *ctx)
{
    return ncp_spsc_count(&((struct nck *)ctx)->sps);
}

/* Where the strategy applies: a real-clock position loop on SCHED_FIFO
 * (the virtual clock's threads spin and never run SCHED_FIFO). */
static int applies(const struct nck *n)
{
    return n->cfg->sched.strategy != NCP_SCHED_NONE && !n->setup.virtual_clock;
}

int64_t nck_mono_ns(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (int64_t)t.tv_sec * 1000000000LL + t.tv_nsec;
}

void nck_sched_setup(struct nck *n)
{
    const struct ncp_machine_cfg *c = n->cfg;
    n->job_place = c->interp;
    n->planner_place = c->planner;
    memset(&n->sched, 0, sizeof n->sched);
    n->sched.cfg = c->sched;
    int loop = n->setup.loop_priority_min > 0 && n->setup.loop_priority_min < c->position.priority
                   ? n->setup.loop_priority_min
                   : c->position.priority;
    n->sched.ceiling = ncp_sched_ceiling(loop);
    if (c->sched.strategy == NCP_SCHED_DATAFLOW) {
        /* the scheduler thread just below the loops, its band below it */
        n->sched.thread_priority = n->sched.ceiling;
        n->sched.ceiling--;
    }
    n->sched.n = 2;
    n->sched.task[TASK_JOB] = (struct ncp_sched_task){ .name = "job", .out_fill = segs_fill,
                                                       .out_cap = ncp_spsc_capacity(&n->segs),
                                                       .ctx = n };
    n->sched.task[TASK_PLANNER] = (struct ncp_sched_task){
        .name = "planner", .in_fill = segs_fill, .in_cap = ncp_spsc_capacity(&n->segs),
        .out_fill = sps_fill, .out_cap = ncp_spsc_capacity(&n->sps), .ctx = n
    };
    if (!applies(n))
        return;
    /* both strategies start from the static ranks; data flow moves them */
    int prio[2];
    ncp_sched_static(2, c->sched.floor, n->sched.ceiling, prio);
    n->job_place = (struct ncp_rt_place){ c->interp.cpu, SCHED_FIFO, prio[TASK_JOB] };
    n->planner_place = (struct ncp_rt_place){ c->planner.cpu, SCHED_FIFO, prio[TASK_PLANNER] };
}

int nck_sched_start(struct nck *n)
{
    return applies(n) ? ncp_sched_start(&n->sched) : 0;
}

/* Called by the task's own thread as it starts: it registers with the
 * scheduler and notes the priority it really got. */
void nck_sched_enter(struct nck *n, int task)
{
    ncp_sched_enter(&n->sched.task[task]);
    if (!applies(n))
        return;
    int policy;
    struct sched_param sp;
    if (pthread_getschedparam(pthread_self(), &policy, &sp) == 0)
        atomic_store(&n->prio_seen[task], policy == SCHED_FIFO ? sp.sched_priority : 0);
}

void nck_sched_leave(struct nck *n, int task)
{
    ncp_sched_leave(&n->sched.task[task]);
}

void nck_sched_summary(const struct nck *n, char *buf, size_t len)
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
    if (!n->loop.fifo || n->sched.refused) {
        snprintf(buf, len, "%s: SCHED_FIFO not permitted, the tasks ran without priorities",
                 name);
        return;
    }
    if (c->sched.strategy == NCP_SCHED_STATIC) {
        snprintf(buf, len, "static: position loop %d, planner %d, job %d", c->position.priority,
                 atomic_load(&n->prio_seen[TASK_PLANNER]), atomic_load(&n->prio_seen[TASK_JOB]));
        return;
    }
    const struct ncp_sched_task *p = &n->sched.task[TASK_PLANNER], *j = &n->sched.task[TASK_JOB];
    snprintf(buf, len,
             "dataflow every %d ms: position loop %d, planner %d..%d (%llu changes), "
             "job %d..%d (%llu changes), band %d..%d, scheduler %d",
             c->sched.period_ms, c->position.priority, p->prio_min, p->prio_max,
             (unsigned long long)p->changes, j->prio_min, j->prio_max,
             (unsigned long long)j->changes, c->sched.floor, n->sched.ceiling,
             n->sched.thread_priority);
}
