/* cnc-axis's parts: the position loop (llc.c), the trace writer and main
 * (cnc_axis.c). */
#ifndef NCP_AXIS_AXIS_H
#define NCP_AXIS_AXIS_H

#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>

#include "ncpar/backend.h"
#include "ncpar/config.h"
#include "ncpar/dist.h"
#include "ncpar/msg.h"
#include "ncpar/rt.h"

#include "llc_clock.h"
#include "llc_scale.h"

enum llc_end {
    LLC_END_NONE,
    LLC_END_DONE,       /* the HLC said the program is done */
    LLC_END_HLC_STOP,   /* the HLC ordered a stop (another axis was lost) */
    LLC_END_HLC_SILENT, /* no heartbeat from the HLC for HEARTBEAT_TIMEOUT_MS */
    LLC_END_LOST,       /* MAX_LOST_PERIODS setpoints in a row missing */
    LLC_END_FERROR,     /* following error past FERROR */
    LLC_END_MISSING,    /* DP4: the next record was not here when needed */
    LLC_END_SIGNAL,     /* SIGINT / SIGTERM */
    LLC_END_PROGRAM,    /* DP1: its own NCK could not run the program (fault says why) */
    LLC_END_CLOCK,      /* CLOCK = monotonic or ptp, and the probes find the clocks apart */
    LLC_END_DRIVE       /* its CiA 402 drive faulted (fault says how) */
};

/* Periods an LLC at DP1 plays behind the HLC: more than the 6 standstill
 * marks the HLC sends in a row as its path leaves a standstill (lcm_tx.c). */
#define LLC_DP1_PLAY_DELAY 8
/* Periods an LLC at ADCBI's block-level points (DP4-DP2) plays behind the
 * HLC: a motion's first records leave the HLC as it starts them, so this is
 * the time a lost one has to be asked for again and resent (every 3 periods
 * while missing: 4 tries; with 3 periods, 20 % loss stopped one run in 6). */
#define LLC_BLOCK_PLAY_DELAY 12

struct llc_ai;
struct llc_dp1_ai;
struct ncp_adcai_tap;

struct llc_row {          /* one period of the trace, handed to the main thread */
    int64_t t_ns, slot_ns;
    double cmd, act;
    int state;
    int gap;              /* 0 its own setpoint, 1 bridged, 2 held, 3 left out (late loop), 4 the
                           * next one late (feed-forward guessed), 5 rejoining the stream after 3 */
};

struct llc {
    const struct ncp_machine_cfg *cfg;
    int axis;             /* index in NCP_AXIS_LETTERS */
    int slot;             /* its place in the HLC's setpoint (the machine's axes in order) */
    struct ncp_msg *msg;
    char ch_status[32], ch_heartbeat[32], ch_advert[32], ch_resend[32];
    int64_t period_ns, t_first;   /* the HLC's first setpoint period */
    int64_t hb_period_ns, hb_timeout_ns;
    struct ncp_dist_rx rx;
    struct ncp_sim sim;           /* the servo, unless a drive is (drive.c) */
    struct ncp_machine_cfg drive_cfg;
    struct ncp_backend drive;
    int has_drive, drive_failed;
    double cmd, cmd_prev, act, ferr;
    int state;            /* ncp_ax_status_t's constants */
    enum llc_end end;
    char hlc_axis;        /* LLC_END_HLC_STOP: the axis the HLC named */
    int run_held;         /* setpoints missing in a row */
    uint32_t held_seen;
    int held_moving;      /* the axis was moving when the setpoints stopped */
    uint32_t clamped;     /* setpoints limited to MAX_VELOCITY */
    uint32_t left_out;    /* periods the loop woke too late to play (llc.c) */
    /* block-level points, after periods left out: the interpolator's last sample
     * (mm), the command still on its way back to it, catch_u (mm) closed last period */
    double stream_prev, catch_u;
    int catching;
    uint32_t ff_guessed;  /* periods in motion without the next setpoint for feed-forward */
    int64_t last_hlc_ns, last_hb_ns, last_adv_ns, settle;
    int64_t lost_at_ns;   /* when LLC_END_LOST was decided */
    uint64_t waits;       /* periods before the HLC's first setpoint */
    double fault_ferr;    /* the following error LLC_END_FERROR saw */
    /* The last wake-up that left periods out (on this LLC's clock) and how
     * late it was: a following error soon after it is the host's stall,
     * which the fault then says (fault_late_ns, 0 for none) */
    int64_t late_at, late_ns, fault_late_ns;
    int32_t seq;
    int done_req;
    /* ADCAI's DP3 and DP2, ADCBI's block-level points: the HLC's fine
     * setpoints played (its homing), the last period one came for; the axis
     * then holds until its own stream starts again after it */
    int fine_mode;
    int64_t fine_last;
    /* Block-level points: what the planner's records add to be this axis
     * (homing's offset, mm), as the abort that started them said */
    double rec_off;
    int hold;             /* the HLC's heartbeat says hold (fine setpoints only) */
    int64_t hold_until;   /* after a hold: the HLC's period of its RUN, played from */
    int64_t done_at;      /* the HLC's last period, as its done said */
    _Atomic int signal;   /* set by the signal handler */
    struct ncp_spsc trace_ring;
    int tracing;
    uint32_t trace_dropped;
    struct ncp_rt_loop loop;
    /* DP4 (ACCDECbuf): the records, the interpolator running them from the
     * HLC's first moving period (t_start) on, and the HLC's word on how many
     * it sent (a lost last burst shows there) */
    int dp4;
    int64_t t_start;
    struct ncp_dist_recs recs;
    struct ncp_exec ex;
    int32_t hlc_records, mark_seq;
    /* when the HLC's path left its k-th standstill, and how many of them
     * this interpolator has left */
#define LLC_STARTS 64
    int64_t start_t[LLC_STARTS];
    int32_t start_k[LLC_STARTS];
    int32_t starts_done;
    int ex_on, ex_rest;
    int stop_rested;              /* the head record is after_stop and the rest before it was taken */
    double ex_prev[NCP_AXES];
    int missing;
    int32_t missing_rec;
    int64_t last_resend_ns;
    uint32_t resends;
    ncp_accdec_burst_t burst;   /* decoded here, not on the loop's stack */
    struct llc_ai *ai;          /* ADCAI's DP2 and DP3: this axis's stages (llc_adcai.c) */
    /* The block-level point (4, 3 or 2; 0 not known yet): at DP3 recs holds
     * LAbuf records (profiled as the interpolator takes them), at DP2 the
     * planner's calls, which this LLC's own planner replays into own, the
     * ring the interpolator then runs (dp_block.c). */
    int dp;
    struct ncp_planner *plan;
    struct ncp_dist_recs own;
    int32_t own_n, plan_steps, mark_records, mark_steps;
    ncp_la_burst_t la_burst;
    ncp_int_burst_t int_burst;
    struct llc_dp1 *dp1;          /* DP1: its own NCK (dp1.c) */
    struct llc_dp1_ai *dp1ai;     /* ADCAI's DP1: its NCK's samples (dp1_ai.c) */
    struct llc_scale scale;       /* the HLC's time scaling (llc_scale.h) */
    char fault[200];              /* LLC_END_PROGRAM, LLC_END_DRIVE: why */
    char fault_short[64];         /* the same in what its status carries ("": fault) */
    char end_text[64];            /* its status's word on the end, once said (llc_end_text) */
    struct llc_clock clk;
    int64_t hlc_now;              /* this period's time on the HLC's clock */
    int fault_reports;            /* LLC_END_CLOCK before motion: statuses saying so */
};

/* llc_adcai.c: NULL when out of memory or the INI's limits give no filter */
struct llc_ai *llc_ai_new(const struct ncp_machine_cfg *cfg);
void llc_ai_free(struct llc_ai *a);
/* A DP2 (rough_ipo_t) or DP3 (accdec_ai_t) message: into the setpoint buffer. */
void llc_ai_take(struct llc *l, int dp, const uint8_t *p, size_t len);
void llc_ai_report(const struct llc *l);
/* At DP2 and DP3: the records taken so far have come through the stages
 * whole (the filters and the fine interpolator hold nothing more), so the
 * last setpoint put is where the axis rests until the next record. */
int llc_ai_at_rest(const struct llc_ai *a);
/* Sample k of job is needed: past the last record, stages a bridged record
 * left moving settle where the HLC's chain rested (llc_adcai.c). */
void llc_ai_settle(struct llc_ai *a, int32_t job, int64_t k);
/* llc_ai_play.c: ai_scale_t, the HLC's read of its stream */
void llc_ai_on_scale(struct llc *l, const uint8_t *p, size_t len);
/* The HLC's read position is known: the axis plays its samples. */
int llc_ai_streaming(const struct llc *l);
/* The command of slot, mm, at the HLC's read position then (commit 0: only
 * looked at, for feed-forward); *missing when a sample it needs is not here
 * (l->cmd is returned). */
double llc_ai_play(struct llc *l, int64_t slot, int commit, int *missing);
/* The slot last played stood because the HLC's loop skipped its period. */
int llc_ai_stalled(const struct llc *l);
/* Samples made ahead of the read position. */
int64_t llc_ai_level(const struct llc *l);
/* A job of the HLC's started after period after, by period slot. */
int llc_ai_job_started(const struct llc *l, int64_t after, int64_t slot);
/* The stages one by one (DP1): begin at mm (returned in nm) at point dp, one
 * rough record's sum in, one servo period's setpoint out (nm). */
int64_t llc_ai_begin(struct llc_ai *a, int dp, double mm);
void llc_ai_load(struct llc_ai *a, int axis, int32_t sum);
int64_t llc_ai_step(struct llc_ai *a, int axis);
int llc_ai_ratio(const struct llc_ai *a);

/* dp_block.c: ADCBI DP3 and DP2 at the LLC */
int llc_blocks_init(struct llc *l);
void llc_on_la(struct llc *l, const uint8_t *p, size_t len);
void llc_on_int(struct llc *l, const uint8_t *p, size_t len);
void llc_on_steps(struct llc *l, const uint8_t *p, size_t len);
/* DP2: this LLC's planner as far as the HLC's calls and steps allow. */
void llc_plan_advance(struct llc *l);
/* The ring the interpolator takes its records from, and its next record
 * after one that ended at speed v0 (1), or none here (0). */
struct ncp_dist_recs *llc_exec_ring(struct llc *l);
int llc_exec_head(struct llc *l, double v0, struct ncp_accdec *a);

/* dp1.c: DP1 at the LLC (its own NCK on the HLC's program) */
struct llc_dp1;
int llc_dp1_init(struct llc *l);
void llc_dp1_free(struct llc *l);
void llc_on_program(struct llc *l, const uint8_t *p, size_t len);
void llc_dp1_cycle(struct llc *l);
/* What its status reports as buffered: the HLC starts when every LLC has some. */
int llc_dp1_level(const struct llc *l);

/* dp1_ai.c: ADCAI's DP1, its NCK's samples through this axis's stages */
struct llc_dp1_ai *llc_dp1_ai_new(const struct llc *l, const _Atomic int *quit);
void llc_dp1_ai_free(struct llc_dp1_ai *x);
void llc_dp1_ai_drain(struct llc_dp1_ai *x);
void llc_dp1_ai_tap(void *ctx, const struct ncp_adcai_tap *t);
void llc_dp1_ai_cycle(struct llc *l);
int llc_dp1_ai_level(const struct llc *l, int inner_done);
/* The command of slot (mm); sets l->end when its NCK fell behind in motion. */
double llc_dp1_ai_play(struct llc *l, int64_t slot);
double llc_dp1_ai_ahead(struct llc *l, int64_t slot);
void llc_dp1_ai_report(const struct llc *l);

/* drive.c: the servo, simulated or a CiA 402 drive over SocketCAN */
/* --backend sim|socketcan[:IFACE]: a drive is started (blocking) and the
 * axis takes its position. 0, or -1 with a message on stderr. */
int llc_drive_open(struct llc *l, const char *spec);
/* Just before the position loop: it takes the drive over from the master's
 * own thread. */
void llc_drive_live(struct llc *l);
/* One servo period at cmd (next: the one after); now 0 for a period the
 * loop slept through, which only the simulated plant still runs. Sets
 * l->act and l->ferr, and l->end on a drive fault. */
void llc_servo(struct llc *l, double cmd, double next, int now);
/* A controlled stop of the drive (after the loop), then closed. */
void llc_drive_close(struct llc *l);

/* llc.c */
int llc_cycle(void *ctx, int64_t now_ns);
void llc_take(struct llc *l, int64_t now);
void llc_publish_status(struct llc *l, int64_t slot);
void llc_heartbeat(struct llc *l, int64_t now);
void llc_advertise(struct llc *l);

/* llc_floor.c: what llc.c and its stages share, calling none of them */
/* The HLC's period its path left its k-th standstill, 0 not known (yet). */
int64_t llc_start_at(const struct llc *l, int32_t k);
/* src as much as a status's fault field (n bytes) carries, cut at a word
 * with "..." when it does not fit. */
void llc_fault_short(char *dst, size_t n, const char *src);
/* Why the loop ends (l->end), in the words its status carries (fault[64]):
 * "" for none and for the program's end. */
void llc_end_text(const struct llc *l, char *dst, size_t n);
int64_t llc_now(void);

#endif
