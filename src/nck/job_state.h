/* A job and the job thread's state. The caller fills a job in before it
 * starts the thread and reads its result after the join (or once finished
 * is set); in between the job thread alone writes here, except the atomics.
 * So the job thread's files and the caller's job control (control.c,
 * batch.c) include this; the planner's and the loop's files do not. */
#ifndef NCPAR_NCK_JOB_STATE_H
#define NCPAR_NCK_JOB_STATE_H

#include "job.h"

#include <pthread.h>

/* A program, an MDI line or a list of moves (jog, homing, a safe approach). */
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
    /* the program's last line handed over by the interpreter (job thread;
     * read for the progress line: motion may lag far behind it) */
    _Atomic uint32_t line_read;
    struct ncp_machine_sync answer;
    /* the canon map: the job thread's while a job runs, the caller's
     * between jobs (moves, homing, an unpark's rest) */
    struct ncp_canon_map map;
    uint32_t aux_seq;            /* the last pack numbered (job threads, in turn) */
    uint64_t marks_base;         /* marks_sent when the current job started */
};

#endif
