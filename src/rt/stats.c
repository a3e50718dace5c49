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

void ncp_rt_stats_print(const struct ncp_rt_stats *s, FILE *f)
{
    if (!s->cycles) {
        fprintf(f, "  loop latency: no cycles\n");
        return;
    }
    fprintf(f, "  loop latency: min %.1f us, avg %.1f us, max %.1f us over %llu cycles\n",
            (double)s->lat_min_ns / 1e3, s->lat_sum_ns / (double)s->cycles / 1e3,
            (double)s->lat_max_ns / 1e3, (unsigned long long)s->cycles);
    fprintf(f, "  latency histogram (us: cycles):");
    int shown = 0;
    for (int i = 0; i < NCP_RT_HIST_BINS; i++) {
        if (!s->hist[i])
            continue;
        fprintf(f, "%s %d: %llu", shown++ % 8 ? "," : "\n   ", i,
                (unsigned long long)s->hist[i]);
    }
    if (s->overflow)
        fprintf(f, "%s >=%d: %llu", shown ? "," : "\n   ", NCP_RT_HIST_BINS,
                (unsigned long long)s->overflow);
    fputc('\n', f);
}
