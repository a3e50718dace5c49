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

#include <pthread.h>

#define NCK_CONTOUR_HISTORY 64

/* The segment ring's messages. END closes a job's motion; SYNC makes the
 * planner run what it has to a stop without ending the job (single block);
 * AUX too, and the stop's sample carries the machine functions (aux) that
 * wait for motion, as LinuxCNC's task waits for motion before them. */
enum { NCK_MSG_SEG, NCK_MSG_END, NCK_MSG_SYNC, NCK_MSG_AUX };
struct nck_seg_msg {
    int kind;
    uint32_t aux;              /* END/SYNC/AUX: machine functions due at the stop */
    /* AUX: after the stop the stream goes on from seg.end (a spindle-
     * synchronised run the position loop moves itself ends there) */
    int jump;
    struct ncp_seg seg;
};

/* ---- machine functions (aux.c, applied by the position loop) -----------------
 * The job thread turns the non-motion calls into aux actions, in packs
 * numbered 1, 2, ... (seq) on their own ring to the position loop. Samples
 * carry the seq of the last pack due by them (ncp_setpoint.aux): the loop
 * applies the packs up to it when it reaches the sample, so a spindle start
 * or an M0 happens where it stands in the program, not when interpreted. A
 * pack that waits for motion is sent after an AUX stop; one that goes with
 * motion (M62/M63/M67) rides on the next segment. */
enum nck_aux_kind {
    NCK_AUX_SPINDLE,       /* v: rpm, signed (M3 +, M4 -, 0 stop) */
    NCK_AUX_ORIENT,        /* v: angle in degrees, i: M19's P; waits until oriented */
    NCK_AUX_AT_SPEED,      /* waits until the spindle is at its speed */
    NCK_AUX_MIST, NCK_AUX_FLOOD,  /* i: on */
    NCK_AUX_DOUT,          /* idx, i: on */
    NCK_AUX_AOUT,          /* idx, v */
    NCK_AUX_WAIT_INPUT,    /* idx, i: mode (L), v: timeout s; a: 1 analog */
    NCK_AUX_PAUSE,         /* i: enum nck_wait (M0, M1, M60); waits for resume */
    NCK_AUX_TOOL,          /* i: the tool; waits for the change */
    NCK_AUX_PREPARE,       /* i: the tool (T) */
    NCK_AUX_ENABLE,        /* i: enum nck_enable, a: on */
    NCK_AUX_PROBE,         /* i: NCP_PROBE_F_*; rides on the probe move, arms the probe */
    NCK_AUX_SYNC,          /* the next run of the sync ring; waits until it has run */
};
enum nck_enable { NCK_EN_FEED_OVERRIDE, NCK_EN_SPEED_OVERRIDE, NCK_EN_FEED_HOLD,
                  NCK_EN_ADAPTIVE };
/* What the loop waits for (nck_fb.wait): 0 nothing. */
enum nck_wait { NCK_WAIT_NONE, NCK_WAIT_M0, NCK_WAIT_M1, NCK_WAIT_M60, NCK_WAIT_TOOL,
                NCK_WAIT_SPINDLE, NCK_WAIT_ORIENT, NCK_WAIT_INPUT, NCK_WAIT_INDEX };
struct nck_aux {
    uint8_t kind, a;
    int16_t idx;
    int32_t i;
    uint32_t line;
    double v;
};
#define NCK_AUX_PACK 6
struct nck_aux_pack {
    uint32_t seq;
    int n;
    struct nck_aux a[NCK_AUX_PACK];
};
#define NCK_AUX_RING 256

/* ---- spindle-synchronised motion (sync.c, the position loop) -----------------
 * G33, G76's passes and G33.1 do not go through the planner: their position
 * along the path is pitch x the spindle's turns since its index, which only
 * the position loop knows. The job thread gathers a run of consecutive
 * synchronised lines (one START_SPEED_FEED_SYNCH .. STOP stretch; the pitch
 * may change between lines, as at G76's tapers) and sends it on the sync
 * ring; an NCK_AUX_SYNC action after an AUX stop at the run's start makes
 * the loop run it, and the planner goes on from the run's end. */
#define NCK_SYNC_LINES 8
#define NCK_SYNC_RING 16
struct nck_sync_run {
    int n;
    int tap;                   /* G33.1: in, spindle reversed, back out */
    double start[NCP_AXES];
    struct nck_sync_line {
        double end[NCP_AXES];
        double len, pitch;     /* mm, mm per turn along the line */
        uint32_t line;
    } l[NCK_SYNC_LINES];
};
enum nck_sync_phase { NCK_SYNC_IDLE, NCK_SYNC_ARRIVE, NCK_SYNC_AT_SPEED, NCK_SYNC_INDEX,
                      NCK_SYNC_FOLLOW, NCK_SYNC_TAP_IN, NCK_SYNC_TAP_OUT, NCK_SYNC_TAP_TURN,
                      NCK_SYNC_PLACE, NCK_SYNC_DONE };
/* The loop's state of the run it moves (its thread only). */
struct nck_sync_state {
    int phase;                 /* enum nck_sync_phase */
    struct nck_sync_run run;
    double total;              /* the run's length, mm */
    double s, v;               /* distance along the run and its speed */
    double acc, vmax;          /* along the path, within every axis's limits */
    double index;              /* the spindle turn (whole) its index came at */
    double rev_last;           /* the spindle angle the period before, turns */
    int sgn;                   /* the spindle's direction at the start: turns count this way */
    double rpm_cmd;            /* G33.1: the speed the tap went in at */
};

/* The machine as the position loop drives it (its thread only). */
struct nck_mach {
    double rpm_cmd;            /* the program's: signed, before the override */
    double rpm;                /* actual, signed */
    double rev;                /* spindle angle in turns since start */
    int orienting;             /* 1 braking, 2 turning to the angle */
    double orient_to;          /* turns, 0..1 */
    int orient_dir, orient_sign;
    int mist, flood, tool, prepared;
    uint64_t dout;
    double aout[NCP_AIO_MAX];
    int en[4];                 /* enum nck_enable: 1 enabled (the default) */
    uint32_t seq_reached;      /* the highest aux of the samples taken */
    struct nck_aux_pack pack;  /* the pack being applied */
    int have_pack, at;         /* and its next action */
    struct nck_aux_pack ahead; /* the next pack, taken off the ring, not due yet */
    int have_ahead;
    int wait;                  /* enum nck_wait */
    uint32_t waits;            /* waits begun */
    uint32_t wait_line;
    int64_t wait_since;
    uint64_t resume_used;
    int in_last;               /* M66 L1/L2: the input's previous value */
    double m66_result;         /* #5399 as the machine found it */
    int spun;                  /* the spindle was stepped at spun_at */
    int64_t spun_at;
};

/* The probe (probe.c): the position loop writes it; the job thread reads
 * the result once the probe move's stop was reached (ends_taken). */
enum nck_probe_state { NCK_PROBE_OFF, NCK_PROBE_ARMED, NCK_PROBE_STOPPING, NCK_PROBE_DROPPING };
enum nck_probe_error { NCK_PROBE_OK, NCK_PROBE_TRIPPED_AT_START, NCK_PROBE_NOT_TRIPPED_AT_START };
struct nck_probe {
    int state, flags;
    double last[NCP_AXES];     /* the previous period's actual position */
    uint64_t ends_at_trip;
    int tripped, error;
    double trip[NCP_AXES];     /* machine coordinates */
    double rest[NCP_AXES];     /* where the axes stopped after a trip */
};

/* Homing (homing.c): the position loop drives each axis of the request on
 * its own, away from the planner, through LinuxCNC's phases; the trace's
 * `home` column shows each axis's phase as one digit. */
enum nck_home_phase { NCK_HP_NONE, NCK_HP_OFF_SWITCH, NCK_HP_SEARCH, NCK_HP_BACK_OFF,
                      NCK_HP_LATCH, NCK_HP_LATCHED, NCK_HP_FINAL };
enum nck_home_result { NCK_HOME_OK, NCK_HOME_NOT_FOUND, NCK_HOME_STOPPED };
struct nck_home_axis {
    int phase;             /* enum nck_home_phase */
    int queued;            /* waits for its HOME_SEQUENCE's turn */
    int stopping;          /* the phase's event came: braking to a stop */
    double pos, v;         /* commanded position (machine coordinates), velocity */
    double from;           /* where the phase began: a search's travel is bounded */
    double latched;        /* where the switch latched, simulated machine's coordinates */
};
struct nck_homing {
    /* the caller's thread writes mask, then counts req; the loop counts
     * done once that request is over (result, final and latched then hold) */
    unsigned mask;
    _Atomic uint32_t req, done;
    uint32_t taken;
    int active;
    int result, fail_axis;
    struct nck_home_axis ax[NCP_AXES];
    /* the simulated machine's position minus the machine position: homing
     * sets the machine position where the switch latches */
    double off[NCP_AXES];
    double final[NCP_AXES];
};

/* One servo cycle as the position loop saw it. */
struct nck_fb {
    double t, v;
    double cmd[NCP_AXES], act[NCP_AXES];
    double jcmd[NCP_AXES], jact[NCP_AXES];  /* the joints (= cmd, act under trivkins) */
    double tool_z;                          /* the kinematics' tool length */
    uint32_t line;
    uint32_t flags;          /* the setpoint's (NCP_SP_RAPID / NCP_SP_ARC for the trace) */
    /* the machine functions */
    double rpm, rev;         /* spindle: actual rpm (signed), angle in turns */
    uint64_t dout;
    uint8_t mist, flood, wait;  /* wait: enum nck_wait */
    uint32_t waits;             /* waits begun so far */
    int32_t tool;
    uint32_t wait_line;
    struct ncp_inject_ev inj;   /* the timing faults of the cycle (trace column inject) */
    uint64_t home;              /* homing phase per axis, 4 bits each (enum nck_home_phase) */
    /* TRACE_RINGS: the rings' fill and the tasks' last times (ns) */
    uint32_t seg_fill, sp_fill;
    int64_t plan_resp_ns, plan_cycle_ns, job_cycle_ns, loop_cycle_ns;
};

struct nck_summary {
    uint64_t rows, moving;
    double ferr_max, ferr_sum, ferr_axis_max[NCP_AXES];
    double contour_max, contour_sum;
    double hist[NCK_CONTOUR_HISTORY][NCP_AXES];
    size_t hist_n, hist_at;
    uint32_t line;
    double t, v;
    double path;             /* length of the commanded path actually run */
    double last[NCP_AXES];
    double act[NCP_AXES];    /* the last cycle's actual position */
    double rpm_max;          /* the spindle's highest actual speed */
    /* Trace rows are gathered here and written whole (write(2) of complete
     * rows only), so that even a killed process leaves a parseable trace. */
    char tbuf[1 << 16];
    size_t tlen;
    int trace_errno;         /* the first failed write's errno, 0 = none */
    int inject_col;          /* the trace has the inject column */
    int joints;              /* the trace has joint columns (non-trivial kinematics) */
    int rings;               /* the trace has the ring and task columns (TRACE_RINGS) */
    uint32_t seg_cap, sp_cap;
};

/* NCK_LF_TIMING: a miss limit tripped; NCK_LF_JOINT: a joint commanded
 * beyond its limit (fault_axis the joint, fault_err the position) */
enum nck_loop_fault { NCK_LF_NONE, NCK_LF_FERROR, NCK_LF_BACKEND, NCK_LF_TIMING, NCK_LF_JOINT };

enum nck_job_kind { NCK_JOB_NONE, NCK_JOB_PROGRAM, NCK_JOB_MDI, NCK_JOB_MOVE };

/* A program, an MDI line or a list of moves (jog, homing, a safe approach). */
#define NCK_JOB_MOVES 4
struct nck_job {
    int kind;
    pthread_t thread;
    int started;
    _Atomic int finished;        /* the job thread pushed its END and returned */
    _Atomic int abort;           /* stop pushing, return */
    /* interpreter jobs */
    int (*interpret)(void *ctx, const struct ncp_output *out, struct ncp_diag *d);
    void *interp_ctx;
    int rc;
    struct ncp_diag diag;        /* the interpreter's error */
    int map_failed;
    struct ncp_diag map_diag;    /* a call the machine cannot run (soft limit, ...) */
    uint32_t from_line;          /* run from this line: earlier lines move nothing */
    int reached;                 /* from_line reached and approached */
    double max_z;                /* highest machine Z of the skipped moves */
    int seen_motion;
    /* single block: after each block's motion the job waits for a resume */
    _Atomic int step;
    _Atomic uint64_t step_go;    /* resume presses (service thread) */
    uint64_t step_used;
    _Atomic int waiting;         /* at a block end, waiting for resume */
    uint32_t step_line;
    /* move jobs */
    struct ncp_seg moves[NCK_JOB_MOVES];
    int n_moves;
    uint64_t marks;              /* END/SYNC messages this job pushed */
    /* machine functions not sent yet (they go out before the next segment
     * or mark) and whether they wait for motion */
    struct nck_aux_pack aux;
    int aux_stop;
    int need_at_speed;           /* a spindle start or S: the next feed waits */
    double capped_said;          /* the last S above MAX_RPM the operator was told of */
    struct nck_sync_run run;     /* synchronised lines gathered, not sent yet */
    int spindle_dir;             /* as the program has set it */
    double origin[NCP_AXES];     /* where the machine was when the job started */
    /* queue busters: the job thread answers each once the machine got
     * there (busters_done, release); the analyzer's thread waits for it */
    _Atomic uint32_t busters_done;
    uint32_t busters_asked;      /* the analyzer's thread */
    _Atomic int emit_stopped;    /* emit refused or failed: no answer will come */
    struct ncp_machine_sync answer;
};

/* What the interpreter last set that the machine does not act on yet, for
 * the status (guarded by ev_lock: the job thread writes, the caller reads). */
struct nck_io {
    double speed;
    int dir, mist, flood, tool, g5x_index;
    double g5x[6];
    uint32_t interp_line;
    struct ncp_active_codes active;  /* as of interp_line's slot */
};

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

/* What ended a load's check before its end (control.c): the ACK names it. */
enum nck_check_end {
    NCK_CHECK_RUNS = 0,
    NCK_CHECK_BY_STOP,
    NCK_CHECK_BY_ABORT,
    NCK_CHECK_BY_ESTOP,
    NCK_CHECK_BY_RESET,
    NCK_CHECK_BY_LOAD,
    NCK_CHECK_BY_SHUTDOWN,
    NCK_CHECK_BY_FREE,
};

/* The steps of dropping what is queued (control.c). */
enum nck_drop {
    NCK_DROP_NONE,
    NCK_DROP_HOLD,       /* feed hold until at rest */
    NCK_DROP_JOB,        /* end the job thread */
    NCK_DROP_PARK,       /* planner parked? then discard */
    NCK_DROP_DISCARD,    /* setpoints discarded? then unpark */
    NCK_DROP_UNPARK      /* planner running again? then done */
};

/* The service's NCK: the core plus the state machine (control.c). */
struct ncp_nck {
    struct nck n;
    int state;                       /* enum ncp_nck_state */
    int resume_state;                /* what a resume returns to */
    struct ncp_analyzer *interp;     /* resident: modal state lives here */
    struct ncp_analyzer_cfg acfg;
    struct ncp_source prog;
    int have_prog;
    char program[256];
    /* load: the program's check runs in load_th, off the caller's thread
     * (a program of millions of blocks takes seconds); the answer is
     * ncp_nck_pending()'s */
    pthread_t load_th;
    int loading;
    /* load_cancel: what ended the check (enum nck_check_end, 0: nothing),
     * asked by the check's interpreter every few blocks */
    _Atomic int load_done, load_cancel;
    int64_t cancel_ns, load_end_ns;  /* when it was asked to end, when it ended */
    struct ncp_source load_src;
    char load_path[256];
    char load_why[256];
    /* a check ended and joined here (a new load, a command right after a
     * stop) whose answer ncp_nck_pending has yet to give */
    int ended_answer;
    char ended_why[256];
    int trace_said;                  /* the trace's early end was told */
    char mdi[NCP_NCK_TEXT_MAX + 2];
    struct ncp_source mdi_src;
    const struct ncp_source *run_src;
    enum nck_drop drop;
    int drop_after;                  /* state after the drop */
    int drop_reset;                  /* the interpreter's end-of-program reset after it */
    int homed[NCP_AXES];
    int homing_axes;                 /* bit per axis of the homing job */
    int jog_continuous;
    int64_t jog_last_ns;
    double rapid_override, spindle_override;
    char error[256];
    uint64_t rejected;
    int shutdown, shutdown_pending;
    uint32_t waits_seen;             /* the loop's wait count the state machine has seen */
    int machine_pause;               /* PAUSED by the program (M0 M1 M60 M6), not by pause */
    int changed;
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
int nck_job_start(struct nck *n);
void nck_job_join(struct nck *n);
/* a line from the map's position to end, traverse or at feed mm/s */
void nck_line(const struct nck *n, struct ncp_seg *s, const double from[NCP_AXES],
              const double to[NCP_AXES], double feed, int traverse);
/* what the status shows of an interpreter op: spindle, coolant, tool, G5x */
void nck_note_state(struct nck *n, const struct ncp_canon *op);

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
enum nck_call { NCK_CALL_MOTION, NCK_CALL_STATE, NCK_CALL_AUX, NCK_CALL_INFO, NCK_CALL_REFUSED };
int nck_call_class(const struct ncp_canon *op, const char *text);
const char *nck_call_what(int kind);
/* A call refused (d filled, its code returned) or taken (0), as the job will
 * take it: the batch run's pass before motion asks the same. */
int nck_check_call(const struct ncp_cmd *cmd, const struct ncp_canon *op, struct ncp_diag *d);

/* probe.c (real-time path) */
void nck_probe_arm(struct nck *n, int flags);
void nck_probe_cycle(struct nck *n, const double act[NCP_AXES]);
int nck_probe_braking(const struct nck *n);

/* homing.c. The loop: nck_home_take instead of the planned setpoint (1 when
 * homing drives this period), nck_home_sense after the backend's cycle,
 * nck_home_cancel on an E-stop or fault (loop.c's drive() puts home.off
 * between the joints and the backend). The caller's thread: nck_home_request
 * (at rest, nothing queued), nck_home_finished once the loop is done. */
int nck_home_take(struct nck *n);
void nck_home_sense(struct nck *n, const double act[NCP_AXES]);
void nck_home_cancel(struct nck *n);
int nck_home_active(const struct nck *n);
uint64_t nck_home_phases(const struct nck *n);
/* The order of homing: HOME_SEQUENCE's absolute value; without any
 * HOME_SEQUENCE in the INI, Z first, then all the others together. */
int nck_home_seq(const struct ncp_machine_cfg *c, int axis);
/* The axes "home all" homes: all of them, or, once any axis has a
 * HOME_SEQUENCE, those that have one (LinuxCNC's rule). */
unsigned nck_home_all_mask(const struct ncp_machine_cfg *c);
void nck_home_request(struct nck *n, unsigned mask);
int nck_home_finished(const struct nck *n);
/* One line per homed axis of the last request (where its switch latched),
 * or why homing failed; 0, or -1 when it failed. */
int nck_home_report(const struct nck *n, char *buf, size_t len);

/* pauses.c: the operator is told of a wait the loop began (stats.c) */
void nck_wait_began(struct nck *n, const struct nck_fb *fb);
const char *nck_wait_name(int wait);
int nck_wait_operator(int wait);

/* events.c */
void nck_post(struct nck *n, int kind, const char *file, uint32_t line, uint32_t col,
              const char *fmt, ...) __attribute__((format(printf, 6, 7)));

/* stats.c */
void nck_account(struct nck_summary *s, unsigned axis_mask, const struct nck_fb *fb, FILE *trace);
/* Reads every cycle the loop has written: trace, summary, last cycle. */
int nck_read_cycles(struct nck *n);
/* The trace's first row: the fixed columns, then cmd and act of each of
 * the machine's axes beyond X Y Z (axis_mask). */
void nck_trace_header(FILE *trace, const struct ncp_machine_cfg *cfg, int joints, int rings);
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
int nck_trace_flush(struct nck_summary *s, FILE *trace);

#endif
