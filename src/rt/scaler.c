/* Time scaling of the setpoint stream. The position loop reads the stream at a
 * rate r (setpoints per period, 0..1), interpolating between neighbouring
 * samples, so it can slow down and stop *along the path* when the ring runs
 * low (a late planner thread) and speed up again when it refills: no jump in
 * position, and the path speed changes at a bounded deceleration. At r = 1 the
 * output is the stream itself, sample for sample. */
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
}

/* Cycles needed to bring the path speed to rest at the scaler's deceleration. */
double nck_scaler_stop_cycles(const struct nck_scaler *s)
{
    double v = s->r * fmax(s->a.v, s->b.v);
    return v / (s->decel * s->period);
}

static void ramp(struct nck_scaler *s, double target)
{
    double vs = fmax(s->a.v, s->b.v);
    double dr = vs > 1e-9 ? s->decel * s->period / vs : 1.0;
    if (target > s->r)
        s->r = fmin(target, s->r + dr);
    else
        s->r = fmax(target, s->r - dr);
}

int nck_scaler_step(struct nck_scaler *s, double target, struct ncp_spsc *ring,
                    struct ncp_setpoint *out)
{
    int dry = 0;
    ramp(s, target);
    s->f += s->r;
    while (s->f >= 1.0) {
        struct ncp_setpoint nx;
        if (ncp_spsc_pop(ring, &nx) != 0) {
            s->f = 1.0;
            dry = s->r > 0 && s->b.v > 0;
            s->r = 0;
            break;
        }
        s->a = s->b;
        s->b = nx;
        s->f -= 1.0;
    }
    double f = s->f;
    for (int j = 0; j < NCP_AXES; j++) {
        out->pos[j] = f <= 0 ? s->a.pos[j] : f >= 1 ? s->b.pos[j]
                                                     : s->a.pos[j] + f * (s->b.pos[j] - s->a.pos[j]);
        out->dir[j] = s->b.dir[j];
    }
    out->v = s->r * (s->a.v + f * (s->b.v - s->a.v));
    out->line = f < 0.5 ? s->a.line : s->b.line;
    out->flags = f <= 0 ? s->a.flags : f >= 1 ? s->b.flags : 0;
    return dry ? -1 : 0;
}
