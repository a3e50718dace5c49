/* The LLC at ADCAI's DP2 (roughIPObuf) and DP3 (ACCDECbuf): each rough
 * period's record, as it arrives, goes through this axis's stages below the
 * point (DP2: its ACC/DEC filters, then fine interpolation; DP3: fine
 * interpolation) into the setpoint buffer, one position per servo period
 * from the period the HLC stamped on it. From there the position loop plays
 * them as it plays DP5's, 3.5-4.5 periods behind the HLC (llc.c).
 *
 * The stages are src/adcai's, on integer nanometres, fed the same
 * increments as the HLC's central chain (the differences of the sums the
 * HLC sends), so the axis commands exactly what a central ADCAI run does.
 * A record lost is bridged as soon as a later one arrives: the missing
 * sums on the straight line to the later one's, so the stages get a
 * plausible increment and the later sum puts the axis back on the path, no
 * drift. With nothing later yet, the buffer holds and the loop counts it,
 * as at DP5 (MAX_LOST_PERIODS).
 *
 * A record stamped later than the one before it ended while the axis was
 * moving is the HLC's loop having skipped periods (a host stall): the
 * periods between hold where the axis was, since no later setpoint may be
 * guessed without leaving the other axes' path. That hold is a gap like a
 * held period at DP5, and the loop counts and traces it as one. */
#include "axis.h"

#include "ncpar/adcai.h"

#include <stdlib.h>
#include <string.h>

struct llc_ai {
    int dp;                         /* 1, 2 or 3 once begun, else 0 */
    int ratio;
    struct ncp_adcai_accdec *acc;   /* DP2 */
    struct ncp_adcai_fine *fine;
    int32_t next_seq;               /* the record expected next */
    int32_t in_sum;                 /* this axis's input summed so far, nm (wraps) */
    int64_t out_nm;                 /* the fine interpolator's output, the setpoint */
    int64_t last_t;                 /* the period of the last setpoint put (0: none) */
    int64_t moved_nm;               /* the last setpoint's step, nm */
    int64_t hold_from, hold_to;     /* periods held in motion, [from, to] (to < from: none) */
    int32_t put_seq;
    int started;
    uint32_t records, lost, stale;
};

struct llc_ai *llc_ai_new(const struct ncp_machine_cfg *cfg)
{
    int n[2], ratio = ncp_machine_cfg_ipo_ratio(cfg);
    if (ratio < 1 || ncp_adcai_windows(cfg, cfg->servo_period * ratio, n) != 0)
        return NULL;
    struct llc_ai *a = calloc(1, sizeof *a);
    if (!a)
        return NULL;
    a->ratio = ratio;
    a->hold_to = -1;
    a->acc = ncp_adcai_accdec_new(n[0], n[1]);
    a->fine = ncp_adcai_fine_new(ratio, cfg->profile == NCP_PROFILE_SCURVE ? 2 : 1);
    if (!a->acc || !a->fine) {
        llc_ai_free(a);
        return NULL;
    }
    ncp_dist_ai_init();
    return a;
}

void llc_ai_free(struct llc_ai *a)
{
    if (!a)
        return;
    ncp_adcai_accdec_free(a->acc);
    ncp_adcai_fine_free(a->fine);
    free(a);
}

static void put(struct llc *l, int64_t t)
{
    (void)ncp_dist_rx_put(&l->rx, l->ai->put_seq++, t, (int32_t)l->ai->out_nm);
    l->ai->last_t = t;
}

int llc_ai_held_in_motion(const struct llc_ai *a, int64_t slot)
{
    return slot >= a->hold_from && slot <= a->hold_to;
}

int64_t llc_ai_begin(struct llc_ai *a, int dp, double mm)
{
    a->started = 1;
    a->dp = dp;
    int32_t nm = 0;
    (void)ncp_dist_mm_to_nm(mm, &nm);
    a->out_nm = nm;
    return nm;
}

void llc_ai_load(struct llc_ai *a, int axis, int32_t sum)
{
    int32_t in[NCP_AXES] = { 0 }, out[NCP_AXES];
    in[axis] = (int32_t)((uint32_t)sum - (uint32_t)a->in_sum);
    a->in_sum = sum;
    /* below DP3 the filters are this LLC's too */
    if (a->dp != 3) {
        ncp_adcai_accdec_step(a->acc, in, out);
        in[axis] = out[axis];
    }
    ncp_adcai_fine_load(a->fine, in);
    a->records++;
}

int64_t llc_ai_step(struct llc_ai *a, int axis)
{
    int32_t out[NCP_AXES];
    ncp_adcai_fine_step(a->fine, out);
    a->out_nm += out[axis];
    return a->out_nm;
}

int llc_ai_at_rest(const struct llc_ai *a)
{
    return a->dp >= 2 && a->started && (a->dp == 3 || ncp_adcai_accdec_drained(a->acc)) &&
           ncp_adcai_fine_drained(a->fine);
}

int llc_ai_ratio(const struct llc_ai *a)
{
    return a->ratio;
}

/* One record through the stages: ratio setpoints from period t on. */
static void stages(struct llc *l, int64_t t, int32_t sum)
{
    struct llc_ai *a = l->ai;
    int64_t T = l->period_ns;
    llc_ai_load(a, l->axis, sum);
    /* the periods the HLC's stream stood still before this record: at rest
     * where it is (the buffer would bridge towards the record, a creep) */
    if (a->last_t) {
        int64_t from = a->last_t + T;
        if (from < t - (NCP_DIST_RX_SLOTS - 8) * T)
            from = t - (NCP_DIST_RX_SLOTS - 8) * T;
        if (from < t && a->moved_nm != 0) {
            /* a range that may not have been played yet joins this one */
            int recent = a->hold_to >= from - (a->ratio + NCP_DIST_PLAY_DELAY + 2) * T;
            a->hold_from = recent && a->hold_from < from ? a->hold_from : from;
            a->hold_to = t - T;
        }
        for (int64_t s = from; s < t; s += T)
            put(l, s);
    }
    for (int k = 0; k < a->ratio; k++) {
        int64_t before = a->out_nm;
        (void)llc_ai_step(a, l->axis);
        a->moved_nm = a->out_nm - before;
        put(l, t + k * T);
    }
}

void llc_ai_take(struct llc *l, int dp, const uint8_t *p, size_t len)
{
    struct llc_ai *a = l->ai;
    struct ncp_dist_ai r;
    if (!a || ncp_dist_decode_ai(p, len, dp, &r) != 0 || r.sender != NCP_DIST_HLC_ID ||
        r.n <= l->slot || r.t_ns <= 0 || (a->dp && a->dp != dp))
        return;
    /* the HLC's sums start at 0 where it found the axis: here */
    if (!a->started)
        llc_ai_begin(a, dp, l->cmd);
    int32_t gap = r.seq - a->next_seq;
    if (gap < 0) {
        a->stale++;   /* a duplicate, or one already bridged */
        l->rx.stale++;
        return;
    }
    int64_t span = (int64_t)a->ratio * l->period_ns;
    for (int32_t i = 1; i <= gap; i++) {
        int32_t d = (int32_t)((uint32_t)r.sum_nm[l->slot] - (uint32_t)a->in_sum);
        stages(l, r.t_ns - (gap + 1 - i) * span,
               (int32_t)((uint32_t)a->in_sum + (uint32_t)(int32_t)((int64_t)d / (gap + 2 - i))));
    }
    a->lost += (uint32_t)gap;
    l->rx.lost += (uint32_t)gap;
    stages(l, r.t_ns, r.sum_nm[l->slot]);
    a->next_seq = r.seq + 1;
}

void llc_ai_report(const struct llc *l)
{
    const struct llc_ai *a = l->ai;
    if (a && a->dp >= 2)
        fprintf(stderr, "cnc-axis %c: DP %d: records %u, lost and bridged %u, stale %u\n",
                NCP_AXIS_LETTERS[l->axis], a->dp, a->records, a->lost, a->stale);
}
