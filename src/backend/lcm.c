/* The distributed NCK's high-level end (the distributed-NCK paper): the position loop's
 * setpoints go to one cnc-axis LLC per axis over LCM, and the actual positions
 * come back in their statuses. Implemented: ADCBI DP5 (fineIPObuf, a message
 * every servo period carrying every axis), the block-level DP4 (ACCDECbuf:
 * the records the planner starts, in bursts, lcm_tx.c; the LLCs interpolate
 * them), DP3 (LAbuf: the look-ahead's records; the LLCs profile and
 * interpolate them), DP2 (INTbuf: the planner's blocks and calls,
 * lcm_dp2.c; each LLC plans them itself) and DP1 (the program: each LLC runs
 * its own NCK on it, lcm_dp1.c); and ADCAI's DP4 (its fineIPObuf: the same
 * stream as ADCBI's DP5), DP3 and DP2 (a record every rough period,
 * lcm_ai.c; the LLCs run the stages below) and DP1 (as ADCBI's: each LLC
 * runs an ADCAI NCK on the program and its axis's stages on its records).
 *
 * start() (blocking): waits for every axis's advertisement and first status,
 * checks its limits and period against the INI, and from then on a thread
 * heartbeats until the loop takes over (live()).
 * cycle() (the real-time path): one setpoint message out, the statuses and
 * heartbeats in, all with MSG_DONTWAIT on the socket opened before (see
 * src/axis/llc.c for why no network thread): no allocation, no lock.
 * stop(): the heartbeat says done (or stop, after a fault) until every LLC
 * still alive reports a standstill.
 *
 * Every time the HLC sends (its grid, heartbeats) is on its clock: CLOCK_MONOTONIC,
 * or CLOCK_REALTIME under [LCM] CLOCK = ptp; lcm_clock.c keeps it and answers
 * the LLCs' probes of it, from which each maps its own clock onto it.
 *
 * The LLC reports the actual position of a period 1.5-2.5 periods back. The
 * loop gets that position carried forward by what the HLC commanded since
 * (fine setpoints), or its command less the LLC's own following error (where
 * the LLC computes its command), so cmd - act is the LLC's following error,
 * not the transport's delay. */
#include "lcm_ai.h"
#include "lcm_clock.h"
#include "lcm_tx.h"
#include "ncpar/backend.h"
#include "ncpar/config.h"
#include "ncpar/dist.h"
#include "ncpar/msg.h"

#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define HIST 64   /* setpoints remembered, periods: more than any status lags */
#define STOP_WAIT_NS 3000000000LL
#define SCALE_WINDOW 16   /* periods each time_scale_t carries */
#define SCALE_AFTER 32    /* periods an advance of 1 is still said after one that was not */
#define HOMING_AFTER 20   /* periods fine setpoints still go out after homing */

struct peer {
    int axis;
    int sub_advert, sub_status, sub_hb, sub_resend;
    int advertised, have_status;
    int done_heard;              /* its heartbeat says it heard the HLC's done */
    ncp_ax_status_t st;          /* the last status */
    int64_t last_status_ns, last_hb_ns;
    int32_t last_seq;
    int run_lost;                /* periods in a row without a status */
    /* lost (its heartbeat or its statuses gone): whatever it says next is
     * an LLC back, a process started again (its counts from 0) or one that
     * stalled, and is taken whatever its sequence number; returns counts
     * those for the serving thread (its axis is no longer homed) */
    int gone;
    atomic_uint returns;
    /* for the serving thread's status: state (-1 none yet), clock offset
     * and following error as the last status said */
    atomic_int pub_state, pub_ferr_nm;
    atomic_llong pub_clock_ns;
    uint64_t statuses, lost, late;
    /* its last error for the operator: err_kind (status_t's LLC_ERR_, 0
     * none) hands err_text over. At 0 the text is the taking side's (start,
     * the idle thread, the position loop, stop: one at a time), which
     * writes it, then the kind; from then on it is the serving thread's,
     * which reads it and on a reset may give it back (0). No lock on the
     * real-time path and no torn text; the error that stopped the LLC
     * stands, not what followed from it (its silence once it left). */
    atomic_int err_kind;
    unsigned err_count;
    char err_text[NCP_LLC_ERROR_MAX];
};

struct lcm_be {
    const struct ncp_machine_cfg *cfg;
    struct ncp_msg *msg;
    int n;
    struct peer p[NCP_AXES];
    int64_t T, t0, last_t, hb_period, hb_timeout, last_hb;
    int32_t seq, fine_seq;   /* heartbeats', setpoints' (the LLCs count gaps in these) */
    int cycles;
    int64_t hist_t[HIST];
    double hist_cmd[HIST][NCP_AXES];
    char fault[200];
    int faulted;
    char fault_axis;
    pthread_t idle;
    atomic_int idle_run;
    atomic_int retake;       /* a reset asks: the LLCs all back, the fault is over */
    int idle_started;
    uint64_t sent_fine;
    int fine_bytes;
    struct lcm_tx *tx;       /* ADCBI's block-level points */
    struct lcm_dp2 dp2;
    struct lcm_dp1 *dp1;     /* DP1: the program the LLCs run */
    struct lcm_ai *ai;       /* ADCAI's DP2, DP3 */
    int rest;                /* the path stood still last period */
    int hold;                /* drives off (serve's E-stop, a fault): HOLD every period */
    int release;             /* periods left that say RUN after a hold (one may be lost) */
    int homing_left;         /* block-level and ADCAI points: periods of fine setpoints left */
    double prev_cmd[NCP_AXES];
    struct lcm_clock clk;    /* answers the LLCs' clock probes; the HLC's clock */
    uint64_t ends_sent;      /* heartbeats saying done (or stop) at the end */
    int64_t last_cycle_ns, end_gap_ns;   /* the loop's last period; from it to the end said */
    /* block-level points: the loop's stream advance of the last SCALE_WINDOW
     * periods (oldest first) and the periods still to say it, the abort
     * whose records are void (time_scale_t) */
    double scale_adv[SCALE_WINDOW];
    int scale_left;
    int32_t scale_seq;
    uint32_t discards_seen;
    int32_t void_below;
    int64_t void_t;
    int32_t void_off_nm[NCP_AXES];   /* homing's offset at that drop */
    uint64_t scale_sent;
};

/* Every time the HLC sends is on this clock ([LCM] CLOCK), its grid too. */
static int64_t hlc_now(const struct lcm_be *s)
{
    return lcm_clock_now(&s->clk);
}

static void heartbeat(struct lcm_be *s, int command, char axis)
{
    /* done names the loop's last period: an LLC that plays further behind
     * (block-level points) runs its own command up to there */
    int64_t t = command == NCP_HEARTBEAT_T_COMMAND_DONE && s->cycles ? s->last_t : hlc_now(s);
    ncp_heartbeat_t h = { s->seq++, NCP_DIST_HLC_ID, t, (int8_t)s->cfg->lcm.dp,
                          (int8_t)command, (uint8_t)axis };
    uint8_t buf[64];
    int n = ncp_heartbeat_t_encode(buf, 0, sizeof buf, &h);
    if (n > 0)
        (void)ncp_msg_publish(s->msg, NCP_DIST_CH_HLC_HEARTBEAT, buf, (size_t)n);
}

_Static_assert(NCP_STATUS_T_LLC_ERR_HLC_STOP == NCP_AX_STATUS_T_END_HLC_STOP &&
               NCP_STATUS_T_LLC_ERR_DRIVE == NCP_AX_STATUS_T_END_DRIVE &&
               NCP_STATUS_T_LLC_ERR_UNHEARD == NCP_AX_STATUS_T_END_DRIVE + 1,
               "an LLC's error is its end, where it said one");

static void keep_error(struct peer *p, int kind, const char *text)
{
    if (atomic_load_explicit(&p->err_kind, memory_order_acquire) != 0)
        return;
    snprintf(p->err_text, sizeof p->err_text, "%s", text);
    p->err_count++;
    atomic_store_explicit(&p->err_kind, kind, memory_order_release);
}

/* What an LLC's status says of its end: an error but the program's end.
 * Every status of every LLC comes here: nothing is copied unless it is an
 * error to keep (an LLC that stopped says so in each status until it goes). */
static void status_error(struct peer *p, const ncp_ax_status_t *st)
{
    int kind = st->end > NCP_AX_STATUS_T_END_DONE && st->end <= NCP_AX_STATUS_T_END_DRIVE
                   ? st->end
               : st->end == NCP_AX_STATUS_T_END_NONE && (st->state == NCP_AX_STATUS_T_STOPPING ||
                                                        st->state == NCP_AX_STATUS_T_FAULT)
                   ? NCP_STATUS_T_LLC_ERR_OTHER
                   : 0;
    if (!kind || atomic_load_explicit(&p->err_kind, memory_order_relaxed) != 0)
        return;
    char text[sizeof st->fault + 1];
    snprintf(text, sizeof text, "%.*s", (int)sizeof st->fault, (const char *)st->fault);
    keep_error(p, kind, text[0] ? text : "stopped on its own without saying why (see its output)");
}

static void on_status(struct peer *p, const uint8_t *b, size_t len, int64_t now)
{
    ncp_ax_status_t st;
    memset(&st, 0, sizeof st);
    if (ncp_ax_status_t_decode(b, 0, (int)len, &st) != (int)len || st.sender != p->axis + 1)
        return;
    if (p->have_status && st.seq - p->last_seq <= 0 && !p->gone) {
        p->late++;   /* a duplicate or an older one: the newer stands */
        return;
    }
    if (p->gone) {
        p->gone = 0;
        p->run_lost = 0;
        atomic_fetch_add_explicit(&p->returns, 1, memory_order_relaxed);
    }
    p->st = st;
    status_error(p, &st);
    atomic_store_explicit(&p->pub_state, st.state, memory_order_relaxed);
    atomic_store_explicit(&p->pub_ferr_nm, st.ferr_nm, memory_order_relaxed);
    atomic_store_explicit(&p->pub_clock_ns, st.clock_offset_ns, memory_order_relaxed);
    p->last_seq = st.seq;
    p->have_status = 1;
    p->last_status_ns = now;
    p->last_hb_ns = now;   /* a status is as good a sign of life */
    p->statuses++;
}

/* Everything waiting on the socket (bounded by the transport). */
static void take(struct lcm_be *s, int64_t now)
{
    int sub;
    const uint8_t *b;
    size_t len;
    while (ncp_msg_take(s->msg, now, &sub, &b, &len) == 1) {
        for (int i = 0; i < s->n; i++) {
            struct peer *p = &s->p[i];
            if (sub == p->sub_status) {
                on_status(p, b, len, now);
            } else if (sub == p->sub_hb) {
                ncp_heartbeat_t h;
                memset(&h, 0, sizeof h);
                if (ncp_heartbeat_t_decode(b, 0, (int)len, &h) == (int)len &&
                    h.sender == p->axis + 1 && h.command == NCP_HEARTBEAT_T_COMMAND_DONE)
                    p->done_heard = 1;
                p->last_hb_ns = now;
            } else if (sub == p->sub_resend && s->tx) {
                lcm_tx_resend(s->tx, s->msg, b, len);
            } else if (sub == p->sub_advert) {
                ncp_ax_advert_t a;
                memset(&a, 0, sizeof a);
                if (ncp_ax_advert_t_decode(b, 0, (int)len, &a) != (int)len ||
                    a.axis != (uint8_t)NCP_AXIS_LETTERS[p->axis])
                    continue;
                const struct ncp_axis_cfg *c = &s->cfg->axis[p->axis];
                int ai_llc = (a.stage_mask & NCP_AX_ADVERT_T_STAGE_ACCDEC) != 0;
                if (!p->advertised && !s->faulted && s->dp1 &&
                    ai_llc != (s->cfg->nck == NCP_NCK_ADCAI)) {
                    snprintf(s->fault, sizeof s->fault,
                             "axis %c's LLC runs NCK = %s and this HLC %s: at DP 1 each LLC "
                             "runs the NCK its INI's [PLANNER] NCK names on the program, so "
                             "both INIs must name the same", a.axis, ai_llc ? "adcai" : "adcbi",
                             ai_llc ? "adcbi" : "adcai");
                    s->faulted = 1;
                } else if (!p->advertised && !s->faulted &&
                    (a.period_ns != s->T || a.max_vel < c->max_vel || a.max_acc < c->max_acc ||
                     a.min_limit > c->min_limit || a.max_limit < c->max_limit ||
                     !(a.dp_mask & (1 << s->cfg->lcm.dp)))) {
                    snprintf(s->fault, sizeof s->fault,
                             "axis %c's LLC does not fit the INI: period %lld ns, travel "
                             "%.3f..%.3f mm, MAX_VELOCITY %.3f, MAX_ACCELERATION %.3f, DPs 0x%x "
                             "(the INI: %lld ns, %.3f..%.3f, %.3f, %.3f, DP %d)",
                             a.axis, (long long)a.period_ns, a.min_limit, a.max_limit, a.max_vel,
                             a.max_acc, (unsigned)a.dp_mask, (long long)s->T, c->min_limit,
                             c->max_limit, c->max_vel, c->max_acc, s->cfg->lcm.dp);
                    s->faulted = 1;
                }
                p->advertised = 1;
                p->last_hb_ns = now;
            }
        }
    }
}

static void *idle_main(void *arg)
{
    struct lcm_be *s = arg;
    while (atomic_load(&s->idle_run)) {
        int64_t now = hlc_now(s);
        take(s, now);
        if (now - s->last_hb >= s->hb_period) {
            s->last_hb = now;
            heartbeat(s, NCP_HEARTBEAT_T_COMMAND_RUN, 0);
        }
        struct timespec ts = { 0, 1000000 };
        nanosleep(&ts, NULL);
    }
    return NULL;
}

static void fail(struct lcm_be *s, const struct peer *p, const char *why)
{
    if (s->faulted)
        return;
    s->faulted = 1;
    s->fault_axis = NCP_AXIS_LETTERS[p->axis];
    snprintf(s->fault, sizeof s->fault, "axis %c's LLC: %s", s->fault_axis, why);
}

/* "X Z": the letters of the axes whose LLC is not ready, for a message. */
static void axes_not(const struct lcm_be *s, int (*ready)(const struct peer *), char *out,
                     size_t len)
{
    size_t k = 0;
    for (int i = 0; i < s->n && k + 2 < len; i++)
        if (!ready(&s->p[i])) {
            if (k)
                out[k++] = ' ';
            out[k++] = NCP_AXIS_LETTERS[s->p[i].axis];
        }
    out[k] = 0;
}

static int has_record(const struct peer *p)
{
    return p->st.buffer_level > 0;
}

static int answered(const struct peer *p)
{
    return p->advertised && p->have_status;
}

/* DP1: the LLCs' NCKs start on the program message; this one waits (up to
 * AXIS_WAIT_MS) until each has its first record, as its own planner would
 * have before moving. Starting without one would only stop the run a few
 * periods later at that LLC ("record 0 missing"): nothing moves instead,
 * and the message names the axes and the wait. */
static int dp1_wait(struct lcm_be *s, int64_t deadline)
{
    int64_t last = 0;
    for (;;) {
        int64_t now = hlc_now(s);
        if (now - last >= 100000000LL) {   /* again for one that lost it */
            last = now;
            lcm_dp1_send(s->dp1, s->msg);
        }
        take(s, now);
        int ready = 0;
        for (int i = 0; i < s->n; i++) {
            struct peer *p = &s->p[i];
            if (p->st.state == NCP_AX_STATUS_T_FAULT) {
                s->fault_axis = NCP_AXIS_LETTERS[p->axis];
                snprintf(s->fault, sizeof s->fault, "axis %c's LLC: DP 1: %.*s",
                         NCP_AXIS_LETTERS[p->axis], (int)sizeof p->st.fault,
                         (const char *)p->st.fault);
                s->faulted = 1;
                return -1;
            }
            if (now - p->last_hb_ns > s->hb_timeout) {
                char why[120];
                snprintf(why, sizeof why, "heartbeat lost (silent for %lld ms) while its NCK "
                         "started on the program", (long long)((now - p->last_hb_ns) / 1000000));
                keep_error(p, NCP_STATUS_T_LLC_ERR_UNHEARD, why);
                fail(s, p, why);
                return -1;
            }
            ready += has_record(p);
        }
        if (ready == s->n)
            return 0;
        if (now > deadline) {
            char missing[2 * NCP_AXES];
            axes_not(s, has_record, missing, sizeof missing);
            snprintf(s->fault, sizeof s->fault,
                     "DP 1: the NCK of axis %s's LLC had no record within %d ms ([LCM] "
                     "AXIS_WAIT_MS): a busy host, or a program that computes long before "
                     "its first move",
                     missing, s->cfg->lcm.axis_wait_ms);
            s->faulted = 1;
            return -1;
        }
        if (now - s->last_hb >= s->hb_period) {
            s->last_hb = now;
            heartbeat(s, NCP_HEARTBEAT_T_COMMAND_RUN, 0);
        }
        struct timespec ts = { 0, 1000000 };
        nanosleep(&ts, NULL);
    }
}

static int lcm_start(struct ncp_backend *b, double pos[NCP_AXES])
{
    struct lcm_be *s = b->impl;
    int64_t start = hlc_now(s), deadline = start + s->cfg->lcm.axis_wait_ms * 1000000LL;
    for (;;) {
        int64_t now = hlc_now(s);
        take(s, now);
        if (s->faulted)
            return -1;
        if (now - s->last_hb >= s->hb_period) {
            s->last_hb = now;
            heartbeat(s, NCP_HEARTBEAT_T_COMMAND_RUN, 0);
        }
        int ready = 0;
        for (int i = 0; i < s->n; i++) {
            const struct peer *p = &s->p[i];
            if (p->have_status && p->st.state == NCP_AX_STATUS_T_FAULT && p->st.fault[0]) {
                /* one that cannot start says why (its clock, ...); the
                 * others hear which axis stopped them */
                s->fault_axis = NCP_AXIS_LETTERS[p->axis];
                snprintf(s->fault, sizeof s->fault, "axis %c's LLC: %.*s", s->fault_axis,
                         (int)sizeof p->st.fault, (const char *)p->st.fault);
                s->faulted = 1;
                return -1;
            }
            ready += answered(p);
        }
        if (ready == s->n)
            break;
        if (now > deadline) {
            char missing[2 * NCP_AXES];
            axes_not(s, answered, missing, sizeof missing);
            snprintf(s->fault, sizeof s->fault,
                     "no LLC answered for axis %s within %d ms ([LCM] AXIS_WAIT_MS): start "
                     "`cnc-axis --axis L --config INI` for each, on the same LCM URL",
                     missing, s->cfg->lcm.axis_wait_ms);
            s->faulted = 1;
            return -1;
        }
        struct timespec ts = { 0, 1000000 };
        nanosleep(&ts, NULL);
    }
    for (int j = 0; j < NCP_AXES; j++)
        pos[j] = 0;
    for (int i = 0; i < s->n; i++)
        pos[s->p[i].axis] = ncp_dist_nm_to_mm(s->p[i].st.act_nm);
    if (s->dp1 && dp1_wait(s, hlc_now(s) + s->cfg->lcm.axis_wait_ms * 1000000LL) != 0)
        return -1;
    atomic_store(&s->idle_run, 1);
    s->idle_started = pthread_create(&s->idle, NULL, idle_main, s) == 0;
    return 0;
}

static void idle_stop(struct lcm_be *s)
{
    if (!s->idle_started)
        return;
    atomic_store(&s->idle_run, 0);
    pthread_join(s->idle, NULL);
    s->idle_started = 0;
}

static void lcm_live(struct ncp_backend *b)
{
    idle_stop(b->impl);
}

/* The HLC no longer hears p: its error (unless it said one first), the
 * fault, and whatever it says next taken as an LLC back (on_status). */
static void lose(struct lcm_be *s, struct peer *p, const char *why)
{
    keep_error(p, NCP_STATUS_T_LLC_ERR_UNHEARD, why);
    fail(s, p, why);
    p->gone = 1;
}

static void check_peer(struct lcm_be *s, struct peer *p, uint64_t before, int64_t now)
{
    char why[120];
    if (p->statuses == before) {
        p->lost++;
        /* counted from the LLC's first period played (it starts its loop
         * on the first setpoints; until then its heartbeat says it lives) */
        if (p->st.t_ns > 0 && ++p->run_lost > s->cfg->lcm.max_lost_periods) {
            snprintf(why, sizeof why, "no status for %d periods ([LCM] MAX_LOST_PERIODS %d)",
                     p->run_lost, s->cfg->lcm.max_lost_periods);
            lose(s, p, why);
        }
    } else {
        p->run_lost = 0;
    }
    if (now - p->last_hb_ns > s->hb_timeout) {
        snprintf(why, sizeof why, "heartbeat lost (silent for %lld ms)",
                 (long long)((now - p->last_hb_ns) / 1000000));
        lose(s, p, why);
        /* its last status said running: the operator must not read that
         * of an LLC that is gone (a status of its, should it come back,
         * stands again) */
        atomic_store_explicit(&p->pub_state, NCP_AX_STATUS_T_FAULT, memory_order_relaxed);
    } else if (p->st.state == NCP_AX_STATUS_T_STOPPING || p->st.state == NCP_AX_STATUS_T_STOPPED ||
               p->st.state == NCP_AX_STATUS_T_FAULT) {
        if (p->st.fault[0]) {
            snprintf(why, sizeof why, "stopped on its own: %.*s", (int)sizeof p->st.fault,
                     (const char *)p->st.fault);
            fail(s, p, why);
        } else {
            fail(s, p, "stopped on its own (lost setpoints, following error or a signal: see "
                       "its output)");
        }
    }
}

static void send_fine(struct lcm_be *s, int64_t t, const double cmd[NCP_AXES])
{
    struct ncp_dist_fine f = { s->fine_seq++, NCP_DIST_HLC_ID, t, (int8_t)s->n, { 0 } };
    int bad = 0;
    for (int i = 0; i < s->n; i++)
        bad |= ncp_dist_mm_to_nm(cmd[s->p[i].axis], &f.pos_nm[i]);
    uint8_t buf[128];
    int n = bad ? -1 : ncp_dist_encode_fine(buf, sizeof buf, &f);
    if (n > 0 && ncp_msg_publish(s->msg, NCP_DIST_CH_FINE, buf, (size_t)n) == 0) {
        s->sent_fine++;
        s->fine_bytes = n;
    }
}

static void scale_put(struct lcm_be *s, double adv)
{
    memmove(s->scale_adv, s->scale_adv + 1, (SCALE_WINDOW - 1) * sizeof s->scale_adv[0]);
    s->scale_adv[SCALE_WINDOW - 1] = adv;
    if (adv != 1.0)
        s->scale_left = SCALE_AFTER;
}

/* Block-level points: the LLCs' interpolators advance as this loop read its
 * stream (ncp_backend.adv), period by period (llc_scale.c). A period the
 * loop skipped (it woke late) goes on at the advance of the period after
 * it: standing still for it would jolt every axis in motion (they then run
 * a period ahead of this stream until a standstill's mark, as before the
 * scaling), and in a hold (0) they must not move. An abort (the loop dropped its stream) makes
 * every record numbered so far void: the planner was parked before, so
 * every record of the aborted job is among them. At DP2 the records are the
 * planner's calls, which each LLC's planner must replay all of to stay the
 * HLC's (the aborted job's included, and the DROP mark and RESET the
 * planner thread journals once parked, which a drop here could lose):
 * there void_below counts the aborts, and each LLC drops what its own
 * planner made before that many DROP marks (dp_block.c). */
static void scale_cycle(struct lcm_be *s, const struct ncp_backend *b, int64_t t, int64_t skipped)
{
    for (int64_t k = 0; k < skipped && k < SCALE_WINDOW; k++)
        scale_put(s, b->adv);
    scale_put(s, b->adv);
    if (b->discards != s->discards_seen) {
        s->discards_seen = b->discards;
        s->void_below = s->tx->kind == &lcm_kind_int ? s->void_below + 1 : lcm_tx_void(s->tx);
        s->void_t = t;
        s->scale_left = SCALE_AFTER;
        /* the records after this drop start where the plan stands, which
         * homing may have moved off the axes' counts; the offset changes
         * only in homing, which ends in a drop (control.c) */
        for (int j = 0; j < NCP_AXES; j++)
            if (ncp_dist_mm_to_nm(b->home_off[j], &s->void_off_nm[j]) != 0)
                s->void_off_nm[j] = 0;
        /* its fine setpoints stop here: the LLCs' stream starts again */
        if (!b->homing)
            s->homing_left = 0;
    }
    if (s->scale_left <= 0)
        return;
    s->scale_left--;
    ncp_time_scale_t m;
    memset(&m, 0, sizeof m);
    m.seq = s->scale_seq++;
    m.sender = NCP_DIST_HLC_ID;
    m.t_ns = t;
    m.count = SCALE_WINDOW;
    memcpy(m.adv, s->scale_adv, sizeof m.adv);
    m.void_below = s->void_below;
    m.void_t_ns = s->void_t;
    memcpy(m.void_off_nm, s->void_off_nm, sizeof m.void_off_nm);
    uint8_t buf[256];
    int n = ncp_time_scale_t_encode(buf, 0, sizeof buf, &m);
    if (n > 0 && ncp_msg_publish(s->msg, NCP_DIST_CH_SCALE, buf, (size_t)n) == 0)
        s->scale_sent++;
}

static void tap(void *impl, const struct ncp_la *la, const struct ncp_accdec *rec)
{
    struct lcm_tx *x = ((struct lcm_be *)impl)->tx;
    lcm_tx_push(x, x->kind == &lcm_kind_la ? (const void *)la : (const void *)rec);
}

static void journal(void *impl, enum ncp_plan_call c, const struct ncp_seg *seg,
                    const double *pos)
{
    struct lcm_be *s = impl;
    lcm_dp2_journal(s->tx, &s->dp2, c, seg, pos);
}

/* A reset after an LLC was lost: the fault is over once every LLC is heard
 * again and says it waits or runs (one started again, or the others held).
 * At DP5 an LLC plays whatever setpoints come, so one started again joins
 * at once: the reset's rest at the actual position (its status's) makes its
 * first setpoints where its axis stands, and the hold until then keeps it
 * there. Where the LLCs run records of a job (block-level points, ADCAI,
 * DP1), one started again lacks that job's past: it is not taken, and the
 * fault says so. */
static void take_back(struct lcm_be *s, int64_t now)
{
    for (int i = 0; i < s->n; i++) {
        const struct peer *p = &s->p[i];
        if (p->gone || !p->have_status || now - p->last_hb_ns > s->hb_timeout ||
            (p->st.state != NCP_AX_STATUS_T_WAITING && p->st.state != NCP_AX_STATUS_T_RUNNING))
            return;
    }
    if (s->tx || s->ai || s->dp1) {
        snprintf(s->fault, sizeof s->fault,
                 "every LLC is heard again, but at DP %d of %s an LLC that started again "
                 "cannot join: its records of the job are gone; restart serve",
                 s->cfg->lcm.dp, s->cfg->nck == NCP_NCK_ADCAI ? "ADCAI" : "ADCBI");
        return;
    }
    s->faulted = 0;
    s->fault[0] = 0;
    s->fault_axis = 0;
    for (int i = 0; i < s->n; i++)
        s->p[i].run_lost = 0;
}

static int lcm_cycle(struct ncp_backend *b, const double cmd[NCP_AXES], const double next[NCP_AXES],
                     double act[NCP_AXES])
{
    (void)next;
    struct lcm_be *s = b->impl;
    int64_t now = hlc_now(s);
    if (atomic_exchange_explicit(&s->retake, 0, memory_order_acquire) && s->faulted)
        take_back(s, now);
    if (s->cycles == 0)
        s->t0 = now;
    /* this period on the grid the LLCs play by: the loop's absolute schedule
     * wakes it up to a latency after the period's start (a later wake-up
     * skips periods), so rounding down, with a tenth of a period for the
     * clock read, names its period */
    int64_t t = s->t0 + (now - s->t0 + s->T / 10) / s->T * s->T;
    /* a wake-up a little late must not name the next period twice: the
     * grid only jumps for periods the loop skipped */
    if (s->cycles > 0 && t <= s->last_t + s->T)
        t = s->last_t + s->T;
    int64_t skipped = s->cycles > 0 ? (t - s->last_t) / s->T - 1 : 0;
    s->last_t = t;
    unsigned h = (unsigned)((uint64_t)(t / s->T) % HIST);
    s->hist_t[h] = t;
    memcpy(s->hist_cmd[h], cmd, sizeof s->hist_cmd[h]);
    if (s->tx) {
        /* the LLCs' interpolators leave each standstill when this does. A
         * standstill begins only in a period that read the stream at its
         * own pace: there this command is the stream's samples, as the
         * LLCs' is; in a scaled period (a hold, a landing, an underrun)
         * the two round differently near 0, and a standstill one side
         * counted and the other not would shift every mark after it */
        int moving = 0;
        for (int j = 0; j < NCP_AXES && s->cycles > 0 && !b->homing; j++)
            moving |= cmd[j] != s->prev_cmd[j];
        /* after an abort the next job starts from a standstill, as the
         * LLCs' interpolators do once they dropped its records (the
         * command's jump onto the actual position is no start) */
        if (b->discards != s->discards_seen) {
            s->rest = 1;
            moving = 0;
        }
        int start = moving && s->rest;
        if (b->adv == 1.0 || moving || s->cycles == 0)
            s->rest = !moving;
        memcpy(s->prev_cmd, cmd, sizeof s->prev_cmd);
        scale_cycle(s, b, t, skipped);
        int32_t taken = INT32_MAX;
        for (int i = 0; i < s->n; i++)
            taken = s->p[i].st.rec_next < taken ? s->p[i].st.rec_next : taken;
        int32_t steps = atomic_load_explicit(&s->dp2.steps, memory_order_acquire);
        lcm_tx_cycle(s->tx, s->msg, t, s->T, start, taken, s->rest);
        if (start)   /* the LLCs' stream starts again here (no abort after homing) */
            s->homing_left = 0;
        if (s->tx->kind == &lcm_kind_int)
            lcm_dp2_mark(s->tx, &s->dp2, s->msg, steps, t, s->T);
        if (s->dp1 && s->cycles % 20 == 0)   /* an LLC that lost the first one */
            lcm_dp1_send(s->dp1, s->msg);
    } else if (s->ai) {
        lcm_ai_cycle(s->ai, s->msg, t, skipped, b, cmd);
    } else {
        send_fine(s, t, cmd);
    }
    /* homing is the loop's own motion, in no record: where the LLCs make
     * their own setpoints (ADCAI's DP3 and DP2, ADCBI's block-level points)
     * they play these meanwhile, and for a while after (the last ones may
     * be lost); the NCK then restarts the planner where homing left the
     * axes (an abort of nothing), which starts their stream again */
    if (s->ai || (s->tx && !s->dp1)) {
        if (b->homing)
            s->homing_left = HOMING_AFTER;
        if (s->homing_left > 0) {
            s->homing_left -= !b->homing;
            send_fine(s, t, cmd);
        }
    }
    if (s->hold || s->release > 0 || now - s->last_hb >= s->hb_period) {
        s->release -= s->release > 0;
        s->last_hb = now;
        heartbeat(s, s->hold ? NCP_HEARTBEAT_T_COMMAND_HOLD : NCP_HEARTBEAT_T_COMMAND_RUN, 0);
    }
    uint64_t before[NCP_AXES];
    for (int i = 0; i < s->n; i++)
        before[i] = s->p[i].statuses;
    take(s, now);
    s->cycles++;
    s->last_cycle_ns = now;
    for (int j = 0; j < NCP_AXES; j++)
        act[j] = cmd[j];
    for (int i = 0; i < s->n; i++) {
        struct peer *p = &s->p[i];
        check_peer(s, p, before[i], now);
        int j = p->axis;
        double a = ncp_dist_nm_to_mm(p->st.act_nm);
        unsigned k = (unsigned)((uint64_t)(p->st.t_ns / s->T) % HIST);
        /* its period's setpoint is remembered (it always is, unless the
         * status is older than HIST periods): carried forward from there.
         * Where the LLC computes its own command (ADCBI's block-level DPs,
         * ADCAI's DP2 and DP3) it runs on its own clock, up to a rough period
         * or the periods this loop skipped apart from this one's command:
         * only its own following error says how well it follows */
        if (!s->tx && !s->ai && p->have_status && p->st.t_ns > 0 && s->hist_t[k] == p->st.t_ns)
            act[j] = a + cmd[j] - s->hist_cmd[k][j];
        else if (s->tx && s->hold && p->have_status)
            /* an E-stop froze the LLC's command where it was then, a play
             * delay behind this one's: a serving NCK rests there */
            act[j] = ncp_dist_nm_to_mm(p->st.cmd_nm);
        else
            act[j] = cmd[j] - ncp_dist_nm_to_mm(p->st.ferr_nm);
    }
    return s->faulted ? -1 : 0;
}

/* Real-time, from the position loop: off is a serving NCK's E-stop or
 * fault. The LLCs hear HOLD every period from the next cycle() on and keep
 * their command where it is then, rather than play the frozen setpoints a
 * play delay later; on, RUN goes out for the next 10 periods to let them
 * follow again. */
static void lcm_enable(struct ncp_backend *b, int on)
{
    struct lcm_be *s = b->impl;
    s->release = on && s->hold ? 10 : 0;
    s->hold = !on;
}

static void lcm_stop(struct ncp_backend *b)
{
    struct lcm_be *s = b->impl;
    idle_stop(s);
    int command = s->faulted ? NCP_HEARTBEAT_T_COMMAND_STOP : NCP_HEARTBEAT_T_COMMAND_DONE;
    int64_t end = hlc_now(s) + STOP_WAIT_NS;
    /* Said every servo period, not every heartbeat period, until each LLC
     * still alive has answered (its status says done or stopped, or its
     * heartbeat says it heard done): an LLC whose setpoints ended in motion
     * holds them for only MAX_LOST_PERIODS periods, so one lost "done"
     * must cost a period, not a heartbeat period. */
    for (;;) {
        int64_t now = hlc_now(s);
        heartbeat(s, command, s->fault_axis);
        if (s->ends_sent++ == 0 && s->last_cycle_ns)
            s->end_gap_ns = now - s->last_cycle_ns;
        take(s, now);
        int busy = 0;
        for (int i = 0; i < s->n; i++) {
            const struct peer *p = &s->p[i];
            int alive = now - p->last_hb_ns <= s->hb_timeout;
            busy += alive && p->st.state != NCP_AX_STATUS_T_DONE &&
                    p->st.state != NCP_AX_STATUS_T_STOPPED &&
                    !(command == NCP_HEARTBEAT_T_COMMAND_DONE && p->done_heard);
        }
        if (!busy || now > end)
            break;
        struct timespec ts = { 0, (long)s->T };
        nanosleep(&ts, NULL);
    }
    struct ncp_msg_stats st;
    ncp_msg_get_stats(s->msg, &st);
    if (s->ai)
        lcm_ai_report(s->ai);
    else if (s->dp1)
        fprintf(stderr, "lcm: DP 1 (%s): the program (%lld bytes, by path) in messages of %d "
                        "bytes (%d with the LCM header), %d sent\n",
                s->cfg->nck == NCP_NCK_ADCAI ? "ADCAI" : "ADCBI", (long long)s->dp1->msg.size,
                s->dp1->bytes,
                s->dp1->bytes + 8 + (int)sizeof NCP_DIST_CH_PROGRAM, (int)s->dp1->seq);
    else if (s->tx)
        fprintf(stderr, "lcm: DP %d: %d records in %llu bursts of %d bytes (%d with the LCM "
                        "header), %llu resent on request, %llu lost to a full tap ring\n",
                s->tx->kind->dp, s->tx->sent, (unsigned long long)s->tx->bursts,
                s->tx->burst_bytes,
                s->tx->burst_bytes + 8 + (int)strlen(s->tx->kind->channel) + 1,
                (unsigned long long)s->tx->resent, (unsigned long long)s->tx->overflow);
    if (s->ai)
        ;   /* its line says how the read positions went */
    else if (s->tx && !s->dp1)
        fprintf(stderr, "lcm: time scaling: %llu messages (the stream's advance not 1, and "
                        "%d periods after)\n",
                (unsigned long long)s->scale_sent, SCALE_AFTER);
    else
        fprintf(stderr, "lcm: DP %d (%s): %llu setpoint messages of %d bytes (all %d axes; %d "
                        "with the LCM header), %.0f per second\n",
                s->cfg->lcm.dp, s->cfg->nck == NCP_NCK_ADCAI ? "ADCAI" : "ADCBI",
                (unsigned long long)s->sent_fine, s->fine_bytes, s->n,
                s->fine_bytes + 8 + (int)sizeof NCP_DIST_CH_FINE, 1e9 / (double)s->T);
    for (int i = 0; i < s->n; i++) {
        const struct peer *p = &s->p[i];
        fprintf(stderr, "lcm: axis %c: %llu statuses, %llu periods without one, %llu late; "
                        "its setpoints: lost %d, held %d, stale %d, duplicate %d\n",
                NCP_AXIS_LETTERS[p->axis], (unsigned long long)p->statuses,
                (unsigned long long)p->lost, (unsigned long long)p->late, p->st.lost,
                p->st.held, p->st.stale, p->st.duplicate);
        if (p->st.clock_rtt_ns > 0)
            fprintf(stderr, "lcm: axis %c: clock %s: the HLC's clock ahead of the LLC's by "
                            "%+.3f ms (round trip %.1f us, jitter %.1f us)\n",
                    NCP_AXIS_LETTERS[p->axis], ncp_lcm_clock_name(p->st.clock_mode),
                    (double)p->st.clock_offset_ns * 1e-6,
                    (double)p->st.clock_rtt_ns * 1e-3, (double)p->st.clock_jitter_ns * 1e-3);
    }
    fprintf(stderr, "lcm: the end (%s) said %llu times, the first %.1f ms after the loop's "
                    "last period\n",
            command == NCP_HEARTBEAT_T_COMMAND_DONE ? "done" : "stop",
            (unsigned long long)s->ends_sent, (double)s->end_gap_ns * 1e-6);
    fprintf(stderr, "lcm: transport: sent %llu (%llu send errors), taken %llu, injected loss "
                    "%llu, delayed %llu; dropped %llu without the key's seal, %llu older than "
                    "MAX_AGE_MS\n",
            (unsigned long long)st.sent, (unsigned long long)st.send_errors,
            (unsigned long long)st.taken, (unsigned long long)st.inject_lost,
            (unsigned long long)st.inject_delayed, (unsigned long long)st.auth_failed,
            (unsigned long long)st.stale);
}

static void lcm_describe(const struct ncp_backend *b, char *buf, size_t len)
{
    const struct lcm_be *s = b->impl;
    snprintf(buf, len, "%s", s->fault);
}

static void free_tx(struct lcm_be *s)
{
    free(s->dp1);
    s->dp1 = NULL;
    if (s->tx) {
        lcm_tx_free(s->tx);
        free(s->tx);
        s->tx = NULL;
    }
    if (s->ai) {
        lcm_ai_free(s->ai);
        free(s->ai);
        s->ai = NULL;
    }
}

static void ai_tap(void *impl, const struct ncp_adcai_tap *t)
{
    lcm_ai_push(((struct lcm_be *)impl)->ai, t);
}

static void lcm_close(struct ncp_backend *b)
{
    struct lcm_be *s = b->impl;
    if (!s)
        return;
    idle_stop(s);
    lcm_clock_stop(&s->clk);
    ncp_msg_close(s->msg);
    free_tx(s);
    free(s);
    b->impl = NULL;
}

static int lcm_llcs(const struct ncp_backend *b, struct ncp_llc_info *out, int max)
{
    struct lcm_be *s = b->impl;
    int n = 0;
    for (; s && n < s->n && n < max; n++) {
        struct peer *p = &s->p[n];
        out[n] = (struct ncp_llc_info){
            p->axis, atomic_load_explicit(&p->pub_state, memory_order_relaxed),
            atomic_load_explicit(&p->pub_clock_ns, memory_order_relaxed),
            atomic_load_explicit(&p->pub_ferr_nm, memory_order_relaxed), 0, 0, "",
            atomic_load_explicit(&p->returns, memory_order_relaxed) };
        /* the text and count are ours to read once the kind is set */
        out[n].error = atomic_load_explicit(&p->err_kind, memory_order_acquire);
        if (out[n].error) {
            out[n].error_count = p->err_count;
            snprintf(out[n].error_text, sizeof out[n].error_text, "%s", p->err_text);
        }
    }
    return n;
}

static void lcm_llc_ack(struct ncp_backend *b)
{
    struct lcm_be *s = b->impl;
    for (int i = 0; s && i < s->n; i++) {
        struct peer *p = &s->p[i];
        int st = atomic_load_explicit(&p->pub_state, memory_order_relaxed);
        if (st == NCP_AX_STATUS_T_WAITING || st == NCP_AX_STATUS_T_RUNNING ||
            st == NCP_AX_STATUS_T_DONE)
            atomic_store_explicit(&p->err_kind, 0, memory_order_release);
    }
    if (s)
        atomic_store_explicit(&s->retake, 1, memory_order_release);
}

static const struct ncp_backend_ops lcm_ops = {
    "lcm", lcm_start, lcm_cycle, lcm_stop, lcm_describe, lcm_close, lcm_enable, lcm_live, NULL, NULL,
    lcm_llcs, NULL, lcm_llc_ack,
};

int ncp_backend_open_lcm(struct ncp_backend *b, const struct ncp_machine_cfg *cfg,
                         struct ncp_diag *d)
{
    int adcai = cfg->nck == NCP_NCK_ADCAI;
    /* ADCAI's fineIPObuf is its DP 4: the same setpoint stream as ADCBI's DP 5 */
    int fine = adcai ? cfg->lcm.dp == 4 : cfg->lcm.dp == 5;
    /* DP 1 of either variant sends no records, only its standstill marks
     * through the block-level sender */
    int blocks = cfg->lcm.dp == 1 || (!adcai && cfg->lcm.dp >= 2 && cfg->lcm.dp <= 4);
    if (adcai ? !ncp_dist_adcai_dp(cfg->lcm.dp) : !fine && !blocks)
        return ncp_diag_set(d, NCP_ERR_SEMANTIC, 0, 0,
                            "[PLANNER] NCK = %s has no DP %d (ADCBI: DP 1-5; ADCAI: DP 1-4)",
                            adcai ? "adcai" : "adcbi", cfg->lcm.dp);
    /* ADCAI's LLCs fine-interpolate at every point but its DP 4 */
    if (blocks && !adcai && ncp_machine_cfg_ipo_ratio(cfg) != 1)
        return ncp_diag_set(d, NCP_ERR_SEMANTIC, 0, 0,
                            "DP %d needs [TRAJ] PLANNING_PERIOD equal to SERVO_PERIOD: the LLCs "
                            "do not fine-interpolate yet", cfg->lcm.dp);
    struct lcm_be *s = calloc(1, sizeof *s);
    if (!s)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "out of memory for the lcm backend");
    s->cfg = cfg;
    if (!fine && adcai && !blocks) {
        s->ai = malloc(sizeof *s->ai);
        if (!s->ai || lcm_ai_init(s->ai, cfg->lcm.dp, cfg) != 0) {
            free(s->ai);
            free(s);
            return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "out of memory for the lcm backend");
        }
    } else if (blocks) {
        const struct lcm_tx_kind *k = cfg->lcm.dp == 2   ? &lcm_kind_int
                                      : cfg->lcm.dp == 3 ? &lcm_kind_la
                                                         : &lcm_kind_accdec;
        s->tx = malloc(sizeof *s->tx);
        if (!s->tx || lcm_tx_init(s->tx, k) != 0) {
            free(s->tx);
            free(s);
            return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "out of memory for the lcm backend");
        }
    }
    if (cfg->lcm.dp == 1) {
        s->dp1 = malloc(sizeof *s->dp1);
        if (!s->dp1 || lcm_dp1_init(s->dp1, &cfg->lcm) != 0) {
            int rc = ncp_diag_set(d, NCP_ERR_IO, 0, 0, "DP 1: cannot read the program %s",
                                  cfg->lcm.program);
            free_tx(s);
            free(s);
            return rc;
        }
    }
    s->T = llround(cfg->servo_period * 1e9);
    s->hb_period = cfg->lcm.heartbeat_period_ms * 1000000LL;
    s->hb_timeout = cfg->lcm.heartbeat_timeout_ms * 1000000LL;
    ncp_dist_init();
    struct ncp_dist_msg_opts mo;
    int rc = ncp_dist_msg_opts(&cfg->lcm, &mo, d);
    if (rc == NCP_OK) {
        mo.opts.prefix = NULL;   /* the distributed channels have their own names */
        mo.opts.create_key = 1;  /* the HLC is the NCK: as serve, it makes the key */
        rc = ncp_msg_open(&s->msg, &mo.opts, d);
    }
    if (rc != NCP_OK) {
        free_tx(s);
        free(s);
        return rc;
    }
    for (int j = 0; j < NCP_AXES; j++) {
        if (!(cfg->axis_mask & NCP_AXIS_BIT(j)))
            continue;
        struct peer *p = &s->p[s->n++];
        char ch[32];
        p->axis = j;
        atomic_init(&p->pub_state, -1);
        atomic_init(&p->err_kind, 0);
        atomic_init(&p->returns, 0);
        ncp_dist_ax_channel(ch, sizeof ch, j, NCP_DIST_AX_ADVERT);
        p->sub_advert = ncp_msg_subscribe(s->msg, ch);
        ncp_dist_ax_channel(ch, sizeof ch, j, NCP_DIST_AX_STATUS);
        p->sub_status = ncp_msg_subscribe(s->msg, ch);
        ncp_dist_ax_channel(ch, sizeof ch, j, NCP_DIST_AX_HEARTBEAT);
        p->sub_hb = ncp_msg_subscribe(s->msg, ch);
        ncp_dist_ax_channel(ch, sizeof ch, j, NCP_DIST_AX_RESEND);
        p->sub_resend = ncp_msg_subscribe(s->msg, ch);
    }
    struct ncp_msg_inject in = { cfg->lcm.inject_loss, cfg->lcm.inject_delay_us * 1000LL,
                                 (uint64_t)cfg->lcm.inject_seed };
    if (ncp_msg_set_inject(s->msg, &in) != 0) {
        ncp_msg_close(s->msg);
        free_tx(s);
        free(s);
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "out of memory for the lcm backend");
    }
    /* the probes are answered from now on: an LLC advertises itself only
     * once it knows the HLC's clock */
    rc = lcm_clock_start(&s->clk, cfg, d);
    if (rc != NCP_OK) {
        ncp_msg_close(s->msg);
        free_tx(s);
        free(s);
        return rc;
    }
    memset(b, 0, sizeof *b);
    b->ops = &lcm_ops;
    b->impl = s;
    b->real_clock_only = 1;
    if (s->tx && s->tx->kind == &lcm_kind_int)
        b->plan_journal = journal;
    else if (s->tx && !s->dp1)
        b->plan_tap = tap;
    if (s->ai)
        b->adcai_tap = ai_tap;
    return NCP_OK;
}
