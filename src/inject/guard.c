/* The miss limits of [RT]: so many misses in a row, or more than a share of
 * the last MISS_WINDOW periods. A sliding window of one bit per period,
 * fixed in size, so the count costs the same every period. */
#include "ncpar/inject.h"

#include <stdio.h>
#include <string.h>

void ncp_inject_guard_init(struct ncp_inject_guard *g, const struct ncp_inject_cfg *c)
{
    memset(g, 0, sizeof *g);
    g->max_consecutive = c->max_consecutive;
    g->max_ratio = c->max_ratio;
    g->window = c->window > 0 && c->window <= NCP_INJECT_WINDOW_MAX ? c->window : 1000;
}

int ncp_inject_guard_add(struct ncp_inject_guard *g, int missed)
{
    uint64_t slot = g->seen % (uint64_t)g->window;
    uint64_t *word = &g->bits[slot / 64], bit = 1ULL << (slot % 64);
    if (*word & bit)
        g->in_window--;
    if (missed) {
        *word |= bit;
        g->in_window++;
        g->consecutive++;
    } else {
        *word &= ~bit;
        g->consecutive = 0;
    }
    g->seen++;
    if (g->max_consecutive > 0 && g->consecutive > g->max_consecutive)
        return NCP_TRIP_CONSECUTIVE;
    /* more than the share of a whole window, counted from the first period
     * on: a burst at start-up trips it as it would later */
    if (g->max_ratio > 0 && (double)g->in_window > g->max_ratio * (double)g->window)
        return NCP_TRIP_RATIO;
    return NCP_TRIP_NONE;
}

void ncp_inject_summary(const struct ncp_inject_cfg *c, const struct ncp_inject_report *r,
                        char *buf, size_t len)
{
    if (!len)
        return;
    buf[0] = 0;
    if (!c->kinds)
        return;
    static const char *const names[NCP_INJ_KINDS] = { "missed", "setpoints lost",
                                                      "feedback lost", "latency",
                                                      "io-latency", "jitter",
                                                      "feedback delayed", "late" };
    size_t at = (size_t)snprintf(buf, len, "injected (seed %llu, policy %s):",
                                 (unsigned long long)c->seed, ncp_miss_policy_name(c->policy));
    for (int b = 0; b < NCP_INJ_KINDS && at < len; b++)
        if (r->count[b])
            at += (size_t)snprintf(buf + at, len - at, " %s %llu,", names[b],
                                   (unsigned long long)r->count[b]);
    if (at < len)
        snprintf(buf + at, len - at, " periods missed %llu", (unsigned long long)r->misses);
}

void ncp_inject_trip_text(const struct ncp_inject_cfg *c, const struct ncp_inject_report *r,
                          double period_s, char *buf, size_t len)
{
    double t = (double)r->trip_cycle * period_s;
    if (r->trip == NCP_TRIP_CONSECUTIVE)
        snprintf(buf, len,
                 "%d consecutive deadline misses up to cycle %llu (t %.3f s), over [RT] "
                 "MAX_CONSECUTIVE_MISSES %d; controlled stop along the path",
                 r->trip_run, (unsigned long long)r->trip_cycle, t, c->max_consecutive);
    else
        snprintf(buf, len,
                 "%d deadline misses in the %d periods up to cycle %llu (t %.3f s), over [RT] "
                 "MAX_MISS_RATIO %g of MISS_WINDOW %d; controlled stop along the path",
                 r->trip_in_window, c->window, (unsigned long long)r->trip_cycle, t,
                 c->max_ratio, c->window);
}
