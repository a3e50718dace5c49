/* Jerk-limited (S-curve) velocity profile over a known distance. Each speed
 * change is a ramp of three constant-jerk phases (+j, 0, -j, or +j, -j when
 * the acceleration limit is not reached) that starts and ends at zero
 * acceleration, so profiles of consecutive segments join without an
 * acceleration step. The cruise phase sits between the two ramps. */
#include "planner_int.h"

#include <math.h>
#include <string.h>

#define BISECT_STEPS 48

/* Jerk phase length and constant-acceleration phase length of a ramp by dv. */
static void ramp_times(double dv, double a, double j, double *tj, double *ta)
{
    dv = fabs(dv);
    if (dv * j >= a * a) {
        *tj = a / j;
        *ta = dv / a - a / j;
    } else {
        *tj = sqrt(dv / j);
        *ta = 0;
    }
}

static double ramp_time(double dv, double a, double j)
{
    double tj, ta;
    ramp_times(dv, a, j, &tj, &ta);
    return 2 * tj + ta;
}

double ncp_scurve_dist(double va, double vb, double a, double j)
{
    /* the ramp is point-symmetric about its middle: mean speed (va + vb) / 2 */
    return 0.5 * (va + vb) * ramp_time(vb - va, a, j);
}

double ncp_scurve_reach(double v, double len, double a, double j)
{
    if (len <= 0)
        return v;
    double lo = v, hi = sqrt(v * v + 2 * a * len) + cbrt(len * len * j) + 1e-9;
    for (int k = 0; k < BISECT_STEPS; k++) {
        double mid = 0.5 * (lo + hi);
        if (ncp_scurve_dist(v, mid, a, j) <= len)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

static double peak_dist(const struct ncp_trap *tp, double vp)
{
    return ncp_scurve_dist(tp->v0, vp, tp->a, tp->j) + ncp_scurve_dist(vp, tp->v1, tp->a, tp->j);
}

void ncp_scurve_plan(struct ncp_trap *tp, double len, double v0, double v1, double vmax,
                     double a, double j)
{
    memset(tp, 0, sizeof *tp);
    tp->v0 = v0;
    tp->v1 = v1;
    tp->vp = v0;
    tp->length = len;
    tp->a = a;
    tp->j = j;
    if (len <= 0 || a <= 0 || j <= 0)
        return;
    /* Rounding in the planner's passes may leave the ends a hair out of reach:
     * stiffen the ramp rather than overshoot the distance. */
    while (ncp_scurve_dist(v0, v1, tp->a, tp->j) > len) {
        tp->a *= 1.001;
        tp->j *= 1.002;
    }
    double lo = fmax(v0, v1), hi = fmax(vmax, lo);
    if (peak_dist(tp, hi) > len) {
        for (int k = 0; k < BISECT_STEPS; k++) {
            double mid = 0.5 * (lo + hi);
            if (peak_dist(tp, mid) <= len)
                lo = mid;
            else
                hi = mid;
        }
        hi = lo;
    }
    tp->vp = hi;
    tp->t1 = ramp_time(hi - v0, tp->a, tp->j);
    tp->t3 = ramp_time(hi - v1, tp->a, tp->j);
    tp->d1 = ncp_scurve_dist(v0, hi, tp->a, tp->j);
    double cruise = fmax(0, len - tp->d1 - ncp_scurve_dist(hi, v1, tp->a, tp->j));
    tp->t2 = hi > 0 ? cruise / hi : 0;
    tp->d2 = tp->d1 + cruise;
}

/* Distance and speed t into a ramp from va to vb. */
static double ramp_eval(double va, double vb, double a, double j, double t, double *v)
{
    double tj, ta, sg = vb >= va ? 1.0 : -1.0;
    ramp_times(vb - va, a, j, &tj, &ta);
    const double dur[3] = { tj, ta, tj }, jerk[3] = { sg * j, 0, -sg * j };
    double s = 0, vel = va, acc = 0;
    for (int k = 0; k < 3 && t > 0; k++) {
        double d = fmin(t, dur[k]);
        s += vel * d + 0.5 * acc * d * d + jerk[k] * d * d * d / 6;
        vel += acc * d + 0.5 * jerk[k] * d * d;
        acc += jerk[k] * d;
        t -= d;
    }
    if (t > 0)
        s += vel * t;
    *v = vel;
    return s;
}

double ncp_scurve_eval(const struct ncp_trap *tp, double t, double *v)
{
    double s, vel;
    if (t <= 0) {
        s = 0;
        vel = tp->v0;
    } else if (t < tp->t1) {
        s = ramp_eval(tp->v0, tp->vp, tp->a, tp->j, t, &vel);
    } else if (t < tp->t1 + tp->t2) {
        vel = tp->vp;
        s = tp->d1 + tp->vp * (t - tp->t1);
    } else if (t < tp->t1 + tp->t2 + tp->t3) {
        s = tp->d2 + ramp_eval(tp->vp, tp->v1, tp->a, tp->j, t - tp->t1 - tp->t2, &vel);
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
