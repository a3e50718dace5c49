/* ADCAI's DP1 at the LLC. The NCK this LLC runs on the HLC's program
 * (dp1.c) is an ADCAI one, so its chain interpolates the program roughly
 * itself; its tap hands every servo period's sample over here (the rough
 * record it starts, summed, and whether any axis moves in it). This axis's
 * own ACC/DEC and fine interpolator (llc_adcai.c, as at DP2) run on those
 * records and the position loop plays their output on the HLC's period
 * grid.
 *
 * Alignment: the LLC's inner run is on the virtual clock, so its waits
 * (spindle, pauses, tool changes) last other times than the HLC's. Its
 * samples therefore split into motion runs at every standstill, a sample
 * in which no axis moves, which is also how the HLC counts the standstills
 * its path leaves (lcm.c). Inside a run one sample plays per period, as the
 * HLC's loop plays its stream; the first moving sample after a standstill
 * waits for the period the HLC's mark names for that start (NCP_HLC_SYNC,
 * sent 6 times in a row and every 20 periods). Samples of a standstill move
 * no axis, so they go through the stages as fast as they come: only their
 * number of stage steps matters, not when.
 *
 * The inner chain's own fine setpoint of this axis travels beside each
 * sample: this axis's stages must give exactly it, and a period where they
 * do not is counted (always 0: the same integer stages on the same
 * increments). */
#include "axis.h"

#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "ncpar/adcai.h"

#define SAMPLES (1 << 16)    /* a minute ahead at 1 ms; standstills collapsed */
#define PER_PERIOD 4096      /* samples taken per period at most (a long dwell) */
#define READY 512            /* queued before the HLC may start (0.5 s at 1 ms) */
#define QUEUE 4

enum { S_START = 1, S_MOVED = 2, S_IDLE = 4 };

struct sample {
    int32_t sum;         /* S_START: this axis's rough increments summed */
    int32_t nm;          /* the inner chain's setpoint of this axis */
    uint8_t kind;
};

struct llc_dp1_ai {
    struct ncp_spsc ring;             /* inner planner thread -> position loop */
    const _Atomic int *quit;
    int axis, ratio;
    /* the inner planner thread's */
    int phase, last_idle;
    /* the position loop's */
    struct { int32_t nm; int after_rest; } q[QUEUE];   /* moving samples, stepped */
    int qn, pending_rest, ready, begun;
    int have_off;
    int64_t off;                      /* inner setpoint - this axis's, nm */
    int64_t cur;                      /* the command, nm */
    uint64_t samples, played, late_starts, differ;
    int64_t late_max;
    uint32_t behind;
};

struct llc_dp1_ai *llc_dp1_ai_new(const struct llc *l, const _Atomic int *quit)
{
    struct llc_dp1_ai *x = calloc(1, sizeof *x);
    if (!x || ncp_spsc_init(&x->ring, sizeof(struct sample), SAMPLES) != 0) {
        free(x);
        return NULL;
    }
    x->quit = quit;
    x->axis = l->axis;
    x->ratio = llc_ai_ratio(l->ai);
    x->pending_rest = 1;
    return x;
}

void llc_dp1_ai_free(struct llc_dp1_ai *x)
{
    if (!x)
        return;
    ncp_spsc_destroy(&x->ring);
    free(x);
}

void llc_dp1_ai_drain(struct llc_dp1_ai *x)
{
    struct sample s;
    while (ncp_spsc_pop(&x->ring, &s) == 0)
        ;
}

/* Inner planner thread: one setpoint of its chain. Idle samples (no record
 * in progress, nothing moves) only say "a standstill": one stands for a row. */
void llc_dp1_ai_tap(void *ctx, const struct ncp_adcai_tap *t)
{
    struct llc_dp1_ai *x = ctx;
    int idle = !t->start && x->phase == 0 && !t->moved;
    if (t->start)
        x->phase = x->ratio - 1;
    else if (x->phase > 0)
        x->phase--;
    if (idle && x->last_idle)
        return;
    x->last_idle = idle;
    struct sample s = { t->rough[x->axis], (int32_t)t->pos[x->axis],
                        (uint8_t)((t->start ? S_START : 0) | (t->moved ? S_MOVED : 0) |
                                  (idle ? S_IDLE : 0)) };
    while (ncp_spsc_push(&x->ring, &s) != 0 && !atomic_load(x->quit)) {
        struct timespec ts = { 0, 200000 };
        nanosleep(&ts, NULL);
    }
}

/* The stages on the samples that came, up to two moving ones queued. */
static void refill(struct llc *l, struct llc_dp1_ai *x)
{
    struct sample s;
    for (int n = 0; x->qn < 2 && n < PER_PERIOD && ncp_spsc_pop(&x->ring, &s) == 0; n++) {
        x->samples++;
        if (s.kind & S_IDLE) {
            x->pending_rest = 1;
            continue;
        }
        if (s.kind & S_START)
            llc_ai_load(l->ai, l->axis, s.sum);
        int64_t out = llc_ai_step(l->ai, l->axis);
        if (!x->have_off) {
            x->off = (int64_t)s.nm - out;
            x->have_off = 1;
        } else if ((int64_t)s.nm - out != x->off) {
            x->differ++;
        }
        if (!(s.kind & S_MOVED)) {
            x->pending_rest = 1;
            continue;
        }
        x->q[x->qn].nm = (int32_t)out;
        x->q[x->qn].after_rest = x->pending_rest;
        x->qn++;
        x->pending_rest = 0;
    }
}

void llc_dp1_ai_cycle(struct llc *l)
{
    struct llc_dp1_ai *x = l->dp1ai;
    if (!x->begun) {
        /* the inner run's sums start at 0 where the axis is: here */
        x->begun = 1;
        x->cur = llc_ai_begin(l->ai, 1, l->cmd);
    }
    refill(l, x);
}

int llc_dp1_ai_level(const struct llc *l, int inner_done)
{
    struct llc_dp1_ai *x = l->dp1ai;
    int n = (int)ncp_spsc_count(&x->ring) + x->qn;
    /* the HLC starts when every LLC's NCK is well ahead of it (or done) */
    if (!x->ready && (n >= READY || (inner_done && n > 0)))
        x->ready = 1;
    return x->ready ? (n > 32767 ? 32767 : n) : 0;
}

/* May the queue's first sample play at slot? */
static int may_play(const struct llc *l, const struct llc_dp1_ai *x, int64_t slot)
{
    if (!x->q[0].after_rest)
        return 1;
    int64_t due = llc_start_at(l, l->starts_done);
    return due && slot >= due;
}

double llc_dp1_ai_play(struct llc *l, int64_t slot)
{
    struct llc_dp1_ai *x = l->dp1ai;
    refill(l, x);
    if (x->qn == 0) {
        /* in motion with no sample: its NCK fell behind the HLC (a loaded
         * host) or stopped; the axis must not hold at speed */
        if (!x->pending_rest && l->cmd != l->cmd_prev) {
            x->behind++;
            l->end = LLC_END_PROGRAM;
            snprintf(l->fault, sizeof l->fault, "its NCK had no setpoint ready in motion "
                     "(%llu periods played)", (unsigned long long)x->played);
        }
        return ncp_dist_nm_to_mm((int32_t)x->cur);
    }
    if (!may_play(l, x, slot))
        return ncp_dist_nm_to_mm((int32_t)x->cur);
    if (x->q[0].after_rest) {
        int64_t late = (slot - llc_start_at(l, l->starts_done)) / l->period_ns;
        if (late > 0) {
            x->late_starts++;
            x->late_max = late > x->late_max ? late : x->late_max;
        }
        l->starts_done++;
    }
    x->cur = x->q[0].nm;
    memmove(&x->q[0], &x->q[1], sizeof x->q[0] * (size_t)(QUEUE - 1));
    x->qn--;
    x->played++;
    return ncp_dist_nm_to_mm((int32_t)x->cur);
}

/* Feed-forward: the next period's command, looked at only. */
double llc_dp1_ai_ahead(struct llc *l, int64_t slot)
{
    struct llc_dp1_ai *x = l->dp1ai;
    refill(l, x);
    if (x->qn > 0)
        return ncp_dist_nm_to_mm(may_play(l, x, slot) ? x->q[0].nm : (int32_t)x->cur);
    return x->pending_rest ? l->cmd : 2 * l->cmd - l->cmd_prev;
}

void llc_dp1_ai_report(const struct llc *l)
{
    const struct llc_dp1_ai *x = l->dp1ai;
    if (!x)
        return;
    fprintf(stderr, "cnc-axis %c: DP 1 (ADCAI): %llu periods played of %llu samples from its "
                    "NCK, %d starts (%llu after the HLC's, by %lld periods at most), periods its "
                    "stages and its NCK differ %llu\n",
            NCP_AXIS_LETTERS[l->axis], (unsigned long long)x->played,
            (unsigned long long)x->samples, (int)l->starts_done,
            (unsigned long long)x->late_starts, (long long)x->late_max,
            (unsigned long long)x->differ);
}
