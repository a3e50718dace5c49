/* De Boor's algorithm in homogeneous coordinates (w x, w y, w), one knot span
 * at a time, on the clamped uniform knots LinuxCNC's NURBS_FEED uses. */
#include "nurbs_eval.h"

#include <math.h>
#include <string.h>

_Static_assert((NCP_NURBS_WINDOW & (NCP_NURBS_WINDOW - 1)) == 0, "window is a power of two");
_Static_assert(NCP_NURBS_WINDOW >= NCP_NURBS_MAX_ORDER + NCP_NURBS_POINTS_PER_OP,
               "a span's points and one op's more fit the window");

int ncp_nurbs_stream_begin(struct ncp_nurbs_stream *nb, uint32_t count, int order)
{
    memset(nb, 0, sizeof *nb);
    if (order < 2 || order > NCP_NURBS_MAX_ORDER || count < (uint32_t)order)
        return -1;
    nb->count = count;
    nb->order = order;
    return 0;
}

int ncp_nurbs_stream_add(struct ncp_nurbs_stream *nb, const double *xyw, int n)
{
    for (int k = 0; k < n; k++, xyw += 3) {
        if (nb->received >= nb->count)
            return -2;
        double w = xyw[2];
        if (!(w > 0.0) || !isfinite(w) || !isfinite(xyw[0]) || !isfinite(xyw[1]))
            return -1;
        double *p = nb->pt[nb->received & (NCP_NURBS_WINDOW - 1)];
        p[0] = xyw[0] * w;
        p[1] = xyw[1] * w;
        p[2] = w;
        nb->received++;
    }
    return 0;
}

uint32_t ncp_nurbs_stream_ready(const struct ncp_nurbs_stream *nb)
{
    uint32_t k = (uint32_t)nb->order;
    return nb->received >= k ? nb->received - k + 1 : 0;
}

/* Knot j of n + 1 = count points, order k. */
static double knot(const struct ncp_nurbs_stream *nb, long j)
{
    long k = nb->order, n = (long)nb->count - 1;
    if (j < k)
        return 0.0;
    return (double)(j <= n ? j - k + 1 : n - k + 2);
}

void ncp_nurbs_stream_point(const struct ncp_nurbs_stream *nb, uint32_t span, double t, double xy[2])
{
    int p = nb->order - 1;           /* degree */
    long i = (long)span + p;         /* t in [knot(i), knot(i + 1)] */
    double d[NCP_NURBS_MAX_ORDER][3];
    for (int j = 0; j <= p; j++)
        memcpy(d[j], nb->pt[(span + (uint32_t)j) & (NCP_NURBS_WINDOW - 1)], sizeof d[j]);
    for (int r = 1; r <= p; r++)
        for (int j = p; j >= r; j--) {
            double lo = knot(nb, j + i - p), hi = knot(nb, j + 1 + i - r);
            double alpha = (t - lo) / (hi - lo); /* hi > lo: the span has length 1 */
            for (int c = 0; c < 3; c++)
                d[j][c] = (1.0 - alpha) * d[j - 1][c] + alpha * d[j][c];
        }
    xy[0] = d[p][0] / d[p][2];
    xy[1] = d[p][1] / d[p][2];
}
