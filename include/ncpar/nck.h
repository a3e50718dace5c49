/* The NCK: a controller that stays up. Its threads, joined by SPSC rings:
 *
 *   job thread (interpreter of a program or an MDI line, or a jog or homing
 *   move) -> canon map -> planner/interpolator thread -> position loop (the
 *   periodic real-time thread, driving the backend) -> the caller's thread
 *   (trace rows, statistics, status).
 *
 * The position loop and the planner run for the life of the NCK, so the
 * machine holds its position between jobs; one job runs at a time. The caller
 * owns the NCK from one thread (the service thread): it sends commands,
 * which are accepted or refused with a reason by the state machine, and calls
 * ncp_nck_poll often to move the NCK on and read its status and events.
 * `cnc-run run` is the batch form of the same core (ncp_nck_run).
 *
 * On the real clock the position loop never waits for a slower stage; the
 * virtual clock waits instead, so runs are deterministic. */
#ifndef NCPAR_NCK_H
#define NCPAR_NCK_H

#include <signal.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>

#include "ncpar/analyzer.h"
#include "ncpar/diag.h"
#include "ncpar/motion.h"
#include "ncpar/msg.h"
#include "ncpar/pipeline.h"
#include "ncpar/rt.h"

/* ---- one program, start to end (cnc-run run) ------------------------------------ */

struct ncp_output;
struct ncp_machine_cfg;
struct ncp_adcai_tap;

/* Live controls of a running NCK, safe to use from any thread. */
struct ncp_nck_ctl {
    _Atomic int override_permille;  /* feed override, 0..2000 (1000 = 100 %) */
    _Atomic int hold;               /* feed hold: brake along the path and wait */
    _Atomic int64_t now_ns;         /* machine time of the last position cycle */
    /* Virtual clock only: time stands still at this instant (before its cycle
     * runs) until it is moved on, so a script can act at an exact machine
     * time. INT64_MAX (the default) never pauses. */
    _Atomic int64_t pause_at_ns;
    _Atomic int rapid_permille;     /* rapid override of G0 moves, 0..1000 */
    /* A batch run's controlled stop (SIGINT/SIGTERM): a feed hold along the
     * path, then the run ends once the axes have settled. */
    _Atomic int stop;
    /* Program pauses (M0, M1, M60) and tool changes (M6) go on when these
     * counters move: resume and tool-changed (cnc-run run: after [SIM]
     * AUTO_RESUME_S, or SIGUSR1). */
    _Atomic uint64_t resume_go, tool_go;
    _Atomic int optional_stop;      /* M1 pauses: 1 (the default, as LinuxCNC) */
    _Atomic int spindle_permille;   /* spindle override, 0..2000 */
    _Atomic uint64_t din;           /* digital inputs P0..P63, a bit each */
};

void ncp_nck_ctl_init(struct ncp_nck_ctl *c, double feed_override);
/* 0.0 .. 2.0. Applied by the position loop at run time by rescaling the planned
 * setpoint stream in time, ramped so that no axis exceeds its acceleration
 * limit. The plan itself is made at opts.feed_override: a live value above it
 * runs at it (start with --feed-override 200 for the full range). */
void ncp_nck_set_feed_override(struct ncp_nck_ctl *c, double ov);
void ncp_nck_feed_hold(struct ncp_nck_ctl *c, int hold);

/* Without a terminal (a log, a script) a run says how far it is this often,
 * a line each time: seldom enough that a run of hours leaves a short log. */
#define NCP_NCK_NOTE_S 5

struct ncp_nck_opts {
    const struct ncp_machine_cfg *cfg;
    /* Runs the program, handing command slots to out in program order
     * (ncp_serial_run / ncp_pipeline_run). Called twice: once for the soft-limit
     * check before any motion, once for the run. Returns NCP_OK or d->code. */
    int (*interpret)(void *ctx, const struct ncp_output *out, struct ncp_diag *d);
    void *interp_ctx;
    int virtual_clock;
    double for_s;            /* feed hold after this much machine time, 0 = whole program */
    double feed_override;    /* 1.0 = 100 % (0.01 .. 2.0) */
    FILE *trace;             /* per-cycle CSV or NULL */
    FILE *progress;          /* live progress line (a terminal) or NULL */
    uint32_t total_lines;    /* for the progress line and notes (0: not known) */
    int total_approx;        /* total_lines is an estimate (a long program is not
                              * read through before motion to count its lines) */
    /* the check before motion says how far it is, and so does the run every
     * NCP_NCK_NOTE_S seconds when there is no progress line; or NULL */
    FILE *notes;
    struct ncp_nck_ctl *ctl; /* live override / hold, or NULL */
    /* polled while the run goes on: non-zero asks for a controlled stop, or
     * NULL. Atomic: a signal handler (lock-free atomics are safe there) or
     * another thread (an LLC leaving its DP 1 NCK) sets it */
    atomic_int *interrupt;
    /* home every axis of the home-all list first (as cnc-ctl home all), then
     * run the program from HOME; 0: the machine starts homed where it is */
    int home;
    /* put before the lines the run itself prints on stderr (a pause's note),
     * e.g. "ch2: " when several runs share the terminal; NULL: none */
    const char *label;
    int trace_rings;         /* as ncp_nck_setup's */
    int loop_priority_min;
    /* a what-if run (serve's estimate, estimate.c): nothing said on stderr,
     * no user M program run */
    int quiet;
    /* every segment the ADCBI planner starts (ncp_planner_set_tap; planner
     * thread), or NULL: an LLC at DP 1 runs its own NCK for these */
    void (*plan_tap)(void *ctx, const struct ncp_la *la, const struct ncp_accdec *rec);
    void *plan_tap_ctx;
    /* every setpoint the ADCAI chain emits (ncp_adcai_set_tap; planner
     * thread), or NULL: an LLC at ADCAI's DP 1 takes the rough records here */
    void (*adcai_tap)(void *ctx, const struct ncp_adcai_tap *t);
    void *adcai_tap_ctx;
};

enum ncp_nck_status { NCP_NCK_OK = 0, NCP_NCK_PROGRAM_ERROR = 2, NCP_NCK_FAULT = 3 };

struct ncp_nck_result {
    int status;              /* enum ncp_nck_status */
    int limit_violation;     /* soft limit found before motion (diag says where) */
    int refused;             /* refused before motion, nothing moved: a program error or
                                a call the machine cannot act on (diag says where) */
    int fault;               /* following-error fault */
    int fault_axis;
    double fault_err;
    uint32_t fault_line;
    struct ncp_diag diag;    /* program error or soft-limit violation */
    int for_expired;
    int interrupted;         /* stopped along the path on request (opts.interrupt) */
    int trace_errno;         /* writing the trace failed (errno), 0 = it did not */
    int home_failed;         /* --home: homing failed (diag says why), the program never ran */
    double program_time, path_length;
    unsigned axis_mask;      /* the machine's axes (ncp_machine_cfg.axis_mask) */
    double ferr_max, ferr_avg, ferr_axis_max[NCP_AXES]; /* mm, or degrees for A B C */
    double contour_max, contour_avg;
    uint64_t segments, starved, trace_dropped, replans;
    uint64_t underruns;      /* setpoint ring ran low: slowed down along the path */
    uint64_t dry;            /* cycles it ran empty in motion anyway (held position) */
    /* starts from rest: how many, and the worst wall time (s) from a start's
     * first segment reaching the planner thread to its first setpoint, and
     * to its first setpoint that moves (a dwell or an aux stop first: later) */
    uint64_t starts;
    double start_sp_max, start_move_max;
    int fifo;
    uint64_t calls_in, calls_acted, calls_refused; /* canonical calls the NCK took */
    double spindle_rpm_max;  /* the spindle's highest actual speed */
    uint64_t pauses;         /* program pauses and tool changes waited for */
    double ext_min[NCP_AXES], ext_max[NCP_AXES]; /* commanded extents (min > max: none) */
    char warning[200];
    struct ncp_rt_stats lat;
    /* timing faults injected ([INJECT], --inject) and a miss limit that
     * stopped the run (inject.trip: exit 3) */
    struct ncp_inject_report inject;
    char inject_summary[256];
    /* [SCHED]: the strategy and the priorities the tasks ran at, read back
     * from the threads ("" without a strategy) */
    char sched_summary[256];
};

/* Runs the whole chain. Returns res->status. */
int ncp_nck_run(const struct ncp_nck_opts *o, struct ncp_nck_result *res);
void ncp_nck_print_summary(const struct ncp_nck_result *res, const char *prog, FILE *f);


/* ---- the NCK as a service -------------------------------------------------------- */

/* The controller's states (the values of lcm/ncp_status_t.lcm's constants). */
enum ncp_nck_state {
    NCP_ST_IDLE = 0,
    NCP_ST_RUNNING,
    NCP_ST_PAUSED,
    NCP_ST_STEPPING,
    NCP_ST_MDI,
    NCP_ST_JOGGING,
    NCP_ST_HOMING,
    NCP_ST_STOPPING,
    NCP_ST_ESTOP,
    NCP_ST_FAULT,
    NCP_ST_COUNT
};
const char *ncp_nck_state_name(int state);
/* -1 when the name is none of the states */
int ncp_nck_state_parse(const char *name);

/* Operator commands (the values of lcm/ncp_command_t.lcm's kinds). */
enum ncp_nck_cmd_kind {
    NCP_CMD_LOAD = 1,
    NCP_CMD_RUN,
    NCP_CMD_PAUSE,
    NCP_CMD_RESUME,
    NCP_CMD_STOP,
    NCP_CMD_ABORT,
    NCP_CMD_STEP,
    NCP_CMD_MDI,
    NCP_CMD_JOG,
    NCP_CMD_JOG_STOP,
    NCP_CMD_HOME,
    NCP_CMD_OVERRIDE,
    NCP_CMD_ESTOP,
    NCP_CMD_RESET,
    NCP_CMD_SHUTDOWN,
    NCP_CMD_KEEPALIVE,
    NCP_CMD_TOOL_CHANGED,
    NCP_CMD_OPTIONAL_STOP,
    NCP_CMD_SET_INPUT,
    NCP_CMD_FILES,                  /* the path of "history" or "tool_table" in the reason */
    NCP_CMD_KIND_MAX = NCP_CMD_FILES
};

#define NCP_NCK_TEXT_MAX 512

struct ncp_nck_cmd {
    int kind;                       /* enum ncp_nck_cmd_kind */
    char text[NCP_NCK_TEXT_MAX];    /* path, MDI line, axis letter(s) */
    double value[4];
    int32_t ivalue[4];
};

struct ncp_nck_setup {
    const struct ncp_machine_cfg *cfg;
    int virtual_clock;
    FILE *trace;                     /* per-cycle CSV, or NULL */
    struct ncp_analyzer_cfg interp;  /* tool table, subroutine path of the interpreter; a
                                        tool table G10 L1/L10/L11 change is written back */
    /* [RS274NGC] PARAMETER_FILE's contents (cfg->op.parameter_file), read by
     * the caller: the interpreter starts from them, and the NCK writes the
     * file again whenever a job, a stop or the shutdown changed them. NULL:
     * no parameter file. */
    const struct ncp_var_file *vars;
    enum ncp_thread_mode mode;       /* how programs are interpreted */
    double jog_keepalive_s;          /* a continuous jog stops this long after the last
                                        keep-alive (0: 0.3 s, three of
                                        cnc-ctl's keep-alive periods) */
    double virtual_pace;             /* virtual clock: machine seconds per real second
                                        while moving (0: as fast as the CPU allows) */
    int trace_rings;                 /* ring and task columns in the trace (or [SCHED]'s) */
    int loop_priority_min;           /* the process's lowest position loop priority, where
                                        several NCKs run (0: this NCK's own) */
    /* as ncp_nck_opts' */
    void (*plan_tap)(void *ctx, const struct ncp_la *la, const struct ncp_accdec *rec);
    void *plan_tap_ctx;
    void (*adcai_tap)(void *ctx, const struct ncp_adcai_tap *t);
    void *adcai_tap_ctx;
};

struct ncp_nck;

/* Starts the backend, the planner and the position loop: the machine holds
 * where it is, unhomed unless the INI says homing is not required. NULL
 * with d->msg on failure. */
struct ncp_nck *ncp_nck_new(const struct ncp_nck_setup *s, struct ncp_diag *d);
/* Stops every thread (a job in motion is held first), the backend under
 * control, and frees everything. */
void ncp_nck_free(struct ncp_nck *n);

/* Accepted (0), or refused (-1) with the reason in reason[len], or
 * NCP_NCK_CMD_PENDING: a load, whose program is checked in a thread of its
 * own while the caller goes on (status, other channels, E-stop); its answer
 * comes from ncp_nck_pending. Runs, MDI, jogs and homing are refused until
 * then. Stop, abort, E-stop, reset, a shutdown, a new load and
 * ncp_nck_free end the check within a few blocks of its program (a
 * millisecond at most), in a loop or not: the load is then refused, naming
 * what ended its check. A new load waits that long for the old check to
 * end, and ncp_nck_pending gives the old load's answer before the new
 * one's. */
#define NCP_NCK_CMD_PENDING 1
int ncp_nck_command(struct ncp_nck *n, const struct ncp_nck_cmd *c, char *reason, size_t len);
/* The pending load's answer once its check has ended: 0 (the program is
 * loaded) or -1 with the reason; NCP_NCK_CMD_PENDING while it runs. A
 * load whose check a new load ended is answered first (-1). */
int ncp_nck_pending(struct ncp_nck *n, char *reason, size_t len);
/* Moves the NCK on: reads the position loop's cycles (trace, status), ends
 * jobs whose motion is complete, goes through the steps of a stop, notices
 * faults and lost keep-alives. Call it at least every 10 ms. Returns 1 when
 * the state changed since the last call. */
int ncp_nck_poll(struct ncp_nck *n);

#define NCP_NCK_AXES_MAX 9
struct ncp_nck_snapshot {
    int state;                       /* enum ncp_nck_state */
    char program[256];
    uint32_t line;
    int n_axes;
    char axes[NCP_NCK_AXES_MAX];
    int homed[NCP_NCK_AXES_MAX];
    double pos_cmd[NCP_NCK_AXES_MAX], pos_act[NCP_NCK_AXES_MAX];
    double vel;                      /* mm/min */
    double feed_override, rapid_override, spindle_override; /* percent */
    double spindle_speed;
    int spindle_dir;
    int mist, flood;
    int tool;
    int g5x_index;                   /* 1 = G54 ... 9 = G59.3 */
    double g5x_offset[NCP_NCK_AXES_MAX];
    /* the interpreter's modal codes (it runs ahead of the machine: these are
     * the codes of the line last interpreted, as on LinuxCNC's display) */
    struct ncp_active_codes active;
    int step_mode;
    char error[256];                 /* the last error, "" = none */
    uint64_t rejected, cycles, deadline_misses;
    double latency_max_us;
    /* the loaded program's estimate (enum ncp_nck_estimate_state): its
     * program time, path and largest following error on the simulated
     * machine at 100 %, and how long finding them took */
    int estimate_state;
    double estimate_s, estimate_path_mm, estimate_ferr_mm, estimate_compute_s;
    int estimate_pauses;             /* M0, M1, M6 it waits at */
    double estimate_min[NCP_AXES], estimate_max[NCP_AXES]; /* its extents (min > max: none) */
    double program_time_s;           /* the last program run's, start to end (0: none) */
    /* while a program runs with an estimate done: what is left of it at
     * the feed override now (s; -1: none) */
    double remaining_s;
    /* CiA 402 drives (socketcan backend), as their last frames said */
    int n_drives;
    char drive_axis[NCP_NCK_AXES_MAX];
    unsigned drive_node[NCP_NCK_AXES_MAX];
    uint16_t drive_statusword[NCP_NCK_AXES_MAX], drive_error[NCP_NCK_AXES_MAX];
    /* distributed axes (lcm backend), as their LLCs' last status said:
     * state -1 never heard, else ax_status_t's */
    int n_llcs, llc_dp;
    char llc_axis[NCP_NCK_AXES_MAX];
    int llc_state[NCP_NCK_AXES_MAX];
    int64_t llc_clock_offset_ns[NCP_NCK_AXES_MAX];
    int32_t llc_ferr_nm[NCP_NCK_AXES_MAX];
    int llc_error[NCP_NCK_AXES_MAX];  /* its last error, status_t's LLC_ERR_ (0 none) */
};

/* A load's estimate (cnc-run serve): running in the background, done,
 * failed (the simulated run refused the program or faulted) or cancelled
 * (a run, a new load or the shutdown came first). */
enum ncp_nck_estimate_state {
    NCP_EST_NONE = 0, NCP_EST_RUNNING, NCP_EST_DONE, NCP_EST_FAILED, NCP_EST_CANCELLED
};
_Static_assert(NCP_EST_CANCELLED == NCP_STATUS_T_EST_CANCELLED, "the status's estimate states");
void ncp_nck_get_status(const struct ncp_nck *n, struct ncp_nck_snapshot *st);

enum ncp_nck_event_kind {
    NCP_EV_INFO = 0, NCP_EV_MSG, NCP_EV_DEBUG, NCP_EV_PRINT, NCP_EV_ERROR, NCP_EV_FAULT
};
struct ncp_nck_event {
    int kind;                        /* enum ncp_nck_event_kind */
    char file[256];
    uint32_t line, col;
    char text[NCP_NCK_TEXT_MAX];
};
/* The next event, oldest first: 1, or 0 when there is none. */
int ncp_nck_next_event(struct ncp_nck *n, struct ncp_nck_event *ev);
/* The loaded program's whole text as the NCK read and checked it (the file
 * may have changed since): 0, or -1 when none is loaded. Valid until the
 * next load; the serving thread's (the caller of ncp_nck_command). */
int ncp_nck_program_text(const struct ncp_nck *n, const char **text, size_t *len);
/* A shutdown command was accepted: the caller should free the NCK. */
int ncp_nck_shutdown_requested(const struct ncp_nck *n);
/* SIGINT/SIGTERM: a controlled stop along the path, as the stop command, from
 * any state that moves; then shutdown. */
void ncp_nck_request_shutdown(struct ncp_nck *n);

/* ---- on LCM (service.c; messages in lcm/, transport in src/msg/) ------------------- */

/* A front end beside LCM (the browser panel, src/http/), called on the serving
 * thread. Its commands go the LCM commands' way (resend and order checks per
 * client_id and seq, the NCK, an ACK); it sees every ACK, STATUS and EVENT
 * sent on LCM. The callbacks must not block: they run between polls of the NCK. */
struct ncp_nck_serve_hook {
    int (*next_command)(void *ctx, ncp_command_t *c);     /* 1: c is the next one */
    void (*ack)(void *ctx, const ncp_ack_t *a);
    void (*status)(void *ctx, const ncp_status_t *s);
    void (*event)(void *ctx, const ncp_event_t *e);
    /* a load was accepted: path and the text the NCK checked and will run
     * (valid during the call only; NULL when the front end needs none) */
    void (*loaded)(void *ctx, int channel, const char *path, const char *text, size_t len);
    void *ctx;
};

struct ncp_nck_serve_opts {
    const struct ncp_nck_serve_hook *hook;  /* NULL: LCM only */
    const char *url, *prefix;        /* NULL or "": the INI's [LCM] URL / CHANNEL_PREFIX */
    int (*stop_requested)(void *ctx);/* polled: SIGINT/SIGTERM arrived */
    void (*ready)(void *ctx, const char *prefix); /* listening (may be NULL) */
    void *ctx;
};
/* Serves commands, status and events until a shutdown (command or
 * stop_requested, after a controlled stop). 0; 1 when the NCK was in fault
 * meanwhile; -1 with d->msg when LCM cannot be opened. */
int ncp_nck_serve(struct ncp_nck *n, const struct ncp_nck_serve_opts *o, struct ncp_diag *d);

/* NC channels in one service: ncks[k] is channel nums[k] (the messages'
 * channel field, 0..NCP_NCK_CHANNELS_MAX-1, each once). The LCM URL, prefix
 * and status rate are ncks[0]'s INI's (or o's). A command for a channel not
 * served is refused by its ACK. A shutdown of one channel (a command, or
 * stop_requested) stops all of them under control, then returns. */
#define NCP_NCK_CHANNELS_MAX 16
int ncp_nck_serve_channels(struct ncp_nck *const *ncks, const int *nums, int n,
                           const struct ncp_nck_serve_opts *o, struct ncp_diag *d);

#endif
