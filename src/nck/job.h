/* A job: a program, an MDI line or a list of moves, run on its own thread. */
#ifndef NCPAR_NCK_JOB_H
#define NCPAR_NCK_JOB_H

#include "job_msgs.h"

#include <pthread.h>

struct nck;

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

/* job.c */
int nck_job_start(struct nck *n);
void nck_job_join(struct nck *n);
/* a line from the map's position to end, traverse or at feed mm/s */
void nck_line(const struct nck *n, struct ncp_seg *s, const double from[NCP_AXES],
              const double to[NCP_AXES], double feed, int traverse);
/* what the status shows of an interpreter op: spindle, coolant, tool, G5x */
void nck_note_state(struct nck *n, const struct ncp_canon *op);

/* the job side: how the NCK takes a call (enum nck_call), and the queueing */
enum nck_call { NCK_CALL_MOTION, NCK_CALL_STATE, NCK_CALL_AUX, NCK_CALL_INFO, NCK_CALL_REFUSED };
int nck_call_class(const struct ncp_canon *op, const char *text);
const char *nck_call_what(int kind);
/* A call refused (d filled, its code returned) or taken (0), as the job will
 * take it: the batch run's pass before motion asks the same. */
int nck_check_call(const struct ncp_cmd *cmd, const struct ncp_canon *op, struct ncp_diag *d);

#endif
