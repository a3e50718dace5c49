/* The periodic real-time thread. Set-up (policy, affinity, memory locking) is
 * done once, before the loop; inside the loop there is no allocation, no lock
 * and no I/O: only the clock, the cycle callback and the thread's own stats. */
#include "ncpar/rt.h"
#include "ncpar/clock.h"

#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <sched.h>
#include <stdio.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

#define NCP_RT_STACK_PREFAULT (64 * 1024)
#define NS_PER_S 1000000000LL

static struct timespec ns_ts(int64_t ns)
{
    struct timespec t = { (time_t)(ns / NS_PER_S), (long)(ns % NS_PER_S) };
    return t;
}

/* Touch the stack the loop will use so that its pages are resident (and,
 * with mlockall, stay so) before the first deadline. */
static void prefault_stack(void)
{
    volatile unsigned char buf[NCP_RT_STACK_PREFAULT];
    for (size_t i = 0; i < sizeof buf; i += 256)
        buf[i] = 0;
}

static void run_virtual(struct ncp_rt_loop *l)
{
    int64_t t = 0;
    while (!atomic_load_explicit(&l->stop, memory_order_relaxed)) {
        int r = l->cycle(l->ctx, t);
        if (r == NCP_RT_RETRY) {
            /* the producer is behind: virtual time waits for it (a real clock
             * would not, and the cycle counts an underrun instead) */
            sched_yield();
            continue;
        }
        ncp_rt_stats_add(&l->stats, 0);
        if (r == NCP_RT_STOP)
            break;
        t += l->cfg.period_ns;
        atomic_store_explicit(&l->vnow_ns, t, memory_order_relaxed);
    }
}

static void run_real(struct ncp_rt_loop *l)
{
    const int64_t period = l->cfg.period_ns;
    const int64_t base = l->cfg.start_ns > 0 ? l->cfg.start_ns : ncp_mono_ns();
    int64_t next = base;
    while (!atomic_load_explicit(&l->stop, memory_order_relaxed)) {
        next += period;
        struct timespec ts = ns_ts(next);
        /* clock_nanosleep returns its error instead of setting errno */
        while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL) == EINTR)
            ;
        int64_t late = ncp_mono_ns() - next;
        ncp_rt_stats_add(&l->stats, late);
        if (late > period) {
            /* skip the periods we slept through instead of running them back
             * to back: a burst of catch-up cycles would be a jump */
            int64_t skip = late / period;
            l->stats.misses++;
            l->stats.skipped += (uint64_t)skip;
            next += skip * period;
        }
        if (l->cycle(l->ctx, next - base) == NCP_RT_STOP)
            break;
    }
}

static void *loop_main(void *arg)
{
    struct ncp_rt_loop *l = arg;
    prefault_stack();
    if (l->cfg.virtual_clock)
        run_virtual(l);
    else
        run_real(l);
    atomic_store(&l->running, 0);
    return NULL;
}

/* The lock is the process's, not the loop's: with several loops in one
 * process (NC channels) the first to start locks and the last to end
 * unlocks, so a channel that finishes early never unlocks the pages of one
 * still running. Set-up and tear-down only, never the loop itself. */
static pthread_mutex_t lock_users_mu = PTHREAD_MUTEX_INITIALIZER;
static int lock_users;

/* mlockall(MCL_FUTURE) with a small RLIMIT_MEMLOCK makes later allocations
 * fail, so lock only when the limit allows it. */
static int lock_memory(void)
{
    struct rlimit rl;
    if (getrlimit(RLIMIT_MEMLOCK, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY && geteuid() != 0)
        return 0;
    pthread_mutex_lock(&lock_users_mu);
    int ok = lock_users > 0 || mlockall(MCL_CURRENT | MCL_FUTURE) == 0;
    if (ok)
        lock_users++;
    pthread_mutex_unlock(&lock_users_mu);
    return ok;
}

static void unlock_memory(void)
{
    pthread_mutex_lock(&lock_users_mu);
    if (lock_users > 0 && --lock_users == 0)
        munlockall();
    pthread_mutex_unlock(&lock_users_mu);
}

/* Keeps the CPUs out of deep idle states while the file stays open. */
static int hold_dma_latency(void)
{
    int fd = open("/dev/cpu_dma_latency", O_WRONLY | O_CLOEXEC);
    int32_t zero = 0;
    if (fd >= 0 && write(fd, &zero, sizeof zero) != (ssize_t)sizeof zero) {
        close(fd);
        fd = -1;
    }
    return fd;
}

int ncp_rt_loop_start(struct ncp_rt_loop *l)
{
    ncp_rt_stats_reset(&l->stats);
    atomic_store(&l->stop, 0);
    atomic_store(&l->running, 1);
    atomic_store(&l->vnow_ns, 0);
    l->warning[0] = '\0';
    l->fifo = 0;
    l->memlocked = 0;
    /* a virtual clock spins while waiting for its producer: never FIFO */
    int want_fifo = !l->cfg.virtual_clock && l->cfg.priority > 0;
    l->dma_fd = -1;
    if (want_fifo) {
        l->memlocked = lock_memory();
        l->dma_fd = hold_dma_latency();
    }
    if (l->handover)
        l->handover(l->ctx);
    struct ncp_rt_place at = { l->cfg.cpu, want_fifo ? SCHED_FIFO : SCHED_OTHER,
                               want_fifo ? l->cfg.priority : 0 };
    uint32_t warnings = 0;
    int rc = ncp_rt_start(&l->thread, &at, loop_main, l, &warnings);
    l->fifo = rc == 0 && want_fifo && !(warnings & NCP_RT_WARN_NO_FIFO);
    if (rc == 0 && (l->fifo || !want_fifo))
        return 0;
    if (want_fifo && rc == 0)
        snprintf(l->warning, sizeof l->warning,
                 "SCHED_FIFO %d refused (%s): the position loop runs SCHED_OTHER and its "
                 "latency is not real-time (run as root or grant rtprio)",
                 l->cfg.priority, "not permitted");
    if (rc)
        atomic_store(&l->running, 0);
    return rc;
}

void ncp_rt_loop_join(struct ncp_rt_loop *l)
{
    pthread_join(l->thread, NULL);
    if (l->memlocked)
        unlock_memory();
    l->memlocked = 0;
    if (l->dma_fd >= 0)
        close(l->dma_fd);
    l->dma_fd = -1;
}
