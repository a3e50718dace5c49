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
struct nck_scaler {
    struct ncp_setpoint a, b;  /* samples around the read position */
    struct ncp_setpoint c;     /* the sample after b, fetched ahead (have_c) */
    int have_c;
    double f;                  /* read position between a (0) and b (1) */
    double r;                  /* rate: setpoints per period, 0..1 */
    double decel, period;
    /* Per-axis acceleration limit the output's second difference must keep
     * (INFINITY: unchecked); last two outputs for it. */
    double amax[NCP_AXES];
    double last[2][NCP_AXES];
    int nlast;
    /* Fine interpolation: servo periods per stream sample (1: the stream is
     * at the servo rate and is read linearly, as before), and the stream's
     * sample period. */
    int ratio;
    double tp;
};

void nck_scaler_init(struct nck_scaler *s, const double start[NCP_AXES], double decel,
                     double period);
double nck_scaler_stop_cycles(const struct nck_scaler *s);
/* The stream comes every ratio periods: read it through cubic Hermite
 * interpolation on the samples' velocities (see scaler.c). */
void nck_scaler_set_ratio(struct nck_scaler *s, int ratio);
/* One period at a rate moving towards target. Returns -1 when the stream ran
 * dry in motion (the output holds the last sample), else 0. */
int nck_scaler_step(struct nck_scaler *s, double target, struct ncp_spsc *ring,
                    struct ncp_setpoint *out);

struct nck {
    const struct ncp_nck_opts *o;
    struct ncp_nck_ctl own_ctl;      /* used when the caller passes none */
    struct ncp_nck_ctl *ctl;
    const struct ncp_machine_cfg *cfg;
    struct ncp_spsc segs, sps, fbs;
    struct ncp_planner *planner;
    struct ncp_canon_map map;
    struct ncp_sim sim;
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
    int64_t end_ns, now_ns;
};

void nck_account(struct nck_summary *s, const struct nck_fb *fb, FILE *trace);
void nck_drain(struct nck *n, struct nck_summary *s);

#endif
