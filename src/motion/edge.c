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
#include "blend.h"
#include "planner_int.h"

#include <math.h>
#include <pthread.h>
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

/* A programmed segment, set up for many distances: from a along d, and n
 * the unit normal towards the inside of the turn (zero where there is no
 * turn to tell it by). */
struct edge_seg {
    double a[3], d[3], dd, n[3];
};

/* other: the direction of the corner's other line */
static void seg_init(struct edge_seg *g, const double a[3], const double b[3],
                     const double other[3])
{
    g->dd = 0;
    for (int i = 0; i < 3; i++) {
        g->a[i] = a[i];
        g->d[i] = b[i] - a[i];
        g->dd += g->d[i] * g->d[i];
    }
    double along = g->dd > 0 ? dot3(other, g->d) / g->dd : 0, nn = 0;
    for (int i = 0; i < 3; i++) {
        g->n[i] = other[i] - along * g->d[i];
        nn += g->n[i] * g->n[i];
    }
    nn = nn > 1e-12 * dot3(other, other) ? 1 / sqrt(nn) : 0;
    for (int i = 0; i < 3; i++)
        g->n[i] *= nn;
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

/* A corner point of a blend's piece against a programmed segment: the
 * squared distance, how far along (0 and 1 its ends) and how far inside
 * the turn (signed) it lies. */
struct edge_at {
    double dist2, along, in;
};

static struct edge_at seg_at(const struct edge_seg *g, const double q[3])
{
    double w[3] = { q[0] - g->a[0], q[1] - g->a[1], q[2] - g->a[2] };
    struct edge_at r = { 0, g->dd > 0 ? dot3(w, g->d) / g->dd : 0, dot3(w, g->n) };
    double t = lesser(1, greater(0, r.along));
    for (int i = 0; i < 3; i++) {
        double c = w[i] - t * g->d[i];
        r.dist2 += c * c;
    }
    return r;
}

/* One piece (the triangle of corner points x[3]) against one segment: the
 * distance to a segment is convex and the signed distance to its line
 * linear, so the corners bound the piece. Within tol_in of the segment, or
 * beside it (not beyond its ends) within tol_in inside the turn and
 * tol_out outside: the servo's chords between samples cut in towards the
 * inside of the blend, which here (tangent_ok: the blend's tangent not
 * yet turned a right angle from the segment) points into the turn, so only
 * the inside needs their margin. */
static int piece_fits(const struct edge_seg *g, const struct edge_at x[3], int tangent_ok,
                      double tol_in, double tol_out)
{
    double far2 = greater(x[0].dist2, greater(x[1].dist2, x[2].dist2));
    if (far2 <= tol_in * tol_in)
        return 1;
    if (!tangent_ok || far2 > tol_out * tol_out || (g->n[0] == 0 && g->n[1] == 0 && g->n[2] == 0))
        return 0;
    for (int k = 0; k < 3; k++)
        if (x[k].along < 0 || x[k].along > 1 || x[k].in > tol_in)
            return 0;
    return 1;
}

/* A corner's programmed polyline set up for measuring many blends against
 * it: the two segments, their directions (c - a and b - c) and the band. */
struct edge_band {
    struct edge_seg g[2];
    double u1[3], u2[3], tol_in, tol_out;
};

static void band_init(struct edge_band *e, const struct plan_corner *k, double tol_in)
{
    double back[3];
    e->tol_out = greater(tol_in, k->out) + EDGE_ROUND;
    e->tol_in = tol_in + EDGE_ROUND;
    for (int i = 0; i < 3; i++) {
        e->u1[i] = k->c[i] - k->a[i];
        e->u2[i] = k->b[i] - k->c[i];
        back[i] = -e->u1[i];
    }
    /* inside the turn: towards the second line from the first, back along
     * the first from the second */
    seg_init(&e->g[0], k->a, k->c, e->u2);
    seg_init(&e->g[1], k->c, k->b, back);
}

/* Whether the parabola p0, pc, p1 stays within e's band. Where hint is
 * given and *hint is a piece, that piece is measured first, and a piece
 * that fails goes to *hint: the blends of one search fail alike, those a
 * little too large where they cut in deepest. */
static int band_within(const struct edge_band *e, const double p0[3], const double pc[3],
                       const double p1[3], int *hint)
{
    /* the parabola is the quadratic Bezier start, centre, end; each piece
     * between two samples is one too, inside the triangle of its ends and
     * the meeting of its end tangents */
    struct edge_at on[2][3];
    double q0[3], q1[3], ctrl[3], d0[3], d1[3];
    /* A piece needs only one segment it fits, and the one the piece before
     * fitted is tried first: the blend runs beside the first line, then
     * beside the second. Only a segment tried has its points measured;
     * have[j] says on[j][0] holds the piece's start measured against it. */
    int have[2] = { 0, 0 }, near = 0, ahead = hint && *hint >= 0 ? *hint : -1;
    double out2 = e->tol_out * e->tol_out;
    /* k 0: the piece ahead; k from 1: piece k - 1 */
    for (int k = ahead < 0; k <= EDGE_PIECES; k++) {
        int n = k ? k - 1 : ahead;
        double t0 = (double)n / EDGE_PIECES, t1 = (double)(n + 1) / EDGE_PIECES;
        double tan0 = 0, tan1 = 0;
        if (k <= 1) {
            /* B(t0) and B'(t0) / 2, as the piece before would leave them */
            for (int i = 0; i < 3; i++) {
                q0[i] = n ? (1 - t0) * (1 - t0) * p0[i] + 2 * t0 * (1 - t0) * pc[i] +
                                t0 * t0 * p1[i]
                          : p0[i];
                d0[i] = n ? (1 - t0) * (pc[i] - p0[i]) + t0 * (p1[i] - pc[i]) : pc[i] - p0[i];
            }
            have[0] = have[1] = 0;
        }
        for (int i = 0; i < 3; i++) {
            q1[i] = (1 - t1) * (1 - t1) * p0[i] + 2 * t1 * (1 - t1) * pc[i] + t1 * t1 * p1[i];
            d1[i] = (1 - t1) * (pc[i] - p0[i]) + t1 * (p1[i] - pc[i]);
            /* B(t0) + (t1 - t0) / 2 B'(t0) */
            ctrl[i] = q0[i] + (t1 - t0) * d0[i];
            tan0 += d0[i] * e->u2[i];
            tan1 += d1[i] * e->u1[i];
        }
        if (k && n == ahead) {
            /* measured already */
            have[0] = have[1] = 0;
            memcpy(q0, q1, sizeof q0);
            memcpy(d0, d1, sizeof d0);
            continue;
        }
        /* the tangent turns one way along the blend: at the piece's end it
         * has turned furthest from the first line, at its start least far
         * from the second */
        int tangent_ok[2] = { tan1 >= 0, tan0 >= 0 }, tried[2] = { 0, 0 }, fit = -1;
        for (int m = 0; m < 2 && fit < 0; m++) {
            int j = near ^ m;
            const struct edge_seg *g = &e->g[j];
            if (!have[j])
                on[j][0] = seg_at(g, q0);
            /* a corner beyond tol_out fails the piece whatever the others
             * (tol_out >= tol_in): the rest are not measured */
            if (on[j][0].dist2 > out2)
                continue;
            on[j][1] = seg_at(g, q1);
            tried[j] = 1;
            if (on[j][1].dist2 > out2)
                continue;
            on[j][2] = seg_at(g, ctrl);
            if (piece_fits(g, on[j], tangent_ok[j], e->tol_in, e->tol_out))
                fit = j;
        }
        if (fit < 0) {
            if (hint)
                *hint = n;
            return 0;
        }
        for (int j = 0; j < 2; j++) {
            have[j] = tried[j];
            if (tried[j])
                on[j][0] = on[j][1];
        }
        near = fit;
        memcpy(q0, q1, sizeof q0);
        memcpy(d0, d1, sizeof d0);
    }
    return 1;
}

int ncp_edge_within(const struct ncp_seg *blend, const struct plan_corner *k, double tol_in)
{
    struct edge_band e;
    band_init(&e, k, tol_in);
    return band_within(&e, blend->start, blend->center, blend->end, NULL);
}

/* Does the blend of trim d (fan: rho d off cur) stay within e's band? No
 * where there is no such blend. */
static int fits(const struct ncp_blend_fan *fan, const struct edge_band *e, double d, int *hint)
{
    double start[3], end[3];
    return ncp_blend_fan_at(fan, d, start, end) && band_within(e, start, fan->c, end, hint);
}

/* The trim nearest the edge of the range between one that fits and one
 * that does not, either side of it: EDGE_BISECT halvings. */
static double edge_bisect(const struct ncp_blend_fan *fan, const struct edge_band *e, double fit,
                          double miss, int *hint)
{
    for (int i = 0; i < EDGE_BISECT; i++) {
        double m = 0.5 * (fit + miss);
        if (fits(fan, e, m, hint))
            fit = m;
        else
            miss = m;
    }
    return fit;
}

/* EDGE_STEP^(i - EDGE_SCAN), the scan's trims over its reach: the same
 * powers for every search, taken once. */
static double edge_steps[EDGE_SCAN + 1];
static pthread_once_t edge_steps_once = PTHREAD_ONCE_INIT;

static void edge_steps_make(void)
{
    for (int i = 1; i <= EDGE_SCAN; i++)
        edge_steps[i] = pow(EDGE_STEP, i - EDGE_SCAN);
}

/* The planner takes the powers when it is made, so that no thread that plans
 * in time is ever the first to ask (the first pthread_once may wait). */
void ncp_edge_prepare(void)
{
    pthread_once(&edge_steps_once, edge_steps_make);
}

int ncp_edge_trims(const struct ncp_seg *prev, const struct ncp_seg *cur,
                   const struct plan_corner *k, double tol, double rho, double max_trim,
                   double *lo, double *hi)
{
    /* without P the blend takes what the lines allow: the range to search */
    struct ncp_blend_fan fan;
    double s0[3], e0[3];
    if (!ncp_blend_fan_init(&fan, prev, cur, rho))
        return 0;
    double dmax = ncp_blend_fan_at(&fan, max_trim, s0, e0);
    if (dmax == 0)
        return 0;
    /* a blend too short stays near the moved vertex, one too long cuts in
     * too deep: the trims within tol are one range between them */
    double n[3];
    cross3(fan.u1, fan.u2, n);
    double reach = fmin(dmax, EDGE_REACH * tol / fmax(sqrt(dot3(n, n)), 1e-6));
    struct edge_band band;
    band_init(&band, k, tol);
    double trim[EDGE_SCAN + 2];
    trim[0] = 0;
    trim[EDGE_SCAN + 1] = dmax;
    ncp_edge_prepare();
    for (int i = 1; i <= EDGE_SCAN; i++)
        trim[i] = reach * edge_steps[i];
    /* The range's upper end is found from the last trim that fits, so the
     * scan goes on past the first only where that end is asked for. The
     * blends about each end fail alike (band_within's hint): the one after
     * the last that fits, then the bisection's. */
    int first = 0, last = 0, hint_lo = -1, hint_hi = -1;
    for (int i = 1; i <= EDGE_SCAN; i++) {
        int ok = fits(&fan, &band, trim[i], first ? &hint_hi : NULL);
        if (ok && !first)
            first = i;
        if (ok)
            last = i;
        else if (first)
            break;
        if (first && !hi)
            break;
    }
    if (first < 1 || last < first)
        return 0;
    if (lo)
        *lo = first > 1 ? edge_bisect(&fan, &band, trim[first], trim[first - 1], &hint_lo)
                        : trim[first];
    if (hi)
        *hi = last < EDGE_SCAN
                  ? edge_bisect(&fan, &band, trim[last], fmin(dmax, trim[last + 1]), &hint_hi)
                  : trim[last];
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
