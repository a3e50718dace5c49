/* The servo's side of a late or lost setpoint: what it runs on instead. Hold
 * is what a drive without a plan does; the extrapolations continue the
 * interpolator's profile from the samples it did receive; time-stamped
 * setpoints (sent one period ahead, as a CSP drive gets them, and evaluated
 * at the receiver's own sampling instant) cover a single loss exactly and
 * the sampling latency too. */
#include "ncpar/inject.h"

#include <string.h>

void ncp_inject_rx_init(struct ncp_inject_rx *rx, int policy)
{
    memset(rx, 0, sizeof *rx);
    rx->policy = policy;
}

/* Lagrange through the m newest samples, evaluated at t (in periods). */
static double through(const struct ncp_inject_rx *rx, int m, int j, double t)
{
    double sum = 0;
    for (int a = 0; a < m; a++) {
        double w = 1;
        for (int b = 0; b < m; b++)
            if (b != a)
                w *= (t - (double)rx->k[b]) / (double)(rx->k[a] - rx->k[b]);
        sum += w * rx->c[a][j];
    }
    return sum;
}

/* The setpoint the policy expects at t from what it received. */
static double estimate(const struct ncp_inject_rx *rx, int j, double t)
{
    switch (rx->policy) {
    case NCP_MISS_TIMESTAMPED:
        if (rx->have_ahead && rx->n >= 1) {
            double k0 = (double)rx->k[0];
            return rx->c[0][j] + (t - k0) * (rx->ahead[j] - rx->c[0][j]);
        }
        break;
    case NCP_MISS_EXTRAPOLATE2:
    case NCP_MISS_EXTRAPOLATE:
        /* too few samples yet for a parabola: a line; for a line: hold */
        if (rx->n >= 3 && rx->policy == NCP_MISS_EXTRAPOLATE2)
            return through(rx, 3, j, t);
        if (rx->n >= 2)
            return through(rx, 2, j, t);
        break;
    default:
        break;
    }
    return rx->last[j];
}

void ncp_inject_rx_take(struct ncp_inject_rx *rx, int64_t k, int arrived, const double *cmd,
                        const double *next, double frac, int axes, double *use,
                        double *use_next)
{
    if (!rx->have_last) {
        /* nothing used yet: the machine rests where the stream starts */
        memcpy(rx->last, cmd, sizeof rx->last[0] * (size_t)axes);
        rx->have_last = 1;
    }
    if (arrived) {
        memmove(rx->c[1], rx->c[0], sizeof rx->c[0] * 2);
        memmove(&rx->k[1], &rx->k[0], sizeof rx->k[0] * 2);
        memcpy(rx->c[0], cmd, sizeof rx->c[0][0] * (size_t)axes);
        rx->k[0] = k;
        if (rx->n < 3)
            rx->n++;
        memcpy(rx->ahead, next, sizeof rx->ahead[0] * (size_t)axes);
        rx->have_ahead = 1;
        for (int j = 0; j < axes; j++) {
            double d = next[j] - cmd[j];
            int ts = rx->policy == NCP_MISS_TIMESTAMPED;
            use[j] = ts ? cmd[j] + frac * d : cmd[j];
            use_next[j] = use[j] + d;
        }
    } else {
        double t = (double)k + (rx->policy == NCP_MISS_TIMESTAMPED ? frac : 0.0);
        for (int j = 0; j < axes; j++) {
            use[j] = estimate(rx, j, t);
            use_next[j] = rx->policy == NCP_MISS_HOLD ? use[j] : estimate(rx, j, t + 1);
        }
    }
    memcpy(rx->last, use, sizeof rx->last[0] * (size_t)axes);
}
