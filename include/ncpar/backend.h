/* Backends: what the position loop drives. The simulated machine (default) is a
 * plant per axis under PID with feed-forward; it reports actual positions. */
#ifndef NCPAR_BACKEND_H
#define NCPAR_BACKEND_H

#include "ncpar/motion.h"

struct ncp_sim_axis {
    double x, v;         /* plant state: position (mm) and velocity (mm/s) */
    double integ;        /* PID integral */
    double e_prev;       /* last following error */
    double vff_prev;     /* feed-forward velocity of the previous cycle */
};

/* Each axis: G(s) = K / (s (s + p)), K = 250, p = 25 (seed 003), discretised
 * exactly with a zero-order hold over the servo period. */
struct ncp_sim {
    double T, K, p, E;   /* E = exp(-p T) */
    double kp, ki, kd, ff1, ff2;
    struct ncp_sim_axis ax[NCP_AXES];
};

void ncp_sim_init(struct ncp_sim *s, const struct ncp_machine_cfg *cfg,
                  const double start[NCP_AXES]);
/* One servo cycle: measures the actual positions (act, before the step), runs
 * the controller on the error to cmd and applies its output over the period.
 * next is the command of the following cycle: feed-forward uses the velocity
 * of the interval being driven, not the one just past. */
void ncp_sim_step(struct ncp_sim *s, const double cmd[NCP_AXES], const double next[NCP_AXES],
                  double act[NCP_AXES]);

#endif
