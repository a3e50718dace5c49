/* Geometry of one segment: where the tool is at a path distance. */
#include "ncpar/motion.h"

#include <math.h>

static void unit(double v[3])
{
    double n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int i = 0; i < 3; i++)
        v[i] = n > 0 ? v[i] / n : 0;
}

static void eval_line(const struct ncp_seg *s, double dist, double pos[NCP_AXES],
                      double tan[NCP_AXES])
{
    double f = s->length > 0 ? dist / s->length : 1.0;
    for (int i = 0; i < NCP_AXES; i++) {
        double d = s->end[i] - s->start[i];
        /* the end point is hit bit-exactly, whatever the rounding of f */
        pos[i] = f >= 1.0 ? s->end[i] : s->start[i] + d * f;
        if (tan)
            tan[i] = s->length > 0 ? d / s->length : 0;
    }
}

void ncp_seg_set_length(struct ncp_seg *s)
{
    double xyz = 0, abc = 0;
    for (int i = 0; i < 6; i++) {
        double d = (s->end[i] - s->start[i]) * (s->end[i] - s->start[i]);
        if (i < 3)
            xyz += d;
        else
            abc += d;
    }
    s->angular = xyz < 1e-18 && abc > 0;
    s->length = sqrt(s->angular ? abc : xyz);
}

int ncp_seg_moves_other(const struct ncp_seg *s)
{
    for (int i = 3; i < NCP_AXES; i++)
        if (s->end[i] != s->start[i])
            return 1;
    return 0;
}

static void eval_arc(const struct ncp_seg *s, double dist, double pos[NCP_AXES],
                     double tan[NCP_AXES])
{
    if (dist >= s->length) {
        for (int i = 0; i < NCP_AXES; i++)
            pos[i] = s->end[i];
        dist = s->length;
    }
    double l = s->length > 0 ? dist / s->length : 1.0;
    /* the axes beyond X Y Z follow the arc linearly */
    for (int i = 3; i < NCP_AXES; i++) {
        double d = s->end[i] - s->start[i];
        if (dist < s->length)
            pos[i] = s->start[i] + d * l;
        if (tan)
            tan[i] = s->length > 0 ? d / s->length : 0;
    }
    double phi = s->angle * l;
    double r = s->r0 + (s->r1 - s->r0) * l;
    double c = cos(phi), sn = sin(phi);
    if (dist < s->length) {
        for (int i = 0; i < 3; i++)
            pos[i] = s->center[i] + r * (c * s->u[i] + sn * s->w[i]) + s->normal[i] * s->axial * l;
    }
    if (tan) {
        double dr = s->r1 - s->r0;
        for (int i = 0; i < 3; i++)
            tan[i] = dr * (c * s->u[i] + sn * s->w[i]) +
                     r * s->angle * (-sn * s->u[i] + c * s->w[i]) + s->normal[i] * s->axial;
        unit(tan);
    }
}

/* The corner a parabola turns at: C in X Y Z; the other axes do not turn
 * in it (start and end agree there), so their midpoint. */
static void parab_corner(const struct ncp_seg *s, double c[NCP_AXES])
{
    for (int i = 0; i < NCP_AXES; i++)
        c[i] = i < 3 ? s->center[i] : 0.5 * (s->start[i] + s->end[i]);
}

double ncp_seg_ratio(const struct ncp_seg *s)
{
    return s->kind == NCP_SEG_PARAB && s->r0 > 0 && s->r1 > 0 && s->r0 != s->r1 ? s->r1 / s->r0
                                                                                  : 0;
}

/* The corner curve: a quadratic through start, the corner and end. Its
 * second derivative is constant, so at a constant parameter speed every
 * axis accelerates constantly, the axes of both lines at once (an uneven
 * one: on its ramp, see ncp_seg_ratio). */
static void eval_parab(const struct ncp_seg *s, double dist, double pos[NCP_AXES],
                       double tan[NCP_AXES])
{
    double l, dsdl, c[NCP_AXES];
    dist = fmin(dist, s->length);
    if (ncp_seg_ratio(s) > 0) {
        /* dist = 2 r0 l + (r1 - r0) l^2 solved for l, in the form that
         * stays exact as r1 - r0 goes to 0 */
        l = s->length > 0 ? dist / (s->r0 + sqrt(s->r0 * s->r0 + (s->r1 - s->r0) * dist)) : 1.0;
        l = fmin(l, 1.0);
        dsdl = 2 * s->r0 + 2 * (s->r1 - s->r0) * l;
    } else {
        l = s->length > 0 ? fmin(dist / s->length, 1.0) : 1.0;
        dsdl = s->length;
    }
    double m = 1 - l;
    parab_corner(s, c);
    for (int i = 0; i < NCP_AXES; i++) {
        pos[i] = l >= 1.0 ? s->end[i] : m * m * s->start[i] + 2 * l * m * c[i] + l * l * s->end[i];
        if (tan)
            tan[i] = dsdl > 0 ? 2 * (m * (c[i] - s->start[i]) + l * (s->end[i] - c[i])) / dsdl : 0;
    }
}

void ncp_seg_parab_rates(const struct ncp_seg *s, double rate[NCP_AXES], double curv[NCP_AXES])
{
    double c[NCP_AXES], ratio = ncp_seg_ratio(s);
    parab_corner(s, c);
    for (int j = 0; j < NCP_AXES; j++) {
        if (ratio > 0) {
            double u1 = (c[j] - s->start[j]) / s->r0, u2 = (s->end[j] - c[j]) / s->r1;
            rate[j] = fmax(fabs(u1), fabs(u2));
            curv[j] = fabs(ratio * u2 - u1) / (2 * s->r0);
            continue;
        }
        double u1 = 2 * (c[j] - s->start[j]) / s->length, u2 = 2 * (s->end[j] - c[j]) / s->length;
        rate[j] = fmax(fabs(u1), fabs(u2));
        curv[j] = fabs(u2 - u1) / s->length;
    }
}

void ncp_seg_eval(const struct ncp_seg *s, double dist, double pos[NCP_AXES],
                  double tangent[NCP_AXES])
{
    if (dist < 0)
        dist = 0;
    switch (s->kind) {
    case NCP_SEG_ARC:
        eval_arc(s, dist, pos, tangent);
        break;
    case NCP_SEG_LINE:
        eval_line(s, dist, pos, tangent);
        break;
    case NCP_SEG_PARAB:
        eval_parab(s, dist, pos, tangent);
        break;
    default:
        for (int i = 0; i < NCP_AXES; i++) {
            pos[i] = s->end[i];
            if (tangent)
                tangent[i] = 0;
        }
    }
}
