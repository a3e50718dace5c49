/* The LLC at ADCAI's DP2 and DP3 plays its samples (llc_adcai.c) as the
 * HLC's position loop read the same stream: ai_scale_t gives the loop's
 * advance in each period and, now and then, its read position itself. The
 * read position of a slot is the newest one said at or after it less the
 * advances between (exact while the message carrying it is within its
 * window), else the last slot's plus this slot's advance. At the stream's own
 * pace it lands on the samples themselves; between two it interpolates as
 * the loop does (a straight line, or with the S-curve the loop's quintic on
 * the samples' positions, velocities and accelerations, here taken from this
 * axis's neighbouring samples: the loop's own zero at a path standstill is
 * this axis's zero velocity, which differs only where this axis rests while
 * another moves, between samples). So a feed hold, an override, a stop or a
 * stall at the HLC moves this axis along the same path at the same
 * instants, a play delay later.
 *
 * An abort starts a job: from its period on the read position is the new
 * job's, which begins two samples before its first at its start. */
#include "axis.h"
#include "llc_ai.h"

#include <math.h>
#include <string.h>

struct readpos {
    int32_t job;
    int64_t k;
    double f;
};

void llc_ai_on_scale(struct llc *l, const uint8_t *p, size_t len)
{
    struct llc_ai *a = l->ai;
    ncp_ai_scale_t m;
    memset(&m, 0, sizeof m);
    if (!a || ncp_ai_scale_t_decode(p, 0, (int)len, &m) != (int)len ||
        m.sender != NCP_DIST_HLC_ID || m.count < 1 || m.count > 16 || m.n <= l->slot ||
        m.n > NCP_AXES || m.job < 0)
        return;
    /* lcm-gen decodes doubles through int64_t pointers: copied out as
     * bytes (see llc_scale.c) */
    double adv[16], f;
    memcpy(adv, m.adv, sizeof adv);
    memcpy(&f, &m.read_f, sizeof f);
    llc_scale_put(l, m.t_ns, adv, m.count);
    struct llc_ai_job *j = &a->jobs[(uint32_t)m.job % LLC_AI_JOBS];
    if (!j->known || j->job != m.job) {
        j->job = m.job;
        j->k = m.job_k;
        j->t = m.job_t_ns;
        j->base_nm = m.base_nm[l->slot];
        j->known = 1;
    }
    if (!a->have_anchor || m.t_ns > a->anchor_t) {
        a->have_anchor = 1;
        a->anchor_t = m.t_ns;
        a->anchor_k = m.read_k;
        a->anchor_f = f;
        a->anchor_job = m.job;
    }
    a->scales++;
    /* the HLC's grid, as at the other points */
    if (!l->t_start)
        l->t_start = m.t_ns;
}

static void normalise(struct readpos *r)
{
    while (r->f >= 1.0) {
        r->f -= 1.0;
        r->k++;
    }
    while (r->f < 0.0) {
        r->f += 1.0;
        r->k--;
    }
    /* the rounding of a sum of advances: a sample is landed on */
    if (r->f > 1.0 - 1e-9) {
        r->f = 0;
        r->k++;
    } else if (r->f < 1e-9) {
        r->f = 0;
    }
}

/* A period's advance: a period the HLC's loop slept through (-1) read
 * nothing. */
static double adv_at(const struct llc *l, int64_t u)
{
    return fmax(0.0, llc_scale_at(l, u));
}

static int before(const struct readpos *a, const struct readpos *b)
{
    return a->k < b->k || (a->k == b->k && a->f < b->f - 1e-9);
}

/* The HLC's read position for slot: 0, or -1 before anything said it.
 * Between the HLC's words it goes on at the last advance heard; where that
 * ran ahead of what the HLC then says (its loop stalled, or a hold's first
 * word was lost), the axis stands (*behind) until the HLC's read is there
 * again: never back along the path. */
static int read_at(const struct llc *l, int64_t slot, struct readpos *r, int *behind)
{
    const struct llc_ai *a = l->ai;
    int64_t T = l->period_ns, from;
    *behind = 0;
    struct readpos prev = { a->play_job, a->play_k, a->play_f };
    int have_prev = a->playing;
    if (have_prev) {
        *r = prev;
        from = a->play_slot;
    } else if (a->have_anchor) {
        *r = (struct readpos){ a->anchor_job, a->anchor_k, a->anchor_f };
        from = a->anchor_t;
    } else {
        return -1;
    }
    /* an abort at the HLC by then: the next job's stream */
    for (int i = 0; i < LLC_AI_JOBS; i++) {
        const struct llc_ai_job *j = &a->jobs[i];
        if (j->known && j->job > r->job && j->t > 0 && j->t <= slot) {
            *r = (struct readpos){ j->job, j->k - 2, 0.0 };
            from = j->t;
            have_prev = 0;
        }
    }
    int anchored = a->have_anchor && a->anchor_job == r->job;
    if (anchored && a->anchor_t >= slot && a->anchor_t - slot < 16 * T) {
        *r = (struct readpos){ a->anchor_job, a->anchor_k, a->anchor_f };
        for (int64_t u = a->anchor_t; u > slot; u -= T)
            r->f -= adv_at(l, u);
    } else {
        if (anchored && a->anchor_t > from && a->anchor_t < slot) {
            *r = (struct readpos){ a->anchor_job, a->anchor_k, a->anchor_f };
            from = a->anchor_t;
        }
        if (from > slot)
            return -1;   /* the first word heard is of a later period */
        /* a long silence of this loop (stalled) counts its periods, not more */
        if (slot - from > 4096 * T)
            from = slot - 4096 * T;
        for (int64_t u = from + T; u <= slot; u += T)
            r->f += adv_at(l, u);
    }
    normalise(r);
    if (have_prev && before(r, &prev)) {
        *r = prev;
        *behind = 1;
    }
    return 0;
}

/* This axis's sample k of job, nm: 0, or -1 when it is not here. */
static int sample(const struct llc_ai *a, int32_t job, int64_t k, double *nm)
{
    const struct llc_ai_job *j = llc_ai_job(a, job);
    if (!j)
        return -1;
    unsigned i = (unsigned)((uint64_t)k % LLC_AI_SAMPLES);
    if (k < j->k || job > a->job || !a->started) {
        /* before the job's first sample, or nothing of it made yet: where
         * it starts (the chain stood there) */
        *nm = j->base_nm;
        return 0;
    }
    if (a->smp_k[i] == k && a->smp_job[i] == job) {
        *nm = (double)j->base_nm + a->smp_nm[i];
        return 0;
    }
    /* past the last record, the stages drained: the chain stands there */
    if (job == a->job && k >= a->top_k && llc_ai_at_rest(a)) {
        *nm = (double)(j->base_nm + a->out_nm);
        return 0;
    }
    return -1;
}

static double vel(const double p[5], int i)
{
    return 0.5 * (p[i + 1] - p[i - 1]);
}

/* The loop's quintic Hermite between samples k and k+1 (p[2], p[3]), with
 * p[0..4] the samples k-2..k+2, in periods. */
static double quintic(const double p[5], double f)
{
    double va = vel(p, 2), vb = vel(p, 3);
    double vz = 0.5 * (p[2] - p[0]);
    double acc_a = va == 0 ? 0 : 6 * (p[1] - p[2]) + 2 * vz + 4 * va;
    double acc_b = vb == 0 ? 0 : 6 * (p[2] - p[3]) + 2 * va + 4 * vb;
    double f2 = f * f, f3 = f2 * f, f4 = f3 * f, f5 = f4 * f;
    double h0 = 1 - 10 * f3 + 15 * f4 - 6 * f5, h5 = 1 - h0;
    double h1 = f - 6 * f3 + 8 * f4 - 3 * f5, h4 = -4 * f3 + 7 * f4 - 3 * f5;
    double h2 = 0.5 * (f2 - 3 * f3 + 3 * f4 - f5), h3 = 0.5 * (f3 - 2 * f4 + f5);
    return h0 * p[2] + h5 * p[3] + h1 * va + h4 * vb + h2 * acc_a + h3 * acc_b;
}

/* The command at r, mm: 0, or -1 when a sample it needs is missing. */
static int command_at(const struct llc_ai *a, const struct readpos *r, double *mm)
{
    double p[5];
    if (sample(a, r->job, r->k, &p[2]) != 0)
        return -1;
    if (r->f == 0) {
        *mm = p[2] / NCP_ADCAI_UNITS_PER_MM;
        return 0;
    }
    if (sample(a, r->job, r->k + 1, &p[3]) != 0)
        return -1;
    if (!a->scurve) {
        *mm = (p[2] + r->f * (p[3] - p[2])) / NCP_ADCAI_UNITS_PER_MM;
        return 0;
    }
    if (sample(a, r->job, r->k - 2, &p[0]) != 0 || sample(a, r->job, r->k - 1, &p[1]) != 0 ||
        sample(a, r->job, r->k + 2, &p[4]) != 0)
        return -1;
    *mm = quintic(p, r->f) / NCP_ADCAI_UNITS_PER_MM;
    return 0;
}

int llc_ai_streaming(const struct llc *l)
{
    return l->ai && l->ai->dp >= 2 && (l->ai->have_anchor || l->ai->playing);
}

double llc_ai_play(struct llc *l, int64_t slot, int commit, int *missing)
{
    struct llc_ai *a = l->ai;
    struct readpos r;
    double mm;
    int behind;
    *missing = 0;
    if (read_at(l, slot, &r, &behind) != 0)
        return l->cmd;
    if (command_at(a, &r, &mm) != 0) {
        *missing = 1;
        mm = l->cmd;
    }
    if (commit) {
        double adv = llc_scale_at(l, slot);
        /* the HLC's loop slept through this period, or the axis waits for
         * its read to come back level: a hold, counted as one, no loss */
        a->stalled = a->playing && (behind || adv < 0);
        a->jobs_played += a->playing && r.job != a->play_job;
        a->playing = 1;
        a->play_job = r.job;
        a->play_k = r.k;
        a->play_f = r.f;
        a->play_slot = slot;
        a->play_adv = adv;
    }
    return mm;
}

int llc_ai_job_started(const struct llc *l, int64_t after, int64_t slot)
{
    for (int i = 0; i < LLC_AI_JOBS; i++) {
        const struct llc_ai_job *j = &l->ai->jobs[i];
        if (j->known && j->t > after && j->t <= slot)
            return 1;
    }
    return 0;
}

int llc_ai_stalled(const struct llc *l)
{
    return l->ai && l->ai->stalled;
}

int64_t llc_ai_level(const struct llc *l)
{
    const struct llc_ai *a = l->ai;
    return a->playing && a->job == a->play_job && a->top_k > a->play_k ? a->top_k - a->play_k : 0;
}
