/* cpu-speed [ROUNDS]: how fast each CPU runs the same integer loop alone, and
 * how fast both run it at once; prints the medians of ROUNDS interleaved
 * measurements and the bound they set on any parallel speed-up.
 *
 * Why a benchmark needs it: on the virtual machines we measure on, one vCPU
 * can run a plain loop 1.5x slower than the other for minutes (a busy
 * neighbour on the host, or two vCPUs that are hyperthreads of one core), and
 * both busy at once can be slower than either alone. A two-thread run of
 * perfectly divisible work can then beat one thread on the faster CPU by at
 * most (rate of CPU 0 + rate of CPU 1, both busy) / (rate of the faster CPU
 * alone): "parallel vs serial" figures mean little without that bound beside
 * them, so bench-parse prints it before and after its runs. */
#ifndef _GNU_SOURCE
#define _GNU_SOURCE
#endif
#include <pthread.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#define LOOP_ITERS 40000000UL
#define MAX_ROUNDS 99

static double now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec * 1e3 + (double)t.tv_nsec / 1e6;
}

static int pin(int cpu)
{
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(cpu, &set);
    return pthread_setaffinity_np(pthread_self(), sizeof set, &set);
}

/* A dependency chain of cheap integer operations: what the CPU sustains, not
 * what the memory system does. */
static double spin_ms(void)
{
    volatile unsigned long sink = 0;
    unsigned long x = 88172645463325252UL;
    double t0 = now_ms();
    for (unsigned long i = 0; i < LOOP_ITERS; i++) {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
    }
    sink = x;
    (void)sink;
    return now_ms() - t0;
}

struct job {
    int cpu;
    pthread_barrier_t *start;
    double ms;
};

static void *run_job(void *arg)
{
    struct job *j = arg;
    if (pin(j->cpu) != 0) {
        j->ms = -1.0;
        return NULL;
    }
    if (j->start)
        pthread_barrier_wait(j->start);
    j->ms = spin_ms();
    return NULL;
}

/* Runs the loop on the given CPUs at once (one thread each); 0 on success. */
static int run_on(const int *cpus, int n, double *ms)
{
    pthread_t t[2];
    struct job j[2];
    pthread_barrier_t start;
    if (pthread_barrier_init(&start, NULL, (unsigned)n) != 0)
        return -1;
    int rc = 0;
    for (int k = 0; k < n; k++) {
        j[k] = (struct job){cpus[k], &start, 0.0};
        if (pthread_create(&t[k], NULL, run_job, &j[k]) != 0) {
            fprintf(stderr, "cpu-speed: cannot start a thread\n");
            exit(1);
        }
    }
    for (int k = 0; k < n; k++) {
        pthread_join(t[k], NULL);
        ms[k] = j[k].ms;
        if (j[k].ms < 0)
            rc = -1;
    }
    pthread_barrier_destroy(&start);
    return rc;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : (v[n / 2 - 1] + v[n / 2]) / 2.0;
}

int main(int argc, char **argv)
{
    int rounds = argc > 1 ? atoi(argv[1]) : 5;
    if (rounds < 1 || rounds > MAX_ROUNDS) {
        fprintf(stderr, "usage: cpu-speed [ROUNDS 1..%d]\n", MAX_ROUNDS);
        return 2;
    }
    double alone0[MAX_ROUNDS], alone1[MAX_ROUNDS], both0[MAX_ROUNDS], both1[MAX_ROUNDS];
    for (int r = 0; r < rounds; r++) {
        const int c0[] = {0}, c1[] = {1}, c01[] = {0, 1};
        double ms[2];
        if (run_on(c0, 1, ms) || (alone0[r] = ms[0], run_on(c1, 1, ms)) ||
            (alone1[r] = ms[0], run_on(c01, 2, ms))) {
            fprintf(stderr, "cpu-speed: needs CPUs 0 and 1\n");
            return 1;
        }
        both0[r] = ms[0];
        both1[r] = ms[1];
    }
    double a0 = median(alone0, rounds), a1 = median(alone1, rounds);
    double b0 = median(both0, rounds), b1 = median(both1, rounds);
    double fastest_alone = a0 < a1 ? a0 : a1;
    /* rates in loops per ms; the bound is the summed rate both busy over the
     * best single rate */
    double bound = (1.0 / b0 + 1.0 / b1) * fastest_alone;
    printf("loop ms alone: cpu0 %.1f cpu1 %.1f; both at once: cpu0 %.1f cpu1 %.1f; "
           "two threads can beat one on the faster CPU by at most %.2fx\n",
           a0, a1, b0, b1, bound);
    return 0;
}
