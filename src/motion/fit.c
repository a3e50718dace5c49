/* Arcs through CAM chains: a run of short G64 lines that samples a smooth
 * curve is run as the curve, not corner by corner. A corner's blend may use
 * only half of its shorter chord, so on 0.02-0.2 mm chords each parabola is
 * tiny and the speed follows the chords' uneven turns; a circle through
 * several chords turns at the curve's own radius. After fairing (fair.c)
 * the held lines are covered by biarcs (two arcs meeting tangent) from one
 * faired chord's midpoint to a later one's, tangent to both chords, so that
 * an arc starts and ends where a line could take over without a corner.
 * Each biarc reaches as far as it stays within P of the lines AS
 * PROGRAMMED: every programmed vertex within P of it, and every point of it
 * within P of the programmed polyline (P less the servo chords'
 * cut); where none fits, the faired lines and their blends run as before.
 * The arcs are cut where they pass each programmed vertex and each piece
 * carries its line's number, so a trace still says which block it ran.
 * Work per block is bounded: a biarc spans at most PLAN_FAIR_MAX chords,
 * each end is tried once, and only the longest that covers the vertices is
 * sampled (the next shorter where that fails). bench/RESULTS.md, "Planner
 * against LinuxCNC 2.9's". */
#include "planner_int.h"

#include <math.h>
#include <string.h>

/* an arc sweeping more than this (rad) is not taken as a sample of the
 * chords: they turn at most FAIR_TURN_MAX each and a biarc's halves follow
 * them; it would rather be a loop the fit invented */
#define FIT_SWEEP_MAX 2.5
/* samples of the final biarc per P (biarc_inside) */
#define FIT_SAMPLES_P 2

/* One circular arc (or a line, r == 0) from p0 along t0. */
struct fit_arc {
    double p0[3], t0[3], c[3], n[3], u[3], w[3], r, sweep, len;
};

struct biarc {
    struct fit_arc a[2];
    double len;
};

static double norm3(const double a[3])
{
    return sqrt(dot3(a, a));
}

/* Hands on the part of held line k (of n) from a to b, on its faired
 * course, with the P its blends may use; more: not the line's first piece. */
static void line_out(struct ncp_planner *p, int n, int k, const double a[3], const double b[3],
                     int more)
{
    /* a segment whose ends moved by at most e lies within e of the
     * programmed one; the blend at its end turns onto line k + 1 */
    double e = 0;
    for (int i = k; i <= k + 2 && i <= n; i++)
        e = fmax(e, dist3(p->fair_pt[i], p->fair_orig[i]));
    struct ncp_seg s = p->fair_seg[k];
    memcpy(s.start, a, 3 * sizeof a[0]);
    memcpy(s.end, b, 3 * sizeof b[0]);
    ncp_seg_set_length(&s);
    s.tolerance -= e;
    p->fair_out_flags[p->fair_out_n] = more ? PLAN_OUT_MORE : 0;
    p->fair_out[p->fair_out_n++] = s;
}

/* The arc from p0 along the unit t0 through e. 0 when it sweeps too far. */
static int arc_to(const double p0[3], const double t0[3], const double e[3], struct fit_arc *a)
{
    double c[3], perp[3];
    for (int j = 0; j < 3; j++)
        c[j] = e[j] - p0[j];
    double cl = norm3(c), ct = dot3(c, t0);
    for (int j = 0; j < 3; j++)
        perp[j] = c[j] - ct * t0[j];
    double pl = norm3(perp);
    memcpy(a->p0, p0, sizeof a->p0);
    memcpy(a->t0, t0, sizeof a->t0);
    if (cl <= 0)
        return 0;
    if (pl <= 1e-12 * cl) {
        a->r = 0;
        a->sweep = 0;
        a->len = cl;
        return ct > 0;
    }
    double half = atan2(pl, ct);
    a->sweep = 2 * half;
    if (a->sweep > FIT_SWEEP_MAX)
        return 0;
    a->r = cl / (2 * sin(half));
    for (int j = 0; j < 3; j++) {
        a->u[j] = -perp[j] / pl;
        a->w[j] = t0[j];
        a->c[j] = p0[j] - a->r * a->u[j];
    }
    cross3(a->u, a->w, a->n);
    a->len = a->r * a->sweep;
    return 1;
}

static void arc_eval(const struct fit_arc *a, double s, double p[3], double t[3])
{
    if (a->r <= 0) {
        for (int j = 0; j < 3; j++) {
            p[j] = a->p0[j] + s * a->t0[j];
            if (t)
                t[j] = a->t0[j];
        }
        return;
    }
    double phi = s / a->r, c = cos(phi), sn = sin(phi);
    for (int j = 0; j < 3; j++) {
        p[j] = a->c[j] + a->r * (c * a->u[j] + sn * a->w[j]);
        if (t)
            t[j] = -sn * a->u[j] + c * a->w[j];
    }
}

/* Distance from q to the arc and the arc length of its nearest point. */
static double arc_dist(const struct fit_arc *a, const double q[3], double *at)
{
    double d[3], e[3], s_end = a->len;
    if (a->r > 0) {
        for (int j = 0; j < 3; j++)
            d[j] = q[j] - a->c[j];
        double h = dot3(d, a->n), x = dot3(d, a->u), y = dot3(d, a->w);
        double phi = atan2(y, x);
        if (phi < 0)
            phi += 2 * M_PI;
        if (phi <= a->sweep) {
            *at = phi * a->r;
            double rho = sqrt(x * x + y * y) - a->r;
            return sqrt(h * h + rho * rho);
        }
    } else {
        for (int j = 0; j < 3; j++)
            d[j] = q[j] - a->p0[j];
        double s = fmin(a->len, fmax(0, dot3(d, a->t0)));
        for (int j = 0; j < 3; j++)
            e[j] = d[j] - s * a->t0[j];
        *at = s;
        return norm3(e);
    }
    /* beyond its ends: the nearer end */
    arc_eval(a, s_end, e, NULL);
    double d0 = dist3(q, a->p0), d1 = dist3(q, e);
    *at = d1 < d0 ? s_end : 0;
    return fmin(d0, d1);
}

static double biarc_dist(const struct biarc *b, const double q[3], double *at)
{
    double s0, s1;
    double d0 = arc_dist(&b->a[0], q, &s0), d1 = arc_dist(&b->a[1], q, &s1);
    *at = d0 <= d1 ? s0 : b->a[0].len + s1;
    return fmin(d0, d1);
}

static void biarc_eval(const struct biarc *b, double s, double p[3])
{
    if (s <= b->a[0].len)
        arc_eval(&b->a[0], s, p, NULL);
    else
        arc_eval(&b->a[1], fmin(s, b->len) - b->a[0].len, p, NULL);
}

/* The biarc from p0 along t0 to p1 along t1 (unit tangents) whose tangent
 * legs are d0 and d1 = k d0: they meet at j, d0 along q0 = p0 + d0 t0
 * towards q1 = p1 - d1 t1, where |q1 - q0| = d0 + d1. */
static int biarc_make(const double p0[3], const double t0[3], const double p1[3],
                      const double t1[3], double k, struct biarc *b)
{
    double v[3], t[3], jt[3], j[3];
    for (int i = 0; i < 3; i++) {
        v[i] = p1[i] - p0[i];
        t[i] = t0[i] + k * t1[i];
    }
    double vt = dot3(v, t), vv = dot3(v, v), a = 2 * k * (1 - dot3(t0, t1)), d;
    if (vv <= 0)
        return 0;
    if (a < 1e-12) {
        if (vt <= 0)
            return 0;
        d = vv / (2 * vt);
    } else {
        d = (-vt + sqrt(vt * vt + a * vv)) / a;
    }
    if (!(d > 0))
        return 0;
    for (int i = 0; i < 3; i++) {
        double q0 = p0[i] + d * t0[i], q1 = p1[i] - k * d * t1[i];
        j[i] = q0 + (q1 - q0) / (1 + k);
    }
    if (!arc_to(p0, t0, j, &b->a[0]))
        return 0;
    double pe[3];
    arc_eval(&b->a[0], b->a[0].len, pe, jt);
    if (!arc_to(j, jt, p1, &b->a[1]))
        return 0;
    b->len = b->a[0].len + b->a[1].len;
    return 1;
}

/* The ratios of a biarc's legs tried for each end: the equal one, and one
 * leg twice the other either way, where a vertex off the curve would put
 * all the turn into one half. Of those that fit, the one whose tighter half
 * is widest (it sets the speed). On bench/gen-planner.py's tiny: 4.638 s
 * with equal legs only, 4.567 with these three, 4.559 with 1/4 and 4 too. */
static const double fit_legs[] = { 1, 0.5, 2 };
#define FIT_LEGS ((int)(sizeof fit_legs / sizeof fit_legs[0]))

/* The radius of the tighter half (a straight one: infinite). */
static double biarc_rmin(const struct biarc *b)
{
    double r0 = b->a[0].r > 0 ? b->a[0].r : INFINITY, r1 = b->a[1].r > 0 ? b->a[1].r : INFINITY;
    return fmin(r0, r1);
}

/* Every programmed vertex a+1..b within budget of the biarc, passed in
 * order (at[] its arc lengths there), and every programmed chord's middle
 * between them too. */
static int biarc_covers(const struct ncp_planner *p, const struct biarc *bi, int a, int b,
                        double budget, double at[])
{
    double last = 0, s;
    for (int k = a + 1; k <= b; k++) {
        const double *v = p->fair_seg[k].start;
        if (biarc_dist(bi, v, &s) > budget || s <= last || s >= bi->len)
            return 0;
        at[k - a - 1] = last = s;
    }
    for (int k = a + 1; k < b; k++) {
        double mid[3];
        for (int j = 0; j < 3; j++)
            mid[j] = 0.5 * (p->fair_seg[k].start[j] + p->fair_seg[k].end[j]);
        if (biarc_dist(bi, mid, &s) > budget)
            return 0;
    }
    return 1;
}

/* Every point of the biarc within budget of the programmed chords a..b.
 * The distance to one chord (a convex set) along a path of curvature
 * kappa has a second derivative of at least -kappa, so between two samples
 * h apart it exceeds the larger of their distances by at most
 * kappa h^2 / 8: two neighbouring samples both within lim of the same
 * chord keep the whole piece between them within budget. */
static int biarc_inside(const struct ncp_planner *p, const struct biarc *bi, int a, int b,
                        double budget)
{
    double h = budget / FIT_SAMPLES_P, kappa = 1 / biarc_rmin(bi);
    double lim = budget - kappa * h * h / 8;
    int steps = (int)ceil(bi->len / h), k = a;
    uint64_t near_prev = 0;
    for (int i = 0; i <= steps; i++) {
        double q[3], best = INFINITY;
        int at = k;
        uint64_t near = 0;
        biarc_eval(bi, bi->len * i / steps, q);
        for (int c = k > a ? k - 1 : a; c <= b && c <= k + 2; c++) {
            double d = plan_chord_dist(q, p->fair_seg[c].start, p->fair_seg[c].end, 3);
            if (d <= lim)
                near |= (uint64_t)1 << (c - a);
            if (d < best) {
                best = d;
                at = c;
            }
        }
        if (!near || (i > 0 && !(near & near_prev)))
            return 0;
        near_prev = near;
        k = at > k ? at : k;
    }
    return 1;
}

/* Midpoint and unit direction of faired chord k; 0 where it has none. */
static int chord_mid(const struct ncp_planner *p, int k, double m[3], double t[3])
{
    double l = 0;
    for (int j = 0; j < 3; j++) {
        m[j] = 0.5 * (p->fair_pt[k][j] + p->fair_pt[k + 1][j]);
        t[j] = p->fair_pt[k + 1][j] - p->fair_pt[k][j];
        l += t[j] * t[j];
    }
    l = sqrt(l);
    for (int j = 0; j < 3; j++)
        t[j] = l > 0 ? t[j] / l : 0;
    return l > 1e-9;  /* else no direction to be tangent to */
}

/* The farthest chord b in (a, last] whose midpoint a biarc from p0 along
 * t0 reaches within budget (of the leg ratios, the widest); a when none. */
static int fit_reach(const struct ncp_planner *p, int a, int last, const double p0[3],
                     const double t0[3], double budget, struct biarc *out, double at[])
{
    struct biarc bi[PLAN_FAIR_MAX];
    double s[PLAN_FAIR_MAX][PLAN_FAIR_MAX];
    int top = a, ok[PLAN_FAIR_MAX] = { 0 };
    if (dot3(t0, t0) < 0.5)
        return a;
    /* every end is tried, not only up to the first miss: a vertex stepped
     * off the curve (Z rounded per block) may stop one biarc where a longer
     * one passes it closer */
    for (int b = a + 1; b <= last; b++) {
        double m[3], t[3], sk[PLAN_FAIR_MAX];
        struct biarc cand;
        if (!chord_mid(p, b, m, t))
            continue;
        for (int q = 0; q < FIT_LEGS; q++) {
            if (!biarc_make(p0, t0, m, t, fit_legs[q], &cand) ||
                !biarc_covers(p, &cand, a, b, budget, sk))
                continue;
            if (ok[b - a - 1] && biarc_rmin(&cand) <= biarc_rmin(&bi[b - a - 1]))
                continue;
            bi[b - a - 1] = cand;
            memcpy(s[b - a - 1], sk, sizeof sk);
            ok[b - a - 1] = 1;
            top = b;
        }
    }
    for (int b = top; b > a; b--) {
        if (!ok[b - a - 1])
            continue;
        if (!biarc_inside(p, &bi[b - a - 1], a, b, budget))
            continue;
        *out = bi[b - a - 1];
        memcpy(at, s[b - a - 1], (size_t)(b - a) * sizeof at[0]);
        return b;
    }
    return a;
}

/* Hands on the part of the biarc from s0 to s1 as segments of line k. */
static void arc_out(struct ncp_planner *p, const struct biarc *bi, int k, double s0, double s1,
                    double budget, int more)
{
    for (int h = 0; h < 2; h++) {
        const struct fit_arc *a = &bi->a[h];
        double off = h ? bi->a[0].len : 0;
        double x0 = fmax(s0 - off, 0), x1 = fmin(s1 - off, a->len);
        if (x1 - x0 <= 1e-9 || p->fair_out_n >= PLAN_FIT_OUT_MAX)
            continue;
        struct ncp_seg s = p->fair_seg[k];
        /* the arc used the budget of P: a blend on it (none is expected:
         * it meets its neighbours tangent) gets what is left */
        s.tolerance -= budget;
        arc_eval(a, x0, s.start, NULL);
        arc_eval(a, x1, s.end, NULL);
        if (a->r > 0) {
            double phi = x0 / a->r, c = cos(phi), sn = sin(phi);
            s.kind = NCP_SEG_ARC;
            for (int j = 0; j < 3; j++) {
                s.center[j] = a->c[j];
                s.normal[j] = a->n[j];
                s.u[j] = c * a->u[j] + sn * a->w[j];
                s.w[j] = c * a->w[j] - sn * a->u[j];
            }
            s.r0 = s.r1 = a->r;
            s.angle = (x1 - x0) / a->r;
            s.axial = 0;
            s.length = x1 - x0;
        } else {
            ncp_seg_set_length(&s);
        }
        p->fair_out_flags[p->fair_out_n] = (uint8_t)(PLAN_OUT_FITTED | (more ? PLAN_OUT_MORE : 0));
        p->fair_out[p->fair_out_n++] = s;
        more = 1;
    }
}

/* The biarc from chord a's midpoint to chord b's, cut at the programmed
 * vertices a+1..b (at[]: their arc lengths), within budget of them. */
static void biarc_out(struct ncp_planner *p, const struct biarc *bi, int a, int b,
                      const double at[], double budget)
{
    double s = 0;
    for (int k = a; k <= b; k++) {
        double e = k < b ? at[k - a] : bi->len;
        arc_out(p, bi, k, s, e, budget, k == a);
        s = e;
    }
}

static int fit_on(const struct ncp_planner *p)
{
    return !plan_scurve(p) && !ncp_kins_active(&p->cfg);
}

int ncp_fit_emit(struct ncp_planner *p, int n, int m, int flush)
{
    double budget = p->fair_seg[0].tolerance - p->chord - 1e-6, p0[3], t0[3], at[PLAN_FAIR_MAX];
    int last = flush ? n - 1 : m, i = 0, on_arc = p->fit_half;
    struct biarc bi;
    if (on_arc) {  /* fair_pt[0] is the last arc's end on line 0, its tangent line 0's */
        chord_mid(p, 0, p0, t0);
        memcpy(p0, p->fair_pt[0], sizeof p0);
    }
    int fit = budget > 0 && fit_on(p);
    /* each round starts at line i, from the last arc's end (on_arc) or
     * from the faired chord's midpoint, and runs a biarc from there or the
     * line to its end */
    while (i < n && (flush || i < m)) {
        double mid[3], tm[3];
        if (!on_arc)
            chord_mid(p, i, mid, tm);
        int b = fit ? fit_reach(p, i, last, on_arc ? p0 : mid, on_arc ? t0 : tm, budget, &bi, at)
                    : i;
        if (b > i) {
            if (!on_arc)
                line_out(p, n, i, p->fair_pt[i], mid, 0);
            biarc_out(p, &bi, i, b, at, budget);
            i = b;
            chord_mid(p, b, p0, t0);
            on_arc = 1;
            continue;
        }
        line_out(p, n, i, on_arc ? p0 : p->fair_pt[i], p->fair_pt[i + 1], on_arc);
        i++;
        on_arc = 0;
    }
    p->fit_half = on_arc && i < n;
    if (p->fit_half) {
        /* the window goes on from the arc's end, on line i: its programmed
         * counterpart (for how far the vertices moved) is the programmed
         * chord's midpoint, within the larger move of its ends */
        memcpy(p->fair_pt[i], p0, sizeof p0);
        for (int j = 0; j < 3; j++)
            p->fair_orig[i][j] = 0.5 * (p->fair_seg[i].start[j] + p->fair_seg[i].end[j]);
    }
    return i;
}
