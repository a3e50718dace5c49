/* Planner state shared by the look-ahead (planner.c) and the interpolator
 * (interp.c). Not part of the public contract. */
#ifndef NCPAR_MOTION_PLANNER_INT_H
#define NCPAR_MOTION_PLANNER_INT_H

#include "ncpar/motion.h"

#include <math.h>

struct plan_seg {
    struct ncp_seg s;
    double vmax;    /* cruise cap: feed and per-axis velocity / centripetal limits */
    double acc;     /* path acceleration that keeps every axis within its limit */
    double acc_full;/* the same before a corner (kink) took its share */
    double jerk;    /* path jerk that keeps every axis within its limit (S-curve) */
    /* An arc's acceleration vector bound and curvature: below its cruise cap the
     * centripetal part v^2 kappa is smaller and leaves more for the tangent
     * (plan_acc_at); a_cap bounds what the other axes and caps allow. */
    double a_eff, kappa, a_cap;
    /* A fitted arc's per-axis room as well (arc_limits): the tangent may take
     * min_j (box_a[j] - v^2 box_kappa box_b[j]) where that beats the disc a_eff.
     * box_kappa 0: none. */
    double box_a[3], box_b[3], box_kappa;
    double vjunc;   /* entry speed cap from the junction with the previous segment */
    double v_in;    /* planned entry speed (backward pass: can still stop at the end) */
    int blend;      /* a G64 corner arc, not a programmed segment */
    /* an arc fitted through a CAM chain's lines (fit.c): feed path, not a
     * G2/G3, with its own share of the acceleration bound for the turn */
    int fitted;
    /* a line fairing moved (fair.c): its corner with a line as programmed
     * is held to the corner point, the band being the programmed lines' */
    int faired;
};

/* At most this many programmed lines are joined into one (LinuxCNC's bound). */
#define PLAN_CHAIN_MAX 100
/* At most this many short lines are held back to be faired (fair.c). */
#define PLAN_FAIR_MAX 32
/* What fairing and arc fitting may hand on from one window (fit.c). */
#define PLAN_FIT_OUT_MAX (4 * PLAN_FAIR_MAX + 4)
/* fair_out_flags: a fitted arc; a further piece of the same programmed line */
#define PLAN_OUT_FITTED 1u
#define PLAN_OUT_MORE 2u

/* A corner between two lines under G64 P whose vertex may be moved out
 * (edge.c): the programmed points around it, a before the corner c, b after. */
struct plan_corner {
    int valid;               /* a, c, b hold: the corner is between two such lines */
    int shifted;             /* the vertex runs at the outer edges' meeting point */
    int measured;            /* a line beside it left the programmed one: the blend
                              * is sized by measuring it against a, c, b */
    double a[3], c[3], b[3];
    double out;              /* how far outside the lines the path may run (P) */
};

struct ncp_planner {
    struct ncp_machine_cfg cfg;
    size_t cap;              /* look-ahead window */
    struct plan_seg *q;      /* ring of cap entries */
    size_t head, count;
    size_t programmed;       /* queued segments that are not blend arcs */
    int finished;
    int ended;               /* the interpolator got "no more": the next record is after_stop */
    /* the interpolator: ex.active = q[head] is executing with a frozen profile */
    struct ncp_exec ex;
    void (*tap)(void *ctx, const struct ncp_la *la, const struct ncp_accdec *rec);
    void *tap_ctx;
    int have_last;           /* last_pushed valid: junctions need the previous segment */
    struct ncp_seg last_pushed;
    double last_vmax;        /* its cruise cap */
    double chord;            /* how far a servo chord of a blend arc cuts inside it, mm */
    double chord_all;        /* the same for an uneven corner parabola (uneven_blend) */
    /* G64 Q (LinuxCNC's naive CAM detector): feed lines held back and joined
     * into one while every programmed point stays within Q of it */
    int chain_n;                        /* programmed points in the chain, 0 = none */
    struct ncp_seg chain;               /* the joined line so far */
    double chain_pt[PLAN_CHAIN_MAX][NCP_AXES];
    /* CAM chains held back to be faired (fair.c): the lines as programmed,
     * their programmed vertices and the moved ones (fair_n + 1 each) */
    int fair_n, fair_max;
    struct ncp_seg fair_seg[PLAN_FAIR_MAX];
    double fair_orig[PLAN_FAIR_MAX + 1][3], fair_pt[PLAN_FAIR_MAX + 1][3];
    /* fair_seg[0] was partly run as the end of a fitted arc (fit.c):
     * fair_pt[0] is where that arc ended, on the faired line, and fair_pt[1]
     * stays where it was so that the line keeps the arc's end tangent */
    int fit_half;
    /* faired lines and fitted arcs for the planner to queue, in order; a line
     * is at most two pieces of line and two of arc per biarc through it */
    int fair_out_n;
    struct ncp_seg fair_out[PLAN_FIT_OUT_MAX];
    /* per piece of fair_out: PLAN_OUT_FITTED, PLAN_OUT_MORE */
    uint8_t fair_out_flags[PLAN_FIT_OUT_MAX];
    int pushing_fit;         /* fair_drain is queueing a fitted arc */
    int pushing_fair;        /* fair_drain is queueing what fairing moved already */
    /* G64 P lines held back (edge.c): a vertex between the first two moves
     * only once the segment after the second shows that the second's end is
     * a corner between such lines too; the corner at each one's start */
    int edge_n;
    struct ncp_seg edge_line[2];
    struct plan_corner edge_start[2];
    /* the corner try_blend is blending (measured or shifted: edge.c) */
    struct plan_corner corner;
    struct ncp_planner_stats st;
};

/* X Y Z vector products and distances, for the blends', fairing's and the
 * fitted arcs' geometry. */
static inline double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static inline void cross3(const double a[3], const double b[3], double o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

static inline double dist3(const double a[3], const double b[3])
{
    double d[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] };
    return sqrt(dot3(d, d));
}

/* Distance from q to the segment a-b over their first dims coordinates
 * (G64 Q's chains measure all axes, the fitted arcs X Y Z). */
static inline double plan_chord_dist(const double *q, const double *a, const double *b, int dims)
{
    double ab2 = 0, t = 0, d2 = 0;
    for (int j = 0; j < dims; j++) {
        ab2 += (b[j] - a[j]) * (b[j] - a[j]);
        t += (q[j] - a[j]) * (b[j] - a[j]);
    }
    t = ab2 > 0 ? fmin(1, fmax(0, t / ab2)) : 0;
    for (int j = 0; j < dims; j++) {
        double e = a[j] + t * (b[j] - a[j]) - q[j];
        d2 += e * e;
    }
    return sqrt(d2);
}

static inline struct plan_seg *plan_at(struct ncp_planner *p, size_t k)
{
    return &p->q[(p->head + k) % p->cap];
}

void ncp_planner_pop(struct ncp_planner *p);

/* fair.c: may s join the CAM chain held back (or start one)? */
int ncp_fair_takes(const struct ncp_planner *p, const struct ncp_seg *s);
/* fair.c: holds s back; a full window hands its first lines on, faired
 * (fair_out). */
void ncp_fair_add(struct ncp_planner *p, const struct ncp_seg *s);
/* fair.c: fairs every line held back and hands it on (fair_out). */
void ncp_fair_flush(struct ncp_planner *p);
/* fit.c: hands on the held lines (of n) up to line m (to the end on flush)
 * as fitted arcs where they fit and as faired lines where not; returns
 * how many lines are done with: the window moves on by that many, its first
 * line partly run when p->fit_half is set. */
int ncp_fit_emit(struct ncp_planner *p, int n, int m, int flush);

/* planner.c: queues the lines held back for a moved vertex when little is
 * left to run (before each step). */
void ncp_planner_edge_low(struct ncp_planner *p);

/* edge.c: whether the corner parabola blend stays within k's band: tol_in
 * inside the programmed polyline a-c-b, k->out outside. */
int ncp_edge_within(const struct ncp_seg *blend, const struct plan_corner *k, double tol_in);
/* edge.c: the blends between prev and cur, even (rho 1) or uneven (trim d
 * off prev, rho d off cur), d up to max_trim and the lines' share, that stay
 * within tol of k's programmed polyline: d from *lo to *hi (either may be
 * NULL where not wanted, and its end of the range is not searched for). 0
 * when none does. */
void ncp_edge_prepare(void);
int ncp_edge_trims(const struct ncp_seg *prev, const struct ncp_seg *cur,
                   const struct plan_corner *k, double tol, double rho, double max_trim,
                   double *lo, double *hi);
/* edge.c: the vertex moved out along the outer bisector of a-c-b to where
 * the lines' outer edges at distance tol meet. 0 for a turn too slight or
 * too sharp to gain from it. */
int ncp_edge_vertex(const double a[3], const double c[3], const double b[3], double tol,
                    double out[3]);

/* scurve.c: evaluation of a jerk-limited profile (ncp_trap with j > 0). */
double ncp_scurve_eval(const struct ncp_trap *tp, double t, double *v);

static inline int plan_scurve(const struct ncp_planner *p)
{
    return p->cfg.profile == NCP_PROFILE_SCURVE;
}

/* Highest speed at one end of ps from which speed v at the other end is
 * reachable over len, under the profile (scurve: jerk-limited). */
static inline double plan_reach(int scurve, double acc, double jerk, double v, double len)
{
    if (scurve && jerk > 0 && isfinite(jerk))
        return ncp_scurve_reach(v, len, acc, jerk);
    return sqrt(v * v + 2 * acc * len);
}

/* The tangent a fitted arc's box leaves at centripetal acceleration a_n. */
static inline double plan_box_at(const struct plan_seg *ps, double a_n)
{
    double at = INFINITY;
    for (int j = 0; j < 3; j++)
        at = fmin(at, ps->box_a[j] - a_n * ps->box_b[j]);
    return at;
}

/* The path acceleration ps allows at speeds up to v: an arc's centripetal
 * acceleration v^2 kappa (a corner parabola's turn, parab_limits) takes less
 * of its bound a_eff below the cruise cap, so the tangent gets the rest,
 * scaled as a corner scaled acc. Never below acc, the value at the cruise cap.
 * A fitted arc's box (box_kappa) is read beside the disc: each is a bound on
 * what every axis allows, so the larger is too. */
static inline double plan_acc_at(const struct plan_seg *ps, double v)
{
    if (ps->kappa <= 0 || ps->acc_full <= 0)
        return ps->acc;
    double an = v * v * ps->kappa;
    double at = ps->a_eff > an ? sqrt(ps->a_eff * ps->a_eff - an * an) : 0;
    if (ps->box_kappa > 0)
        at = fmax(at, plan_box_at(ps, v * v * ps->box_kappa));
    return ps->acc / ps->acc_full * fmax(ps->acc_full, fmin(ps->a_cap, at));
}

/* planner.c: plan_reach for a queued segment, its acceleration taken at the
 * highest speed of the move (the arc's tangential share grows as it slows). */
double ncp_plan_seg_reach(int scurve, const struct plan_seg *ps, double v, double len);

/* planner.c: the largest constant acceleration for ps's profile from v0 to v1
 * whose peak speed (capped at vmax) still allows it. */
double ncp_plan_seg_profile_acc(int scurve, const struct plan_seg *ps, double v0, double v1,
                                double vmax);

#endif
