/* The two priority assignments of the task-scheduling paper, as pure functions of the chain. */
#include "ncpar/sched.h"

static int clamp(int p, int floor, int ceiling)
{
    return p < floor ? floor : p > ceiling ? ceiling : p;
}

int ncp_sched_ceiling(int loop_priority)
{
    return loop_priority - 1;
}

void ncp_sched_static(int n, int floor, int ceiling, int *prio)
{
    for (int i = 0; i < n; i++)
        prio[i] = clamp(ceiling - (n - 1 - i), floor, ceiling);
}

/* Input waiting minus output ready, both as shares of their rings: the
 * task-scheduling paper's difference of upstream and downstream data, made comparable
 * between rings of different sizes. */
static double pressure(const struct ncp_sched_fill *f)
{
    double in = f->in_cap ? (double)f->in_fill / (double)f->in_cap : 1.0;
    double out = f->out_cap ? (double)f->out_fill / (double)f->out_cap : 0.0;
    return in - out;
}

static int runnable(const struct ncp_sched_fill *f)
{
    return (!f->in_cap || f->in_fill > 0) && (!f->out_cap || f->out_fill < f->out_cap);
}

void ncp_sched_dataflow(const struct ncp_sched_fill *f, int n, int floor, int ceiling,
                        int *prio)
{
    ncp_sched_dataflow_ranked(f, NULL, n, floor, ceiling, prio);
}

/* j is nearer the position loop than i */
static int downstream(const int *rank, int j, int i)
{
    if (rank && rank[j] != rank[i])
        return rank[j] > rank[i];
    return j > i;
}

void ncp_sched_dataflow_ranked(const struct ncp_sched_fill *f, const int *rank, int n,
                               int floor, int ceiling, int *prio)
{
    /* rank among the runnable: a task outranks another with less pressure,
     * or the same pressure further upstream (nearer the position loop) */
    for (int i = 0; i < n; i++) {
        if (!runnable(&f[i])) {
            prio[i] = floor;
            continue;
        }
        int above = 0;
        double pi = pressure(&f[i]);
        for (int j = 0; j < n; j++) {
            if (j == i || !runnable(&f[j]))
                continue;
            double pj = pressure(&f[j]);
            if (pj > pi || (pj == pi && downstream(rank, j, i)))
                above++;
        }
        prio[i] = clamp(ceiling - above, floor, ceiling);
    }
}
