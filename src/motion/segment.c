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

static void eval_arc(const struct ncp_seg *s, double dist, double pos[NCP_AXES],
                     double tan[NCP_AXES])
{
    if (dist >= s->length) {
        for (int i = 0; i < NCP_AXES; i++)
            pos[i] = s->end[i];
        dist = s->length;
    }
    double l = s->length > 0 ? dist / s->length : 1.0;
    double phi = s->angle * l;
    double r = s->r0 + (s->r1 - s->r0) * l;
    double c = cos(phi), sn = sin(phi);
    if (dist < s->length) {
        for (int i = 0; i < NCP_AXES; i++)
            pos[i] = s->center[i] + r * (c * s->u[i] + sn * s->w[i]) + s->normal[i] * s->axial * l;
    }
    if (tan) {
        double dr = s->r1 - s->r0;
        for (int i = 0; i < NCP_AXES; i++)
            tan[i] = dr * (c * s->u[i] + sn * s->w[i]) +
                     r * s->angle * (-sn * s->u[i] + c * s->w[i]) + s->normal[i] * s->axial;
        unit(tan);
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
    default:
        for (int i = 0; i < NCP_AXES; i++) {
            pos[i] = s->end[i];
            if (tangent)
                tangent[i] = 0;
        }
    }
}
