/* ADCAI's DP2 and DP3 on the HLC. The ADCAI chain taps every setpoint it
 * puts in the stream, with the rough record it started if it started one;
 * the taps come in the stream's order, so the n-th tap is the stream's
 * sample n, the index the position loop reports its read position in
 * (ncp_backend.read_k). A record goes out stamped with the index of its
 * first sample once the loop has read to within LEAD samples of it: well
 * before any LLC needs it (a lost one is bridged from the next), and never
 * more than an LLC keeps.
 *
 * Each period the loop's advance goes into ai_scale_t's window, and the
 * message goes out every period while the advance is not 1 (a feed hold, a
 * stop, an override, a start) and for 8 periods after, otherwise every
 * 100 (an LLC looks at words at most 2 periods after a slot, and each
 * carries the last 4 periods' advances: one lost is in the next): each LLC plays its own samples at the loop's read position, a play
 * delay later, so every axis slows, stops and goes on along the program's
 * path as the HLC's command does. A period the loop slept through (a host
 * stall) read nothing: it is said as such (-1), and the LLCs, which went on
 * at the last advance heard, stand until the HLC's read is level again.
 *
 * The record before a standstill (a job's end, a dwell) has no later one
 * to bridge it from: lost, its axis would rest short of where the chain
 * rests, by that record's increment (488 nm at DP 3 when the last two of
 * ends.ngc were lost at 20 % loss, tests/dist adcai-ends-loss-dp3). It is said
 * again when no later record went out for a rough period and REPEAT_EVERY
 * servo periods more (in motion one goes every rough period), REPEATS times,
 * the same bytes: an LLC that has it takes the copy as stale.
 *
 * An abort (stop, E-stop) drops the stream. The ADCAI chain restarts with
 * its sums at 0 where the loop rests; the next job is numbered, its first
 * sample and where it starts go out in ai_scale_t, and each record names
 * its job, so an LLC resets its stages for it, whatever arrives first. */
#include "lcm_ai.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define LEAD 128          /* samples a record is sent ahead of the loop's read */
#define SENDS_MAX 16      /* records a period at most: a start's lead builds up over a few */
#define SCALE_AFTER 8     /* periods an advance of 1 is still said after one that was not */
#define SCALE_EVERY 100   /* periods between messages at the stream's own pace */
#define REPEAT_EVERY 10   /* periods without a record before the last goes again, */
#define REPEATS 6         /* so many times: 20 % loss leaves 1 in 78000 lost 7 times */

int lcm_ai_init(struct lcm_ai *x, int dp, const struct ncp_machine_cfg *cfg)
{
    memset(x, 0, sizeof *x);
    x->dp = dp;
    x->T = (int64_t)llround(cfg->servo_period * 1e9);
    x->ratio = ncp_machine_cfg_ipo_ratio(cfg);
    for (int j = 0; j < NCP_AXES; j++)
        if (cfg->axis_mask & NCP_AXIS_BIT(j))
            x->axis[x->n++] = j;
    for (int i = 0; i < LCM_AI_WINDOW; i++)
        x->adv[i] = 1.0;
    ncp_dist_ai_init();
    /* every sample the planner may have put in the stream beyond LEAD */
    return ncp_spsc_init(&x->tapped, sizeof(struct ncp_adcai_tap),
                         (size_t)cfg->setpoint_ring + (size_t)2 * LEAD + 64);
}

void lcm_ai_free(struct lcm_ai *x)
{
    ncp_spsc_destroy(&x->tapped);
}

void lcm_ai_push(struct lcm_ai *x, const struct ncp_adcai_tap *t)
{
    if (ncp_spsc_push(&x->tapped, t) != 0)
        x->overflow++;
}

static const char *record_channel(const struct lcm_ai *x)
{
    return x->dp == 2 ? NCP_DIST_CH_ROUGH : NCP_DIST_CH_ACCDEC_AI;
}

static void send_record(struct lcm_ai *x, struct ncp_msg *m, int64_t t, int64_t k,
                        const struct ncp_adcai_tap *e)
{
    struct ncp_dist_ai r = { x->seq++, NCP_DIST_HLC_ID, k, x->job, (int8_t)e->stop, (int8_t)x->n,
                             { 0 } };
    for (int i = 0; i < x->n; i++)
        r.sum_nm[i] = x->dp == 2 ? e->rough[x->axis[i]] : e->accdec[x->axis[i]];
    int n = ncp_dist_encode_ai(x->last, sizeof x->last, x->dp, &r);
    x->last_len = n > 0 ? n : 0;
    x->repeats_left = x->last_len ? REPEATS : 0;
    x->last_t = t;
    if (n > 0 && ncp_msg_publish(m, record_channel(x), x->last, (size_t)n) == 0) {
        x->sent++;
        x->bytes = n;
    }
}

/* The last record again, while the stream stands after it. */
static void repeat_record(struct lcm_ai *x, struct ncp_msg *m, int64_t t)
{
    if (x->repeats_left <= 0 || t - x->last_t < (x->ratio + REPEAT_EVERY) * x->T)
        return;
    x->repeats_left--;
    x->last_t = t;
    if (ncp_msg_publish(m, record_channel(x), x->last, (size_t)x->last_len) == 0)
        x->repeated++;
}

static void send_scale(struct lcm_ai *x, struct ncp_msg *m, int64_t t, const struct ncp_backend *b)
{
    ncp_ai_scale_t s;
    memset(&s, 0, sizeof s);
    s.seq = x->scale_seq++;
    s.sender = NCP_DIST_HLC_ID;
    s.t_ns = t;
    s.read_k = b->read_k;
    s.read_f = b->read_f;
    s.count = LCM_AI_WINDOW;
    memcpy(s.adv, x->adv, sizeof s.adv);
    s.job = x->job;
    s.job_k = x->job_k;
    s.job_t_ns = x->job_t;
    s.n = (int8_t)x->n;
    memcpy(s.base_nm, x->base_nm, sizeof s.base_nm);
    uint8_t buf[320];
    int n = ncp_ai_scale_t_encode(buf, 0, sizeof buf, &s);
    if (n > 0 && ncp_msg_publish(m, NCP_DIST_CH_AI_SCALE, buf, (size_t)n) == 0)
        x->scale_sent++;
    x->last_scale_t = t;
}

static void put_adv(struct lcm_ai *x, double adv)
{
    memmove(x->adv, x->adv + 1, (LCM_AI_WINDOW - 1) * sizeof x->adv[0]);
    x->adv[LCM_AI_WINDOW - 1] = adv;
    if (adv != 1.0)
        x->left = SCALE_AFTER;
}

static void base_at(struct lcm_ai *x, const double cmd[NCP_AXES])
{
    for (int i = 0; i < x->n; i++)
        x->base_nm[i] = (int32_t)nearbyint(cmd[x->axis[i]] * NCP_ADCAI_UNITS_PER_MM);
    x->based = 1;
}

void lcm_ai_cycle(struct lcm_ai *x, struct ncp_msg *m, int64_t t, int64_t skipped,
                  const struct ncp_backend *b, const double cmd[NCP_AXES])
{
    /* the first job's sums start where the loop first stood; an abort's
     * next job where it rests after it (the chain was reset there) */
    if (!x->based)
        base_at(x, cmd);
    if (b->discards != x->discards_seen) {
        x->discards_seen = b->discards;
        x->job++;
        x->job_k = b->drop_k;
        x->job_t = t;
        base_at(x, cmd);
        x->left = SCALE_AFTER;
        x->repeats_left = 0;   /* the aborted job's last record: void now */
    }
    for (int sends = 0; sends < SENDS_MAX;) {
        if (!x->have_front) {
            x->have_front = ncp_spsc_pop(&x->tapped, &x->front) == 0;
            if (!x->have_front)
                break;
            x->k_next++;
        }
        int64_t k = x->k_next - 1;
        if (k < x->job_k) {   /* the aborted job's: the loop dropped them */
            x->dropped += x->front.start;
            x->have_front = 0;
            continue;
        }
        if (k > b->read_k + LEAD)
            break;
        if (x->front.start) {
            send_record(x, m, t, k, &x->front);
            sends++;
        }
        x->have_front = 0;
    }
    repeat_record(x, m, t);
    for (int64_t i = 0; i < skipped && i < LCM_AI_WINDOW; i++)
        put_adv(x, -1.0);
    put_adv(x, b->adv);
    if (x->left > 0 || t - x->last_scale_t >= SCALE_EVERY * x->T) {
        x->left -= x->left > 0;
        send_scale(x, m, t, b);
    }
}

void lcm_ai_report(const struct lcm_ai *x)
{
    const char *ch = record_channel(x);
    fprintf(stderr, "lcm: DP %d (ADCAI): %llu %s messages of %d bytes (all %d axes; %d with the "
                    "LCM header), one a rough period; %llu read positions (ai_scale_t); %d "
                    "aborts, %llu records dropped by them; %llu lost to a full tap ring; %llu "
                    "said again before a standstill\n",
            x->dp, (unsigned long long)x->sent, x->dp == 2 ? "roughIPObuf" : "ACCDECbuf", x->bytes,
            x->n, x->bytes + 8 + (int)strlen(ch) + 1, (unsigned long long)x->scale_sent, x->job,
            (unsigned long long)x->dropped, (unsigned long long)x->overflow,
            (unsigned long long)x->repeated);
}
