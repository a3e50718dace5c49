/* Lathe cycle profile geometry (see g7x_path.h). The profile is first turned
 * (mirrored, and for G72 rotated) so that it runs towards -Z and -X; passes
 * are computed in that frame and every move is turned back on its way out.
 * Decisions and tolerances are rs274 2.9's, so the passes come out the same. */
#include "g7x_path.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ncpar/diag.h"

#define TOL 1e-6
/* rs274 loops for ever on some degenerate profiles: stop long before. */
#define MAX_OFFSET_STEPS 100000
#define MAX_POCKET_STEPS 10000000L
#define MAX_PASSES 10000

/* Moves out of the turned frame: flip says how the profile was turned. */
struct sink {
    const struct ncp_g7x_out *out;
    int flip;
};

/* Intersections with a line x = const: at most two per segment (lines lying
 * on it give both ends). */
struct hits {
    int n;
    double z[2];
};

/* Written as rs274's complex products (I * p, not a swap of parts): the
 * products' signed zeros are what rs274 prints, -0.0000 included. */
static double complex unturn(int flip, double complex p)
{
    switch (flip) {
    case 1: return -conj(p);
    case 2: return conj(p);
    case 3: return -p;
    case 4: return I * p;
    case 5: return conj(I * p);
    case 6: return -conj(I * p);
    case 7: return -I * p;
    default: return p;
    }
}

static int mirrors(int flip)
{
    return flip == 1 || flip == 2 || flip == 5 || flip == 6;
}

static int out_line(const struct sink *k, int rapid, double complex end)
{
    return k->out->line(k->out->ctx, rapid, unturn(k->flip, end));
}

static int out_arc(const struct sink *k, int ccw, double complex c, double complex end)
{
    int dir = mirrors(k->flip) ? !ccw : ccw;
    return k->out->arc(k->out->ctx, dir, unturn(k->flip, c), unturn(k->flip, end));
}

static int geom_error(struct ncp_g7x_path *p, const char *msg)
{
    snprintf(p->err, sizeof p->err, "%s", msg);
    return NCP_G7X_EGEOM;
}

static double norm2(double complex v)
{
    return creal(v) * creal(v) + cimag(v) * cimag(v);
}

/* ---------------------------------------------------------------------
 * The path as a growable array
 * --------------------------------------------------------------------- */

void ncp_g7x_path_init(struct ncp_g7x_path *p)
{
    memset(p, 0, sizeof *p);
}

void ncp_g7x_path_free(struct ncp_g7x_path *p)
{
    free(p->seg);
    p->seg = NULL;
    p->n = p->cap = 0;
}

static int reserve(struct ncp_g7x_path *p, int n)
{
    if (n <= p->cap)
        return NCP_OK;
    if (n > NCP_G7X_MAX_SEGS)
        return geom_error(p, "profile has too many segments");
    int cap = p->cap ? p->cap : 16;
    while (cap < n)
        cap *= 2;
    struct ncp_g7x_seg *s = realloc(p->seg, (size_t)cap * sizeof *s);
    if (!s)
        return geom_error(p, "out of memory");
    p->seg = s;
    p->cap = cap;
    return NCP_OK;
}

static int insert(struct ncp_g7x_path *p, int at, const struct ncp_g7x_seg *s)
{
    int rc = reserve(p, p->n + 1);
    if (rc != NCP_OK)
        return rc;
    memmove(p->seg + at + 1, p->seg + at, (size_t)(p->n - at) * sizeof *s);
    p->seg[at] = *s;
    p->n++;
    return NCP_OK;
}

static void erase(struct ncp_g7x_path *p, int at)
{
    memmove(p->seg + at, p->seg + at + 1, (size_t)(p->n - at - 1) * sizeof *p->seg);
    p->n--;
}

static int copy_path(struct ncp_g7x_path *dst, const struct ncp_g7x_path *src)
{
    ncp_g7x_path_init(dst);
    dst->flip = src->flip;
    int rc = reserve(dst, src->n);
    if (rc != NCP_OK)
        return rc;
    if (src->n && dst->seg)
        memcpy(dst->seg, src->seg, (size_t)src->n * sizeof *src->seg);
    dst->n = src->n;
    return NCP_OK;
}

static struct ncp_g7x_seg make_line(double complex s, double complex e)
{
    struct ncp_g7x_seg g = {.kind = NCP_G7X_LINE, .s = s, .e = e};
    return g;
}

static struct ncp_g7x_seg make_arc(int ccw, double complex s, double complex c, double complex e)
{
    struct ncp_g7x_seg g = {.kind = NCP_G7X_ARC, .ccw = ccw, .s = s, .e = e, .c = c};
    return g;
}

int ncp_g7x_add_line(struct ncp_g7x_path *p, double complex s, double complex e)
{
    struct ncp_g7x_seg g = make_line(s, e);
    return insert(p, p->n, &g);
}

int ncp_g7x_add_arc(struct ncp_g7x_path *p, int ccw, double complex s, double complex c,
                    double complex e)
{
    struct ncp_g7x_seg g = make_arc(ccw, s, c, e);
    return insert(p, p->n, &g);
}

int ncp_g7x_add_corner(struct ncp_g7x_path *p, int corner, double size, double complex at)
{
    struct ncp_g7x_seg g = corner == NCP_G7X_FILLET ? make_arc(0, at, at, at) : make_line(at, at);
    g.corner = (unsigned char)corner;
    g.finish = size;
    return insert(p, p->n, &g);
}

/* ---------------------------------------------------------------------
 * One segment
 * --------------------------------------------------------------------- */

static double seg_radius(const struct ncp_g7x_seg *g)
{
    if (g->kind == NCP_G7X_LINE)
        return cabs(g->s - g->e);
    return fmin(cabs(g->s - g->e), cabs(g->s - g->c));
}

/* Runs towards -Z (and, for arcs, stays on one side of its centre). */
static int seg_monotonic(const struct ncp_g7x_seg *g)
{
    if (g->kind == NCP_G7X_LINE)
        return creal(g->e - g->s) <= 1e-3;
    if (g->finish != 0)
        return 1;
    double entry = cimag(g->s - g->c), exit = cimag(g->e - g->c), dz = creal(g->e - g->s);
    if (g->ccw)
        return entry >= -1e-3 && exit >= -1e-3 && dz <= -1e-3;
    return entry <= 1e-3 && exit <= 1e-3 && dz <= -1e-3;
}

static void seg_offset(struct ncp_g7x_seg *g, double distance)
{
    if (g->kind == NCP_G7X_LINE) {
        double complex d = I * distance * (g->s - g->e) / cabs(g->s - g->e);
        g->s += d;
        g->e += d;
        return;
    }
    double r = cabs(g->s - g->c);
    double factor = (r + (g->ccw ? 1 : -1) * distance) / r;
    g->s = factor * (g->s - g->c) + g->c;
    g->e = factor * (g->e - g->c) + g->c;
}

static void seg_flip_x(struct ncp_g7x_seg *g)
{
    g->s = conj(g->s);
    g->e = conj(g->e);
    if (g->kind == NCP_G7X_ARC) {
        g->ccw = !g->ccw;
        g->c = conj(g->c);
    }
}

static void seg_flip_z(struct ncp_g7x_seg *g)
{
    g->s = -conj(g->s);
    g->e = -conj(g->e);
    if (g->kind == NCP_G7X_ARC) {
        g->ccw = !g->ccw;
        g->c = -conj(g->c);
    }
}

/* A quarter turn: z + i x -> x - i z, as rs274's product -v * I (its
 * signed zeros included). */
static double complex quarter(double complex v)
{
    return -v * I;
}

static void seg_rotate(struct ncp_g7x_seg *g)
{
    g->s = quarter(g->s);
    g->e = quarter(g->e);
    if (g->kind == NCP_G7X_ARC)
        g->c = quarter(g->c);
}

static void seg_move(struct ncp_g7x_seg *g, double complex d)
{
    g->s += d;
    g->e += d;
    if (g->kind == NCP_G7X_ARC)
        g->c += d;
}

static int seg_draw(const struct ncp_g7x_seg *g, const struct sink *k)
{
    if (g->kind == NCP_G7X_LINE)
        return out_line(k, 0, g->e);
    return out_arc(k, g->ccw, g->c, g->e);
}

static int arc_holds(const struct ncp_g7x_seg *g, double complex p)
{
    double a = cimag(conj(g->s - g->c) * (p - g->c));
    double b = cimag(conj(g->e - g->c) * (p - g->c));
    if (g->ccw)
        return a >= -TOL && b <= TOL;
    return a <= TOL && b >= -TOL;
}

static void push_hit(struct hits *h, double z)
{
    if (h->n < 2)
        h->z[h->n++] = z;
}

/* Where the segment crosses X = x (in z, in rs274's order). */
static void seg_cross(const struct ncp_g7x_seg *g, double x, struct hits *h)
{
    h->n = 0;
    if (g->kind == NCP_G7X_LINE) {
        double sx = cimag(g->s), ex = cimag(g->e);
        if (fmin(sx, ex) > x + TOL || fmax(sx, ex) < x - TOL)
            return;
        if (fabs(cimag(g->s - g->e)) < TOL) {
            push_hit(h, creal(g->s));
            push_hit(h, creal(g->e));
        } else {
            push_hit(h, (x - sx) / (ex - sx) * (creal(g->e) - creal(g->s)) + creal(g->s));
        }
        return;
    }
    double r = cabs(g->s - g->c);
    double s = -(x - r - cimag(g->c)) * (x + r - cimag(g->c));
    if (s < -TOL)
        return;
    if (s < 0)
        s = 0;
    s = sqrt(s);
    double complex p1 = CMPLX(creal(g->c) + s, x), p2 = CMPLX(creal(g->c) - s, x);
    if (arc_holds(g, p1))
        push_hit(h, creal(p1));
    if (arc_holds(g, p2))
        push_hit(h, creal(p2));
}

static double complex with_z(double complex p, double z)
{
    return CMPLX(z, cimag(p));
}

/* The top of an arc going up (G3 past its centre): where a climb stops. */
static double complex arc_top(const struct ncp_g7x_seg *g)
{
    if (creal(g->e) < creal(g->c))
        return CMPLX(creal(g->c), cimag(g->c) + cabs(g->s - g->c));
    return g->e;
}

/* Follow the segment up from *loc; 1 when it does not climb (a pocket may start). */
static int seg_climb(struct ncp_g7x_path *p, const struct ncp_g7x_seg *g, double complex *loc,
                     const struct sink *k, int *stop)
{
    int rc = NCP_OK;
    *stop = 0;
    if (g->kind == NCP_G7X_LINE) {
        if (cimag(g->e) + TOL < cimag(g->s)) {
            *stop = 1;
            return NCP_OK;
        }
        if (cabs(*loc - g->s) > TOL)
            return geom_error(p, "How did we get here?");
        rc = out_line(k, 0, g->e);
        *loc = g->e;
        return rc;
    }
    if (!g->ccw) {
        if (creal(*loc) > creal(g->c)) {
            *stop = 1;
            return NCP_OK;
        }
        if (cabs(*loc - g->e) > 1e-3)
            rc = out_arc(k, g->ccw, g->c, g->e);
        *loc = g->e;
        return rc;
    }
    *stop = 1;
    if (creal(*loc) < creal(g->c))
        return NCP_OK;
    double complex ep = arc_top(g);
    if (cabs(*loc - ep) > 1e-3)
        rc = out_arc(k, g->ccw, g->c, ep);
    *loc = ep;
    return rc;
}

/* After the first roughing pass without pockets: follow what rises. */
static int seg_climb_only(const struct ncp_g7x_seg *g, double complex *loc, const struct sink *k)
{
    struct hits h;
    int rc = NCP_OK;
    if (g->kind == NCP_G7X_LINE && cimag(g->e) < cimag(g->s))
        return NCP_OK;
    seg_cross(g, cimag(*loc), &h);
    if (!h.n)
        return NCP_OK;
    if (g->kind == NCP_G7X_LINE) {
        *loc = with_z(*loc, h.z[0]);
        rc = out_line(k, 0, *loc);
        if (rc == NCP_OK)
            rc = out_line(k, 0, g->e);
        *loc = g->e;
        return rc;
    }
    if (!g->ccw) {
        if (h.z[h.n - 1] > creal(g->c))
            return NCP_OK;
        *loc = with_z(*loc, h.z[h.n - 1]);
        rc = out_line(k, 0, *loc);
        if (rc == NCP_OK && cabs(*loc - g->e) > 1e-3)
            rc = out_arc(k, g->ccw, g->c, g->e);
        *loc = g->e;
        return rc;
    }
    if (h.z[0] < creal(g->c))
        return NCP_OK;
    *loc = with_z(*loc, h.z[0]);
    rc = out_line(k, 0, *loc);
    double complex ep = arc_top(g);
    if (rc == NCP_OK && cabs(*loc - ep) > 1e-3)
        rc = out_arc(k, g->ccw, g->c, ep);
    *loc = ep;
    return rc;
}

/* Follow the segment down to X = x; *climbs = 1 when it does not go down. */
static int seg_dive(struct ncp_g7x_path *p, const struct ncp_g7x_seg *g, double complex *loc,
                    double x, const struct sink *k, int fast, int *climbs)
{
    struct hits h;
    *climbs = 0;
    if (g->kind == NCP_G7X_LINE) {
        if (cimag(g->s) <= cimag(g->e) + TOL) {
            *climbs = 1;
            return NCP_OK;
        }
        double complex ep = g->e;
        if (x >= cimag(g->e)) {
            seg_cross(g, x, &h);
            if (!h.n)
                return geom_error(p, "x too large in straight dive");
            ep = CMPLX(h.z[0], x);
        }
        *loc = ep;
        return out_line(k, fast, ep);
    }
    if (cabs(*loc - g->e) < TOL || creal(*loc - g->e) <= TOL) {
        *loc = g->e;
        return NCP_OK;
    }
    seg_cross(g, x, &h);
    if (!h.n)
        seg_cross(g, x - TOL, &h);
    double complex ep = g->e;
    if (g->ccw) {
        if (creal(*loc) - TOL > creal(g->c)) {
            *climbs = 1;
            return NCP_OK;
        }
        if (h.n && h.z[h.n - 1] <= creal(g->c))
            ep = CMPLX(h.z[h.n - 1], x);
    } else {
        if (creal(*loc) <= creal(g->c)) {
            *climbs = 1;
            return NCP_OK;
        }
        if (h.n && h.z[0] < creal(g->c))
            return NCP_OK; /* only its back side is hit: the pocket steps down */
        if (h.n)
            ep = CMPLX(h.z[0], x);
    }
    *loc = ep;
    return out_arc(k, g->ccw, g->c, ep);
}

/* ---------------------------------------------------------------------
 * Joining two segments: correct a's end and b's start to where they meet
 * --------------------------------------------------------------------- */

static int meet_lines(struct ncp_g7x_path *p, struct ncp_g7x_seg *a, struct ncp_g7x_seg *b)
{
    double complex rot = conj(b->s - b->e) / cabs(b->s - b->e);
    double complex ps = (a->s - b->e) * rot, pe = (a->e - b->e) * rot;
    if (cimag(ps - pe) == 0)
        return geom_error(p, "Cannot intersect parallel lines");
    double f = cimag(ps) / cimag(ps - pe);
    double complex is = (ps + f * (pe - ps)) / rot + b->e;
    b->s = a->e = is;
    return NCP_OK;
}

/* A line and an arc (its point pt, centre c) meet where the arc's circle
 * crosses the line: of the two crossings, the one nearer to near. */
static double complex meet_line_arc(const struct ncp_g7x_seg *line, double complex pt,
                                    double complex c, double complex near)
{
    double complex rot = conj(line->s - line->e) / cabs(line->s - line->e);
    double complex pe = (pt - line->e) * rot, pc = (c - line->e) * rot;
    double b = norm2(pc - pe) - cimag(pc) * cimag(pc);
    b = b < 0 ? 0 : sqrt(b);
    double complex s1 = (creal(pc) + b) / rot + line->e;
    double complex s2 = (creal(pc) - b) / rot + line->e;
    return cabs(near - s1) < cabs(near - s2) ? s1 : s2;
}

static void meet_arcs(struct ncp_g7x_seg *a, struct ncp_g7x_seg *b)
{
    double ra = cabs(b->s - b->c), rb = cabs(a->s - a->c), c = cabs(b->c - a->c);
    double cosb = (c * c + ra * ra - rb * rb) / 2.0 / ra / c;
    double cosb2 = cosb * cosb;
    if (cosb2 > 1)
        cosb2 = 1;
    double complex rot = CMPLX(cosb, sqrt(1 - cosb2));
    double complex is = rot * (a->c - b->c) / c * ra + b->c;
    a->e = b->s = is;
}

/* Move a's end and b's start to where the two meet. */
static int meet(struct ncp_g7x_path *p, struct ncp_g7x_seg *a, struct ncp_g7x_seg *b)
{
    if (a->kind == NCP_G7X_LINE && b->kind == NCP_G7X_LINE)
        return meet_lines(p, a, b);
    if (a->kind == NCP_G7X_ARC && b->kind == NCP_G7X_ARC) {
        meet_arcs(a, b);
        return NCP_OK;
    }
    if (cabs(b->s - a->e) < TOL)
        return NCP_OK;
    double complex is = b->kind == NCP_G7X_LINE ? meet_line_arc(b, a->e, a->c, b->s)
                                                : meet_line_arc(a, b->e, b->c, b->s);
    b->s = a->e = is;
    return NCP_OK;
}

/* ---------------------------------------------------------------------
 * Corners: a fillet or chamfer between two segments
 * --------------------------------------------------------------------- */

static int corner_shape(struct ncp_g7x_path *p, struct ncp_g7x_seg *g, struct ncp_g7x_seg *prev,
                        struct ncp_g7x_seg *next, double complex *centre)
{
    struct ncp_g7x_seg a = *prev, b = *next;
    seg_offset(&a, g->finish);
    seg_offset(&b, g->finish);
    if (creal(a.e - b.s) > 1e-2) {
        g->finish = -g->finish;
        a = *prev;
        b = *next;
        seg_offset(&a, g->finish);
        seg_offset(&b, g->finish);
    }
    if (creal(a.e - b.s) > 1e-2) {
        snprintf(p->err, sizeof p->err, "Corner finish failed at (%g,%g)", creal(prev->e),
                 cimag(prev->e));
        return NCP_G7X_EGEOM;
    }
    int rc = meet(p, &a, &b);
    if (rc != NCP_OK)
        return rc;
    *centre = (a.e + b.s) / 2.0;
    seg_offset(&a, -g->finish);
    seg_offset(&b, -g->finish);
    g->s = prev->e = a.e;
    g->e = next->s = b.s;
    return NCP_OK;
}

static int seg_finish(struct ncp_g7x_path *p, struct ncp_g7x_seg *g, struct ncp_g7x_seg *prev,
                      struct ncp_g7x_seg *next)
{
    double complex centre;
    if (g->corner == NCP_G7X_PLAIN)
        return NCP_OK;
    int rc = corner_shape(p, g, prev, next, &centre);
    if (rc != NCP_OK || g->corner != NCP_G7X_FILLET)
        return rc;
    g->c = centre;
    g->ccw = cimag(g->s - centre) > 0 || cimag(g->e - centre) > 0;
    g->finish = 0;
    return NCP_OK;
}

/* ---------------------------------------------------------------------
 * The whole path
 * --------------------------------------------------------------------- */

static void path_rotate(struct ncp_g7x_path *p)
{
    for (int k = 0; k < p->n; k++)
        seg_rotate(&p->seg[k]);
    p->flip ^= 4;
}

/* Mirror so that the profile runs from its start towards -X and -Z. */
static void path_orient(struct ncp_g7x_path *p)
{
    double complex d = p->seg[0].e - p->seg[p->n - 1].e;
    if (cimag(d) > 0) {
        for (int k = 0; k < p->n; k++)
            seg_flip_x(&p->seg[k]);
        p->flip ^= 2;
    }
    if (creal(d) < 0) {
        for (int k = 0; k < p->n; k++)
            seg_flip_z(&p->seg[k]);
        p->flip ^= 1;
    }
}

static int path_monotonic(struct ncp_g7x_path *p)
{
    struct ncp_g7x_seg *f = &p->seg[0];
    if (creal(f->e - f->s) > 0)
        f->s = with_z(f->s, creal(f->e));
    for (int k = 0; k < p->n; k++)
        if (!seg_monotonic(&p->seg[k]))
            return geom_error(p, "Not monotonic");
    return NCP_OK;
}

static int path_corners(struct ncp_g7x_path *p)
{
    for (int k = 1; k < p->n - 1; k++) {
        int rc = seg_finish(p, &p->seg[k], &p->seg[k - 1], &p->seg[k + 1]);
        if (rc != NCP_OK)
            return rc;
    }
    for (int k = 0; k < p->n;) {
        if (seg_radius(&p->seg[k]) < 1e-3)
            erase(p, k);
        else
            k++;
    }
    return NCP_OK;
}

/* Join neighbours that an offset pulled apart with an arc around the old
 * corner (it is convex there). */
static int offset_bridge(struct ncp_g7x_path *p, double step, double distance)
{
    for (int k = 0; k < p->n - 1; k++) {
        struct ncp_g7x_seg *a = &p->seg[k], *b = &p->seg[k + 1];
        if (creal(a->e - b->s) <= 1e-2)
            continue;
        struct ncp_g7x_seg s = *a, e = *b;
        seg_offset(&s, -step);
        seg_offset(&e, -step);
        double complex centre = (s.e + e.s) / 2.0;
        struct ncp_g7x_seg arc = make_arc(distance > 0, a->e, centre, b->s);
        int rc = insert(p, k + 1, &arc);
        if (rc != NCP_OK)
            return rc;
        k++;
    }
    return NCP_OK;
}

/* Drop what an offset turned around or shrank away, join the rest. */
static int offset_trim(struct ncp_g7x_path *p)
{
    for (int k = 0; k < p->n - 1; k++) {
        if (!seg_monotonic(&p->seg[k])) {
            if (k == 0) /* rs274 compares with the element before the first */
                return geom_error(p, "Not monotonic");
            int drop = seg_radius(&p->seg[k]) < seg_radius(&p->seg[k - 1]) ? k : k - 1;
            erase(p, drop);
            k = 0;
            if (k >= p->n - 1)
                break;
        }
        if (seg_radius(&p->seg[k]) < 1e-3) {
            erase(p, k);
            k = 0; /* and the loop steps past the new first one, as rs274's does */
            continue;
        }
        int rc = meet(p, &p->seg[k], &p->seg[k + 1]);
        if (rc != NCP_OK)
            return rc;
    }
    return NCP_OK;
}

/* Offset the profile (not its lead-in, the first segment) by distance, in
 * steps no larger than half the shortest segment. */
static int path_offset(struct ncp_g7x_path *p, double distance)
{
    if (p->n < 2)
        return geom_error(p, "profile too short");
    double complex v1 = p->seg[0].e - p->seg[0].s;
    double complex v2 = p->seg[p->n - 1].s - p->seg[0].s;
    if (cimag(v1 / v2) < 0)
        distance = -distance;
    struct ncp_g7x_seg lead = p->seg[0];
    erase(p, 0);
    double done = 0;
    for (int steps = 0; done != distance; steps++) {
        if (steps >= MAX_OFFSET_STEPS || p->n == 0)
            return geom_error(p, "profile offset does not converge");
        double step = 1e9;
        for (int k = 0; k < p->n; k++)
            step = fmin(step, seg_radius(&p->seg[k]) / 2);
        step = fmin(step, fabs(distance - done));
        if (distance < 0)
            step = -step;
        for (int k = 0; k < p->n;) {
            seg_offset(&p->seg[k], step);
            if (seg_radius(&p->seg[k]) < 1e-3)
                erase(p, k);
            else
                k++;
        }
        int rc = offset_bridge(p, step, distance);
        if (rc == NCP_OK)
            rc = offset_trim(p);
        if (rc != NCP_OK)
            return rc;
        done += step;
    }
    if (p->n == 0)
        return geom_error(p, "profile offset does not converge");
    for (int k = 0; k < p->n - 1; k++) {
        double complex mid = (p->seg[k].e + p->seg[k + 1].s) / 2.0;
        p->seg[k].e = p->seg[k + 1].s = mid;
    }
    lead.e = p->seg[0].s;
    return insert(p, 0, &lead);
}

/* ---------------------------------------------------------------------
 * G70
 * --------------------------------------------------------------------- */

/* Turn the profile the way its own part (without the lead-in) runs monotonic. */
static int finish_orient(struct ncp_g7x_path *p)
{
    struct ncp_g7x_path probe;
    int rc = copy_path(&probe, p);
    if (rc == NCP_OK && probe.n < 2)
        rc = geom_error(&probe, "profile too short");
    if (rc == NCP_OK) {
        erase(&probe, 0);
        path_orient(&probe);
        for (int k = 0; k < probe.n; k++) {
            if (!seg_monotonic(&probe.seg[k])) {
                path_rotate(&probe);
                path_orient(&probe);
                break;
            }
        }
        rc = path_monotonic(&probe);
    }
    if (rc != NCP_OK)
        memcpy(p->err, probe.err, sizeof p->err);
    int rotate = probe.flip & 4;
    ncp_g7x_path_free(&probe);
    if (rc != NCP_OK)
        return rc;
    if (rotate)
        path_rotate(p);
    path_orient(p);
    rc = path_corners(p);
    return rc == NCP_OK ? path_monotonic(p) : rc;
}

int ncp_g7x_finish(struct ncp_g7x_path *p, const struct ncp_g7x_out *out,
                   double complex start, double d, double e, double passes)
{
    p->seg[0].s = start;
    int rc = finish_orient(p);
    if (rc != NCP_OK)
        return rc;
    /* rs274 truncates P to an int (NaN and huge values to INT_MIN: no pass) */
    if (passes > MAX_PASSES)
        return geom_error(p, "too many passes (P)");
    int npass = passes >= 1 ? (int)passes : 0;
    struct sink k = {out, p->flip};
    for (int pass = npass; pass > 0 && rc == NCP_OK; pass--) {
        double distance = (pass - 1) * (d - e) / passes + e;
        struct ncp_g7x_path q;
        rc = copy_path(&q, p);
        if (rc == NCP_OK)
            rc = path_offset(&q, distance);
        if (rc == NCP_OK && q.n < 2)
            rc = geom_error(&q, "profile too short");
        if (rc == NCP_OK)
            rc = out_line(&k, 1, q.seg[0].s);
        if (rc == NCP_OK)
            rc = out_line(&k, 1, q.seg[0].e);
        for (int j = 1; j < q.n && rc == NCP_OK; j++)
            rc = seg_draw(&q.seg[j], &k);
        if (rc == NCP_G7X_EGEOM)
            memcpy(p->err, q.err, sizeof p->err);
        ncp_g7x_path_free(&q);
    }
    return rc;
}

/* ---------------------------------------------------------------------
 * G71 / G72
 * --------------------------------------------------------------------- */

struct rough {
    struct ncp_g7x_path *p;
    struct sink k;
    int cycle;                    /* 0 all, 1 no pockets, 2 pockets only (then 3) */
    double delta;                 /* depth of cut */
    double complex escape;        /* retract, r + i r */
    double complex starts[2];     /* X where the passes of the current pocket begin */
    int nstarts;
    long steps;
};

/* One cut along Z at the location's X, from location to the profile segment
 * ip it meets, then the retract and the rapid back. *next_seg and *x say
 * where the pocket goes on. */
static int rough_cut(struct rough *r, int *seg, double complex loc, double *x)
{
    struct ncp_g7x_path *p = r->p;
    for (int ip = *seg; ip < p->n; ip++) {
        struct hits h;
        seg_cross(&p->seg[ip], cimag(loc), &h);
        if (!h.n)
            continue;
        /* the diving segment itself may be hit further along, if it is an arc */
        double dest_z = ip != *seg ? h.z[0] : h.z[h.n - 1];
        double distance = fabs(dest_z - creal(loc));
        if (dest_z - TOL > creal(loc))
            continue;
        if (distance < TOL) {
            if (ip == *seg)
                continue;
            if (cabs(loc - p->seg[ip].s) < TOL)
                *seg = ip;
            else
                *x -= r->delta;
            return NCP_OK;
        }
        double complex dest = with_z(loc, dest_z);
        int rc = out_line(&r->k, 0, dest);
        double scale = fmin(1.0, distance / 2 / creal(r->escape));
        dest += scale * r->escape;
        if (rc == NCP_OK)
            rc = out_line(&r->k, 1, dest);
        dest = loc - conj(scale * r->escape);
        if (rc == NCP_OK)
            rc = out_line(&r->k, 1, dest);
        if (rc == NCP_OK)
            rc = out_line(&r->k, *seg == 0, loc);
        *x -= r->delta;
        return rc;
    }
    return NCP_OK;
}

/* The profile is done diving at segment seg: follow it up, without pockets
 * (subcycle 1), or until the next pocket (*again = 1, at *seg). */
static int rough_climb(struct rough *r, int *seg, double complex *loc, int *again)
{
    struct ncp_g7x_path *p = r->p;
    *again = 0;
    if (r->cycle == 1) {
        for (; *seg < p->n; (*seg)++) {
            int rc = seg_climb_only(&p->seg[*seg], loc, &r->k);
            if (rc != NCP_OK)
                return rc;
        }
        return NCP_OK;
    }
    for (; *seg < p->n; (*seg)++) {
        int stop;
        int rc = seg_climb(p, &p->seg[*seg], loc, &r->k, &stop);
        if (rc != NCP_OK)
            return rc;
        if (!stop)
            continue;
        if (r->cycle == 3) {
            if (cimag(*loc) > cimag(r->starts[r->nstarts - 1]) && r->nstarts > 1)
                r->nstarts--;
            if (r->nstarts == 1)
                r->starts[r->nstarts++] = *loc;
        }
        *again = 1;
        return NCP_OK;
    }
    return NCP_OK;
}

/* Cut the pocket under loc from segment seg on, then each pocket after it. */
static int rough_pockets(struct rough *r, int seg, double complex loc)
{
    struct ncp_g7x_path *p = r->p;
    int rc;
    if (r->cycle == 2) {
        /* the first roughing pass was G71.1's: pick up after it */
        for (; seg < p->n; seg++) {
            int climbs;
            rc = seg_dive(p, &p->seg[seg], &loc, -1e9, &r->k, seg == 0, &climbs);
            if (rc != NCP_OK)
                return rc;
            if (climbs)
                break;
        }
        r->cycle = 3;
    }
    double x = cimag(r->starts[r->nstarts - 1]);
    while (seg < p->n) {
        if (++r->steps > MAX_POCKET_STEPS)
            return geom_error(p, "roughing does not converge");
        while (x - TOL > cimag(loc))
            x -= r->delta;
        int climbs;
        rc = seg_dive(p, &p->seg[seg], &loc, x, &r->k, seg == 0, &climbs);
        if (rc != NCP_OK)
            return rc;
        if (climbs) {
            int again;
            rc = rough_climb(r, &seg, &loc, &again);
            if (rc != NCP_OK || !again)
                return rc;
            x = cimag(r->starts[r->nstarts - 1]);
            continue;
        }
        if (fabs(cimag(loc) - x) > TOL) {
            seg++; /* x is below this segment: the next one goes on down */
            continue;
        }
        rc = rough_cut(r, &seg, loc, &x);
        if (rc != NCP_OK)
            return rc;
    }
    return NCP_OK;
}

int ncp_g7x_rough(struct ncp_g7x_path *p, const struct ncp_g7x_out *out, int subcycle,
                  int rotated, double complex start, double complex uw, double d, double i,
                  double r)
{
    p->seg[0].s = start;
    if (rotated)
        path_rotate(p);
    path_orient(p);
    int rc = path_corners(p);
    if (rc == NCP_OK)
        rc = path_monotonic(p);
    if (rc == NCP_OK)
        rc = path_offset(p, d);
    if (rc != NCP_OK)
        return rc;
    for (int k = 0; k < p->n; k++)
        seg_move(&p->seg[k], uw);
    struct rough ro = {.p = p, .k = {out, p->flip}, .cycle = subcycle,
                       .delta = fmax(i, 2 * TOL), .escape = CMPLX(r, r)};
    rc = out_line(&ro.k, 1, p->seg[0].s);
    if (rc != NCP_OK)
        return rc;
    double complex last = p->seg[p->n - 1].e;
    if (cimag(last) < cimag(p->seg[0].s)) {
        rc = ncp_g7x_add_line(p, last, with_z(p->seg[0].s, creal(last)));
        if (rc != NCP_OK)
            return rc;
    }
    ro.starts[ro.nstarts++] = p->seg[0].s;
    return rough_pockets(&ro, 0, p->seg[0].s);
}
