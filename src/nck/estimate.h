/* The loaded program's cycle time, found before the first cut (estimate.c):
 * the NCK's own batch run (ncp_nck_run, the planner and position loop of
 * cnc-run run --clock virtual) on a copy of the machine, in a thread of its
 * own at a low priority. The service thread starts, polls and ends it; the
 * serving NCK's real-time threads never see it. */
#ifndef NCPAR_NCK_ESTIMATE_H
#define NCPAR_NCK_ESTIMATE_H

#include "ncpar/analyzer.h"
#include "ncpar/config.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

struct nck_estimate_run;

struct nck_estimate {
    struct nck_estimate_run *run;    /* the thread's, while state is RUNNING */
    pthread_t th;
    int state;                       /* enum ncp_nck_estimate_state */
    double program_time, path_length, ferr_max;  /* s, mm, mm (state DONE) */
    int pauses;                      /* M0, M1, M6 waited at (state DONE) */
    double ext_min[NCP_AXES], ext_max[NCP_AXES]; /* commanded extents (state DONE) */
    double seconds;                  /* how long it took to find (host time) */
    char why[256];                   /* FAILED, CANCELLED: why */
    /* Threads not yet ended, cancelled ones too (they end on their own):
     * kept across starts, so it stays last (nck_estimate_start clears the
     * fields before it) */
    atomic_int live;
};

/* What the estimate runs: the program's text as loaded (copied), the
 * machine, the interpreter's configuration and its parameters now (offsets,
 * the coordinate system), and where the machine's joints stand. */
struct nck_estimate_input {
    const char *name, *text;
    size_t len;
    const struct ncp_machine_cfg *cfg;
    const struct ncp_analyzer_cfg *acfg;
    const struct ncp_analyzer *interp;
    const double *joints;            /* NCP_AXES, or NULL: the machine's zero */
    const double *machine;           /* the same point as machine axes (NCP_AXES), where
                                        the program's first move starts; NULL: zero */
};

/* Ends an estimate still running (cancel), then starts one. 0, or -1 with
 * the reason in e->why (state FAILED). */
int nck_estimate_start(struct nck_estimate *e, const struct nck_estimate_input *in);
/* 1 when a running estimate has just ended (its result is in e), else 0. */
int nck_estimate_poll(struct nck_estimate *e);
/* Asks a running estimate to end within a few blocks of its program, and
 * returns without waiting for it (its thread frees what it ran on when it
 * ends): state CANCELLED with why. Nothing when none runs; the result when
 * it had ended already. */
void nck_estimate_cancel(struct nck_estimate *e, const char *why);
/* Cancels what still runs and waits until every estimate thread, cancelled
 * ones too, has ended (the NCK's end). */
void nck_estimate_free(struct nck_estimate *e);

#endif
