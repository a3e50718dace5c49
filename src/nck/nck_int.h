/* One NCK's core: what is fixed at start, what crosses its threads, and a
 * pointer to each thread's own state. Not part of the public contract.
 *
 * The threads: the job thread (one at a time), the planner thread, the
 * position loop (real-time) and the caller's thread (the service thread, or
 * the batch run's caller). Requests between them are pairs of counters (req
 * written by one side, ack by the other), so nothing ever blocks the
 * position loop; crossing.h says who writes and who reads each. */
#ifndef NCPAR_NCK_INT_H
#define NCPAR_NCK_INT_H

#include "ncpar/backend.h"
#include "ncpar/nck.h"

#include "crossing.h"
#include "cycle.h"
#include "homing.h"
#include "job.h"
#include "probe.h"

/* The core of one NCK. What is fixed once it starts sits here, for every
 * thread to read; what crosses threads is cross (crossing.h); each thread's
 * own state is behind a pointer whose type only that thread's files
 * complete, by including its state header, so the compiler keeps one
 * thread's code off another's state. core.c, which sets it all up before
 * the threads start and takes it down after they end, includes them all. */
struct nck_loop;      /* loop_state.h: the position loop's */
struct nck_planner;   /* planner_state.h: the planner thread's */
struct nck_job;       /* job_state.h: the job thread's, handed over at start and join */
struct nck_service;   /* service_state.h: the caller's thread's */

struct nck_core {
    /* fixed at start (nck_start and what the caller set before it) */
    struct ncp_nck_setup setup;
    const struct ncp_machine_cfg *cfg;
    /* batch (ncp_nck_run): one program, then the loop ends by itself */
    int batch;
    const char *label;           /* batch: before its own lines on stderr ("ch2: "), or "" */
    /* batch: a what-if run (serve's estimate): nothing said on stderr, no
     * user M program run (its side effects are the machine's, not the
     * estimate's) */
    int quiet;
    double plan_override;        /* feed override the plan is made at (1.0 = 100 %) */
    double for_s;                /* batch: feed hold after this much machine time */
    struct ncp_nck_ctl own_ctl;
    struct ncp_nck_ctl *ctl;     /* live override / hold / virtual pause: atomics, the
                                    caller writes, the loop reads */
    int trace_rings;
    double start[NCP_AXES];      /* where the backend reported the axes at start */

    struct nck_cross cross;
    struct nck_loop *loop;
    struct nck_planner *plan;
    struct nck_job *job;
    struct nck_service *svc;
};

/* One allocation for the threads' parts; 0, or -1 out of memory. */
int nck_core_alloc(struct nck_core *n);
void nck_core_free(struct nck_core *n);

/* core.c */
/* Backend, rings, planner thread; the position loop separately (a batch run
 * starts it with the program, so its clock starts with the motion). */
int nck_start(struct nck_core *n, const struct ncp_nck_setup *s, int batch, struct ncp_diag *d);
int nck_start_loop(struct nck_core *n, struct ncp_diag *d);
void nck_finish(struct nck_core *n);
/* After nck_finish: the backend closed, the rings and the planner freed. */
void nck_release(struct nck_core *n);
/* The steps of a drop, each a request that the other thread acknowledges. */
void nck_park_planner(struct nck_core *n);
int nck_planner_parked(const struct nck_core *n);
void nck_discard(struct nck_core *n, int to_actual);
/* read_pos.c: the scaler's read of the stream for the next command (after a
 * step or a rebase), and the next command's read handed to the backend. */
void nck_loop_note_read(struct nck_core *n);
void nck_loop_take_read(struct nck_core *n);
int nck_discarded(const struct nck_core *n);
void nck_unpark_planner(struct nck_core *n);
int nck_planner_unparked(const struct nck_core *n);
/* The job's motion is complete: every mark it sent has been reached. */
int nck_motion_done(const struct nck_core *n);

/* loop.c: the position cycle (real-time path) */
int nck_position_cycle(void *ctx, int64_t now_ns);
/* What a batch run reports of the loop's own state: the caller's thread,
 * only after nck_finish joined the loop. */
struct nck_loop_report {
    uint64_t underruns, dry, fb_dropped;
    int ended, for_expired;
    int64_t end_ns;
    uint32_t line_done;
};
void nck_loop_report(const struct nck_core *n, struct nck_loop_report *r);

/* inject.c: the servo's part of the position cycle under injected timing
 * faults and the miss limits (real-time path) */
void nck_inject_setup(struct nck_core *n);
int nck_servo_cycle(struct nck_core *n, const double cmd[NCP_AXES], const double next[NCP_AXES],
                    double act[NCP_AXES]);
/* a stop for a miss limit is complete (the machine rests): serving NCK's fault */
void nck_inject_rest(struct nck_core *n);
void nck_inject_clear(struct nck_core *n);
/* the serving NCK's error text for NCK_LF_TIMING */
void nck_inject_describe(const struct nck_core *n, char *buf, size_t len);

/* planner_thread.c */
void *nck_planner_main(void *arg);
/* The planner thread's starts from rest (ncp_nck_result's starts, ns):
 * only after nck_finish joined it. */
void nck_planner_starts(const struct nck_core *n, uint64_t *starts, int64_t *sp_max_ns,
                        int64_t *move_max_ns);

/* plan_src.c: the planner's protocol (ncpar/motion.h) on whichever variant
 * the NCK runs */
int nck_plan_new(struct nck_core *n);
void nck_plan_free(struct nck_core *n);
int nck_plan_full(const struct nck_core *n);
size_t nck_plan_queued(const struct nck_core *n);
int nck_plan_idle(const struct nck_core *n);
void nck_plan_push(struct nck_core *n, const struct ncp_seg *s);
void nck_plan_finish(struct nck_core *n);
void nck_plan_restart(struct nck_core *n);
void nck_plan_reset(struct nck_core *n, const double pos[NCP_AXES]);
/* An abort dropped the job planned so far (parked): said to the journal of
 * an HLC at ADCBI's DP2, whose LLCs' planners replay it. */
void nck_plan_dropped(const struct nck_core *n);
int nck_plan_step(struct nck_core *n, struct ncp_setpoint *out);
void nck_plan_stats(const struct nck_core *n, struct ncp_planner_stats *st);
/* Servo periods per setpoint of the stream the position loop reads. */
int nck_plan_stream_ratio(const struct ncp_machine_cfg *c);

/* job.c */
/* aux.c: the machine functions on the position loop. 1 while the loop must
 * hold where it is (a pack waits), else 0. */
int nck_aux_cycle(struct nck_core *n);
void nck_aux_discard(struct nck_core *n);
/* spindle.c: the speed the spindle ramps to (rpm, signed), and whether it
 * is there, within [SPINDLE_0]'s at-speed tolerance */
double nck_spindle_target(const struct nck_core *n);
int nck_spindle_at_speed(const struct nck_core *n);

/* sync.c (real-time path): one period of the run an NCK_AUX_SYNC starts; 1
 * while it runs (it writes n->loop->next itself) or waits, 0 once done, 2 while
 * the stream has yet to reach the run's start (the loop reads on). */
int nck_sync_cycle(struct nck_core *n);
void nck_sync_discard(struct nck_core *n);
/* the job side: how the NCK takes a call (enum nck_call), and the queueing */
/* events.c */
void nck_post(struct nck_core *n, int kind, const char *file, uint32_t line, uint32_t col,
              const char *fmt, ...) __attribute__((format(printf, 6, 7)));

/* stats.c */
/* sched.c: [SCHED] for this NCK (task 0 the job thread, 1 the planner) */
void nck_sched_setup(struct nck_core *n);
int nck_sched_start(struct nck_core *n);
void nck_sched_enter(struct nck_core *n, int task);
void nck_sched_leave(struct nck_core *n, int task);
void nck_sched_summary(const struct nck_core *n, char *buf, size_t len);
/* For the job's interpreter output: its pipeline threads join the strategy
 * (NULL where none applies). */
const struct ncp_pipe_hooks *nck_sched_pipe_hooks(struct nck_core *n);
/* Writes the rows gathered so far. 0, or -1 when the write failed. */

#endif
