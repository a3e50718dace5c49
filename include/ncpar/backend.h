/* Backends: what the position loop drives. The simulated machine (default) is a
 * plant per axis under PID with feed-forward; it reports actual positions. */
#ifndef NCPAR_BACKEND_H
#define NCPAR_BACKEND_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "ncpar/inject.h"
#include "ncpar/motion.h"

struct ncp_sim_axis {
    double x, v;         /* plant state: position (mm) and velocity (mm/s) */
    double integ;        /* PID integral */
    double e_prev;       /* last following error */
    double vff_prev;     /* feed-forward velocity of the previous cycle */
};

/* Each axis: G(s) = K / (s (s + p)), K = 250, p = 25 (the timing-faults paper), discretised
 * exactly with a zero-order hold over the servo period.
 *
 * The drive saturates as a servo amplifier does, whatever the gains: its
 * current limit caps the acceleration K u - p v at a_peak, its speed limit
 * the velocity at v_peak. With u constant the acceleration only decays and
 * the velocity moves monotonically towards K u / p, so a u checked where it
 * starts to act (the acceleration) and where it stops (the velocity) keeps
 * both within their caps all the time it acts: the axis never moves more
 * than v_peak T in a period, and a loop that cannot follow is stopped by the
 * following-error check, not thrown across the table.
 *
 * The caps are NCP_SIM_PEAK times the joint's MAX_VELOCITY and
 * MAX_ACCELERATION (ncpar.ini(5) states the factor: src/config/ini_keys.c).
 * Three, as an AC servo's peak torque is about three times its rated one;
 * and far enough above the limits that a run within them stays linear, as
 * Wan et al.'s plant is ("Performance analysis model for real-time
 * Ethernet-based CNC system"): a planned profile with feed-forward asks up
 * to 1.2 times the limits, their 1000 mm circle without feed-forward under
 * a burst of missed periods 2.2 times its acceleration. Only FF2 on a missed
 * or lost setpoint asks for a hundredfold acceleration for a period, which
 * no drive gives. */
#define NCP_SIM_PEAK 3.0
struct ncp_sim {
    double T, K, p, E;   /* E = exp(-p T) */
    double kp, ki, kd, ff1, ff2;
    double v_peak[NCP_AXES], a_peak[NCP_AXES];  /* mm/s, mm/s^2 (deg for A B C) */
    int disabled;        /* drives off (E-stop): no controller output */
    struct ncp_sim_axis ax[NCP_AXES];
};

void ncp_sim_init(struct ncp_sim *s, const struct ncp_machine_cfg *cfg,
                  const double start[NCP_AXES]);
/* One servo cycle: measures the actual positions (act, before the step), runs
 * the controller on the error to cmd and applies its output over the period.
 * next is the command of the following cycle: feed-forward uses the velocity
 * of the interval being driven, not the one just past. */
void ncp_sim_step(struct ncp_sim *s, const double cmd[NCP_AXES], const double next[NCP_AXES],
                  double act[NCP_AXES]);

/* The same plant with the timing of one period injected (ncpar/inject.h): the
 * servo samples at ev->sample_s into the period, its feedback ev->delay_fb_s
 * older than that (or the last sample again when lost), and its output acts
 * ev->io_s after the sample; until then the previous output drives the
 * plant. The plant's recent periods are kept to serve a delayed feedback. */
struct ncp_sim_period {
    double x0, v0;       /* state at the period's start */
    double ua, tsw, ub;  /* output ua until tsw into the period, ub after */
};
struct ncp_sim_timed {
    uint64_t k;                          /* periods stepped */
    double u_prev[NCP_AXES], fb[NCP_AXES];
    struct ncp_sim_period hist[NCP_INJECT_FB_HISTORY][NCP_AXES];
};
void ncp_sim_step_timed(struct ncp_sim *s, struct ncp_sim_timed *tm,
                        const struct ncp_inject_ev *ev, const double cmd[NCP_AXES],
                        const double next[NCP_AXES], double act[NCP_AXES]);

/* ---- the interface the position loop drives ------------------------------ */

struct ncp_backend;
struct ncp_adcai_tap;

/* A drive as the operator's status shows it (CiA 402 drives). */
struct ncp_drive_info {
    int axis;             /* 0..8 = X..W */
    unsigned node;        /* CANopen node-ID */
    uint16_t statusword;  /* 0x6041: the CiA 402 state is in it */
    uint16_t error;       /* the last EMCY error code, 0 none */
};

/* A distributed axis (an LLC of the lcm backend) as the operator's status
 * shows it, from its last status message, and its last error: why it
 * stopped, as it said or as the HLC found, kept until a reset acknowledges
 * it (llc_ack). */
#define NCP_LLC_ERROR_MAX 128
struct ncp_llc_info {
    int axis;                 /* 0..8 = X..W */
    int state;                /* ax_status_t's: -1 never heard, else WAITING .. DONE */
    int64_t clock_offset_ns;  /* how far the HLC's clock is ahead of the LLC's */
    int32_t ferr_nm;          /* its following error */
    int error;                /* status_t's LLC_ERR_: 0 none */
    unsigned error_count;     /* errors kept for it so far: a new one counts up */
    char error_text[NCP_LLC_ERROR_MAX];   /* "" none */
    unsigned returns;         /* times it was heard again after it was lost */
};

struct ncp_backend_ops {
    const char *name;
    /* Before the real-time loop (may block, allocate, talk SDO): brings the
     * machine up and reports where its axes are: the joints it drives are
     * written, the others keep the caller's value (0). 0, or -1 with fault(). */
    int (*start)(struct ncp_backend *b, double pos[NCP_AXES]);
    /* Real-time, once per servo period: cmd is this period's setpoint, next
     * the one after (feed-forward, or what a CSP drive gets now and runs at
     * the next SYNC); act gets the latest actual positions. Non-blocking, no
     * allocation, no locks. 0, or -1 on a fault (act still filled). */
    int (*cycle)(struct ncp_backend *b, const double cmd[NCP_AXES], const double next[NCP_AXES],
                 double act[NCP_AXES]);
    /* After the loop, fault or not: a controlled stop of every axis. */
    void (*stop)(struct ncp_backend *b);
    /* The fault that made start() or cycle() fail, naming node, object and cause. */
    void (*describe_fault)(const struct ncp_backend *b, char *buf, size_t len);
    void (*close)(struct ncp_backend *b);
    /* Real-time, from the position loop: drives on (1) or off (0: E-stop;
     * no torque, CiA 402 "disable operation"). NULL: the backend cannot turn
     * its drives off; the loop then holds them at a frozen setpoint. */
    void (*enable)(struct ncp_backend *b, int on);
    /* Just before the real-time loop takes over (not real-time): a backend
     * that kept the machine alive on its own since start() hands over. CAN
     * drives, once enabled, must see SYNC, RPDOs and the master's heartbeat
     * all the time (they guard the master), also while the program is
     * checked before motion. NULL: nothing to hand over. */
    void (*live)(struct ncp_backend *b);
    /* Not real-time (the serving thread): the drives as their last frames
     * said, one per row up to max; the count. NULL: no drives to show. */
    int (*drives)(const struct ncp_backend *b, struct ncp_drive_info *out, int max);
    /* Real-time, after cycle(): the home switch of the axis's drive as its
     * last frame said, 1 pressed or 0; -1 when the backend has none to read
     * (NULL: the same). Homing then uses the simulated switch. */
    int (*home_switch)(const struct ncp_backend *b, int axis);
    /* Not real-time (the serving thread): the LLCs as their last status
     * said, one per row up to max; the count. NULL: no LLCs to show. */
    int (*llcs)(const struct ncp_backend *b, struct ncp_llc_info *out, int max);
    /* Real-time, the position loop's homing: the axis's drive homes itself
     * ([AXIS_L] HOME_METHOD = drive:N). go 1 starts it (0, or -1 when the
     * axis has no such drive); go -1 aborts it (an operator's stop); go 0
     * asks how it goes: 1 under way, 0 homed (the drive counts from its
     * home now; the backend held it at its actual position until this
     * answer and follows cmd again from the next cycle), -1 over without
     * a home (aborted, or failed: cycle() then reports the fault). NULL:
     * no drive homes itself on this backend. */
    int (*drive_home)(struct ncp_backend *b, int axis, int go);
    /* Not real-time (the serving thread, on a reset): each LLC's last error
     * is acknowledged where that LLC is back (its last status says waiting,
     * running or done); one still stopped or unheard keeps it. A fault of a
     * lost LLC ends with the next cycle() where every LLC is back and can
     * join (lcm.c). NULL: no LLCs. */
    void (*llc_ack)(struct ncp_backend *b);
};

/* The ADCBI planner's calls, as plan_journal sees them; DROP is no call but
 * the mark of an abort: the job whose calls came before it was dropped (a
 * RESET follows). */
enum ncp_plan_call { NCP_PLAN_PUSH, NCP_PLAN_FINISH, NCP_PLAN_RESTART, NCP_PLAN_RESET,
                     NCP_PLAN_STEP, NCP_PLAN_DROP };

struct ncp_backend {
    const struct ncp_backend_ops *ops;
    void *impl;
    int real_clock_only;   /* real drives: the virtual clock cannot drive them */
    /* Injected timing of the coming cycle (set by the position loop, NULL =
     * none): the simulated plant models it; real drives have their own. */
    const struct ncp_inject_ev *timing;
    /* Set by the position loop before each cycle: how far its scaler read
     * the setpoint stream to make this cycle's cmd (samples; 1 the stream's
     * own pace, 0 standing: a feed hold, homing, an E-stop), and how many
     * times it dropped the stream (an abort). An HLC at a block-level point
     * has its LLCs follow both (lcm.c). */
    double adv;
    uint32_t discards;
    /* And where it read: the index of the sample cmd lies at or past
     * (read_k, counting every sample the planner thread has put in the
     * stream; the two before the first after a start or an abort stand for
     * where the stream began) and the fraction towards the next (read_f).
     * After an abort the next job's first sample is drop_k. An HLC at ADCAI's
     * DP2 and DP3 has its LLCs play their own samples at the same place. */
    int64_t read_k;
    double read_f;
    int64_t drop_k;
    /* The loop drives the axes itself this cycle (homing), not from the
     * stream: an HLC whose LLCs make their own setpoints sends it them. */
    int homing;
    /* Homing's offset the loop adds to its joints to make cmd (cmd = the
     * plan's joint + home_off): an HLC whose LLCs run the planner's records
     * tells them, the records being in the plan's coordinates. */
    double home_off[NCP_AXES];
    /* An HLC at a block-level point sends on what the ADCBI planner starts:
     * the NCK hands it to the planner's tap (planner thread; NULL: none). */
    void (*plan_tap)(void *impl, const struct ncp_la *la, const struct ncp_accdec *rec);
    /* An HLC at ADCAI's DP2 or DP3 sends what the ADCAI chain taps there
     * (planner thread; ncpar/adcai.h; NULL: none). */
    void (*adcai_tap)(void *impl, const struct ncp_adcai_tap *t);
    /* An HLC at ADCBI's DP2 sends on what the planner is given: every call
     * on the ADCBI planner, in order (planner thread; NULL: none). s is the
     * block (PUSH) or NULL; pos the position (RESET, and the start) or NULL. */
    void (*plan_journal)(void *impl, enum ncp_plan_call call, const struct ncp_seg *s,
                         const double *pos);
};

/* Opens what cfg->backend names (not started yet). log gets start-up
 * progress (may be NULL). On error d->msg says what is wrong. */
int ncp_backend_open(struct ncp_backend *b, const struct ncp_machine_cfg *cfg, FILE *log,
                     struct ncp_diag *d);
int ncp_backend_open_sim(struct ncp_backend *b, const struct ncp_machine_cfg *cfg,
                         struct ncp_diag *d);
/* cnc-axis LLCs over LCM ([LCM] URL, DP, heartbeat and injection keys; the
 * distributed mode, ncpar/dist.h). [PLANNER] NCK = adcbi takes DP 1-5 and
 * adcai DP 1-4; another DP is refused here, as is a block-level ADCBI point
 * (DP 2-4) whose PLANNING_PERIOD differs from SERVO_PERIOD. Not real-time:
 * it allocates and opens the LCM transport. */
int ncp_backend_open_lcm(struct ncp_backend *b, const struct ncp_machine_cfg *cfg,
                         struct ncp_diag *d);
int ncp_backend_open_socketcan(struct ncp_backend *b, const struct ncp_machine_cfg *cfg,
                               FILE *log, struct ncp_diag *d);

/* ---- socketcan: position scaling and configuration checks -------------- */

/* mm -> encoder counts, rounded to nearest; -1 when out of the int32 range. */
int ncp_mm_to_counts(double mm, double counts_per_mm, int32_t *counts);
double ncp_counts_to_mm(int32_t counts, double counts_per_mm);
/* Every axis has a NODE_ID and COUNTS_PER_MM, its soft limits fit in 32-bit
 * counts, [CAN] INTERFACE is set; else d->msg names section and key. */
int ncp_socketcan_check_cfg(const struct ncp_machine_cfg *cfg, struct ncp_diag *d);
/* A --backend of sim or socketcan[:IFACE] (cnc-run run, cnc-axis) into
 * cfg->backend and [CAN] INTERFACE: 0; 1 when spec is neither; -1 for a bad
 * interface name (d->msg says which). */
int ncp_backend_spec(const char *spec, struct ncp_machine_cfg *cfg, struct ncp_diag *d);

/* ---- channels of one service on their own backends (cell.c) ------------ */

/* Channel ch of a channels INI on its machine cfg (ncp_cell_apply done): a
 * socketcan channel's axes are all CAN drives, an lcm channel's DP is one
 * of its variant's. NCP_OK, or an error with d->line the channels INI's. */
int ncp_backend_cell_channel(const struct ncp_cell_channel *ch, const struct ncp_machine_cfg *cfg,
                             struct ncp_diag *d);
/* No two channels (cfgs[k] is cell->ch[k]'s machine) on one CAN interface
 * (one master sends SYNC on a bus; one node is one drive) or one LCM URL
 * (one HLC per set of LLCs). NCP_OK, or an error as above. */
int ncp_backend_cell_shared(const struct ncp_cell *cell, const struct ncp_machine_cfg *const cfgs[],
                            struct ncp_diag *d);

#endif
