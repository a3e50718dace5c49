/* One servo cycle as the loop hands it to the caller's thread, and the
 * summary and trace the caller makes of them (stats.c). */
#ifndef NCPAR_NCK_CYCLE_H
#define NCPAR_NCK_CYCLE_H

#include "ncpar/backend.h"
#include "ncpar/nck.h"

#include <stdio.h>

#define NCK_CONTOUR_HISTORY 64

struct nck_core;

/* One servo cycle as the position loop saw it. */
struct nck_fb {
    double t, v;
    double adv;              /* the scaler's read of the stream (samples; 1: 100 %) */
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
    double job_ferr_max;     /* since serve's last program run began */
    double job_done_s;       /* of the stream's time at 100 %, read since it began */
    double ext_min[NCP_AXES], ext_max[NCP_AXES];  /* commanded, since the start */
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

/* stats.c */
void nck_account(struct nck_summary *s, unsigned axis_mask, const struct nck_fb *fb, FILE *trace);
/* Reads every cycle the loop has written: trace, summary, last cycle. */
int nck_read_cycles(struct nck_core *n);
/* The trace's first row: the fixed columns, then cmd and act of each of
 * the machine's axes beyond X Y Z (axis_mask). */
void nck_trace_header(FILE *trace, const struct ncp_machine_cfg *cfg, int joints, int rings);
/* Writes the rows gathered so far. 0, or -1 when the write failed. */
int nck_trace_flush(struct nck_summary *s, FILE *trace);

/* pauses.c: the operator is told of a wait the loop began (stats.c) */
void nck_wait_began(struct nck_core *n, const struct nck_fb *fb);
const char *nck_wait_name(int wait);
int nck_wait_operator(int wait);

#endif
