/* The simulated plant under injected timing: the same motor, PID and
 * feed-forward as sim.c, but the period is cut where the servo samples and
 * where its output acts, and the plant is stepped exactly over each piece.
 * Kept apart from ncp_sim_step so that a run without injection is stepped
 * exactly as before. */
#include "ncpar/backend.h"

#include <math.h>
#include <string.h>

#include "sim_drive.h"

/* x' = v, v' = -p v + K u, u constant over dt (ZOH, exact) */
static void evolve(const struct ncp_sim *s, double *x, double *v, double u, double dt)
{
    if (dt <= 0)
        return;
    double e = exp(-s->p * dt);
    double vinf = s->K * u / s->p;
    double dv = *v - vinf;
    *x += vinf * dt + dv * (1.0 - e) / s->p;
    *v = vinf + dv * e;
}

static double at_in(const struct ncp_sim *s, const struct ncp_sim_period *h, double t)
{
    double x = h->x0, v = h->v0;
    evolve(s, &x, &v, h->ua, fmin(t, h->tsw));
    if (t > h->tsw)
        evolve(s, &x, &v, h->ub, t - h->tsw);
    return x;
}

/* The axis' position t seconds from the current period's start (t < 0: in
 * the periods kept; before the first one the axis rested where it began). */
static double position_at(const struct ncp_sim *s, const struct ncp_sim_timed *tm, int i,
                          double t, double u_now)
{
    if (t >= 0) {
        double x = s->ax[i].x, v = s->ax[i].v;
        evolve(s, &x, &v, u_now, t);
        return x;
    }
    uint64_t back = (uint64_t)ceil(-t / s->T - 1e-12);
    if (back == 0)
        back = 1;
    if (back > tm->k)
        return tm->k ? tm->hist[0][i].x0 : s->ax[i].x;   /* back < the history here */
    if (back >= NCP_INJECT_FB_HISTORY)
        back = NCP_INJECT_FB_HISTORY - 1;
    const struct ncp_sim_period *h = &tm->hist[(tm->k - back) % NCP_INJECT_FB_HISTORY][i];
    return at_in(s, h, t + (double)back * s->T);
}

void ncp_sim_step_timed(struct ncp_sim *s, struct ncp_sim_timed *tm,
                        const struct ncp_inject_ev *ev, const double cmd[NCP_AXES],
                        const double next[NCP_AXES], double act[NCP_AXES])
{
    double ws = fmin(fmax(ev->sample_s, 0.0), s->T);
    double ta = fmin(ws + fmax(ev->io_s, 0.0), s->T);
    int lost = (ev->what & NCP_INJ_LOSE_FB) != 0;
    for (int i = 0; i < NCP_AXES; i++) {
        struct ncp_sim_axis *a = &s->ax[i];
        struct ncp_sim_period *h = &tm->hist[tm->k % NCP_INJECT_FB_HISTORY][i];
        act[i] = a->x;
        double u0 = tm->u_prev[i], u;
        if (s->disabled) {
            a->integ = a->e_prev = a->vff_prev = 0;
            u0 = u = 0;
            ta = 0;
        } else {
            double y = position_at(s, tm, i, ws - ev->delay_fb_s, u0);
            if (lost && tm->k > 0)
                y = tm->fb[i];
            tm->fb[i] = y;
            double vff = (next[i] - cmd[i]) / s->T;
            double aff = (vff - a->vff_prev) / s->T;
            double e = cmd[i] - y;
            a->integ += e * s->T;
            u = s->kp * e + s->ki * a->integ + s->kd * (e - a->e_prev) / s->T + s->ff1 * vff +
                s->ff2 * aff;
            a->e_prev = e;
            a->vff_prev = vff;
        }
        double x0 = a->x, v0 = a->v;
        evolve(s, &a->x, &a->v, u0, ta);
        /* the drive saturates against the speed it meets when u takes over
         * (off, it gives no torque at all); u acts until the next period's
         * output does, at most a period from now */
        if (!s->disabled)
            u = ncp_sim_drive(s, i, u, a->v, exp(-s->p * (2.0 * s->T - ta)));
        evolve(s, &a->x, &a->v, u, s->T - ta);
        *h = (struct ncp_sim_period){ x0, v0, u0, ta, u };
        tm->u_prev[i] = u;
    }
    tm->k++;
}
