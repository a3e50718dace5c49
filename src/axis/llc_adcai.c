/* The LLC at ADCAI's DP2 (roughIPObuf) and DP3 (ACCDECbuf): each rough
 * period's record, as it arrives, goes through this axis's stages below the
 * point (DP2: its ACC/DEC filters, then fine interpolation; DP3: fine
 * interpolation) into samples numbered by the HLC's stream index, the first
 * being the record's k. llc_ai_play.c plays them at the HLC's read position.
 *
 * The stages are src/adcai's, on integer nanometres, fed the same
 * increments as the HLC's central chain (the differences of the sums the
 * HLC sends), so the axis's samples are exactly the central chain's. Between
 * two records the chain may have stood (a dwell, a wait, the end of a job):
 * those samples are where the stages rest. A record lost is bridged as soon
 * as a later one arrives: the missing sums on the straight line to the later
 * one's, just before it, so the stages get a plausible increment and the
 * later sum puts the axis back on the path, no drift.
 *
 * The HLC sends no record only where its chain rests, and a chain at rest
 * stands on its input's sum. Without a loss these stages rest where the
 * HLC's do, after the same record; a bridge, though, may have put part of
 * a motion's last increment on records after the one that ended it (the
 * straight line to the next sum), so these stages may still move where the
 * HLC's records end. Run on, they would reach the sum after the HLC's
 * stream ended, and its read stops there, short of it: so past the last
 * record, while a bridged record is in their memory, they settle on the
 * sum the HLC said last, as its chain did (a step of what the bridge held
 * back, within MAX_VELOCITY). Stages the HLC's own (no bridge in their
 * memory) still moving past the last record mean a record missing: the
 * axis holds for it.
 *
 * An abort at the HLC (stop, E-stop) resets its chain with the sums at 0
 * where its loop rests, and numbers the next job: a record of a later job
 * resets these stages the same way. Where that job starts on the axis comes
 * with the HLC's read position (ai_scale_t); the samples are kept relative
 * to it, so a record may arrive before it. */
#include "axis.h"
#include "llc_ai.h"

#include <stdlib.h>
#include <string.h>

struct llc_ai *llc_ai_new(const struct ncp_machine_cfg *cfg)
{
    int n[2], ratio = ncp_machine_cfg_ipo_ratio(cfg);
    if (ratio < 1 || ncp_adcai_windows(cfg, cfg->servo_period * ratio, n) != 0)
        return NULL;
    struct llc_ai *a = calloc(1, sizeof *a);
    if (!a)
        return NULL;
    a->ratio = ratio;
    a->scurve = cfg->profile == NCP_PROFILE_SCURVE;
    a->acc = ncp_adcai_accdec_new(n[0], n[1]);
    a->fine = ncp_adcai_fine_new(ratio, a->scurve ? 2 : 1);
    /* in records: ACC/DEC's windows count rough periods; fine holds the
     * record it spreads and its averages, a rough period each */
    a->acc_memory = n[0] + n[1];
    a->fine_memory = (a->scurve ? 2 : 1) + 1;
    if (!a->acc || !a->fine) {
        llc_ai_free(a);
        return NULL;
    }
    for (int i = 0; i < LLC_AI_SAMPLES; i++)
        a->smp_k[i] = -1;
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

const struct llc_ai_job *llc_ai_job(const struct llc_ai *a, int32_t job)
{
    const struct llc_ai_job *j = &a->jobs[(uint32_t)job % LLC_AI_JOBS];
    return j->known && j->job == job ? j : NULL;
}

static void put(struct llc_ai *a, int64_t k)
{
    unsigned i = (unsigned)((uint64_t)k % LLC_AI_SAMPLES);
    a->smp_k[i] = k;
    a->smp_job[i] = a->job;
    a->smp_nm[i] = (int32_t)a->out_nm;
}

/* The chain rested: the stages at rest, their output on their input. */
static void settle(struct llc_ai *a)
{
    ncp_adcai_accdec_reset(a->acc);
    ncp_adcai_fine_reset(a->fine);
    a->out_nm += (int32_t)((uint32_t)a->in_sum - (uint32_t)(int32_t)a->out_nm);
    a->guess_left = 0;
}

/* One record through the stages: ratio samples from k on, and before them
 * the samples the chain stood at since the last one (it rested there).
 * guess: a bridged record's sum. */
static void stages(struct llc_ai *a, int axis, int64_t k, int32_t sum, int guess)
{
    if (a->top_k < k && !llc_ai_at_rest(a))
        settle(a);
    for (int64_t s = a->top_k > k - LLC_AI_SAMPLES ? a->top_k : k - LLC_AI_SAMPLES; s < k; s++)
        put(a, s);
    llc_ai_load(a, axis, sum);
    for (int i = 0; i < a->ratio; i++) {
        (void)llc_ai_step(a, axis);
        put(a, k + i);
    }
    a->top_k = k + a->ratio;
    if (guess)
        a->guess_left = (a->dp == 3 ? 0 : a->acc_memory) + a->fine_memory;
    else if (a->guess_left > 0)
        a->guess_left--;
}

void llc_ai_settle(struct llc_ai *a, int32_t job, int64_t k)
{
    if (a->started && job == a->job && k >= a->top_k && a->guess_left > 0 &&
        !llc_ai_at_rest(a))
        settle(a);
}

/* A job's first record (the first this LLC hears, or an abort's next job's):
 * the stages start again, at rest at 0. */
static void new_job(struct llc_ai *a, int32_t job, int64_t k)
{
    ncp_adcai_accdec_reset(a->acc);
    ncp_adcai_fine_reset(a->fine);
    a->job = job;
    a->in_sum = 0;
    a->out_nm = 0;
    a->guess_left = 0;
    const struct llc_ai_job *j = llc_ai_job(a, job);
    a->top_k = j && j->k <= k ? j->k : k;
}

void llc_ai_take(struct llc *l, int dp, const uint8_t *p, size_t len)
{
    struct llc_ai *a = l->ai;
    struct ncp_dist_ai r;
    if (!a || ncp_dist_decode_ai(p, len, dp, &r) != 0 || r.sender != NCP_DIST_HLC_ID ||
        r.n <= l->slot || r.k < 0 || (a->dp && a->dp != dp))
        return;
    if (!a->started) {
        a->started = 1;
        a->dp = dp;
        a->next_seq = r.seq;
        new_job(a, r.job, r.k);
    }
    int32_t gap = r.seq - a->next_seq;
    if (gap < 0 || r.job < a->job || (r.job == a->job && r.k < a->top_k)) {
        a->stale++;   /* a duplicate, one already bridged, or an aborted job's */
        l->rx.stale++;
        return;
    }
    a->next_seq = r.seq + 1;
    a->lost += (uint32_t)gap;
    l->rx.lost += (uint32_t)gap;
    if (r.job != a->job) {
        new_job(a, r.job, r.k);
        gap = 0;   /* what went missing before a job's start is no part of it */
    }
    /* the lost records lay just before this one, as far as the samples
     * since the last one leave room for them */
    int64_t room = (r.k - a->top_k) / a->ratio;
    if (gap > room)
        gap = (int32_t)room;
    for (int32_t i = 1; i <= gap; i++) {
        int32_t d = (int32_t)((uint32_t)r.sum_nm[l->slot] - (uint32_t)a->in_sum);
        stages(a, l->axis, r.k - (int64_t)(gap + 1 - i) * a->ratio,
               (int32_t)((uint32_t)a->in_sum + (uint32_t)(int32_t)((int64_t)d / (gap + 2 - i))),
               1);
    }
    stages(a, l->axis, r.k, r.sum_nm[l->slot], 0);
}

void llc_ai_report(const struct llc *l)
{
    const struct llc_ai *a = l->ai;
    if (a && a->dp >= 2)
        fprintf(stderr, "cnc-axis %c: DP %d: records %u, lost and bridged %u, stale %u; read "
                        "positions %u, jobs %u\n",
                NCP_AXIS_LETTERS[l->axis], a->dp, a->records, a->lost, a->stale, a->scales,
                a->jobs_played);
}
