/* The service's NCK: the core plus the operator's state machine (control.c). */
#ifndef NCPAR_NCK_CONTROL_H
#define NCPAR_NCK_CONTROL_H

#include "nck_int.h"
#include "diskwriter.h"
#include "estimate.h"
#include "history.h"
#include "persist.h"

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
    NCK_DROP_UNPARK,     /* planner running again? then hand what changed to the writer */
    NCK_DROP_WRITE       /* written? then the state after (a job's end comes here too) */
};

/* The service's NCK: the core plus the state machine (control.c). */
struct ncp_nck {
    struct nck_core core;
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
    int reset_after_drop;            /* a reset came while an E-stop's or fault's drop ran */
    uint32_t run_from_line;          /* the program run's --from-line (0: from its start) */
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
    struct nck_persist persist;      /* the parameter file, the tool table */
    /* the loaded program's cycle time, found in the background; a run
     * cancels it (the estimate's threads stay off a running job's CPUs) */
    struct nck_estimate est;
    int64_t run_t0_ns;               /* the loop's time when the program run began */
    double program_time;             /* the last program run's, s (0: none yet) */
    struct nck_history hist;         /* [DISPLAY] HISTORY_FILE */
    struct nck_writer writer;        /* writes the history and the persist files */
    /* a command that needs the disk caught up (a run, MDI, a load, the
     * history's path) kept until the writer is, then acted on; answered
     * by ncp_nck_pending. deferred_end: what ended its wait (enum
     * nck_check_end, 0: nothing) */
    int deferred, deferred_end;
    int deferred_told;               /* its long wait was said */
    int64_t deferred_ns;             /* since when it waits */
    struct ncp_nck_cmd deferred_cmd;
    unsigned llc_errors_told[NCP_NCK_AXES_MAX];  /* each LLC's error count told (llcs.c) */
    unsigned llc_returns_told[NCP_NCK_AXES_MAX]; /* and its returns after it was lost */
};

/* llcs.c: each LLC's new last error as an event; a reset's acknowledgement */
void nck_llcs_poll(struct ncp_nck *s);
void nck_llcs_ack(struct ncp_nck *s);

#endif
