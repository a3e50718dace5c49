/* Wake-up latency statistics, cyclictest style: 1 us bins. Written by the loop
 * thread only; read by others after it has stopped. */
#include "ncpar/rt.h"

#include <stdint.h>
#include <string.h>

void ncp_rt_stats_reset(struct ncp_rt_stats *s)
{
    memset(s, 0, sizeof *s);
    s->lat_min_ns = INT64_MAX;
}

void ncp_rt_stats_add(struct ncp_rt_stats *s, int64_t latency_ns)
{
    if (latency_ns < 0)
        latency_ns = 0;
    s->cycles++;
    if (latency_ns < s->lat_min_ns)
        s->lat_min_ns = latency_ns;
    if (latency_ns > s->lat_max_ns)
        s->lat_max_ns = latency_ns;
    s->lat_sum_ns += (double)latency_ns;
    int64_t bin = latency_ns / 1000;
    if (bin < NCP_RT_HIST_BINS)
        s->hist[bin]++;
    else
        s->overflow++;
}
