/* The LLC at ADCAI's DP2 and DP3 plays its samples (llc_adcai.c) as the
 * HLC's position loop read the same stream: ai_scale_t gives the loop's
 * advance in each period and its read position. The read position of a
 * slot comes from the newest word of the HLC's stamped at most
 * LLC_AI_SEE periods after it: exactly, if that word is of the slot or
 * later (less the advances between), else that word's position gone on at
 * its last advance. Words stamped later are not looked at even when they
 * are here: whether one has come by the time a slot is played is a matter
 * of timing, and every LLC must play every slot alike, or their axes part
 * from the path by a sample (a host stall at the HLC showed it: one axis a
 * sample ahead of another for four periods). A word of the slot's period
 * leaves the HLC in that period, LLC_AI_SEE periods before the earliest
 * the slot is played (the play delay, 3.5-4.5 periods), so it is here.
 *
 * At the stream's own pace the read position lands on the samples
 * themselves; between two it interpolates as the loop does (a straight
 * line, or with the S-curve the loop's quintic on the samples' positions,
 * velocities and accelerations, here taken from this axis's neighbouring
 * samples: the loop's own zero at a path standstill is this axis's zero
 * velocity, which differs only where this axis rests while another moves,
 * between samples). So a feed hold, an override, a stop or a stall at the
 * HLC moves this axis along the same path at the same instants, a play
 * delay later. Where the read went on ahead of what the HLC then says (its
 * loop slept through periods), the axis stands until the HLC's read is
 * level again: never back along the path.
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
        m.sender != NCP_DIST_HLC_ID || m.count < 1 || m.count > 4 || m.n <= l->slot ||
        m.n > NCP_AXES || m.job < 0)
        return;
    /* lcm-gen decodes doubles through int64_t pointers: copied out as
     * bytes (see llc_scale.c) */
    double adv[4], f;
    memcpy(adv, m.adv, sizeof adv);
    memcpy(&f, &m.read_f, sizeof f);
    struct llc_ai_job *j = &a->jobs[(uint32_t)m.job % LLC_AI_JOBS];
    if (!j->known || j->job != m.job) {
        j->job = m.job;
        j->k = m.job_k;
        j->t = m.job_t_ns;
        j->base_nm = m.base_nm[l->slot];
        j->known = 1;
    }
    /* kept in place of the oldest (a duplicate in place of itself) */
    struct llc_ai_mark *k = &a->marks[0];
    for (int i = 0; i < LLC_AI_MARKS; i++) {
        if (a->marks[i].t == m.t_ns) {
            k = &a->marks[i];
            break;
        }
        if (a->marks[i].t < k->t)
            k = &a->marks[i];
    }
    k->t = m.t_ns;
    k->k = m.read_k;
    k->f = f;
    k->job = m.job;
    k->job_t = m.job_t_ns;
    for (int i = 0; i < 4; i++)
        k->adv[i] = i >= 4 - m.count ? adv[i - (4 - m.count)] : 1.0;
    a->have_marks = 1;
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

#define LLC_AI_SEE 2   /* periods after a slot whose words on it are looked at */

static int before(const struct readpos *a, const struct readpos *b)
{
    return a->k < b->k || (a->k == b->k && a->f < b->f - 1e-9);
}

/* The newest word stamped by deadline whose job had started by slot. */
static const struct llc_ai_mark *word_for(const struct llc_ai *a, int64_t slot, int64_t deadline)
{
    const struct llc_ai_mark *w = NULL;
    for (int i = 0; i < LLC_AI_MARKS; i++) {
        const struct llc_ai_mark *m = &a->marks[i];
        if (m->t > 0 && m->t <= deadline && m->job_t <= slot && (!w || m->t > w->t))
            w = m;
    }
    return w;
}

/* The HLC's read position for slot: 0, or -1 before anything said it.
 * *behind: the axis stands for the HLC, whose loop slept through the slot
 * (-1: it read nothing) or whose read is behind where this one went on. */
static int read_at(const struct llc *l, int64_t slot, struct readpos *r, int *behind)
{
    const struct llc_ai *a = l->ai;
    int64_t T = l->period_ns;
    *behind = 0;
    const struct llc_ai_mark *w = word_for(a, slot, slot + LLC_AI_SEE * T);
    if (!w)
        return -1;
    *r = (struct readpos){ w->job, w->k, w->f };
    if (w->t >= slot) {
        for (int64_t u = w->t; u > slot; u -= T)
            r->f -= fmax(0.0, w->adv[3 - (w->t - u) / T]);
        int64_t i = 3 - (w->t - slot) / T;
        *behind = i >= 0 && w->adv[i] < 0;
    } else {
        int64_t n = (slot - w->t) / T;
        r->f += (double)n * fmax(0.0, w->adv[3]);
        *behind = w->adv[3] < 0;
    }
    normalise(r);
    struct readpos prev = { a->play_job, a->play_k, a->play_f };
    if (a->playing && prev.job == r->job && before(r, &prev)) {
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
    /* past the last record, the stages rested: the chain stands there
     * (llc_ai_settle rests them where a bridge left them moving) */
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
    return l->ai && l->ai->dp >= 2 && l->ai->have_marks;
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
    /* the last sample the read needs (the quintic's) */
    llc_ai_settle(a, r.job, r.k + 2);
    if (command_at(a, &r, &mm) != 0) {
        *missing = 1;
        mm = l->cmd;
    }
    if (commit) {
        /* the axis waits for the HLC's read to come back level (its loop
         * slept through periods): a hold, counted as one, no loss */
        a->stalled = a->playing && behind;
        a->jobs_played += a->playing && r.job != a->play_job;
        a->playing = 1;
        a->play_job = r.job;
        a->play_k = r.k;
        a->play_f = r.f;
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
