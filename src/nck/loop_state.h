/* The position loop's own state: written and read on its real-time thread
 * only (core.c sets it up before the loop starts; loop.c's report reads it
 * after the join). Anything another thread needs is in crossing.h. */
#ifndef NCPAR_NCK_LOOP_STATE_H
#define NCPAR_NCK_LOOP_STATE_H

#include "homing.h"
#include "machine.h"
#include "probe.h"

struct nck_loop {
    struct nck_sync_state sync;      /* the synchronised run it moves (sync.c) */
    struct nck_mach mach;            /* the machine functions (aux.c) */
    struct nck_homing home;          /* the axes homing (homing.c) */
    struct nck_probe probe;          /* the probe as armed and watched (probe.c) */
    struct ncp_setpoint cur, next;
    double jcmd[NCP_AXES], jnext[NCP_AXES], jact[NCP_AXES];  /* cur, next, actual as joints */
    struct ncp_scaler scaler;
    double decel_normal, decel_full;
    double adv_next;          /* the scaler's read advance that made next (backend.h's adv) */
    int64_t read_k_next;      /* and where it read then (backend.h's read_k, read_f) */
    double read_f_next;
    int slowing;
    uint64_t dry, underruns, fb_dropped;
    int end_seen;                    /* the output sits on an END sample */
    uint64_t ends_seen;              /* the scaler's END count already added to ends_taken */
    int ended, settle, for_expired;  /* batch */
    int drives_on;
    double frozen_prev[NCP_AXES];    /* the actual position one frozen period ago */
    int still_periods, frozen_periods;
    int64_t end_ns, now_ns;
    uint32_t line_now, line_done;
    int64_t loop_last_ns;

    /* timing faults (inject.c); the report is crossing.h's inj_rep */
    int inj_on, inj_timed;           /* anything configured; the plant models timing */
    struct ncp_inject inj;
    struct ncp_inject_rx rx;
    struct ncp_inject_rx rx_axis[NCP_AXES];   /* SETPOINT_FRAMES = per-axis: one per drive */
    struct ncp_inject_guard guard;
    struct ncp_inject_ev inj_ev;
    uint64_t real_misses_seen;
    int timing_stop;                 /* a miss limit tripped: stop along the path */
};

#endif
