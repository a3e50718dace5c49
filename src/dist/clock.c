/* The LLC's estimate of the HLC's clock from probe round trips (NTP's four
 * timestamps). A probe's offset is exact when the request and the answer
 * took as long; what makes them differ is waiting (a socket queue, a thread
 * not yet woken), which also lengthens the round trip. So the probe with the
 * shortest round trip in the window is trusted, and the others only say how
 * much the estimate scatters. */
#include "ncpar/dist.h"

#include <math.h>
#include <string.h>

void ncp_dist_clock_init(struct ncp_dist_clock *c)
{
    memset(c, 0, sizeof *c);
}

int ncp_dist_clock_add(struct ncp_dist_clock *c, int64_t t1, int64_t t2, int64_t t3, int64_t t4)
{
    int64_t rtt = (t4 - t1) - (t3 - t2);
    if (t4 < t1 || t3 < t2 || rtt < 0)
        return -1;
    /* halves first: the sum of two offsets of a clock far away must not wrap */
    c->probe[c->next].offset_ns = (t2 - t1) / 2 + (t3 - t4) / 2;
    c->probe[c->next].rtt_ns = rtt;
    c->next = (c->next + 1) % NCP_DIST_CLOCK_WINDOW;
    if (c->n < NCP_DIST_CLOCK_WINDOW)
        c->n++;
    return 0;
}

int ncp_dist_clock_estimate(const struct ncp_dist_clock *c, struct ncp_dist_clock_est *e)
{
    if (c->n == 0)
        return -1;
    /* the newest first, so that of equal round trips the newest wins (a
     * drifting clock has moved on since the older ones) */
    int best = (c->next - 1 + NCP_DIST_CLOCK_WINDOW) % NCP_DIST_CLOCK_WINDOW;
    for (int k = 2; k <= c->n; k++) {
        int i = (c->next - k + NCP_DIST_CLOCK_WINDOW) % NCP_DIST_CLOCK_WINDOW;
        if (c->probe[i].rtt_ns < c->probe[best].rtt_ns)
            best = i;
    }
    double sq = 0;
    for (int k = 0; k < c->n; k++) {
        double d = (double)(c->probe[k].offset_ns - c->probe[best].offset_ns);
        sq += d * d;
    }
    e->offset_ns = c->probe[best].offset_ns;
    e->rtt_ns = c->probe[best].rtt_ns;
    e->jitter_ns = llround(sqrt(sq / c->n));
    e->probes = c->n;
    return 0;
}

int64_t ncp_dist_clock_slew(int64_t applied, int64_t target, int64_t max_step)
{
    if (target > applied + max_step)
        return applied + max_step;
    if (target < applied - max_step)
        return applied - max_step;
    return target;
}
