/* The limits of rt-config/lcnc-compare.ini (LinuxCNC's comparison machine:
 * per axis 100 mm/s and 1000 mm/s^2) and the check of a trace against its
 * acceleration, shared by the motion tests that run against it. Include after
 * trace_rows.h and ncpar/config.h. */
#ifndef NCP_TEST_LCNC_LIMITS_H
#define NCP_TEST_LCNC_LIMITS_H

#include <math.h>

/* the trace's 6 decimals: a second difference is off by up to 4 half-units / T^2 */
#define PRINT_Q 0.5e-6
#define AMAX 1000.0
#define VMAX 100.0

static void lcnc_like_cfg(struct ncp_machine_cfg *c)
{
    ncp_machine_cfg_default(c);
    for (int j = 0; j < 3; j++) {
        c->axis[j].max_vel = VMAX;
        c->axis[j].max_acc = AMAX;
    }
}

/* The program text run on lcnc_like_cfg's machine (gcode_src.h's run_text,
 * included before): its trace, n rows, the servo period in *T. */
static inline struct row *run_lcnc_like(const char *prog, size_t *n, double *T)
{
    struct ncp_machine_cfg cfg;
    struct ncp_nck_result res;
    lcnc_like_cfg(&cfg);
    *T = cfg.servo_period;
    return run_text(prog, &cfg, n, &res);
}

/* Largest per-axis acceleration over the limit, from the commanded samples. */
static double worst_acc(const struct row *r, size_t n, double T)
{
    double w = 0;
    for (size_t k = 2; k < n; k++)
        for (int j = 0; j < 3; j++) {
            double a = fabs(r[k].cmd[j] - 2 * r[k - 1].cmd[j] + r[k - 2].cmd[j]) / (T * T);
            w = fmax(w, (a - 4 * PRINT_Q / (T * T)) / AMAX);
        }
    return w;
}

#endif
