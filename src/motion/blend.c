/* G64 corner blending: two lines meeting at a corner are joined by a curve
 * tangent to both, so the path keeps its tangent and the corner is taken at
 * speed. Between lines the curve is a parabola (NCP_SEG_PARAB): run at a
 * constant speed its velocity turns linearly from the one line's to the
 * other's, so each axis brakes or speeds up at a constant rate and the axes
 * of both lines work at once, where on a circle the centripetal acceleration
 * falls on one axis after the other: within the same P the parabola is
 * faster (v^2 <= 8 P a / (|u2 - u1| |u2_j - u1_j|) per axis j against the
 * circle's a r, r = P cos(phi/2) / (1 - cos(phi/2)), always below). Where
 * that even parabola holds the corner below the feed, the planner may take
 * an uneven one instead (ncp_blend_corner_ratio): entered slower than it is
 * left, or the other way, its constant acceleration turns towards the axis
 * the even one leaves idle. Between an arc and a line the blend is the
 * parabola through the pull of the arc's tangent and the line (a circle
 * where the cut is too small for one). Each stays within the tolerance P of
 * the programmed path (the line-line parabolas within P of the two lines,
 * the G64 P band; an arc's blend within P of the corner point, which is
 * nearer) and uses at most the rest of the line before it and half of the
 * line after it, so neighbouring blends never overlap; the planner
 * (try_blend) makes an even one no larger than the speed it is for needs. */
#include "blend.h"
#include "planner_int.h"

#include <math.h>
#include <string.h>

/* What a blend leaves of the line before it, mm. */
#define BLEND_LINE_LEFT 1e-3

static void direction(const struct ncp_seg *s, double u[3])
{
    for (int i = 0; i < 3; i++)
        u[i] = (s->end[i] - s->start[i]) / s->length;
}

/* The sine of the turn between unit directions u1 and u2: how far a point
 * of one line lies from the other per unit of its distance from the corner. */
static double band_sin(const double u1[3], const double u2[3])
{
    double n[3];
    cross3(u1, u2, n);
    return sqrt(dot3(n, n));
}

int ncp_blend_corner(const struct ncp_seg *prev, const struct ncp_seg *cur, double max_trim,
                     struct ncp_seg *blend, double *trim)
{
    /* the blend is drawn in X Y Z: a corner where another axis moves is a
     * kink instead */
    if (prev->kind != NCP_SEG_LINE || cur->kind != NCP_SEG_LINE ||
        prev->term != NCP_TERM_CONTINUOUS || prev->length <= 0 || cur->length <= 0 ||
        ncp_seg_moves_other(prev) || ncp_seg_moves_other(cur))
        return 0;
    double u1[3], u2[3];
    direction(prev, u1);
    direction(cur, u2);
    double c = dot3(u1, u2);
    /* collinear needs no blend; a near reversal would need a vanishing radius */
    if (c > 1 - 1e-12 || c < -0.999)
        return 0;
    /* prev's start is settled by the corner before: what is left of it may
     * all go to this corner (a micrometre stays, so its direction stays
     * exact); cur keeps half for the corner after */
    double d = fmin(max_trim, fmin(prev->length - BLEND_LINE_LEFT, 0.5 * cur->length));
    /* G64 P bounds the path's distance from the programmed lines, not from
     * the corner point: the curve's points lie t^2 d sin(phi) from the one
     * line and (1 - t)^2 d sin(phi) from the other, so at most d sin(phi) / 4
     * from the nearer one (halfway, where it passes the corner point
     * d |u2 - u1| / 4 = P / cos(phi/2) away, as every path in the band must
     * at that speed) */
    if (prev->tolerance > 0)
        d = fmin(d, 4 * prev->tolerance / band_sin(u1, u2));
    if (d < 1e-6)
        return 0;
    memset(blend, 0, sizeof *blend);
    blend->kind = NCP_SEG_PARAB;
    blend->term = NCP_TERM_CONTINUOUS;
    blend->traverse = (uint8_t)(prev->traverse && cur->traverse);
    blend->line = cur->line;  /* the corner is where the next block's motion begins */
    blend->tool_z = prev->tool_z;
    blend->aux = prev->aux;   /* what comes with the next block waits for its own segment */
    blend->rev_rpm = prev->rev_rpm;
    blend->feed = fmin(prev->feed, cur->feed);
    blend->blend_feed = fmin(prev->blend_feed > 0 ? prev->blend_feed : prev->feed,
                             cur->blend_feed > 0 ? cur->blend_feed : cur->feed);
    for (int i = 3; i < NCP_AXES; i++)
        blend->start[i] = blend->end[i] = prev->end[i];
    for (int i = 0; i < 3; i++) {
        blend->start[i] = prev->end[i] - u1[i] * d;
        blend->end[i] = prev->end[i] + u2[i] * d;
        blend->center[i] = prev->end[i];
    }
    blend->length = 2 * d;
    *trim = d;
    return 1;
}

/* How far an uneven parabola with corner C, start C - u1 and end C + rho u2
 * (|u1| = |u2| = 1, turning by phi) strays from the two lines: at parameter l
 * it lies rho l^2 sin(phi) from the first and (1 - l)^2 sin(phi) from the
 * second, and the nearer of the two is farthest where they are equal,
 * l = 1 / (1 + sqrt(rho)). The curve is scaled by r0 for a real blend. */
static double ratio_depth(double rho, double sin_phi)
{
    double q = 1 + sqrt(rho);
    return rho * sin_phi / (q * q);
}

/* f for the corner between prev and cur, where ncp_blend_corner blends it */
static void fan_set(struct ncp_blend_fan *f, const struct ncp_seg *prev, const struct ncp_seg *cur,
                    double rho)
{
    direction(prev, f->u1);
    direction(cur, f->u2);
    memcpy(f->c, prev->end, sizeof f->c);
    f->rho = rho;
    /* within the lines as the even blend is */
    f->room = fmin(prev->length - BLEND_LINE_LEFT, 0.5 * cur->length / rho);
}

/* f where the corner between prev and cur has a blend (its even one, P
 * aside, left in *blend); 0 where it has none. */
static int fan_corner(struct ncp_blend_fan *f, const struct ncp_seg *prev, const struct ncp_seg *cur,
                      double rho, struct ncp_seg *blend)
{
    struct ncp_seg free_prev = *prev;
    double d;
    free_prev.tolerance = 0;
    if (rho <= 0 || !ncp_blend_corner(&free_prev, cur, INFINITY, blend, &d))
        return 0;
    fan_set(f, prev, cur, rho);
    return 1;
}

int ncp_blend_fan_init(struct ncp_blend_fan *f, const struct ncp_seg *prev,
                       const struct ncp_seg *cur, double rho)
{
    struct ncp_seg blend;
    return fan_corner(f, prev, cur, rho, &blend);
}

/* At rho 1 the bounds and the end are ncp_blend_corner's: a division by 1
 * and a product with 1 change no bit. */
double ncp_blend_fan_at(const struct ncp_blend_fan *f, double r0, double start[3], double end[3])
{
    r0 = fmin(r0, f->room);
    if (r0 < 1e-6)
        return 0;
    for (int i = 0; i < 3; i++) {
        start[i] = f->c[i] - f->u1[i] * r0;
        end[i] = f->c[i] + f->u2[i] * f->rho * r0;
    }
    return r0;
}

int ncp_blend_corner_ratio_at(const struct ncp_seg *prev, const struct ncp_seg *cur, double rho,
                              double r0, struct ncp_seg *blend, double *trim_prev, double *trim_cur)
{
    struct ncp_blend_fan f;
    if (!fan_corner(&f, prev, cur, rho, blend))
        return 0;
    r0 = ncp_blend_fan_at(&f, r0, blend->start, blend->end);
    if (r0 == 0)
        return 0;
    blend->tolerance = 0;
    blend->r0 = r0;
    blend->r1 = rho * r0;
    blend->length = blend->r0 + blend->r1;
    *trim_prev = blend->r0;
    *trim_cur = blend->r1;
    return 1;
}

int ncp_blend_corner_ratio(const struct ncp_seg *prev, const struct ncp_seg *cur, double rho,
                           struct ncp_seg *blend, double *trim_prev, double *trim_cur)
{
    if (prev->tolerance <= 0 || rho <= 0 || rho == 1 || prev->length <= 0 || cur->length <= 0)
        return 0;
    double u1[3], u2[3];
    direction(prev, u1);
    direction(cur, u2);
    double reach = ratio_depth(rho, band_sin(u1, u2));
    if (!(reach > 0))
        return 0;
    /* the largest r0 within P */
    return ncp_blend_corner_ratio_at(prev, cur, rho, prev->tolerance / reach, blend, trim_prev,
                                     trim_cur);
}

/* The same segment run backwards (lines, and arcs without axial travel). */
static void reverse(const struct ncp_seg *s, struct ncp_seg *o)
{
    *o = *s;
    memcpy(o->start, s->end, sizeof o->start);
    memcpy(o->end, s->start, sizeof o->end);
    if (s->kind != NCP_SEG_ARC)
        return;
    double c = cos(s->angle), sn = sin(s->angle);
    for (int i = 0; i < 3; i++) {
        o->u[i] = c * s->u[i] + sn * s->w[i];
        o->w[i] = c * s->w[i] - sn * s->u[i];
    }
    o->angle = -s->angle;
    o->r0 = s->r1;
    o->r1 = s->r0;
}

int ncp_blend_line_leaves(const struct ncp_seg *arc, const struct ncp_seg *line)
{
    double u[3];
    direction(line, u);
    return fabs(dot3(u, arc->normal)) > 1e-9;
}

static int plane_arc(const struct ncp_seg *s)
{
    /* a programmed arc's radii differ by the rounding of its end and centre */
    return s->kind == NCP_SEG_ARC && fabs(s->axial) < 1e-12 &&
           fabs(s->r1 - s->r0) < 1e-3 * fmax(s->r0, s->r1) && s->length > 0;
}

/* An arc (prev) running into a line (cur) in its plane: the arc's last
 * arc_trim of length is given up; the tangent at the cut meets the line at X,
 * and the blend joins the points at equal distance s from X on both: the
 * corner parabola through the pull of X (a circle tangent at those points
 * where s is too small for a parabola). Its distance from the programmed
 * path is at most the blend's from X plus X's from the corner plus the arc's
 * sagitta over the cut. Where the line turns the same way as the arc, the
 * tangent meets it only behind the corner, on its extension (q < 0): X is
 * then that far outside, which the same sum counts (so only under a G64 P),
 * and the blend still ends on the line as long as s reaches past the corner.
 * A line that leaves the arc's plane (a CAM contour's Z beside a G2/G3 in
 * XY) never meets that tangent: X is then the tangent's point nearest the
 * line, the blend ends s from it along the line's direction, off the line by
 * their distance (skew), and the line runs on from there to its end (a kink
 * of about skew / length there, which the junction's speed takes); the sum
 * counts the skew too. Before, such a corner was a kink: an arc into a
 * 15 degree turn came down to 2 mm/s. Returns 0 when the cut gives no
 * proper blend. */
static int arc_line(const struct ncp_seg *prev, const struct ncp_seg *cur, double arc_trim,
                    struct ncp_seg *arc, struct ncp_seg *prev_out, struct ncp_seg *cur_out,
                    double *dev)
{
    double q1[NCP_AXES], t1[NCP_AXES], t2[3], n[3], d[3], a[3], b[3];
    double r_arc = fmax(prev->r0, prev->r1);
    if (arc_trim <= 0 || arc_trim > 0.5 * prev->length)
        return 0;
    ncp_seg_eval(prev, prev->length - arc_trim, q1, t1);
    direction(cur, t2);
    int skewed = ncp_blend_line_leaves(prev, cur);
    if (skewed && prev->tolerance <= 0)
        return 0;  /* off the plane only where P bounds the blend */
    cross3(t1, t2, n);
    double nn = dot3(n, n), c = dot3(t1, t2);
    if (nn < 1e-18 || c < -0.999)
        return 0;
    for (int i = 0; i < 3; i++)
        d[i] = prev->end[i] - q1[i];
    cross3(d, t2, a);
    cross3(d, t1, b);
    double s = dot3(a, n) / nn, q = dot3(b, n) / nn;
    /* X behind the corner only where P bounds how far outside it lies: as
     * the cut grows it runs away from the path far faster than in front */
    if (s <= 0 || q + s <= 0 || (q < 0 && prev->tolerance <= 0) || q + s > 0.5 * cur->length)
        return 0;
    double phi = acos(c), r = s / tan(0.5 * phi);
    double xc = 0, nin[3], nl = 0, du = 0;
    for (int i = 0; i < 3; i++) {
        double x = q1[i] + s * t1[i];
        xc += (x - prev->end[i]) * (x - prev->end[i]);
        nin[i] = t2[i] - c * t1[i];
        nl += nin[i] * nin[i];
        du += (t2[i] - t1[i]) * (t2[i] - t1[i]);
    }
    nl = sqrt(nl);
    double skew = 0;   /* from the tangent's X to the line's nearest point */
    for (int i = 0; skewed && i < 3; i++) {
        double k = q1[i] + s * t1[i] - (prev->end[i] + q * t2[i]);
        skew += k * k;
    }
    skew = sqrt(skew);
    /* Between the same two points the corner parabola (through the pull of
     * X) passes X closer, s |t2 - t1| / 4 against the circle's
     * r (1 / cos(phi/2) - 1), and faster: both axes turn at once. Only a cut
     * so small that the parabola would have no length keeps the circle. */
    int parab = s >= 1e-6;
    *dev = (parab ? 0.25 * s * sqrt(du) : r * (1.0 / cos(0.5 * phi) - 1.0)) + sqrt(xc) +
           r_arc * (1 - cos(arc_trim / r_arc)) + skew;
    *prev_out = *prev;
    prev_out->angle = prev->angle * (1 - arc_trim / prev->length);
    prev_out->length = prev->length - arc_trim;
    prev_out->r1 = prev->r0 + (prev->r1 - prev->r0) * (1 - arc_trim / prev->length);
    memcpy(prev_out->end, q1, sizeof prev_out->end);
    *cur_out = *cur;
    cur_out->length = cur->length - (q + s);
    memset(arc, 0, sizeof *arc);
    arc->kind = parab ? NCP_SEG_PARAB : NCP_SEG_ARC;
    arc->term = NCP_TERM_CONTINUOUS;
    arc->line = cur->line;
    arc->aux = prev->aux;
    arc->rev_rpm = prev->rev_rpm;
    arc->feed = fmin(prev->feed, cur->feed);
    arc->blend_feed = fmin(prev->blend_feed > 0 ? prev->blend_feed : prev->feed,
                           cur->blend_feed > 0 ? cur->blend_feed : cur->feed);
    for (int i = 0; i < 3; i++) {
        cur_out->start[i] = q1[i] + s * t1[i] + s * t2[i];
        arc->start[i] = q1[i];
        arc->end[i] = cur_out->start[i];
        if (parab) {
            arc->center[i] = q1[i] + s * t1[i];  /* X, the parabola's corner */
            continue;
        }
        arc->center[i] = q1[i] + r * nin[i] / nl;
        arc->u[i] = -nin[i] / nl;
        arc->normal[i] = n[i] / sqrt(nn);
    }
    for (int i = 3; i < NCP_AXES; i++) {
        arc->start[i] = q1[i];
        arc->end[i] = cur_out->start[i] = cur->start[i];
    }
    if (skewed) {
        ncp_seg_set_length(cur_out);
        if (cur_out->length <= 0.5 * cur->length)
            return 0;
    }
    if (parab) {
        arc->length = 2 * s;
        return 1;
    }
    cross3(arc->normal, arc->u, arc->w);
    arc->r0 = arc->r1 = r;
    arc->angle = phi;
    arc->length = r * phi;
    return 1;
}

int ncp_blend_arc_corner(const struct ncp_seg *prev, const struct ncp_seg *cur, double arc_trim,
                         struct ncp_seg *arc, struct ncp_seg *prev_out, struct ncp_seg *cur_out)
{
    /* drawn in X Y Z, as the line-line blend: a corner where another axis
     * moves stays a kink */
    if (prev->term != NCP_TERM_CONTINUOUS || prev->traverse || cur->traverse ||
        ncp_seg_moves_other(prev) || ncp_seg_moves_other(cur))
        return 0;
    double dev = 0;
    if (plane_arc(prev) && cur->kind == NCP_SEG_LINE && cur->length > 0) {
        if (!arc_line(prev, cur, arc_trim, arc, prev_out, cur_out, &dev))
            return 0;
    } else if (prev->kind == NCP_SEG_LINE && prev->length > 0 && plane_arc(cur)) {
        struct ncp_seg ra, rl, rarc, ro_a, ro_l;
        reverse(cur, &ra);
        reverse(prev, &rl);
        if (!arc_line(&ra, &rl, arc_trim, &rarc, &ro_a, &ro_l, &dev))
            return 0;
        reverse(&ro_l, prev_out);
        reverse(&ro_a, cur_out);
        reverse(&rarc, arc);
        arc->line = cur->line;
        arc->aux = prev->aux;
        prev_out->kind = NCP_SEG_LINE;
    } else {
        return 0;
    }
    return prev->tolerance <= 0 || dev <= prev->tolerance;
}
