/* Trapezoidal velocity profile over a known distance. */
#include "planner_int.h"

#include <math.h>
#include <string.h>

void ncp_trap_plan(struct ncp_trap *tp, double len, double v0, double v1, double vmax,
                   double a)
{
    memset(tp, 0, sizeof *tp);
    tp->v0 = v0;
    tp->v1 = v1;
    tp->length = len;
    if (len <= 0 || a <= 0) {
        tp->a = a;
        tp->vp = v0;
        return;
    }
    /* Rounding in the planner's passes may leave the ends a hair out of reach:
     * stretch the acceleration rather than overshoot the distance. */
    double need = fabs(v1 * v1 - v0 * v0) / (2 * len);
    if (need > a)
        a = need;
    tp->a = a;
    double vp = sqrt(a * len + 0.5 * (v0 * v0 + v1 * v1));
    if (vp > vmax)
        vp = vmax;
    if (vp < v0)
        vp = v0;
    if (vp < v1)
        vp = v1;
    tp->vp = vp;
    tp->t1 = (vp - v0) / a;
    tp->t3 = (vp - v1) / a;
    double d1 = (vp * vp - v0 * v0) / (2 * a);
    double d3 = (vp * vp - v1 * v1) / (2 * a);
    double cruise = len - d1 - d3;
    if (cruise < 0)
        cruise = 0;
    tp->t2 = vp > 0 ? cruise / vp : 0;
    tp->d1 = d1;
    tp->d2 = d1 + cruise;
}

double ncp_trap_duration(const struct ncp_trap *tp)
{
    return tp->t1 + tp->t2 + tp->t3;
}

double ncp_trap_eval(const struct ncp_trap *tp, double t, double *v)
{
    if (tp->j > 0)
        return ncp_scurve_eval(tp, t, v);
    double s, vel;
    if (t <= 0) {
        s = 0;
        vel = tp->v0;
    } else if (t < tp->t1) {
        vel = tp->v0 + tp->a * t;
        s = tp->v0 * t + 0.5 * tp->a * t * t;
    } else if (t < tp->t1 + tp->t2) {
        vel = tp->vp;
        s = tp->d1 + tp->vp * (t - tp->t1);
    } else if (t < tp->t1 + tp->t2 + tp->t3) {
        double tau = t - tp->t1 - tp->t2;
        vel = tp->vp - tp->a * tau;
        s = tp->d2 + tp->vp * tau - 0.5 * tp->a * tau * tau;
    } else {
        s = tp->length;
        vel = tp->v1;
    }
    if (s > tp->length)
        s = tp->length;
    if (v)
        *v = vel;
    return s;
}
