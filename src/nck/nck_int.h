/* One NCK's threads and what they share. Not part of the public contract.
 *
 * Who writes what:
 * - the job thread (one at a time): the segment ring's producer, job.*, the
 *   canon map while a job runs;
 * - the planner thread: the planner, the setpoint ring's producer;
 * - the position loop (real-time): the setpoint ring's and the scaler's
 *   consumer, the cycle ring's producer, the loop-only fields below;
 * - the caller's thread (the service thread): everything else, the cycle
 *   ring's consumer, the canon map between jobs.
 * Requests between them are pairs of counters (req written by one side, ack by
 * the other), so nothing ever blocks the position loop. */
#ifndef NCPAR_NCK_INT_H
#define NCPAR_NCK_INT_H

#include "ncpar/backend.h"
#include "ncpar/nck.h"

#include "cycle.h"
#include "homing.h"
#include "job.h"
#include "machine.h"
#include "probe.h"

#include <pthread.h>

/* NCK_LF_TIMING: a miss limit tripped; NCK_LF_JOINT: a joint commanded
 * beyond its limit (fault_axis the joint, fault_err the position) */
enum nck_loop_fault { NCK_LF_NONE, NCK_LF_FERROR, NCK_LF_BACKEND, NCK_LF_TIMING, NCK_LF_JOINT };

struct nck {
    struct ncp_nck_setup setup;
    const struct ncp_machine_cfg *cfg;
    /* batch (ncp_nck_run): one program, then the loop ends by itself */
    int batch;
    const char *label;           /* batch: before its own lines on stderr ("ch2: "), or "" */
    double plan_override;        /* feed override the plan is made at (1.0 = 100 %) */
    double for_s;                /* batch: feed hold after this much machine time */
    struct ncp_nck_ctl own_ctl;
    struct ncp_nck_ctl *ctl;     /* live override / hold / virtual pause */
    struct ncp_backend be;
    int be_open, be_started;
    struct ncp_spsc segs, sps, fbs;
    struct ncp_spsc auxq;            /* machine function packs, job -> position loop */
    struct ncp_spsc syncq;           /* synchronised runs, job -> position loop */
    struct nck_sync_state sync;      /* position loop only */
    uint32_t aux_seq;                /* the last pack numbered (job threads, in turn) */
    struct nck_mach mach;            /* position loop only */
    struct nck_probe probe;          /* position loop; the result for the job (probe.c) */
    struct nck_homing home;          /* position loop; the request and result (homing.c) */
    _Atomic int job_pending;         /* batch --home: the program's job starts after homing;
                                        the loop holds still (virtual clock: time too) */
    /* canonical calls the jobs took, acted on and refused, per kind (job
     * threads, in turn; read after the job) */
    uint64_t calls_in[NCP_C__COUNT], calls_acted[NCP_C__COUNT], calls_refused[NCP_C__COUNT];
    /* the planner thread's source of setpoints: the ADCBI planner, or under
     * [PLANNER] NCK = adcai the ADCAI chain (the other is NULL) */
    struct ncp_planner *planner;
    struct ncp_adcai *adcai;
    struct ncp_canon_map map;
    struct ncp_rt_loop loop;
    pthread_t planner_thread;
    int planner_started, loop_started;
    /* [SCHED]: task 0 the job thread, task 1 the planner (sched.c) */
    struct ncp_sched sched;
    struct ncp_rt_place job_place, planner_place;
    _Atomic int prio_seen[NCP_SCHED_TASKS]; /* each task's priority, read back by itself */
    /* the interpreter pipeline's threads as tasks (src/nck/sched.c) */
    struct ncp_pipe_thread pipe_thread[NCP_SCHED_TASKS];
    struct ncp_pipe_hooks pipe_hooks;
    int trace_rings;
    /* ring and task timing for the trace (TRACE_RINGS): written by their task */
    _Atomic int64_t plan_resp_ns, plan_cycle_ns, job_cycle_ns;
    int64_t loop_last_ns;        /* position loop only */
    _Atomic int quit;            /* planner thread: leave */
    double start[NCP_AXES];      /* where the backend reported the axes at start */

    /* Stream marks: END/SYNC messages sent (job), END setpoints pushed
     * (planner), END setpoints reached (loop). A job's motion is complete when
     * ends_taken reaches the marks it sent. */
    _Atomic uint64_t marks_sent, ends_pushed, ends_taken;
    uint64_t marks_base;             /* marks_sent when the current job started */

    /* The steps of dropping what is queued (stop, abort, E-stop, fault):
     * park the planner, discard the setpoint ring, start the planner again. */
    _Atomic int park_req, park_ack;
    _Atomic int discard_req, discard_ack;
    _Atomic int discard_to_actual;   /* rest at the actual position, not the commanded */
    double rest[NCP_AXES];           /* where the loop rested; valid once discard_ack */
    _Atomic int unpark_req, unpark_ack;
    _Atomic int full_decel;          /* abort: hold at the axes' full deceleration */
    _Atomic int frozen;              /* E-stop / fault: setpoints frozen, drives off */

    /* position loop: its thread only, except the atomics */
    struct ncp_setpoint cur, next;
    double jcmd[NCP_AXES], jnext[NCP_AXES], jact[NCP_AXES];  /* cur, next, actual as joints */
    struct ncp_scaler scaler;
    double decel_normal, decel_full;
    int slowing;
    uint64_t dry, underruns, fb_dropped;
    int end_seen;                    /* the output sits on an END sample */
    uint64_t ends_seen;              /* the scaler's END count already added to ends_taken */
    int ended, settle, for_expired;  /* batch */
    int drives_on;
    int64_t end_ns, now_ns;
    uint32_t line_now, line_done;
    _Atomic int loop_fault;          /* enum nck_loop_fault; details written before it */
    int fault_axis;
    double fault_err;
    uint32_t fault_line;
    _Atomic int at_rest;             /* no motion: rate 0 or the stream at a stop */
    _Atomic uint64_t pub_misses;
    _Atomic int64_t pub_lat_max_ns;

    /* timing faults (inject.c, position loop only; the report is read once
     * the loop has ended, or by the service after loop_fault) */
    int inj_on, inj_timed;           /* anything configured; the plant models timing */
    struct ncp_inject inj;
    struct ncp_inject_rx rx;
    struct ncp_inject_rx rx_axis[NCP_AXES];   /* SETPOINT_FRAMES = per-axis: one per drive */
    struct ncp_inject_guard guard;
    struct ncp_inject_ev inj_ev;
    uint64_t real_misses_seen;
    int timing_stop;                 /* a miss limit tripped: stop along the path */
    struct ncp_inject_report inj_rep;

    /* events, oldest first (job thread and caller's thread post them) */
#define NCK_EVENTS 256
    pthread_mutex_t ev_lock;
    struct ncp_nck_event ev[NCK_EVENTS];
    unsigned ev_head, ev_count;
    uint64_t ev_dropped;
    int post_prints;                 /* service: PRINT/MSG/DEBUG as events, not stderr */
    struct nck_io io;
    uint64_t pauses;                 /* operator waits begun (caller's thread) */

    /* the caller's thread */
    struct nck_job job;
    struct nck_summary sum;
    struct nck_fb last_fb;
    int have_fb;
};

/* core.c */
/* Backend, rings, planner thread; the position loop separately (a batch run
 * starts it with the program, so its clock starts with the motion). */
int nck_start(struct nck *n, const struct ncp_nck_setup *s, int batch, struct ncp_diag *d);
int nck_start_loop(struct nck *n, struct ncp_diag *d);
void nck_finish(struct nck *n);
/* After nck_finish: the backend closed, the rings and the planner freed. */
void nck_release(struct nck *n);
/* The steps of a drop, each a request that the other thread acknowledges. */
void nck_park_planner(struct nck *n);
int nck_planner_parked(const struct nck *n);
void nck_discard(struct nck *n, int to_actual);
int nck_discarded(const struct nck *n);
void nck_unpark_planner(struct nck *n);
int nck_planner_unparked(const struct nck *n);
/* The job's motion is complete: every mark it sent has been reached. */
int nck_motion_done(const struct nck *n);

/* loop.c: the position cycle (real-time path) */
int nck_position_cycle(void *ctx, int64_t now_ns);

/* inject.c: the servo's part of the position cycle under injected timing
 * faults and the miss limits (real-time path) */
void nck_inject_setup(struct nck *n);
int nck_servo_cycle(struct nck *n, const double cmd[NCP_AXES], const double next[NCP_AXES],
                    double act[NCP_AXES]);
/* a stop for a miss limit is complete (the machine rests): serving NCK's fault */
void nck_inject_rest(struct nck *n);
void nck_inject_clear(struct nck *n);
/* the serving NCK's error text for NCK_LF_TIMING */
void nck_inject_describe(const struct nck *n, char *buf, size_t len);

/* planner_thread.c */
void *nck_planner_main(void *arg);

/* plan_src.c: the planner's protocol (ncpar/motion.h) on whichever variant
 * the NCK runs */
int nck_plan_new(struct nck *n);
void nck_plan_free(struct nck *n);
int nck_plan_full(const struct nck *n);
size_t nck_plan_queued(const struct nck *n);
int nck_plan_idle(const struct nck *n);
void nck_plan_push(struct nck *n, const struct ncp_seg *s);
void nck_plan_finish(struct nck *n);
void nck_plan_restart(struct nck *n);
void nck_plan_reset(struct nck *n, const double pos[NCP_AXES]);
int nck_plan_step(struct nck *n, struct ncp_setpoint *out);
void nck_plan_stats(const struct nck *n, struct ncp_planner_stats *st);
/* Servo periods per setpoint of the stream the position loop reads. */
int nck_plan_stream_ratio(const struct ncp_machine_cfg *c);

/* job.c */
/* aux.c: the machine functions on the position loop. 1 while the loop must
 * hold where it is (a pack waits), else 0. */
int nck_aux_cycle(struct nck *n);
void nck_aux_discard(struct nck *n);
/* spindle.c: the speed the spindle ramps to (rpm, signed), and whether it
 * is there, within [SPINDLE_0]'s at-speed tolerance */
double nck_spindle_target(const struct nck *n);
int nck_spindle_at_speed(const struct nck *n);

/* sync.c (real-time path): one period of the run an NCK_AUX_SYNC starts; 1
 * while it runs (it writes n->next itself) or waits, 0 once done, 2 while
 * the stream has yet to reach the run's start (the loop reads on). */
int nck_sync_cycle(struct nck *n);
void nck_sync_discard(struct nck *n);
/* the job side: how the NCK takes a call (enum nck_call), and the queueing */
/* events.c */
void nck_post(struct nck *n, int kind, const char *file, uint32_t line, uint32_t col,
              const char *fmt, ...) __attribute__((format(printf, 6, 7)));

/* stats.c */
/* sched.c: [SCHED] for this NCK (task 0 the job thread, 1 the planner) */
void nck_sched_setup(struct nck *n);
int nck_sched_start(struct nck *n);
void nck_sched_enter(struct nck *n, int task);
void nck_sched_leave(struct nck *n, int task);
void nck_sched_summary(const struct nck *n, char *buf, size_t len);
/* For the job's interpreter output: its pipeline threads join the strategy
 * (NULL where none applies). */
const struct ncp_pipe_hooks *nck_sched_pipe_hooks(struct nck *n);
/* Writes the rows gathered so far. 0, or -1 when the write failed. */

#endif
