#include "ramp_check.h"

#include <stdio.h>

void ncp_ramp_axis_init(struct ncp_ramp_axis *a, int32_t start, int32_t step)
{
    *a = (struct ncp_ramp_axis){.start = start, .step = step, .last_j = -1};
}

static void flag(struct ncp_ramp_axis *a, int32_t actual, long k, const char *what)
{
    if (a->bad++ == 0)
        snprintf(a->why, sizeof a->why, "actual %d in cycle %ld %s", actual, k, what);
}

void ncp_ramp_axis_tpdo(struct ncp_ramp_axis *a, int32_t actual, long k, long cycles)
{
    int64_t diff = (int64_t)actual - a->start;
    if (a->step == 0 || diff % a->step != 0)
        return flag(a, actual, k, "is no target the master sent");
    long j = (long)(diff / a->step);
    if (j < 0 || j > k)
        return flag(a, actual, k, "is a target not sent yet");
    if (j < a->last_j)
        return flag(a, actual, k, "goes back to an older target");
    /* Repeats are normal only while the target holds: the TPDOs of the
     * enabling cycles (j = 0) and of the settling ones (j = cycles). */
    if (j == a->last_j && j != 0 && j != cycles)
        return flag(a, actual, k, "repeats the previous cycle's target");
    if (j > a->last_j && j >= 1)
        a->seen++;
    a->last_j = j;
}

long ncp_ramp_axis_lag(struct ncp_ramp_axis *a, long k)
{
    long lag = k - (a->last_j < 0 ? 0 : a->last_j);
    if (lag > a->max_lag)
        a->max_lag = lag;
    return lag;
}
