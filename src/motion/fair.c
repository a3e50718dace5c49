/* Fairing of CAM chains: a run of short G64 feed lines that sample a smooth
 * curve (CAM output, 0.02-0.2 mm chords) turns a little at every vertex, and
 * the turns are uneven: the chords' lengths vary, and a coordinate rounded
 * or stepped per block (Z in 4 decimals over a 0.02 mm chord) jerks the
 * direction back and forth. Each corner's blend may only use half of its
 * shortest neighbour, so the uneven turns hold the corner speeds far below
 * what the curve itself allows. The planner holds such a run back and moves
 * each inner vertex towards the point of the chord through its neighbours
 * (at the ratio of the chords' lengths: where the vertex would be if the
 * curve did not turn there) by a few smoothing passes, each vertex at most
 * FAIR_SHARE of P from where it was programmed. The turns spread evenly
 * along the curve and the blends then get what is left of P: a segment
 * whose ends moved by at most e lies within e of its programmed one, so a
 * blend within P - e of the moved corner keeps the path within P of the
 * programmed one. bench/RESULTS.md, "Planner against LinuxCNC 2.9's". */
#include "planner_int.h"

#include <math.h>
#include <string.h>

/* A chain is made of lines no longer than this many times P ... */
#define FAIR_LEN_P 50.0
/* ... turning at most this much (rad) at each vertex: a sharper corner is a
 * corner of the part, not a sample of a curve, and keeps its whole P */
#define FAIR_TURN_MAX 0.6
/* how far a vertex may move, as a share of P; the blends get the rest */
#define FAIR_SHARE 0.5
/* Jacobi passes and their step: each pass reaches one vertex further, and
 * more passes gained nothing on bench/gen-planner.py's tiny */
#define FAIR_PASSES 4
#define FAIR_STEP 0.5
/* when the window is full, this many lines stay for the next round, so that
 * every line sent had FAIR_PASSES neighbours on both sides */
#define FAIR_KEEP (2 * FAIR_PASSES)

static int fair_line(const struct ncp_planner *p, const struct ncp_seg *s)
{
    return p->fair_max > 2 * FAIR_KEEP && s->kind == NCP_SEG_LINE && !s->traverse &&
           s->term == NCP_TERM_CONTINUOUS && s->tolerance > 0 && s->length > 1e-6 &&
           s->length <= FAIR_LEN_P * s->tolerance && !ncp_seg_moves_other(s);
}

/* The turn from a's direction to b's, rad. */
static double turn(const struct ncp_seg *a, const struct ncp_seg *b)
{
    double c = 0;
    for (int j = 0; j < 3; j++)
        c += (a->end[j] - a->start[j]) * (b->end[j] - b->start[j]);
    c /= a->length * b->length;
    return acos(fmax(-1, fmin(1, c)));
}

int ncp_fair_takes(const struct ncp_planner *p, const struct ncp_seg *s)
{
    if (!fair_line(p, s))
        return 0;
    if (!p->fair_n)
        return 1;
    const struct ncp_seg *last = &p->fair_seg[p->fair_n - 1];
    if (s->feed != last->feed || s->blend_feed != last->blend_feed ||
        s->tolerance != last->tolerance || s->aux != last->aux || s->rev_rpm != last->rev_rpm ||
        s->tool_z != last->tool_z)
        return 0;
    for (int j = 0; j < NCP_AXES; j++)
        if (fabs(s->start[j] - last->end[j]) > 1e-9)
            return 0;
    return turn(last, s) <= FAIR_TURN_MAX;
}

/* Smooths pt[1 .. n-1] (pt[0] and pt[n] stay), from the programmed points;
 * pt[1] stays too where line 0 is the rest of a fitted arc's last line. */
static void relax(struct ncp_planner *p, int n)
{
    double (*pt)[3] = p->fair_pt, nxt[PLAN_FAIR_MAX + 1][3];
    double lim = FAIR_SHARE * p->fair_seg[0].tolerance;
    int first = p->fit_half ? 2 : 1;
    for (int i = first; i < n; i++)
        memcpy(pt[i], p->fair_orig[i], sizeof pt[i]);
    for (int pass = 0; pass < FAIR_PASSES; pass++) {
        for (int i = first; i < n; i++) {
            double l1 = dist3(pt[i - 1], pt[i]), l2 = dist3(pt[i], pt[i + 1]), d[3], m = 0;
            double t = l1 + l2 > 0 ? l1 / (l1 + l2) : 0.5;
            for (int j = 0; j < 3; j++) {
                double q = pt[i - 1][j] + t * (pt[i + 1][j] - pt[i - 1][j]);
                d[j] = pt[i][j] + FAIR_STEP * (q - pt[i][j]) - p->fair_orig[i][j];
                m += d[j] * d[j];
            }
            m = sqrt(m);
            double k = m > lim ? lim / m : 1;
            for (int j = 0; j < 3; j++)
                nxt[i][j] = p->fair_orig[i][j] + k * d[j];
        }
        for (int i = first; i < n; i++)
            memcpy(pt[i], nxt[i], sizeof pt[i]);
    }
}

void ncp_fair_add(struct ncp_planner *p, const struct ncp_seg *s)
{
    int n = p->fair_n;
    if (!n) {
        p->fit_half = 0;
        memcpy(p->fair_orig[0], s->start, sizeof p->fair_orig[0]);
        memcpy(p->fair_pt[0], s->start, sizeof p->fair_pt[0]);
    }
    p->fair_seg[n] = *s;
    memcpy(p->fair_orig[n + 1], s->end, sizeof p->fair_orig[0]);
    memcpy(p->fair_pt[n + 1], s->end, sizeof p->fair_pt[0]);
    p->fair_n = ++n;
    if (n < p->fair_max)
        return;
    /* up to the first n - FAIR_KEEP go; the rest start again from where
     * the last piece sent ended */
    relax(p, n);
    int m = ncp_fit_emit(p, n, n - FAIR_KEEP, 0);
    memmove(p->fair_seg, p->fair_seg + m, (size_t)(n - m) * sizeof p->fair_seg[0]);
    memmove(p->fair_orig, p->fair_orig + m, (size_t)(n - m + 1) * sizeof p->fair_orig[0]);
    memmove(p->fair_pt, p->fair_pt + m, (size_t)(n - m + 1) * sizeof p->fair_pt[0]);
    p->fair_n = n - m;
}

void ncp_fair_flush(struct ncp_planner *p)
{
    int n = p->fair_n;
    if (!n)
        return;
    p->fair_n = 0;
    relax(p, n);
    ncp_fit_emit(p, n, n, 1);
    p->fit_half = 0;
}
