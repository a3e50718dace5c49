/* State of one NCK run, shared by its threads (nck.c) and the statistics
 * consumer (nck_stats.c). Not part of the public contract. */
#ifndef NCPAR_RT_NCK_INT_H
#define NCPAR_RT_NCK_INT_H

#include "ncpar/backend.h"
#include "ncpar/motion.h"
#include "ncpar/pipeline.h"
#include "ncpar/rt.h"

#define NCK_CONTOUR_HISTORY 64

enum { NCK_MSG_SEG, NCK_MSG_END };
struct nck_seg_msg {
    int kind;
    struct ncp_seg seg;
};

/* One servo cycle as the position loop saw it. */
struct nck_fb {
    double t, v;
    double cmd[NCP_AXES], act[NCP_AXES];
    uint32_t line;
    uint32_t flags;          /* the setpoint's (NCP_SP_RAPID / NCP_SP_ARC for the trace) */
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
};

/* scaler.c: reads the setpoint stream at a variable rate (see there). */
#include "scaler.h"

struct nck {
    const struct ncp_nck_opts *o;
    struct ncp_nck_ctl own_ctl;      /* used when the caller passes none */
    struct ncp_nck_ctl *ctl;
    const struct ncp_machine_cfg *cfg;
    struct ncp_spsc segs, sps, fbs;
    struct ncp_planner *planner;
    struct ncp_canon_map map;
    struct ncp_backend *be;          /* opened and started by ncp_nck_run */
    struct ncp_rt_loop loop;
    _Atomic int abort;
    _Atomic int planner_done;
    /* interpreter thread */
    int interp_rc;
    struct ncp_diag interp_diag, map_diag;
    int map_failed;
    /* position loop (its thread only) */
    struct ncp_setpoint cur, next;   /* commanded this period, and the one after */
    struct nck_scaler scaler;
    int slowing;                     /* the ring ran low: decelerating along the path */
    uint64_t dry;                    /* the ring ran empty in motion anyway */
    uint64_t underruns, fb_dropped;
    int ended, settle, fault, for_expired, fault_axis;
    double fault_err;
    uint32_t fault_line;
    int backend_fault;               /* the backend's cycle failed (drive fault) */
    uint32_t line_now, line_done;    /* block in progress, last completed block */
    int64_t end_ns, now_ns;
};

void nck_account(struct nck_summary *s, const struct nck_fb *fb, FILE *trace);
void nck_drain(struct nck *n, struct nck_summary *s);

#endif
