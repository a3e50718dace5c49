/* core-latency [CPU_A CPU_B] [ROUNDS]: the round trip of one cache line
 * between two CPUs (two threads, each pinned, bouncing a counter), median of
 * ROUNDS measurements of 20,000 round trips each.
 *
 * Why a benchmark needs it: every command the pipeline hands from one stage
 * to the next crosses between cores as cache lines. On a virtual machine the
 * two vCPUs may share a core complex on the host (round trip ~100 ns) or sit
 * on different dies (~450 ns, measured here), and the host may move them
 * between runs. Pipeline-vs-serial ratios mean little without this number
 * beside them, so bench-parse prints it before and after its runs. */
#ifndef _GNU_SOURCE
#define _GNU_SOURCE
#endif
#include <pthread.h>
#include <sched.h>
#include <stdalign.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#define TRIPS 20000

static alignas(64) _Atomic unsigned long ball;
static alignas(64) _Atomic int ready; /* 1: the returner is in place, 2: it cannot be */
static int cpu_b;

static int pin(int cpu)
{
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(cpu, &set);
    return pthread_setaffinity_np(pthread_self(), sizeof set, &set);
}

/* Returns the ball: odd values are the main thread's serves. */
static void *returner(void *arg)
{
    (void)arg;
    if (pin(cpu_b) != 0) {
        atomic_store(&ready, 2);
        return NULL;
    }
    atomic_store(&ready, 1);
    for (unsigned long i = 0; i < TRIPS; i++) {
        while (atomic_load_explicit(&ball, memory_order_acquire) != 2 * i + 1)
            ;
        atomic_store_explicit(&ball, 2 * i + 2, memory_order_release);
    }
    return NULL;
}

static double now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e9 + (double)ts.tv_nsec;
}

static double one_round(int cpu_a)
{
    pthread_t t;
    if (pin(cpu_a) != 0)
        return -1;
    atomic_store(&ball, 0);
    atomic_store(&ready, 0);
    if (pthread_create(&t, NULL, returner, NULL) != 0)
        return -1;
    int r;
    while ((r = atomic_load(&ready)) == 0)
        ;
    if (r != 1) {
        pthread_join(t, NULL);
        return -1;
    }
    double t0 = now_ns();
    for (unsigned long i = 0; i < TRIPS; i++) {
        atomic_store_explicit(&ball, 2 * i + 1, memory_order_release);
        while (atomic_load_explicit(&ball, memory_order_acquire) != 2 * i + 2)
            ;
    }
    double t1 = now_ns();
    pthread_join(t, NULL);
    return (t1 - t0) / TRIPS;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int main(int argc, char **argv)
{
    int cpu_a = argc > 2 ? atoi(argv[1]) : 0;
    cpu_b = argc > 2 ? atoi(argv[2]) : 1;
    int rounds = argc > 3 ? atoi(argv[3]) : argc == 2 ? atoi(argv[1]) : 5;
    if (rounds < 1 || rounds > 1000) {
        fprintf(stderr, "usage: core-latency [CPU_A CPU_B] [ROUNDS 1..1000]\n");
        return 1;
    }
    double ns[1000];
    for (int r = 0; r < rounds; r++) {
        ns[r] = one_round(cpu_a);
        if (ns[r] < 0) {
            fprintf(stderr, "core-latency: cannot run on CPUs %d and %d\n", cpu_a, cpu_b);
            return 1;
        }
    }
    qsort(ns, (size_t)rounds, sizeof ns[0], cmp_double);
    printf("core-to-core round trip CPU%d<->CPU%d: %.0f ns (median of %d, min %.0f, max %.0f)\n",
           cpu_a, cpu_b, ns[rounds / 2], rounds, ns[0], ns[rounds - 1]);
    return 0;
}
