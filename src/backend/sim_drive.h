/* The simulated drive's saturation (struct ncp_sim's comment): shared by the
 * plain and the timed step, so that both bound the plant alike. */
#ifndef NCPAR_SIM_DRIVE_H
#define NCPAR_SIM_DRIVE_H

#include <math.h>

#include "ncpar/backend.h"

/* u as the drive of joint i delivers it to a plant moving at v, for a time
 * over which the velocity decays by E = exp(-p t) towards K u / p: the speed
 * at the end of that time within v_peak, then the acceleration at its start
 * within a_peak, which wins when they disagree (an axis above v_peak, which
 * only a change of limits could leave it at, brakes at a_peak, not at once).
 * Both intervals hold u = p v / K, so they always meet. */
static inline double ncp_sim_drive(const struct ncp_sim *s, int i, double u, double v, double E)
{
    double g = s->p / (s->K * (1.0 - E));
    u = fmin(fmax(u, g * (-s->v_peak[i] - v * E)), g * (s->v_peak[i] - v * E));
    double lo = (s->p * v - s->a_peak[i]) / s->K, hi = (s->p * v + s->a_peak[i]) / s->K;
    return fmin(fmax(u, lo), hi);
}

#endif
