/* Reading back the per-cycle trace of `cnc-run run --trace` (ncp_nck_opts.trace)
 * in the motion tests: one struct row per servo cycle. Include after <cmocka.h>. */
#ifndef NCP_TEST_TRACE_ROWS_H
#define NCP_TEST_TRACE_ROWS_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

struct row {
    double t, cmd[3], act[3], v;  /* the X Y Z columns; other axes come after all others */
    unsigned line;
    int motion;   /* 0 rapid, 1 feed, 2 arc (G2/G3) */
};

/* The whole trace in f (rewound first); checks the header names the columns.
 * Caller frees the rows. */
static inline struct row *read_trace(FILE *f, size_t *n)
{
    char buf[512];
    rewind(f);
    assert_non_null(fgets(buf, sizeof buf, f));
    /* the axes first; the machine functions follow in columns of their own */
    assert_memory_equal(buf, "t,line,x_cmd,y_cmd,z_cmd,x_act,y_act,z_act,v,motion,", 50);
    size_t cap = 4096;
    struct row *r = malloc(cap * sizeof *r);
    assert_non_null(r);
    *n = 0;
    while (fgets(buf, sizeof buf, f)) {
        if (*n == cap) {
            struct row *bigger = realloc(r, (cap *= 2) * sizeof *r);
            assert_non_null(bigger);
            r = bigger;
        }
        struct row *x = &r[(*n)++];
        assert_int_equal(sscanf(buf, "%lf,%u,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%d", &x->t, &x->line,
                                &x->cmd[0], &x->cmd[1], &x->cmd[2], &x->act[0], &x->act[1],
                                &x->act[2], &x->v, &x->motion),
                         10);
    }
    return r;
}

/* The trace prints positions with 6 decimals: a k-th difference may be off by
 * 2^k half-units of the last digit, divided by T^k. */
#define TRACE_PRINT_Q 0.5e-6

/* Worst ratio of |k-th difference of the commanded positions| / limit over all
 * axes and rows (1 = at the limit), the print rounding taken off first. */
struct trace_worst {
    double vel, acc, jerk;
    unsigned jerk_line, acc_line;
    double jerk_t, acc_t;
};

static inline struct trace_worst trace_limits(const struct row *r, size_t n, double T,
                                              const double vmax[3], const double amax[3],
                                              const double jmax[3])
{
    struct trace_worst w = { 0, 0, 0, 0, 0, 0, 0 };
    const double q = TRACE_PRINT_Q;
    for (size_t k = 3; k < n; k++) {
        for (int j = 0; j < 3; j++) {
            double p0 = r[k - 3].cmd[j], p1 = r[k - 2].cmd[j], p2 = r[k - 1].cmd[j],
                   p3 = r[k].cmd[j];
            double v = fabs(p3 - p2) / T, acc = fabs(p3 - 2 * p2 + p1) / (T * T);
            double jerk = fabs(p3 - 3 * p2 + 3 * p1 - p0) / (T * T * T);
            double rv = (v - 2 * q / T) / vmax[j], ra = (acc - 4 * q / (T * T)) / amax[j];
            double rj = (jerk - 8 * q / (T * T * T)) / jmax[j];
            w.vel = fmax(w.vel, rv);
            if (ra > w.acc) {
                w.acc = ra;
                w.acc_line = r[k].line;
                w.acc_t = r[k].t;
            }
            if (rj > w.jerk) {
                w.jerk = rj;
                w.jerk_line = r[k].line;
                w.jerk_t = r[k].t;
            }
        }
    }
    return w;
}

#endif
