/* The HLC's time scaling at ADCBI's block-level points, as one LLC keeps it
 * (llc_scale.c): the stream advance the HLC reported for each of its periods,
 * the newest heard, and the records an abort of its made void. */
#ifndef NCP_AXIS_LLC_SCALE_H
#define NCP_AXIS_LLC_SCALE_H

#include <stddef.h>
#include <stdint.h>

/* Periods of advances kept: a loop woken late steps the interpolator
 * through every period it slept through (llc.c's left_out(), then the 64
 * it plays), each at the advance the HLC said for it, by then that many
 * periods older than the newest. 64 lost the oldest of them, and a stall in
 * a feed hold's ramp ran that axis at 1 there; this covers a stall of 2 s,
 * far past the HLC's heartbeat watch. */
#define LLC_SCALE_HIST 2048
#define LLC_DROPS 8   /* DP2: aborts whose planner records are told apart */

struct llc_scale {
    int64_t t[LLC_SCALE_HIST];
    double adv[LLC_SCALE_HIST];
    int64_t newest_t;
    double newest;
    int32_t void_below;
    int64_t void_t;
    int void_due;
    double void_off;   /* homing's offset on this axis from that drop on (mm) */
    uint32_t voided;   /* aborts whose records were dropped */
    /* DP2: the DROP calls this LLC's planner replayed, and for each the
     * number of its own records then (those before are the aborted job's) */
    int32_t drops;
    int32_t drop_own[LLC_DROPS];
    uint32_t drop_waits;   /* periods stood for a DROP its planner had not replayed */
};

struct llc;
void llc_on_scale(struct llc *l, const uint8_t *p, size_t len);
/* count periods' advances, the last of period t_ns, into the history (the
 * same for ADCAI's ai_scale_t, llc_ai_play.c). */
void llc_scale_put(struct llc *l, int64_t t_ns, const double *adv, int count);
/* The stream advance of the HLC's period slot (samples; 1 its own pace). */
double llc_scale_at(const struct llc *l, int64_t slot);
/* Drops the records an abort of the HLC's made void, once slot reaches
 * the period it dropped them in; the interpolator starts again from the
 * next record's start. 1: due, but at DP2 this LLC's planner has not
 * replayed the abort yet (the axis stands meanwhile, as the HLC's stream
 * does), 0 otherwise. */
int llc_scale_void(struct llc *l, int64_t slot);
/* The same 1 without dropping anything (feed-forward's look ahead). */
int llc_scale_void_waits(const struct llc *l, int64_t slot);

#endif
