/* One period's faults, drawn in the position loop. Every stream advances by
 * the same number of draws each period whatever it decides, so the faults of
 * one kind fall on the same cycles with or without the others. */
#include "ncpar/inject.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

void ncp_inject_init(struct ncp_inject *in, const struct ncp_inject_cfg *c, double period_s)
{
    memset(in, 0, sizeof *in);
    in->cfg = *c;
    in->period_s = period_s;
    for (int i = 0; i < NCP_INJ_STREAMS; i++)
        ncp_xoshiro_seed(&in->rng[i], c->seed * 0x100000001b3ULL + (uint64_t)i * 0x9e37ULL + 1);
}

static int chance(struct ncp_xoshiro *r, double ratio)
{
    double u = ncp_xoshiro_uniform(r);
    return ratio > 0 && u < ratio;
}

void ncp_inject_period(struct ncp_inject *in, uint64_t cycle, struct ncp_inject_ev *ev)
{
    const struct ncp_inject_cfg *c = &in->cfg;
    memset(ev, 0, sizeof *ev);
    if (!c->kinds)
        return;
    /* one frame for every axis: one draw per period; a frame per axis: one
     * draw per axis, each axis' setpoint late or lost on its own */
    const uint32_t all = (1u << NCP_INJECT_AXES) - 1;
    int draws = c->per_axis ? NCP_INJECT_AXES : 1;
    uint32_t miss = 0, lose = 0;
    for (int j = 0; j < draws; j++) {
        uint32_t bit = c->per_axis ? 1u << j : all;
        if (chance(&in->rng[NCP_INJ_STREAM_MISS], c->miss_ratio))
            miss |= bit;
        if (chance(&in->rng[NCP_INJ_STREAM_LOSE_SP], c->lose_sp_ratio))
            lose |= bit;
    }
    for (int i = 0; i < c->n_miss_at; i++)
        if (c->miss_at[i] == cycle)
            miss |= c->miss_at_axes[i] ? c->miss_at_axes[i] : all;
    if (miss)
        ev->what |= NCP_INJ_MISS;
    if (lose)
        ev->what |= NCP_INJ_LOSE_SP;
    ev->miss_axes = miss;
    ev->lose_axes = lose;
    ev->per_axis = c->per_axis;
    if (chance(&in->rng[NCP_INJ_STREAM_LOSE_FB], c->lose_fb_ratio))
        ev->what |= NCP_INJ_LOSE_FB;
    double u = ncp_xoshiro_uniform(&in->rng[NCP_INJ_STREAM_LATENCY]);
    double lat = c->lat_min_s + u * (c->lat_max_s - c->lat_min_s);
    if (c->kinds & NCP_INJ_LATENCY)
        ev->what |= NCP_INJ_LATENCY;
    else
        lat = 0;
    double jit = 0;
    if (c->jitter_normal) {
        double z = ncp_xoshiro_normal(&in->rng[NCP_INJ_STREAM_JITTER]);
        jit = fmin(c->jitter_s, fmax(0.0, c->jitter_s * (0.5 + z / 6.0)));
    } else {
        jit = c->jitter_s * ncp_xoshiro_uniform(&in->rng[NCP_INJ_STREAM_JITTER]);
    }
    if (c->kinds & NCP_INJ_JITTER)
        ev->what |= NCP_INJ_JITTER;
    else
        jit = 0;
    ev->jitter_s = jit;
    ev->sample_s = jit + lat;
    ev->io_s = c->io_s;
    if (c->kinds & NCP_INJ_IO)
        ev->what |= NCP_INJ_IO;
    ev->delay_fb_s = c->delay_fb_s;
    if (c->kinds & NCP_INJ_DELAY_FB)
        ev->what |= NCP_INJ_DELAY_FB;
    /* the control output would act after the period it was computed for:
     * that period's deadline is missed */
    if (ev->sample_s + ev->io_s >= in->period_s)
        ev->what |= NCP_INJ_LATE;
}

int ncp_inject_format(const struct ncp_inject_ev *ev, char *buf, size_t len)
{
    if (!len)
        return -1;
    size_t at = 0;
    buf[0] = 0;
#define ADD(...)                                                                    \
    do {                                                                            \
        int k_ = snprintf(buf + at, len - at, "%s", at ? "+" : "");                 \
        if (k_ < 0 || (size_t)k_ >= len - at)                                       \
            return -1;                                                              \
        at += (size_t)k_;                                                           \
        k_ = snprintf(buf + at, len - at, __VA_ARGS__);                             \
        if (k_ < 0 || (size_t)k_ >= len - at)                                       \
            return -1;                                                              \
        at += (size_t)k_;                                                           \
    } while (0)
    /* a frame per axis: which axes, e.g. miss:Y */
    char ma[NCP_INJECT_AXES + 2] = "", la[NCP_INJECT_AXES + 2] = "";
    for (int j = 0, mi = 0, li = 0; ev->per_axis && j < NCP_INJECT_AXES; j++) {
        if (!mi)
            ma[mi++] = ':';
        if (!li)
            la[li++] = ':';
        if (ev->miss_axes >> j & 1)
            ma[mi++] = "XYZABCUVW"[j];
        if (ev->lose_axes >> j & 1)
            la[li++] = "XYZABCUVW"[j];
    }
    if (ev->what & NCP_INJ_MISS)
        ADD("miss%s", ma);
    if (ev->what & NCP_INJ_LOSE_SP)
        ADD("lose-sp%s", la);
    if (ev->what & NCP_INJ_LOSE_FB)
        ADD("lose-fb");
    if (ev->what & NCP_INJ_LATE)
        ADD("late");
    if (ev->what & NCP_INJ_LATENCY)
        ADD("lat=%.3f", (ev->sample_s - ev->jitter_s) * 1e6);
    if (ev->what & NCP_INJ_JITTER)
        ADD("jit=%.3f", ev->jitter_s * 1e6);
    if (ev->what & NCP_INJ_IO)
        ADD("io=%.3f", ev->io_s * 1e6);
    if (ev->what & NCP_INJ_DELAY_FB)
        ADD("dfb=%.3f", ev->delay_fb_s * 1e6);
#undef ADD
    if (!at)
        return snprintf(buf, len, "-");
    return (int)at;
}
