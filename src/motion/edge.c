/* Corners run on the band's outer edges. G64 P lets the path stray P from
 * the programmed lines; a blend tangent to the lines themselves can only use
 * the inner half of that band. Moving the vertex out along the outer
 * bisector, to where the lines' outer edges (P outside each) meet, lets the
 * blend start P outside and cut in to P inside: twice the depth, so twice
 * the trim and sqrt(2) times the speed of the parabola within P of the
 * lines. The moved line from one vertex to the next stays within P of its
 * programmed line (both ends are at most P off it, square to it, and a
 * straight line between them no further), and the vertex itself, outside
 * the band, is always cut off by a blend that is measured against the
 * programmed polyline (ncp_edge_trims): the planner holds such lines back
 * two deep, so that a vertex moves only where the line after it ends in
 * such a corner too (planner.c). */
#include "planner_int.h"

#include <math.h>
#include <string.h>

/* Pieces of a blend measured against the programmed polyline: each piece's
 * triangle (below) lies at most |B''| / (8 n^2) beyond the curve, 0.3 % of
 * P for the deepest blends of P0.01. */
#define EDGE_PIECES 16
/* A blend that leaves a moved line runs P from the programmed one exactly:
 * rounding may not reject it. */
#define EDGE_ROUND 1e-9
/* Trims tried, in steps of 2^(1/3) over ten octaves below the largest that
 * matters (64 P / sin(phi), where a blend lies 16 P off its lines, or what
 * the lines allow), before the edges of the range within P are bisected: at
 * a moved vertex that range spans a factor of about 2 (4 P / sin(phi) to
 * 8 P / sin(phi)), so these steps cannot miss it. */
#define EDGE_SCAN 30
#define EDGE_STEP 1.2599210498948732
#define EDGE_REACH 64
#define EDGE_BISECT 12
/* Turns this slight gain little from moving the vertex (the blend is long
 * already), turns this sharp move it far beyond the corner (1 / cos(phi/2)). */
#define EDGE_TURN_MIN (5 * M_PI / 180)
#define EDGE_TURN_MAX (160 * M_PI / 180)

/* A programmed segment, set up for many distances. */
struct edge_seg {
    double a[3], d[3], dd;
};

static void seg_init(struct edge_seg *g, const double a[3], const double b[3])
{
    g->dd = 0;
    for (int i = 0; i < 3; i++) {
        g->a[i] = a[i];
        g->d[i] = b[i] - a[i];
        g->dd += g->d[i] * g->d[i];
    }
}

/* fmin and fmax are calls here (NaN rules); these are not */
static inline double lesser(double x, double y)
{
    return x < y ? x : y;
}

static inline double greater(double x, double y)
{
    return x > y ? x : y;
}

static double seg_dist2(const struct edge_seg *g, const double q[3])
{
    double w[3] = { q[0] - g->a[0], q[1] - g->a[1], q[2] - g->a[2] };
    double t = g->dd > 0 ? lesser(1, greater(0, dot3(w, g->d) / g->dd)) : 0, e = 0;
    for (int i = 0; i < 3; i++) {
        double c = w[i] - t * g->d[i];
        e += c * c;
    }
    return e;
}

double ncp_edge_dev(const struct ncp_seg *blend, const double a[3], const double c[3],
                    const double b[3], double limit)
{
    /* the parabola is the quadratic Bezier start, centre, end; each piece
     * between two samples is one too, inside the triangle of its ends and
     * the meeting of its end tangents, and the distance to a segment is
     * convex: so the piece lies within the largest of the three corners'
     * distances to whichever programmed segment is nearer for all three */
    struct edge_seg g1, g2;
    seg_init(&g1, a, c);
    seg_init(&g2, c, b);
    double worst = 0, q0[3], q1[3], ctrl[3], first0, second0;
    memcpy(q0, blend->start, sizeof q0);
    first0 = seg_dist2(&g1, q0);
    second0 = seg_dist2(&g2, q0);
    for (int k = 0; k < EDGE_PIECES; k++) {
        double t0 = (double)k / EDGE_PIECES, t1 = (double)(k + 1) / EDGE_PIECES;
        for (int i = 0; i < 3; i++) {
            double p0 = blend->start[i], pc = blend->center[i], p1 = blend->end[i];
            q1[i] = (1 - t1) * (1 - t1) * p0 + 2 * t1 * (1 - t1) * pc + t1 * t1 * p1;
            /* B(t0) + (t1 - t0) / 2 B'(t0) */
            ctrl[i] = q0[i] + (t1 - t0) * ((1 - t0) * (pc - p0) + t0 * (p1 - pc));
        }
        double first1 = seg_dist2(&g1, q1), second1 = seg_dist2(&g2, q1);
        double on_first = greater(first0, greater(first1, seg_dist2(&g1, ctrl)));
        double on_second = greater(second0, greater(second1, seg_dist2(&g2, ctrl)));
        worst = greater(worst, lesser(on_first, on_second));
        if (worst > limit * limit)
            break;  /* beyond what the caller asks about: no need to know how far */
        memcpy(q0, q1, sizeof q0);
        first0 = first1;
        second0 = second1;
    }
    return sqrt(worst);
}

/* Does the blend of trim d (rho d off cur) stay within tol of k's programmed
 * polyline? No where there is no such blend. */
static int fits(const struct ncp_seg *free_prev, const struct ncp_seg *cur,
                const struct plan_corner *k, double rho, double d, double tol)
{
    struct ncp_seg bl;
    double got, got_cur;
    if (rho == 1 ? !ncp_blend_corner(free_prev, cur, d, &bl, &got)
                 : !ncp_blend_corner_ratio_at(free_prev, cur, rho, d, &bl, &got, &got_cur))
        return 0;
    return ncp_edge_dev(&bl, k->a, k->c, k->b, tol + EDGE_ROUND) <= tol + EDGE_ROUND;
}

int ncp_edge_trims(const struct ncp_seg *prev, const struct ncp_seg *cur,
                   const struct plan_corner *k, double tol, double rho, double max_trim,
                   double *lo, double *hi)
{
    /* without P the blend takes what the lines allow: the range to search */
    struct ncp_seg free_prev = *prev, bl;
    free_prev.tolerance = 0;
    double dmax, got_cur;
    if (rho == 1 ? !ncp_blend_corner(&free_prev, cur, max_trim, &bl, &dmax)
                 : !ncp_blend_corner_ratio_at(&free_prev, cur, rho, max_trim, &bl, &dmax, &got_cur))
        return 0;
    /* a blend too short stays near the moved vertex, one too long cuts in
     * too deep: the trims within tol are one range between them */
    double u1[3], u2[3], n[3];
    for (int i = 0; i < 3; i++) {
        u1[i] = (prev->end[i] - prev->start[i]) / prev->length;
        u2[i] = (cur->end[i] - cur->start[i]) / cur->length;
    }
    cross3(u1, u2, n);
    double reach = fmin(dmax, EDGE_REACH * tol / fmax(sqrt(dot3(n, n)), 1e-6));
    double trim[EDGE_SCAN + 2];
    trim[0] = 0;
    trim[EDGE_SCAN + 1] = dmax;
    for (int i = 1; i <= EDGE_SCAN; i++)
        trim[i] = reach * pow(EDGE_STEP, i - EDGE_SCAN);
    int first = 0, last = 0;
    for (int i = 1; i <= EDGE_SCAN; i++) {
        int ok = fits(&free_prev, cur, k, rho, trim[i], tol);
        if (ok && !first)
            first = i;
        if (ok)
            last = i;
        else if (first)
            break;
    }
    if (first < 1 || last < first)
        return 0;
    double a = trim[first - 1], b = trim[first];
    for (int i = 0; i < EDGE_BISECT && first > 1; i++) {
        double m = 0.5 * (a + b);
        if (fits(&free_prev, cur, k, rho, m, tol))
            b = m;
        else
            a = m;
    }
    *lo = b;
    a = trim[last];
    b = fmin(dmax, trim[last + 1]);
    for (int i = 0; i < EDGE_BISECT && last < EDGE_SCAN; i++) {
        double m = 0.5 * (a + b);
        if (fits(&free_prev, cur, k, rho, m, tol))
            a = m;
        else
            b = m;
    }
    *hi = a;
    return 1;
}

int ncp_edge_vertex(const double a[3], const double c[3], const double b[3], double tol,
                    double out[3])
{
    double u1[3], u2[3], w[3], l1 = dist3(a, c), l2 = dist3(c, b);
    if (!(l1 > 0) || !(l2 > 0) || !(tol > 0))
        return 0;
    for (int i = 0; i < 3; i++) {
        u1[i] = (c[i] - a[i]) / l1;
        u2[i] = (b[i] - c[i]) / l2;
        w[i] = u1[i] - u2[i];  /* out of the turn */
    }
    double cphi = fmax(-1, fmin(1, dot3(u1, u2))), phi = acos(cphi), wl = sqrt(dot3(w, w));
    if (phi < EDGE_TURN_MIN || phi > EDGE_TURN_MAX || wl <= 0)
        return 0;
    /* the outer edges meet tol / cos(phi/2) out along the bisector */
    double shift = tol / cos(0.5 * phi);
    for (int i = 0; i < 3; i++)
        out[i] = c[i] + shift * w[i] / wl;
    return 1;
}
