/* The LLC's position loop: once per servo period, on the HLC's period grid.
 *
 * Until the HLC's first setpoint it advertises itself and holds the axis.
 * Then it takes what arrived (non-blocking recv on the one UDP socket, at most
 * 256 datagrams), plays the setpoint of the period NCP_DIST_PLAY_DELAY
 * periods back (late datagrams are still on time), steps the simulated
 * servo of its axis and publishes its status (every period: the HLC counts a
 * period without one as lost). The only system calls are those recv/sendto
 * with MSG_DONTWAIT on a socket set up before the loop, the vDSO's
 * clock_gettime and the loop's clock_nanosleep: UDP sends to the loopback or a
 * LAN interface do not block, and a full socket buffer is a counted send
 * error, not a wait. A separate network thread would add a hand-off and a
 * period of latency for nothing here.
 *
 * At DP4 the HLC sends ACCDECbuf records instead (bursts, numbered; DP3
 * and DP2 their LAbuf and INTbuf records, dp_block.c makes ACCDECbuf ones
 * of them) and
 * the period its motion began; the LLC runs the interpolator (ncp_exec) on
 * them, one step per period from that one on, so its samples are the central
 * run's. A record lost on the way is asked for again (NCP_AX_<L>_RESEND)
 * as soon as a later one, or the HLC's count, shows the gap; one still
 * missing when the interpolator needs it stops the axis (ramp) and says so.
 * At DP1 the records are its own NCK's (dp1.c); with ADCAI its samples go
 * through this axis's stages instead (dp1_ai.c), on the same marks.
 *
 * Safety: a setpoint never moves the axis faster than its MAX_VELOCITY (a
 * step after a gap is limited and counted), and every stop is a ramp at
 * MAX_ACCELERATION from the velocity the axis has, never a jump. */
#include "axis.h"
#include "ncpar/clock.h"

#include <math.h>
#include <string.h>
#include <time.h>

static void on_fine(struct llc *l, const uint8_t *p, size_t len)
{
    struct ncp_dist_fine f;
    if (ncp_dist_decode_fine(p, len, &f) != 0 || f.n <= l->slot)
        return;
    (void)ncp_dist_rx_put(&l->rx, f.seq, f.t_ns, f.pos_nm[l->slot]);
}

static void on_hlc_heartbeat(struct llc *l, const uint8_t *p, size_t len, int64_t now)
{
    ncp_heartbeat_t h;
    memset(&h, 0, sizeof h);
    if (ncp_heartbeat_t_decode(p, 0, (int)len, &h) != (int)len || h.sender != NCP_DIST_HLC_ID)
        return;
    l->last_hlc_ns = now;
    /* the setpoints played next are a play delay old: from before the HLC
     * rested its command on the actual position; the hold lasts until the
     * period the HLC let go in comes to be played */
    int hold = h.command == NCP_HEARTBEAT_T_COMMAND_HOLD;
    if (l->hold && !hold)
        l->hold_until = h.t_ns;
    l->hold = hold;
    if (!l->dp && h.dp >= 1 && h.dp <= 4)
        l->dp = (unsigned char)h.dp;
    if (h.command == NCP_HEARTBEAT_T_COMMAND_DONE && !l->done_req) {
        l->done_req = 1;
        l->done_at = h.t_ns;
    } else if (h.command == NCP_HEARTBEAT_T_COMMAND_STOP && l->end == LLC_END_NONE) {
        l->end = LLC_END_HLC_STOP;
        l->hlc_axis = (char)h.axis;
    }
}

static void on_accdec(struct llc *l, const uint8_t *p, size_t len)
{
    ncp_accdec_burst_t *b = &l->burst;
    if (ncp_accdec_burst_t_decode(p, 0, (int)len, b) != (int)len ||
        b->sender != NCP_DIST_HLC_ID || b->count < 0 || b->count > NCP_DIST_BURST)
        return;
    union ncp_dist_rec u;
    for (int i = 0; i < b->count; i++) {
        ncp_dist_rec_decode(&b->recs[i], &u.a);
        ncp_dist_recs_put(&l->recs, b->first + i, &u);
    }
}

static void on_sync(struct llc *l, const uint8_t *p, size_t len)
{
    ncp_rec_mark_t k;
    memset(&k, 0, sizeof k);
    if (ncp_rec_mark_t_decode(p, 0, (int)len, &k) != (int)len || k.sender != NCP_DIST_HLC_ID)
        return;
    l->dp4 = 1;
    if (k.records > l->hlc_records)
        l->hlc_records = k.records;
    if (k.t_ns > 0 && k.start >= 0) {
        if (!l->t_start)
            l->t_start = k.t_ns;
        l->start_t[(unsigned)k.start % LLC_STARTS] = k.t_ns;
        l->start_k[(unsigned)k.start % LLC_STARTS] = k.start;
    }
}

/* Subscriptions, in the order cnc_axis.c makes them. */
enum { SUB_FINE, SUB_HLC_HEARTBEAT, SUB_ACCDEC, SUB_SYNC, SUB_ROUGH, SUB_ACCDEC_AI, SUB_LA,
       SUB_INT, SUB_STEPS, SUB_PROGRAM, SUB_SCALE, SUB_AI_SCALE };

void llc_take(struct llc *l, int64_t now)
{
    int sub;
    const uint8_t *p;
    size_t len;
    while (ncp_msg_take(l->msg, now, &sub, &p, &len) == 1) {
        if (sub == SUB_FINE)
            on_fine(l, p, len);
        else if (sub == SUB_HLC_HEARTBEAT)
            on_hlc_heartbeat(l, p, len, now);
        else if (sub == SUB_ACCDEC)
            on_accdec(l, p, len);
        else if (sub == SUB_SYNC)
            on_sync(l, p, len);
        else if (sub == SUB_ROUGH || sub == SUB_ACCDEC_AI)
            llc_ai_take(l, sub == SUB_ROUGH ? 2 : 3, p, len);
        else if (sub == SUB_LA)
            llc_on_la(l, p, len);
        else if (sub == SUB_INT)
            llc_on_int(l, p, len);
        else if (sub == SUB_STEPS)
            llc_on_steps(l, p, len);
        else if (sub == SUB_PROGRAM)
            llc_on_program(l, p, len);
        else if (sub == SUB_SCALE)
            llc_on_scale(l, p, len);
        else if (sub == SUB_AI_SCALE)
            llc_ai_on_scale(l, p, len);
    }
}

static int32_t nm(double mm)
{
    int32_t v = 0;
    (void)ncp_dist_mm_to_nm(mm, &v);
    return v;
}

_Static_assert(LLC_END_DONE == NCP_AX_STATUS_T_END_DONE &&
               LLC_END_HLC_STOP == NCP_AX_STATUS_T_END_HLC_STOP &&
               LLC_END_HLC_SILENT == NCP_AX_STATUS_T_END_HLC_SILENT &&
               LLC_END_LOST == NCP_AX_STATUS_T_END_LOST &&
               LLC_END_FERROR == NCP_AX_STATUS_T_END_FERROR &&
               LLC_END_MISSING == NCP_AX_STATUS_T_END_MISSING &&
               LLC_END_SIGNAL == NCP_AX_STATUS_T_END_SIGNAL &&
               LLC_END_PROGRAM == NCP_AX_STATUS_T_END_PROGRAM &&
               LLC_END_CLOCK == NCP_AX_STATUS_T_END_CLOCK &&
               LLC_END_DRIVE == NCP_AX_STATUS_T_END_DRIVE,
               "a status's end is the LLC's own");

void llc_publish_status(struct llc *l, int64_t slot)
{
    ncp_ax_status_t s;
    memset(&s, 0, sizeof s);
    s.seq = l->seq++;
    s.sender = (int16_t)(l->axis + 1);
    s.t_ns = slot;
    s.cmd_nm = nm(l->cmd);
    s.act_nm = nm(l->act);
    s.ferr_nm = nm(l->ferr);
    s.state = (int8_t)l->state;
    /* why it stops, said in every status from then on (one may be lost):
     * worded once, not every period of the ramp */
    s.end = (int8_t)l->end;
    if (l->end != LLC_END_NONE && l->end != LLC_END_DONE && !l->end_text[0])
        llc_end_text(l, l->end_text, sizeof l->end_text);
    memcpy(s.fault, l->end_text, sizeof s.fault);
    llc_clock_status(l, &s);
    /* DP1: its own NCK's records, the HLC waits for the first */
    if (l->dp4 || l->dp == 1) {
        s.buffer_level = (int16_t)(l->dp == 1 ? llc_dp1_level(l)
                                              : ncp_dist_recs_level(llc_exec_ring(l)));
        s.lost = (int32_t)l->recs.gaps;
        s.stale = (int32_t)l->recs.stale;
        s.duplicate = (int32_t)l->recs.duplicate;
        s.rec_next = l->recs.next;
    } else {
        s.buffer_level = (int16_t)(llc_ai_streaming(l) ? llc_ai_level(l)
                                                       : ncp_dist_rx_level(&l->rx, slot));
        s.lost = (int32_t)l->rx.lost;
        s.stale = (int32_t)l->rx.stale;
        s.duplicate = (int32_t)l->rx.duplicate;
        s.held = (int32_t)l->rx.held;
    }
    uint8_t buf[256];
    int n = ncp_ax_status_t_encode(buf, 0, sizeof buf, &s);
    if (n > 0)
        (void)ncp_msg_publish(l->msg, l->ch_status, buf, (size_t)n);
}

void llc_heartbeat(struct llc *l, int64_t now)
{
    if (now - l->last_hb_ns < l->hb_period_ns)
        return;
    l->last_hb_ns = now;
    /* done once the HLC's is heard: the HLC repeats its own until then */
    ncp_heartbeat_t h = { l->seq++, (int16_t)(l->axis + 1), llc_clock_local(&l->clk, now), 0,
                          l->done_req ? NCP_HEARTBEAT_T_COMMAND_DONE : NCP_HEARTBEAT_T_COMMAND_RUN,
                          0 };
    uint8_t buf[64];
    int n = ncp_heartbeat_t_encode(buf, 0, sizeof buf, &h);
    if (n > 0)
        (void)ncp_msg_publish(l->msg, l->ch_heartbeat, buf, (size_t)n);
}

void llc_advertise(struct llc *l)
{
    const struct ncp_axis_cfg *a = &l->cfg->axis[l->axis];
    ncp_ax_advert_t m = { l->seq++,        (int16_t)(l->axis + 1),
                          (uint8_t)NCP_AXIS_LETTERS[l->axis],
                          a->min_limit,    a->max_limit,
                          a->max_vel,      a->max_acc,
                          a->max_jerk,     l->period_ns,
                          (int8_t)(1 << 5 | 1 << 4 | 1 << 3 | 1 << 2 | 1 << 1),
                          (int8_t)(NCP_AX_ADVERT_T_STAGE_FINE |
                                   (l->ai ? NCP_AX_ADVERT_T_STAGE_ACCDEC : 0)) };
    uint8_t buf[128];
    int n = ncp_ax_advert_t_encode(buf, 0, sizeof buf, &m);
    if (n > 0)
        (void)ncp_msg_publish(l->msg, l->ch_advert, buf, (size_t)n);
}

/* target, or as far towards it as MAX_VELOCITY goes in a period (counted):
 * a setpoint at MAX_VELOCITY is no jump, 1 nm of rounding allowed. */
static double within_max_vel(struct llc *l, double target)
{
    double lim = l->cfg->axis[l->axis].max_vel * (double)l->period_ns * 1e-9 + 1e-6;
    double step = target - l->cmd;
    if (fabs(step) <= lim)
        return target;
    l->clamped++;
    return l->cmd + copysign(lim, step);
}

/* Running: the received setpoint, at most MAX_VELOCITY away from the last. */
static double follow(struct llc *l, int64_t slot)
{
    double target = ncp_dist_nm_to_mm(ncp_dist_rx_play(&l->rx, slot));
    if (l->rx.held != l->held_seen) {
        /* a stream that stops with the axis at rest (the program's end, the
         * HLC between jobs) is no loss: heartbeats watch the HLC then */
        if (l->run_held++ == 0)
            l->held_moving = l->cmd != l->cmd_prev;
    } else {
        l->run_held = 0;
    }
    l->held_seen = l->rx.held;
    return within_max_vel(l, target);
}

/* ADCAI's DP2 and DP3: this axis's samples at the HLC's read position
 * (llc_ai_play.c). A sample missing holds the axis and counts as a setpoint
 * lost does (MAX_LOST_PERIODS); a period the HLC's loop skipped stands the
 * stream still in motion, traced as held, but it is the HLC's time, not a
 * loss (the HLC's heartbeat watches a stalled HLC). */
static double follow_ai(struct llc *l, int64_t slot)
{
    int missing;
    double target = llc_ai_play(l, slot, 1, &missing);
    if (missing) {
        l->rx.held++;
        if (l->run_held++ == 0)
            l->held_moving = l->cmd != l->cmd_prev;
    } else {
        l->run_held = 0;
    }
    if (llc_ai_stalled(l))
        l->rx.held++;
    l->held_seen = l->rx.held;
    return within_max_vel(l, target);
}

/* Feed-forward's next setpoint at ADCAI's DP2 and DP3: 1 when its samples
 * are here. */
static int ai_ahead(struct llc *l, int64_t slot, double *mm)
{
    int missing;
    *mm = llc_ai_play(l, slot, 0, &missing);
    return !missing;
}

/* ADCAI's DP3 and DP2, ADCBI's block-level points: 1 the HLC sent its own
 * setpoint for slot (its homing, the loop's own motion), played as at DP5;
 * 2 none came since, and the axis holds where they left it until the HLC's
 * stream starts again after them (the NCK restarts its planner where homing
 * ended: a new ADCAI job, or the abort's void at block-level points, from
 * which the records are offset by homing's offset); 0 its own stream. */
static int fine_phase(struct llc *l, int64_t slot)
{
    int32_t at;
    if (ncp_dist_rx_peek(&l->rx, slot, &at)) {
        l->fine_mode = 1;
        l->fine_last = slot;
        return 1;
    }
    if (!l->fine_mode)
        return 0;
    /* block-level points: the abort's void (serve), or the path's next
     * start where no abort follows homing (`cnc-run run --home`, whose
     * records start where the plan stands: exact only without an offset) */
    int64_t start = l->ai ? 0 : llc_start_at(l, l->starts_done);
    int restarted = l->ai ? llc_ai_job_started(l, l->fine_last, slot)
                          : (l->scale.void_due && l->scale.void_t > l->fine_last &&
                             slot >= l->scale.void_t) ||
                                (start > l->fine_last && slot >= start);
    if (restarted)
        l->fine_mode = 0;
    return restarted ? 0 : 2;
}

/* The block-level points' record source for the interpolator. A record it
 * needs at speed that is not here is missing (at a standstill: see
 * interpolate()). */
static int rec_next(void *ctx, double v0, struct ncp_accdec *rec)
{
    struct llc *l = ctx;
    if (llc_exec_head(l, v0, rec)) {
        /* the HLC's stream rested a sample on the stop before this record
         * (its planner's "no more"): so does this one, and it leaves the
         * stop at the HLC's mark, as from any standstill */
        if (rec->after_stop && v0 == 0 && !l->stop_rested) {
            l->stop_rested = 1;
            return 0;
        }
        return 1;
    }
    if (v0 > 0) {
        l->missing = 1;
        l->missing_rec = llc_exec_ring(l)->next;
    }
    return 0;
}

static void rec_done(void *ctx)
{
    ((struct llc *)ctx)->stop_rested = 0;
    ncp_dist_recs_pop(llc_exec_ring(ctx));
}

static double ramp(struct llc *l);

/* The interpolator's sample for slot (1), or a standstill held (0): the
 * interpolator leaves a standstill at the period the HLC's path did (a step
 * taken too early is taken back), a dwell's time passing meanwhile as it
 * does at the HLC. commit 0: the step is only looked at (feed-forward). */
static int exec_try(struct llc *l, int64_t slot, int commit, double *pos)
{
    struct ncp_accdec first;
    if (!l->ex_on) {
        /* every axis from where the first record starts: a standstill is
         * then the same on every LLC and the HLC */
        if (!llc_exec_head(l, 0, &first))
            first.s.start[l->axis] = l->cmd - l->rec_off;
        ncp_exec_init(&l->ex, first.s.start, (double)l->period_ns * 1e-9);
        memcpy(l->ex_prev, first.s.start, sizeof l->ex_prev);
        l->ex_on = l->ex_rest = 1;
    }
    /* the HLC's loop read nothing of its stream in that period (a hold,
     * a period it skipped): nor does this interpolator, and it is no
     * standstill of the path's, as it is none at the HLC (lcm.c) */
    double adv = llc_scale_at(l, slot);
    if (adv <= 0) {
        *pos = l->ex_prev[l->axis];
        return 1;
    }
    int64_t due = llc_start_at(l, l->starts_done);
    struct ncp_exec before = l->ex;
    l->ex.period = adv * (double)l->period_ns * 1e-9;
    int stop_rested = l->stop_rested;
    struct ncp_dist_recs *q = llc_exec_ring(l);
    int32_t next = q->next;
    const struct ncp_exec_source src = { rec_next, rec_done, l };
    struct ncp_setpoint sp;
    l->missing = 0;
    (void)ncp_exec_step(&l->ex, &src, &sp);
    int moving = 0;
    for (int j = 0; j < NCP_AXES; j++)
        moving |= sp.pos[j] != l->ex_prev[j];
    int hold = moving && l->ex_rest && (!due || slot < due);
    if (!moving && l->ex_rest && due && slot >= due && !llc_exec_head(l, 0, &first)) {
        /* the HLC moved off here: the record it moved on is needed now */
        l->missing = 1;
        l->missing_rec = q->next;
    }
    if (hold || !commit) {
        l->ex = before;
        l->stop_rested = stop_rested;
        q->next = next;
        if (hold)
            l->missing = 0;
        *pos = hold ? l->ex_prev[l->axis] : sp.pos[l->axis];
        return !hold;
    }
    if (moving && l->ex_rest)
        l->starts_done++;
    /* a standstill begins only at the stream's own pace, as at the HLC */
    if (adv == 1.0 || moving)
        l->ex_rest = !moving;
    memcpy(l->ex_prev, sp.pos, sizeof l->ex_prev);
    *pos = sp.pos[l->axis];
    return 1;
}

/* The interpolator's step for slot: 1 and its sample in *pos (mm), 0 where
 * the command stands (before the motion, after an abort until the next
 * job's first record, which starts where the HLC rested on this axis's
 * command), -1 for a record missing (the end is set). */
static int stream_step(struct llc *l, int64_t slot, double *pos)
{
    if (slot < l->t_start || llc_scale_void(l, slot))
        return 0;
    struct ncp_accdec first;
    if (l->scale.voided && !l->ex_on && !llc_exec_head(l, 0, &first))
        return 0;
    (void)exec_try(l, slot, 1, pos);
    if (l->missing) {
        l->end = LLC_END_MISSING;
        l->state = NCP_AX_STATUS_T_STOPPING;
        return -1;
    }
    *pos += l->rec_off;
    return 1;
}

/* The command for the stream's sample target: the sample itself, unless
 * periods left out (left_out()) left the command behind it. Then it closes
 * that distance at MAX_ACCELERATION relative to the stream, braking in time
 * to land on it, and never faster than MAX_VELOCITY: the drive follows
 * that (a catch-up at MAX_VELOCITY at once, as DP5 takes a late setpoint,
 * put 1.13 mm of following error on an axis held 35 periods at 40 mm/s),
 * and the path is the stream's again within a few dozen periods. */
static double rejoin(struct llc *l, double target)
{
    double prev = l->stream_prev;
    l->stream_prev = target;
    if (!l->catching)
        return target;
    double T = (double)l->period_ns * 1e-9;
    double a = l->cfg->axis[l->axis].max_acc * T * T;   /* mm per period, per period */
    double lag = prev - l->cmd, d = fabs(lag);
    /* u: how much of the distance this period closes (negative: the
     * stream draws away), changed by at most MAX_ACCELERATION */
    double u = fmin(l->catch_u + a, sqrt(2 * a * d));
    if (u >= d) {
        l->catching = 0;
        return within_max_vel(l, target);
    }
    double cmd = within_max_vel(l, target - copysign(d - u, lag));
    l->catch_u = d - copysign(1.0, lag) * (target - cmd);
    return cmd;
}

static double interpolate(struct llc *l, int64_t slot)
{
    double pos;
    int r = stream_step(l, slot, &pos);
    return r > 0 ? rejoin(l, pos) : r < 0 ? ramp(l) : l->cmd;
}

/* Feed-forward's next setpoint at DP4: the interpolator's next step, looked
 * at and taken back (a missing record: the current velocity goes on). */
static double interpolate_ahead(struct llc *l, int64_t slot)
{
    double pos;
    struct ncp_accdec first;
    if (slot < l->t_start || llc_scale_void_waits(l, slot) ||
        (l->scale.voided && !l->ex_on && !llc_exec_head(l, 0, &first)))
        return l->cmd;
    (void)exec_try(l, slot, 0, &pos);
    if (l->missing) {
        l->missing = 0;
        return 2 * l->cmd - l->cmd_prev;
    }
    return pos + l->rec_off;
}

/* Asks the HLC again for what a later record or its count shows missing,
 * every few periods while it stays missing. */
static void resend_request(struct llc *l, int64_t now)
{
    int32_t want = l->recs.top > l->hlc_records ? l->recs.top : l->hlc_records;
    if (l->recs.have >= want || now - l->last_resend_ns < 3 * l->period_ns)
        return;
    l->last_resend_ns = now;
    ncp_rec_mark_t k = { l->mark_seq++, (int16_t)(l->axis + 1), now, l->recs.have, -1 };
    uint8_t buf[64];
    int n = ncp_rec_mark_t_encode(buf, 0, sizeof buf, &k);
    if (n > 0 && ncp_msg_publish(l->msg, l->ch_resend, buf, (size_t)n) == 0)
        l->resends++;
}

/* Stopping: the velocity reduced by MAX_ACCELERATION each period. */
static double ramp(struct llc *l)
{
    double T = (double)l->period_ns * 1e-9, v = (l->cmd - l->cmd_prev) / T;
    double dv = l->cfg->axis[l->axis].max_acc * T;
    v = fabs(v) <= dv ? 0.0 : v - copysign(dv, v);
    return l->cmd + v * T;
}

/* ADCAI's DP1: its NCK's samples through this axis's stages, the command
 * on its way back to them after periods left out (rejoin()); a sample
 * missing in motion stops the axis (ramp). */
static double play_ai(struct llc *l, int64_t slot)
{
    double c = llc_dp1_ai_play(l, slot);
    if (l->end == LLC_END_NONE)
        return rejoin(l, c);
    l->state = NCP_AX_STATUS_T_STOPPING;
    return ramp(l);
}

/* A following error within this many periods of a wake-up that left
 * periods out is said to follow it: the command's catch-up, at most
 * MAX_VELOCITY, and the servo's settling after it take a few hundred
 * periods of 1 ms (the plant damps roughly as exp(-70 t)) */
#define LATE_BLAMED_PERIODS 300

static void check_ends(struct llc *l, int64_t now)
{
    if (l->end != LLC_END_NONE)
        return;
    if (atomic_load_explicit(&l->signal, memory_order_relaxed))
        l->end = LLC_END_SIGNAL;
    else if (now - l->last_hlc_ns > l->hb_timeout_ns)
        l->end = LLC_END_HLC_SILENT;
    else if (l->run_held > l->cfg->lcm.max_lost_periods && l->held_moving) {
        l->end = LLC_END_LOST;
        l->lost_at_ns = llc_now();
    }
    else if (fabs(l->ferr) > l->cfg->axis[l->axis].ferror) {
        l->end = LLC_END_FERROR;
        l->fault_ferr = l->ferr;
        if (l->late_at && now - l->late_at <= LATE_BLAMED_PERIODS * l->period_ns)
            l->fault_late_ns = l->late_ns;
    }
}

static void trace(struct llc *l, int64_t now, int64_t slot, int gap)
{
    if (!l->tracing)
        return;
    (void)now;
    struct llc_row r = { l->hlc_now, slot, l->cmd, l->act, l->state, gap };
    if (ncp_spsc_push(&l->trace_ring, &r) != 0)
        l->trace_dropped++;
}

static int hold_now(const struct llc *l, int64_t slot)
{
    return (l->hold || slot < l->hold_until) && !l->dp1ai &&
           l->state == NCP_AX_STATUS_T_RUNNING;
}

/* One period of the axis, slot being the HLC's period it plays. */
static void period(struct llc *l, int64_t now, int64_t slot, int latest)
{
    int64_t T = l->period_ns;
    check_ends(l, now);
    double next_cmd;
    uint32_t gaps = l->rx.held + l->rx.bridged, bridged = l->rx.bridged;
    /* where this LLC computes its command, it runs up to the HLC's last
     * period (it plays further behind than the HLC's done takes to come) */
    int own = l->dp4 || l->dp1ai || llc_ai_streaming(l);
    int play_on = l->done_req && own && slot <= l->done_at;
    int fine = 0;
    if (l->end == LLC_END_NONE && (!l->done_req || play_on)) {
        l->state = NCP_AX_STATUS_T_RUNNING;
        fine = l->dp4 || llc_ai_streaming(l) ? fine_phase(l, slot) : 0;
        next_cmd = l->dp1ai                ? play_ai(l, slot)
                   : fine == 1             ? follow(l, slot)
                   : fine == 2             ? l->cmd
                   : l->dp4                ? interpolate(l, slot)
                   : llc_ai_streaming(l) ? follow_ai(l, slot)
                                           : follow(l, slot);
        /* the HLC's E-stop, heard at once rather than a play delay later
         * in its frozen setpoints: they are still taken (no loss), the
         * command stays; at a block-level point the interpolator runs on
         * behind it until the HLC's stream stood still (its advance 0)
         * and its abort's records are dropped (llc_scale.c) */
        if (hold_now(l, slot))
            next_cmd = l->cmd;
        if (own)
            l->rx.played_t = slot;   /* where a late loop catches up from */
    } else {
        l->state = l->end == LLC_END_NONE || l->end == LLC_END_DONE ? NCP_AX_STATUS_T_DONE
                                                                    : NCP_AX_STATUS_T_STOPPING;
        next_cmd = ramp(l);
        l->rx.played_t = slot;
    }
    l->cmd_prev = l->cmd;
    l->cmd = next_cmd;
    double cmd_ahead;
    /* feed-forward wants the next period's setpoint: it is usually here
     * already (within the velocity limit, as follow() will take it); else
     * the current velocity goes on, a guess that changes what the servo
     * does (one period's acceleration in its velocity: ~10 um of contour
     * at 1 m/s^2), so it is traced (gap 4) and counted */
    int32_t ahead;
    double ahead_mm;
    int guessed = 0;
    double lim = l->cfg->axis[l->axis].max_vel * (double)T * 1e-9 + 1e-6;
    if (hold_now(l, slot) || fine == 2)
        cmd_ahead = l->cmd;
    else if (l->state == NCP_AX_STATUS_T_RUNNING && !fine && (l->dp1ai || l->dp4)) {
        cmd_ahead = l->dp1ai ? llc_dp1_ai_ahead(l, slot + T) : interpolate_ahead(l, slot + T);
        /* catching up (rejoin()): the stream's next step and as much again
         * of the distance to it as this one closed */
        if (l->catching)
            cmd_ahead = l->cmd + fmax(-lim, fmin(lim, cmd_ahead - l->stream_prev +
                                                          copysign(l->catch_u,
                                                                   l->stream_prev - l->cmd)));
    }
    else if (l->state == NCP_AX_STATUS_T_RUNNING && !fine && llc_ai_streaming(l) &&
             ai_ahead(l, slot + T, &ahead_mm))
        cmd_ahead = l->cmd + fmax(-lim, fmin(lim, ahead_mm - l->cmd));
    else if (l->state == NCP_AX_STATUS_T_RUNNING && ncp_dist_rx_peek(&l->rx, slot + T, &ahead))
        cmd_ahead = l->cmd + fmax(-lim, fmin(lim, ncp_dist_nm_to_mm(ahead) - l->cmd));
    else {
        cmd_ahead = 2 * l->cmd - l->cmd_prev;
        guessed = l->state == NCP_AX_STATUS_T_RUNNING && l->cmd != l->cmd_prev;
        l->ff_guessed += (uint32_t)guessed;
    }
    llc_servo(l, l->cmd, cmd_ahead, latest);
    int gap = l->rx.held + l->rx.bridged != gaps ? (l->rx.bridged != bridged ? 1 : 2)
              : l->catching                      ? 5
              : guessed                          ? 4
                                                 : 0;
    trace(l, now, slot, gap);
}

/* At the block-level points a period left out is still one the HLC's
 * stream went on in: the interpolator takes its step (at ADCAI's DP1 the
 * stages their sample), so that this axis stays at the program's time,
 * which the other axes keep; the command rejoins it in the periods played
 * after (rejoin()).
 * Left out of the interpolator too, the step kept this axis behind the
 * others until the next standstill, off the path wherever it bent (a loop
 * woken 100 ms late: 35 periods, 0.7 mm off the central path). */
static void stream_on(struct llc *l, int64_t slot)
{
    double pos;
    if (l->end != LLC_END_NONE || (l->done_req && slot > l->done_at))
        return;
    if (l->dp1ai)
        pos = llc_dp1_ai_play(l, slot);
    else if (fine_phase(l, slot) || stream_step(l, slot, &pos) <= 0)
        return;
    if (l->end != LLC_END_NONE)
        return;
    /* the command stands: the distance grows by the stream's step */
    l->catch_u = -copysign(1.0, pos - l->cmd) * (pos - l->stream_prev);
    l->stream_prev = pos;
    l->catching = 1;
}

/* Periods [from, to) the loop woke too late to play: no setpoint went out
 * in them, so the drive held the last one while the plant's time passed.
 * The trace says so (gap 3): the step the next period takes, limited to
 * MAX_VELOCITY, is a disturbance of the host, not of the path. A servo
 * holding a point has settled long before LEFT_OUT_RUN periods: a longer
 * stall (a debugger, SIGSTOP) only counts the rest, within one cycle's time. */
#define LEFT_OUT_RUN 1000
static void left_out(struct llc *l, int64_t from, int64_t to)
{
    int64_t n = (to - from) / l->period_ns;
    for (int64_t i = 0; i < n; i++) {
        int64_t s = from + i * l->period_ns;
        if (l->dp4 || l->dp1ai)
            stream_on(l, s);
        if (i >= LEFT_OUT_RUN)
            continue;
        l->cmd_prev = l->cmd;
        llc_servo(l, l->cmd, l->cmd, 0);
        trace(l, s, s, 3);
    }
    l->left_out += (uint32_t)n;
}

#define ADVERT_PERIOD_NS 200000000LL   /* 5 a second until the HLC streams */
#define WAIT_STATUS_PERIODS 10
#define FAULT_REPORTS 20

/* The clocks are further apart than CLOCK_TOLERANCE_US while the grid takes
 * them to be one (monotonic: one host; ptp: phc2sys keeps them together). */
static void clock_fault(struct llc *l)
{
    double ms = (double)atomic_load_explicit(&l->clk.est_offset, memory_order_relaxed) * 1e-6;
    l->end = LLC_END_CLOCK;
    /* within the status's 64 bytes also for clocks of different kinds */
    if (fabs(ms) < 1e6)
        snprintf(l->fault, sizeof l->fault, "the clocks disagree by %+.3f ms ([LCM] CLOCK = %s)",
                 ms, ncp_lcm_clock_name(l->clk.mode));
    else
        snprintf(l->fault, sizeof l->fault, "the clocks disagree by %+.0f s ([LCM] CLOCK = %s)",
                 ms * 1e-3, ncp_lcm_clock_name(l->clk.mode));
}

/* Before the HLC's first setpoint: advertise, heartbeat, report the axis at
 * rest, hold the servo where it stands. 1 while waiting, 0 once the grid is
 * known, -1 for an end before any motion. */
static int waiting(struct llc *l, int64_t now)
{
    if (l->t_first)
        return 0;
    if (l->t_start) {
        l->t_first = l->t_start;
        if (l->last_hlc_ns == 0)
            l->last_hlc_ns = now;
        return 0;
    }
    /* the oldest setpoint held names the HLC's period grid */
    int64_t first = 0;
    for (int i = 0; i < NCP_DIST_RX_SLOTS; i++)
        if (l->rx.slot[i].t_ns && (!first || l->rx.slot[i].t_ns < first))
            first = l->rx.slot[i].t_ns;
    if (first) {
        l->t_first = first;
        if (l->last_hlc_ns == 0)
            l->last_hlc_ns = now;
        return 0;
    }
    /* the HLC waits for the advertisement: by then this LLC knows its clock */
    if (llc_clock_known(l) && l->end == LLC_END_NONE && now - l->last_adv_ns >= ADVERT_PERIOD_NS) {
        l->last_adv_ns = now;
        llc_advertise(l);
    }
    if (l->waits++ % WAIT_STATUS_PERIODS == 0)
        llc_publish_status(l, 0);
    llc_heartbeat(l, now);
    if (l->end == LLC_END_NONE) {
        if (atomic_load_explicit(&l->signal, memory_order_relaxed))
            l->end = LLC_END_SIGNAL;
        else if (l->last_hlc_ns && now - l->last_hlc_ns > l->hb_timeout_ns)
            l->end = LLC_END_HLC_SILENT;
        else if (l->done_req)
            l->end = LLC_END_DONE;
        else if (llc_clock_cycle(l, 0) != 0)
            clock_fault(l);
    }
    if (l->end == LLC_END_PROGRAM || l->end == LLC_END_CLOCK || l->end == LLC_END_DRIVE) {
        l->state = NCP_AX_STATUS_T_FAULT;   /* the HLC names the axis and why */
        llc_publish_status(l, 0);
    }
    /* a fault before motion is said for a while (a status may be lost);
     * one found before the HLC came (a drive's start-up) until it is here,
     * or for as long as the HLC would wait for this axis */
    if (l->end == LLC_END_CLOCK || l->end == LLC_END_DRIVE) {
        if (!l->last_hlc_ns &&
            (int64_t)l->waits * l->period_ns < l->cfg->lcm.axis_wait_ms * 1000000LL)
            return 1;
        if (++l->fault_reports < FAULT_REPORTS)
            return 1;
    }
    if (l->end != LLC_END_NONE)
        return -1;
    llc_servo(l, l->cmd, l->cmd, 1);
    return 1;
}

int llc_cycle(void *ctx, int64_t now_ns)
{
    struct llc *l = ctx;
    int64_t now = l->loop.cfg.start_ns + now_ns, T = l->period_ns;
    llc_take(l, llc_now());
    if (l->dp4)
        resend_request(l, now);
    if (l->dp == 2)
        llc_plan_advance(l);
    else if (l->dp == 1)
        llc_dp1_cycle(l);
    int w = waiting(l, now);
    if (w)
        return w < 0 ? NCP_RT_STOP : NCP_RT_CONTINUE;
    if (llc_clock_cycle(l, 1) != 0 && l->end == LLC_END_NONE)
        clock_fault(l);
    /* the HLC's period NCP_DIST_PLAY_DELAY + 0..1 back: from the loop's
     * scheduled time on the HLC's clock, not the clock read now, so a late
     * wake-up never changes it. At DP1 only the standstill marks travel,
     * and a start whose marks all came too late would shift this axis's
     * whole motion run: there the LLC plays further back, so that every one
     * of the marks the HLC sends in a row at a start is still in time; at
     * the other block-level points, so that a motion's first record, sent
     * as the HLC starts it, can still be resent (axis.h) */
    int64_t delay = l->dp == 1 ? LLC_DP1_PLAY_DELAY
                    : l->dp4   ? LLC_BLOCK_PLAY_DELAY
                               : NCP_DIST_PLAY_DELAY;
    l->hlc_now = llc_hlc_time(l, now);
    int64_t slot = l->hlc_now - l->t_first - delay * T - T / 2;
    slot = l->t_first + (slot < 0 ? -((-slot + T - 1) / T) : slot / T) * T;
    /* periods the loop slept through (a deadline miss) still passed for the
     * simulated plant: it runs them now, a few at most. Where this LLC
     * computes its command itself (block-level points, ADCAI's DP1) a
     * period left out would put its axis a period behind the others until
     * the next standstill: there it catches up further (a host that stalls
     * a loop for 10 ms skipped one of them at 8) */
    int64_t from = l->rx.played_t ? l->rx.played_t + T : slot;
    int64_t most = l->dp4 || l->dp1ai ? 64 : 8;
    if (slot - from > most * T) {
        l->late_at = now;
        l->late_ns = slot - from;
        left_out(l, from, slot - most * T);
        from = slot - most * T;
    }
    for (int64_t s = from; s <= slot; s += T)
        period(l, now, s, s == slot);
    llc_publish_status(l, slot);
    llc_heartbeat(l, now);
    if (l->state != NCP_AX_STATUS_T_RUNNING && l->cmd == l->cmd_prev) {
        /* at a standstill: a few periods for the servo to settle, then out */
        if (l->done_req && l->end == LLC_END_NONE)
            l->end = LLC_END_DONE;
        if (++l->settle >= 50) {
            l->state = l->end == LLC_END_DONE ? NCP_AX_STATUS_T_DONE : NCP_AX_STATUS_T_STOPPED;
            llc_publish_status(l, slot);
            return NCP_RT_STOP;
        }
    }
    return NCP_RT_CONTINUE;
}
