/* The task-scheduling paper's six-task load (its Table 1) under the static or the data-flow
 * strategy of src/sched/, on 1..4 channels at once.
 *
 * Each channel is the paper's chain: receive -> B1 -> interpret -> B2 ->
 * discrete -> B3 -> look-ahead -> B4 -> fine interpolation -> B5 -> position
 * control, with ncp_spsc rings. Our own tasks are far faster than the paper's,
 * so each task only emulates its cost: per item it burns its execution time
 * of CPU (thread CPU time, so a preempted task still costs what it should),
 * times --scale, then passes one item on. The soft-RT tasks are released
 * every cycle (the paper's 5 ms, unscaled: the data rate stays the paper's),
 * receive is aperiodic; position control runs every --period ms on an
 * absolute schedule at SCHED_FIFO 90 and counts an underrun when B5 is empty
 * (after its first item). Jitter is the paper's: max - min of the actual cycle.
 *
 * usage: sched-load --strategy static|dataflow --period MS --channels N
 *        [--seconds S] [--scale X] [--cpu C] [--cap N] [--fill CSV]
 * prints one line: key=value ... */
#include <errno.h>
#include <getopt.h>
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <time.h>

#include "ncpar/rt.h"
#include "ncpar/sched.h"

#define TASKS 6             /* receive .. position control */
#define RINGS 5             /* B1 .. B5 */
#define CHANNELS_MAX 4
#define LOOP_PRIORITY 90
#define SAMPLES_MAX 20000

/* Table 1: execution time and cycle (ms); receive has no cycle */
static const double EXEC_MS[TASKS] = { 10, 10, 10, 10, 10, 5 };
static const double CYCLE_MS[TASKS - 1] = { 0, 5, 5, 5, 5 };
static const char *const NAMES[TASKS] = { "receive", "interpret", "discrete", "look-ahead",
                                          "fine-ipo", "position" };

struct channel;

struct task {
    struct channel *ch;
    int index;
    pthread_t thread;
    int64_t exec_ns, cycle_ns;
};

struct channel {
    struct ncp_spsc ring[RINGS];
    struct task task[TASKS];
    struct ncp_sched sched;      /* dataflow: this channel's soft-RT tasks */
    /* position control's record (its thread only, read after the join) */
    uint64_t cycles, underruns, fed;
    int64_t cyc_min, cyc_max;
    uint16_t (*fill)[RINGS];     /* channel 0: the rings' fill every cycle */
    size_t samples;
};

static struct {
    enum ncp_sched_strategy strategy;
    double period_ms, seconds, scale;
    int channels, cpu, cap;
    const char *fill_csv;
} opt = { NCP_SCHED_STATIC, 10, 5, 0.05, 1, 1, 16, NULL };

static _Atomic int stop;

static int64_t ns_of(clockid_t c)
{
    struct timespec t;
    clock_gettime(c, &t);
    return (int64_t)t.tv_sec * 1000000000LL + t.tv_nsec;
}

static void sleep_until(int64_t ns)
{
    struct timespec t = { (time_t)(ns / 1000000000LL), (long)(ns % 1000000000LL) };
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &t, NULL) == EINTR)
        ;
}

static void nap_us(long us)
{
    sleep_until(ns_of(CLOCK_MONOTONIC) + us * 1000);
}

/* The paper's execution time, as CPU time of this thread. */
static void burn(int64_t ns)
{
    int64_t end = ns_of(CLOCK_THREAD_CPUTIME_ID) + ns;
    while (ns_of(CLOCK_THREAD_CPUTIME_ID) < end)
        ;
}

/* ctx is a task's output ring, ch->ring[k]; its input is the one before */
static size_t out_fill(void *ctx)
{
    return ncp_spsc_count(ctx);
}

static size_t in_fill(void *ctx)
{
    return ncp_spsc_count((struct ncp_spsc *)ctx - 1);
}

static void *soft_main(void *arg)
{
    struct task *t = arg;
    struct channel *ch = t->ch;
    struct ncp_spsc *in = t->index ? &ch->ring[t->index - 1] : NULL, *out = &ch->ring[t->index];
    size_t cap = ncp_spsc_capacity(out);
    ncp_sched_enter(&ch->sched.task[t->index]);
    int64_t next = ns_of(CLOCK_MONOTONIC);
    char item = 0;
    while (!atomic_load(&stop)) {
        if ((in && ncp_spsc_count(in) == 0) || ncp_spsc_count(out) >= cap) {
            nap_us(100);   /* the ring wait */
            continue;
        }
        burn(t->exec_ns);
        if (in)
            ncp_spsc_pop(in, &item);
        ncp_spsc_push(out, &item);
        if (!t->cycle_ns)
            continue;
        /* released every cycle; a task behind catches up by one, no burst */
        next += t->cycle_ns;
        int64_t now = ns_of(CLOCK_MONOTONIC);
        if (next < now - t->cycle_ns)
            next = now;
        sleep_until(next);
    }
    ncp_sched_leave(&ch->sched.task[t->index]);
    return NULL;
}

static void *position_main(void *arg)
{
    struct task *t = arg;
    struct channel *ch = t->ch;
    struct ncp_spsc *in = &ch->ring[RINGS - 1];
    int64_t period = (int64_t)(opt.period_ms * 1e6), next = ns_of(CLOCK_MONOTONIC), last = 0;
    char item;
    while (!atomic_load(&stop)) {
        next += period;
        sleep_until(next);
        int64_t now = ns_of(CLOCK_MONOTONIC);
        if (last) {
            int64_t c = now - last;
            if (ch->cycles == 0 || c < ch->cyc_min)
                ch->cyc_min = c;
            if (ch->cycles == 0 || c > ch->cyc_max)
                ch->cyc_max = c;
            ch->cycles++;
        }
        last = now;
        if (ch->fill && ch->samples < SAMPLES_MAX) {
            for (int r = 0; r < RINGS; r++)
                ch->fill[ch->samples][r] = (uint16_t)ncp_spsc_count(&ch->ring[r]);
            ch->samples++;
        }
        if (ncp_spsc_pop(in, &item) == 0) {
            ch->fed++;
            burn(t->exec_ns);
        } else if (ch->fed) {
            ch->underruns++;
        }
        if (now > next + period)   /* a late wake-up skips, never bursts */
            next = now;
    }
    return NULL;
}

static int parse(int argc, char **argv)
{
    static const struct option lo[] = {
        { "strategy", 1, 0, 's' }, { "period", 1, 0, 'p' }, { "channels", 1, 0, 'n' },
        { "seconds", 1, 0, 't' },  { "scale", 1, 0, 'x' },  { "cpu", 1, 0, 'c' },
        { "cap", 1, 0, 'b' },      { "fill", 1, 0, 'f' },   { 0, 0, 0, 0 },
    };
    int c;
    while ((c = getopt_long(argc, argv, "", lo, NULL)) != -1) {
        switch (c) {
        case 's':
            opt.strategy = !strcmp(optarg, "dataflow") ? NCP_SCHED_DATAFLOW
                           : !strcmp(optarg, "static") ? NCP_SCHED_STATIC
                                                       : NCP_SCHED_NONE;
            break;
        case 'p': opt.period_ms = atof(optarg); break;
        case 'n': opt.channels = atoi(optarg); break;
        case 't': opt.seconds = atof(optarg); break;
        case 'x': opt.scale = atof(optarg); break;
        case 'c': opt.cpu = atoi(optarg); break;
        case 'b': opt.cap = atoi(optarg); break;
        case 'f': opt.fill_csv = optarg; break;
        default: return -1;
        }
    }
    if (opt.strategy == NCP_SCHED_NONE || opt.channels < 1 || opt.channels > CHANNELS_MAX ||
        opt.period_ms <= 0 || opt.seconds <= 0 || opt.scale <= 0 || opt.cap < 2)
        return -1;
    return 0;
}

static int start(struct channel *ch, int k, int prio, uint32_t *warn)
{
    struct task *t = &ch->task[k];
    struct ncp_rt_place at = { opt.cpu, SCHED_FIFO, prio };
    return ncp_rt_start(&t->thread, &at, k == TASKS - 1 ? position_main : soft_main, t, warn);
}

int main(int argc, char **argv)
{
    if (parse(argc, argv))
        return fprintf(stderr, "usage: sched-load --strategy static|dataflow --period MS "
                               "--channels 1..4 [--seconds S] [--scale X] [--cpu C] [--cap N] "
                               "[--fill CSV]\n"), 1;
    static struct channel chs[CHANNELS_MAX];
    int ceiling = ncp_sched_ceiling(LOOP_PRIORITY) - 1, floor = 10, prio[TASKS - 1];
    ncp_sched_static(TASKS - 1, floor, ceiling, prio);
    uint32_t warn = 0;
    for (int c = 0; c < opt.channels; c++) {
        struct channel *ch = &chs[c];
        for (int r = 0; r < RINGS; r++)
            if (ncp_spsc_init(&ch->ring[r], 1, (size_t)opt.cap))
                return fprintf(stderr, "sched-load: out of memory\n"), 1;
        if (c == 0 && !(ch->fill = calloc(SAMPLES_MAX, sizeof *ch->fill)))
            return 1;
        ncp_sched_cfg_default(&ch->sched.cfg);
        ch->sched.cfg.strategy = opt.strategy;
        ch->sched.cfg.period_ms = 1;
        ch->sched.cfg.floor = floor;
        ch->sched.ceiling = ceiling;
        ch->sched.thread_priority = ceiling + 1;
        ch->sched.n = TASKS - 1;
        for (int k = 0; k < TASKS; k++) {
            ch->task[k] = (struct task){ ch, k, 0, (int64_t)(EXEC_MS[k] * opt.scale * 1e6),
                                         k < TASKS - 1 ? (int64_t)(CYCLE_MS[k] * 1e6) : 0 };
            if (k < TASKS - 1)
                ch->sched.task[k] = (struct ncp_sched_task){
                    .name = NAMES[k], .in_fill = k ? in_fill : NULL,
                    .in_cap = k ? ncp_spsc_capacity(&ch->ring[k - 1]) : 0,
                    .out_fill = out_fill, .out_cap = ncp_spsc_capacity(&ch->ring[k]),
                    .ctx = &ch->ring[k]
                };
        }
    }
    mlockall(MCL_CURRENT | MCL_FUTURE);
    for (int c = 0; c < opt.channels; c++) {
        if (start(&chs[c], TASKS - 1, LOOP_PRIORITY, &warn))
            return fprintf(stderr, "sched-load: cannot start threads\n"), 1;
        for (int k = 0; k < TASKS - 1; k++)
            if (start(&chs[c], k, prio[k], &warn))
                return fprintf(stderr, "sched-load: cannot start threads\n"), 1;
    }
    if (warn & NCP_RT_WARN_NO_FIFO)
        return fprintf(stderr, "sched-load: SCHED_FIFO not permitted: nothing to compare\n"), 2;
    for (int c = 0; c < opt.channels; c++)
        ncp_sched_start(&chs[c].sched);
    nap_us((long)(opt.seconds * 1e6));
    atomic_store(&stop, 1);
    uint64_t under = 0, cycles = 0, fed = 0, changes = 0;
    int64_t cmin = INT64_MAX, cmax = 0;
    for (int c = 0; c < opt.channels; c++) {
        ncp_sched_stop(&chs[c].sched);
        for (int k = 0; k < TASKS; k++)
            pthread_join(chs[c].task[k].thread, NULL);
        under += chs[c].underruns;
        cycles += chs[c].cycles;
        fed += chs[c].fed;
        cmin = chs[c].cyc_min < cmin ? chs[c].cyc_min : cmin;
        cmax = chs[c].cyc_max > cmax ? chs[c].cyc_max : cmax;
        for (int k = 0; k < TASKS - 1; k++)
            changes += chs[c].sched.task[k].changes;
    }
    printf("strategy=%s period_ms=%g channels=%d cycles=%llu fed=%llu underruns=%llu "
           "cycle_min_us=%.1f cycle_max_us=%.1f jitter_us=%.1f changes=%llu\n",
           ncp_sched_strategy_name(opt.strategy), opt.period_ms, opt.channels,
           (unsigned long long)cycles, (unsigned long long)fed, (unsigned long long)under,
           (double)cmin * 1e-3, (double)cmax * 1e-3, (double)(cmax - cmin) * 1e-3,
           (unsigned long long)changes);
    if (opt.fill_csv) {
        FILE *f = fopen(opt.fill_csv, "w");
        if (!f)
            return perror(opt.fill_csv), 1;
        fprintf(f, "t_ms,B1,B2,B3,B4,B5\n");
        for (size_t i = 0; i < chs[0].samples; i++)
            fprintf(f, "%.1f,%u,%u,%u,%u,%u\n", (double)(i + 1) * opt.period_ms, chs[0].fill[i][0],
                    chs[0].fill[i][1], chs[0].fill[i][2], chs[0].fill[i][3], chs[0].fill[i][4]);
        fclose(f);
    }
    return 0;
}
