/* Real-time support: a lock-free single-producer/single-consumer ring, and a
 * periodic thread (SCHED_FIFO, absolute clock_nanosleep schedule, mlockall,
 * prefaulted stack) that measures its own wake-up latency like cyclictest.
 * The same loop runs on a virtual clock for tests and previews. */
#ifndef NCPAR_RT_H
#define NCPAR_RT_H

#include <pthread.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include "ncpar/diag.h"

/* ---- SPSC ring ------------------------------------------------------------- */

struct ncp_spsc {
    _Alignas(64) _Atomic size_t head;   /* written by the consumer */
    _Alignas(64) _Atomic size_t tail;   /* written by the producer */
    _Alignas(64) size_t mask, elem;
    unsigned char *buf;
};

/* capacity is rounded up to a power of two; storage is allocated and touched
 * here, never on the real-time path. */
int ncp_spsc_init(struct ncp_spsc *r, size_t elem_size, size_t capacity);
void ncp_spsc_destroy(struct ncp_spsc *r);
int ncp_spsc_push(struct ncp_spsc *r, const void *item);   /* 0 ok, -1 full */
int ncp_spsc_pop(struct ncp_spsc *r, void *item);          /* 0 ok, -1 empty */
size_t ncp_spsc_count(struct ncp_spsc *r);
size_t ncp_spsc_capacity(const struct ncp_spsc *r);

/* ---- threads ------------------------------------------------------------------ */

/* Where a thread runs and how it is scheduled: the interpreter pipeline's
 * threads (thread maps) and the NCK's (the machine INI's [RT]) alike. */
struct ncp_rt_place {
    int cpu;        /* < 0: the OS places it */
    int policy;     /* SCHED_OTHER or SCHED_FIFO */
    int priority;   /* SCHED_FIFO's priority, 1..99 */
};

/* What ncp_rt_start had to give up (bits of its warnings). */
enum ncp_rt_warning {
    NCP_RT_WARN_NO_FIFO = 1u << 0, /* SCHED_FIFO not permitted: runs SCHED_OTHER */
    NCP_RT_WARN_NO_CPU = 1u << 1   /* the cpu is not one this process may use: another is */
};

/* Starts fn(arg) with the placement set on its attributes before it exists,
 * so it never runs an instruction on the wrong CPU or policy. SCHED_FIFO
 * refused (EPERM) falls back to SCHED_OTHER and a cpu this process may not use
 * to another one it may; each adds its bit to *warnings (may be NULL).
 * Returns 0 or the pthread_create error. */
int ncp_rt_start(pthread_t *t, const struct ncp_rt_place *pl, void *(*fn)(void *), void *arg,
                 uint32_t *warnings);

/* ---- latency statistics ----------------------------------------------------- */

#define NCP_RT_HIST_BINS 1000    /* 1 us bins; later wake-ups land in overflow */

struct ncp_rt_stats {
    uint64_t cycles;
    uint64_t misses;             /* wake-ups later than one period: skipped periods */
    uint64_t skipped;            /* periods skipped because of misses */
    int64_t lat_min_ns, lat_max_ns;
    double lat_sum_ns;
    uint64_t hist[NCP_RT_HIST_BINS];
    uint64_t overflow;
};

void ncp_rt_stats_reset(struct ncp_rt_stats *s);
void ncp_rt_stats_add(struct ncp_rt_stats *s, int64_t latency_ns);

/* ---- periodic thread ---------------------------------------------------------- */

enum ncp_rt_cycle_result {
    NCP_RT_CONTINUE = 0,   /* next period */
    NCP_RT_STOP = 1,       /* leave the loop */
    NCP_RT_RETRY = 2       /* virtual clock only: nothing to do yet, same instant again */
};

struct ncp_rt_loop_cfg {
    int64_t period_ns;
    int priority;          /* 1..99 SCHED_FIFO, 0 SCHED_OTHER */
    int cpu;               /* < 0: any */
    int virtual_clock;     /* simulated time, as fast as the CPU allows */
    /* real clock: CLOCK_MONOTONIC of the schedule's origin (the first cycle
     * runs one period after it), so that processes can share one period
     * grid; 0: now */
    int64_t start_ns;
};

struct ncp_rt_loop {
    struct ncp_rt_loop_cfg cfg;
    /* called once per period with the cycle's scheduled time (ns since start) */
    int (*cycle)(void *ctx, int64_t now_ns);
    void *ctx;
    /* optional, once the memory is locked and just before the loop's thread
     * starts: whatever kept the machine alive until now hands over (locking
     * the memory may stall every thread of the process for a while) */
    void (*handover)(void *ctx);
    struct ncp_rt_stats stats;    /* written by the loop thread only */
    _Atomic int stop;             /* request from outside */
    _Atomic int running;
    int fifo;                     /* the thread really runs SCHED_FIFO */
    int memlocked;
    int dma_fd;                   /* /dev/cpu_dma_latency held open, or -1 */
    char warning[200];            /* set when the RT set-up had to degrade */
    pthread_t thread;
    _Atomic int64_t vnow_ns;      /* virtual clock */
};

/* Starts the loop thread; degrades to SCHED_OTHER with a warning when the
 * process may not use SCHED_FIFO. Returns 0 or an errno value. */
int ncp_rt_loop_start(struct ncp_rt_loop *l);
void ncp_rt_loop_join(struct ncp_rt_loop *l);

#endif
