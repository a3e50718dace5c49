/* Simulated machine: per axis a motor+load 250/(s(s+25)) under PID with
 * velocity and acceleration feed-forward, stepped exactly (ZOH) at the servo
 * period. Feed-forward FF1 = p/K makes the plant's steady velocity equal the
 * command's, so the PID only corrects disturbances and transients. */
#include "ncpar/backend.h"

#include <math.h>
#include <string.h>

#include "sim_drive.h"

void ncp_sim_init(struct ncp_sim *s, const struct ncp_machine_cfg *cfg,
                  const double start[NCP_AXES])
{
    memset(s, 0, sizeof *s);
    s->T = cfg->servo_period;
    s->K = 250.0;
    s->p = 25.0;
    s->E = exp(-s->p * s->T);
    s->kp = cfg->kp;
    s->ki = cfg->ki;
    s->kd = cfg->kd;
    s->ff1 = cfg->ff1;
    s->ff2 = cfg->ff2;
    for (int i = 0; i < NCP_AXES; i++) {
        const struct ncp_joint_cfg *j = &cfg->joint[i];
        s->v_peak[i] = j->max_vel > 0 ? NCP_SIM_PEAK * j->max_vel : INFINITY;
        s->a_peak[i] = j->max_acc > 0 ? NCP_SIM_PEAK * j->max_acc : INFINITY;
        s->ax[i].x = start ? start[i] : 0;
    }
}

/* x' = v, v' = -p v + K u with u constant over T */
static void plant(struct ncp_sim *s, struct ncp_sim_axis *a, double u)
{
    double vinf = s->K * u / s->p;
    double dv = a->v - vinf;
    a->x += vinf * s->T + dv * (1.0 - s->E) / s->p;
    a->v = vinf + dv * s->E;
}

void ncp_sim_step(struct ncp_sim *s, const double cmd[NCP_AXES], const double next[NCP_AXES],
                  double act[NCP_AXES])
{
    for (int i = 0; i < NCP_AXES; i++) {
        struct ncp_sim_axis *a = &s->ax[i];
        act[i] = a->x;
        if (s->disabled) {
            /* no torque: the axis coasts to rest on the plant's own damping,
             * and the controller starts afresh when enabled again */
            a->integ = 0;
            a->e_prev = 0;
            a->vff_prev = 0;
            plant(s, a, 0.0);
            continue;
        }
        double vff = (next[i] - cmd[i]) / s->T;
        double aff = (vff - a->vff_prev) / s->T;
        double e = cmd[i] - a->x;
        a->integ += e * s->T;
        double u = s->kp * e + s->ki * a->integ + s->kd * (e - a->e_prev) / s->T +
                   s->ff1 * vff + s->ff2 * aff;
        a->e_prev = e;
        a->vff_prev = vff;
        plant(s, a, ncp_sim_drive(s, i, u, a->v, s->E));
    }
}
