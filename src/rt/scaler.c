/* Time scaling of the setpoint stream. The position loop reads the stream at a
 * rate r (setpoints per period, 0..1), interpolating between neighbouring
 * samples, so it can slow down and stop *along the path* when the ring runs
 * low (a late planner thread) and speed up again when it refills: no jump in
 * position, and the path speed changes at a bounded deceleration. At r = 1 the
 * output is the stream itself, sample for sample.
 *
 * Changing r adds its own acceleration (dr/dt times the stream's velocity) to
 * the stream's (r^2 times the planned one): when both point the same way an
 * axis could exceed its limit. Every rate change is therefore checked on the
 * output's second difference per axis and shortened until it fits. The same
 * mechanism carries live feed override and feed hold.
 *
 * Fine interpolation: when the planner's (rough) period is ratio k servo
 * periods, the read position advances r/k samples per period, and between
 * two samples the output follows the cubic Hermite curve through their
 * positions with their velocities (v * dir) as end tangents. It reproduces
 * the planned motion exactly while that is a polynomial of degree <= 3 over
 * the interval (cruise, a single acceleration phase), so position and
 * velocity are continuous at the samples and nothing lags; the samples
 * themselves (every exact-stop end point among them) are passed exactly.
 * Where the planned acceleration changes inside an interval the cubic's
 * acceleration overshoots it, by up to 2/3 of the planned value when it
 * reverses; the planner keeps 3/5 of the limits then (src/motion/planner.c).
 * Chord error on an arc of radius R, theta = v Tp / R turned per rough
 * period: R theta^4 / 384 at constant speed, plus 0.0162 da Tp^2 theta where
 * the tangential acceleration changes by da inside the interval (the cubic
 * misplaces the point along the path by at most 0.0162 da Tp^2). Example:
 * R = 10 mm, v = 50 mm/s, Tp = 4 ms, da = 4000 mm/s^2: 4e-9 + 2.1e-5 mm,
 * where a straight line between the samples would cut R theta^2 / 8 = 0.5 um.
 * The real-time path stays free of allocation and locks: a few multiplies
 * per axis.
 */
#include "nck_int.h"

#include <math.h>
#include <string.h>

void nck_scaler_init(struct nck_scaler *s, const double start[NCP_AXES], double decel,
                     double period)
{
    memset(s, 0, sizeof *s);
    memcpy(s->a.pos, start, sizeof s->a.pos);
    s->b = s->a;
    s->r = 1;
    s->decel = decel;
    s->period = period;
    for (int j = 0; j < NCP_AXES; j++)
        s->amax[j] = INFINITY;
    s->ratio = 1;
    s->tp = period;
}

void nck_scaler_set_ratio(struct nck_scaler *s, int ratio)
{
    s->ratio = ratio < 1 ? 1 : ratio;
    s->tp = s->period * s->ratio;
}

/* Cycles needed to bring the path speed to rest at the scaler's deceleration. */
double nck_scaler_stop_cycles(const struct nck_scaler *s)
{
    double v = s->r * fmax(s->a.v, s->b.v);
    return v / (s->decel * s->period);
}

static double ramp(const struct nck_scaler *s, double target)
{
    double vs = fmax(s->a.v, s->b.v);
    double dr = vs > 1e-9 ? s->decel * s->period / vs : 1.0;

    return target > s->r ? fmin(target, s->r + dr) : fmax(target, s->r - dr);
}

static void lerp(const struct ncp_setpoint *a, const struct ncp_setpoint *b, double f,
                 double pos[NCP_AXES])
{
    for (int j = 0; j < NCP_AXES; j++)
        pos[j] = f <= 0 ? a->pos[j] : f >= 1 ? b->pos[j] : a->pos[j] + f * (b->pos[j] - a->pos[j]);
}

static void hermite(const struct ncp_setpoint *a, const struct ncp_setpoint *b, double f,
                    double tp, double pos[NCP_AXES])
{
    if (f <= 0 || f >= 1) {
        memcpy(pos, f <= 0 ? a->pos : b->pos, sizeof a->pos);
        return;
    }
    double f2 = f * f, f3 = f2 * f;
    double h00 = 2 * f3 - 3 * f2 + 1, h10 = f3 - 2 * f2 + f;
    double h01 = 3 * f2 - 2 * f3, h11 = f3 - f2;
    for (int j = 0; j < NCP_AXES; j++)
        pos[j] = h00 * a->pos[j] + h01 * b->pos[j] +
                 tp * (h10 * a->v * a->dir[j] + h11 * b->v * b->dir[j]);
}

static void blend(const struct nck_scaler *s, const struct ncp_setpoint *a,
                  const struct ncp_setpoint *b, double f, double pos[NCP_AXES])
{
    if (s->ratio > 1)
        hermite(a, b, f, s->tp, pos);
    else
        lerp(a, b, f, pos);
}

/* Output position if this period advances the read position by r; -1 when
 * that needs a sample the ring has not delivered. */
static int probe(const struct nck_scaler *s, double r, double pos[NCP_AXES])
{
    double f = s->f + r / s->ratio;
    if (f < 1.0) {
        blend(s, &s->a, &s->b, f, pos);
        return 0;
    }
    if (!s->have_c)
        return -1;
    blend(s, &s->b, &s->c, f - 1.0, pos);
    return 0;
}

/* How far the second difference at rate r exceeds the limit (<= 0: fits). */
static double excess(const struct nck_scaler *s, double r)
{
    double pos[NCP_AXES], worst = -INFINITY;
    if (s->nlast < 2 || probe(s, r, pos) != 0)
        return 0;
    double T2 = s->period * s->period;
    for (int j = 0; j < NCP_AXES; j++) {
        double acc = fabs(pos[j] - 2 * s->last[0][j] + s->last[1][j]) / T2;
        worst = fmax(worst, acc - s->amax[j] * (1 + 1e-9));
    }
    return worst;
}

/* The rate nearest the wanted one whose output keeps every axis's limit;
 * keeping the current rate is the fallback (it only resamples the stream). */
static double govern(const struct nck_scaler *s, double want)
{
    if (excess(s, want) <= 0)
        return want;
    double ok = s->r, bad = want;
    if (excess(s, ok) > 0)
        return excess(s, want) < excess(s, ok) ? want : ok;
    for (int k = 0; k < 30; k++) {
        double mid = 0.5 * (ok + bad);
        if (excess(s, mid) <= 0)
            ok = mid;
        else
            bad = mid;
    }
    return ok;
}

static void remember(struct nck_scaler *s, const double pos[NCP_AXES])
{
    memcpy(s->last[1], s->last[0], sizeof s->last[0]);
    memcpy(s->last[0], pos, sizeof s->last[0]);
    if (s->nlast < 2)
        s->nlast++;
}

int nck_scaler_step(struct nck_scaler *s, double target, struct ncp_spsc *ring,
                    struct ncp_setpoint *out)
{
    int dry = 0;
    if (!s->have_c)
        s->have_c = ncp_spsc_pop(ring, &s->c) == 0;
    s->r = govern(s, ramp(s, target));
    s->f += s->r / s->ratio;
    /* a whole number of steps must land on the sample, not just below it */
    if (s->ratio > 1 && fabs(s->f - 1.0) < 1e-9)
        s->f = 1.0;
    if (s->f >= 1.0) {
        if (!s->have_c) {
            s->f = 1.0;
            dry = s->r > 0 && s->b.v > 0;
            s->r = 0;
        } else {
            s->a = s->b;
            s->b = s->c;
            s->f -= 1.0;
            s->have_c = ncp_spsc_pop(ring, &s->c) == 0;
        }
    }
    double f = s->f;
    blend(s, &s->a, &s->b, f, out->pos);
    memcpy(out->dir, s->b.dir, sizeof out->dir);
    out->v = s->r * (s->a.v + f * (s->b.v - s->a.v));
    out->line = f < 0.5 ? s->a.line : s->b.line;
    out->flags = f <= 0 ? s->a.flags : f >= 1 ? s->b.flags : 0;
    remember(s, out->pos);
    return dry ? -1 : 0;
}
