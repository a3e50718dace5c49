/* The data-flow scheduler thread: set-up and priority changes happen here,
 * never on the position loop's thread. Tasks are addressed by their Linux
 * thread id, which they publish while they run, so a task that comes and
 * goes (a job thread per program) needs no handshake. */
#include "ncpar/sched.h"
#include "ncpar/rt.h"

#include <errno.h>
#include <sched.h>
#include <time.h>
#include <unistd.h>

void ncp_sched_enter(struct ncp_sched_task *t)
{
    atomic_store_explicit(&t->tid, (int)gettid(), memory_order_release);
}

void ncp_sched_leave(struct ncp_sched_task *t)
{
    atomic_store_explicit(&t->tid, 0, memory_order_release);
}

static int apply(struct ncp_sched_task *t, int prio)
{
    int tid = atomic_load_explicit(&t->tid, memory_order_acquire);
    if (!tid)
        return 0;
    struct sched_param sp = { .sched_priority = prio };
    if (sched_setscheduler(tid, SCHED_FIFO, &sp) != 0)
        return errno == EPERM ? -1 : 0;
    if (t->changes == 0 || prio < t->prio_min)
        t->prio_min = prio;
    if (t->changes == 0 || prio > t->prio_max)
        t->prio_max = prio;
    t->prio = prio;
    t->applied_tid = tid;
    t->changes++;
    return 1;
}

void ncp_sched_leave_sync(struct ncp_sched *s, struct ncp_sched_task *t)
{
    ncp_sched_leave(t);
    /* a round that began before the leave may still read the rings; one that
     * begins after it sees tid 0 and skips them */
    unsigned seq = atomic_load(&s->round_seq);
    while ((seq & 1u) && atomic_load(&s->round_seq) == seq)
        sched_yield();
}

static int ranked_round(struct ncp_sched *s)
{
    struct ncp_sched_fill f[NCP_SCHED_TASKS] = { { 0, 0, 0, 0 } };
    int prio[NCP_SCHED_TASKS] = { 0 }, rank[NCP_SCHED_TASKS] = { 0 }, at[NCP_SCHED_TASKS], k = 0;
    for (int i = 0; i < s->n; i++) {
        struct ncp_sched_task *t = &s->task[i];
        if (!atomic_load_explicit(&t->tid, memory_order_acquire))
            continue;
        if (t->gauge)
            t->gauge(t->ctx, &f[k]);
        else
            f[k] = (struct ncp_sched_fill){ t->in_fill ? t->in_fill(t->ctx) : 0, t->in_cap,
                                            t->out_fill ? t->out_fill(t->ctx) : 0, t->out_cap };
        rank[k] = t->rank;
        at[k++] = i;
    }
    ncp_sched_dataflow_ranked(f, rank, k, s->cfg.floor, s->ceiling, prio);
    int changed = 0;
    for (int m = 0; m < k; m++) {
        struct ncp_sched_task *t = &s->task[at[m]];
        if (t->applied_tid && t->applied_tid == atomic_load(&t->tid) && t->prio == prio[m])
            continue;
        int r = apply(t, prio[m]);
        if (r < 0)
            return -1;
        changed += r;
    }
    return changed;
}

int ncp_sched_round(struct ncp_sched *s)
{
    atomic_fetch_add(&s->round_seq, 1);
    int r = ranked_round(s);
    atomic_fetch_add(&s->round_seq, 1);
    return r;
}

static void *sched_main(void *arg)
{
    struct ncp_sched *s = arg;
    struct timespec next;
    clock_gettime(CLOCK_MONOTONIC, &next);
    while (!atomic_load(&s->stop)) {
        if (ncp_sched_round(s) < 0) {
            s->refused = 1;
            break;
        }
        next.tv_nsec += (long)s->cfg.period_ms * 1000000L;
        while (next.tv_nsec >= 1000000000L) {
            next.tv_nsec -= 1000000000L;
            next.tv_sec++;
        }
        clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, NULL);
    }
    return NULL;
}

int ncp_sched_start(struct ncp_sched *s)
{
    atomic_store(&s->stop, 0);
    s->refused = 0;
    if (s->cfg.strategy != NCP_SCHED_DATAFLOW || s->started)
        return 0;
    struct ncp_rt_place at = { -1, s->thread_priority > 0 ? SCHED_FIFO : SCHED_OTHER,
                               s->thread_priority };
    int rc = ncp_rt_start(&s->thread, &at, sched_main, s, NULL);
    s->started = rc == 0;
    return rc;
}

void ncp_sched_stop(struct ncp_sched *s)
{
    atomic_store(&s->stop, 1);
    if (s->started)
        pthread_join(s->thread, NULL);
    s->started = 0;
}
