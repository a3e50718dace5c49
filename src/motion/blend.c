/* G64 corner blending: two lines meeting at a corner are joined by a circular
 * arc tangent to both, so the path keeps its tangent and the corner is taken at
 * speed. The arc stays within the tolerance P of the corner and uses at most
 * half of either line, so neighbouring blends never overlap; the planner
 * (try_blend) makes it no larger than the speed it is for needs. */
#include "planner_int.h"

#include <math.h>
#include <string.h>

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross3(const double a[3], const double b[3], double o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

static void direction(const struct ncp_seg *s, double u[3])
{
    for (int i = 0; i < 3; i++)
        u[i] = (s->end[i] - s->start[i]) / s->length;
}

int ncp_blend_corner(const struct ncp_seg *prev, const struct ncp_seg *cur, double max_trim,
                     struct ncp_seg *arc, double *trim)
{
    /* the blend arc is drawn in X Y Z: a corner where another axis moves
     * is a kink instead */
    if (prev->kind != NCP_SEG_LINE || cur->kind != NCP_SEG_LINE ||
        prev->term != NCP_TERM_CONTINUOUS || prev->length <= 0 || cur->length <= 0 ||
        ncp_seg_moves_other(prev) || ncp_seg_moves_other(cur))
        return 0;
    double u1[3], u2[3], n[3];
    direction(prev, u1);
    direction(cur, u2);
    double c = dot3(u1, u2);
    /* collinear needs no blend; a near reversal would need a vanishing radius */
    if (c > 1 - 1e-12 || c < -0.999)
        return 0;
    double phi = acos(c), th = tan(0.5 * phi);
    double d = fmin(max_trim, 0.5 * fmin(prev->length, cur->length));
    if (prev->tolerance > 0) {
        double r_tol = prev->tolerance / (1.0 / cos(0.5 * phi) - 1.0);
        d = fmin(d, r_tol * th);
    }
    if (d < 1e-6)
        return 0;
    double r = d / th;
    cross3(u1, u2, n);
    double nl = sqrt(dot3(n, n));
    memset(arc, 0, sizeof *arc);
    arc->kind = NCP_SEG_ARC;
    arc->term = NCP_TERM_CONTINUOUS;
    arc->traverse = (uint8_t)(prev->traverse && cur->traverse);
    arc->line = cur->line;  /* the corner is where the next block's motion begins */
    arc->aux = prev->aux;   /* what comes with the next block waits for its own segment */
    arc->feed = fmin(prev->feed, cur->feed);
    arc->blend_feed = fmin(prev->blend_feed > 0 ? prev->blend_feed : prev->feed,
                           cur->blend_feed > 0 ? cur->blend_feed : cur->feed);
    double bis[3], bl = 0;
    for (int i = 0; i < 3; i++) {
        bis[i] = u2[i] - u1[i];
        bl += bis[i] * bis[i];
    }
    bl = sqrt(bl);
    for (int i = 3; i < NCP_AXES; i++)
        arc->start[i] = arc->end[i] = prev->end[i];
    for (int i = 0; i < 3; i++) {
        arc->start[i] = prev->end[i] - u1[i] * d;
        arc->end[i] = prev->end[i] + u2[i] * d;
        arc->normal[i] = n[i] / nl;
        arc->center[i] = prev->end[i] + bis[i] / bl * (r / cos(0.5 * phi));
    }
    for (int i = 0; i < 3; i++)
        arc->u[i] = (arc->start[i] - arc->center[i]) / r;
    cross3(arc->normal, arc->u, arc->w);
    arc->r0 = arc->r1 = r;
    arc->angle = phi;
    arc->length = r * phi;
    *trim = d;
    return 1;
}
