/* G5.2 / G5.3: a NURBS curve in the XY plane, given one control point a block
 * (X Y, weight P, order L on any of them) and drawn at G5.3. rs274 2.9's
 * rules, checks and messages in its order (interp_convert.cc convert_nurbs):
 * - the first G5.2 puts the current point in front, weight 1 or its P when it
 *   has P and no X Y; the order is 3 unless some L above 3 says more;
 * - every later point needs X, Y and P > 0; the current point does not move
 *   while points are given, so G91 counts from where the curve starts;
 * - G5.3 draws them: the current point becomes the last control point (Z
 *   stays) and the motion mode becomes none, so a bare X Y after it is an
 *   error, as after G80.
 * rs274 -g prints NURBS_FEED(count, ...) only; the points follow the call
 * as NURBS_POINTS ops, which print nothing and carry the curve to the NCK. */
#include "floor.h"
#include "stages.h"

#include <stdlib.h>
#include <string.h>

#define NCP_NURBS_MAX_POINTS (1u << 20)

static int ncp_g52_push(struct ncp_analyzer *a, double x, double y, double w)
{
    struct ncp_g52_points *nb = &a->nurbs;
    if (nb->n == nb->cap) {
        if (nb->cap >= NCP_NURBS_MAX_POINTS)
            return ncp_an_error(a, a->w.line_col,
                                "NURBS with more than %u control points: give it in parts",
                                NCP_NURBS_MAX_POINTS);
        uint32_t cap = nb->cap ? nb->cap * 2 : 64;
        double (*pt)[3] = realloc(nb->pt, cap * sizeof *pt);
        if (!pt)
            return ncp_an_error(a, a->w.line_col, "out of memory for NURBS control points");
        nb->pt = pt;
        nb->cap = cap;
    }
    nb->pt[nb->n][0] = x;
    nb->pt[nb->n][1] = y;
    nb->pt[nb->n][2] = w;
    nb->n++;
    return NCP_OK;
}

int ncp_g52_point(struct ncp_analyzer *a)
{
    struct ncp_state *s = &a->st;
    const struct ncp_words *w = &a->w;
    struct ncp_g52_points *nb = &a->nurbs;
    uint16_t col = NCP_MOTION_COL(w);
    int has_x = NCP_HAS(w, 'X'), has_y = NCP_HAS(w, 'Y');
    double p = NCP_HAS(w, 'P') ? w->v[NCP_LETTER('P')] : -1.0; /* rs274: no P is -1 */
    if (has_x != has_y)
        return ncp_an_error(a, col, "You must specify both X and Y coordinates for Control Points");
    /* the checks see the last curve's points until this block drops them */
    if (!has_x && p > 0.0 && nb->n != 0)
        return ncp_an_error(a, col, "Can specify P without X and Y only for the first control point");
    if (p <= 0.0 && nb->n != 0)
        return ncp_an_error(a, col, "Must specify positive weight P for every Control Point");
    if (s->m.feed_mode == 0 && s->feed == 0.0)
        return ncp_an_error(a, col, "Cannot make a NURBS with 0 feedrate");
    if (s->m.motion != NCP_G5_2)
        nb->n = 0;
    int rc;
    if (nb->n == 0) {
        rc = ncp_g52_push(a, s->pos[NCP_X], s->pos[NCP_Y], !has_x && p > 0.0 ? p : 1.0);
        if (rc != NCP_OK)
            return rc;
        nb->order = 3;
    }
    if (NCP_HAS(w, 'L')) {
        int l = ncp_trunc_int_round(w->v[NCP_LETTER('L')]);
        if (l > 3)
            nb->order = l;
    }
    if (has_x) {
        double end[NCP_NAX];
        rc = ncp_motion_ends(a, w->g[NCP_GG_NONMODAL] == NCP_G53, end);
        if (rc == NCP_OK)
            rc = ncp_g52_push(a, end[NCP_X], end[NCP_Y], p);
        if (rc != NCP_OK)
            return rc;
    }
    s->m.motion = NCP_G5_2;
    return NCP_OK;
}

int ncp_g52_draw(struct ncp_analyzer *a)
{
    struct ncp_state *s = &a->st;
    struct ncp_g52_points *nb = &a->nurbs;
    uint16_t col = a->w.gcol[NCP_GG_NONMODAL];
    if (s->m.motion != NCP_G5_2)
        return ncp_an_error(a, col, "Cannot use G5.3 without G5.2 first");
    if (nb->n < (uint32_t)nb->order)
        return ncp_an_error(a, col,
                            "You must specify a number of control points at least equal to the order L = %d",
                            nb->order);
    const double *last = nb->pt[nb->n - 1];
    struct ncp_canon *op = ncp_an_emit(a, NCP_C_NURBS_FEED);
    op->nurbs.n_points = (int32_t)nb->n;
    op->nurbs.order = nb->order;
    op->nurbs.follow = NCP_NURBS_POINTS_FOLLOW;
    op->nurbs.end[0] = last[0];
    op->nurbs.end[1] = last[1];
    op->nurbs.end[2] = s->pos[NCP_Z];
    for (uint32_t k = 0; k < nb->n; k += NCP_NURBS_POINTS_PER_OP) {
        uint32_t m = nb->n - k < NCP_NURBS_POINTS_PER_OP ? nb->n - k : NCP_NURBS_POINTS_PER_OP;
        op = ncp_an_emit(a, NCP_C_NURBS_POINTS);
        op->nurbs_points.n = (int32_t)m;
        memcpy(op->nurbs_points.pt, nb->pt[k], m * sizeof nb->pt[0]);
    }
    /* rs274's canon reads the point after the last for its own X Y (past the
     * end of its vector; 0 here, as after G5 and G5.1: see motion.c) */
    a->sai.pos[NCP_X] = a->sai.pos[NCP_Y] = 0.0;
    if (ncp_cutcomp_engaged(&a->comp) && !a->comp.firstmove) {
        /* the compensated point moves, the programmed one stays (rs274) */
        ncp_cutcomp_moved_to(&a->comp, last[0], last[1]);
        if (a->comp.plane == 2) /* Y is off the plane: compensation does not hold it back */
            s->pos[NCP_Y] = last[1];
    } else {
        s->pos[NCP_X] = last[0];
        s->pos[NCP_Y] = last[1];
    }
    nb->n = 0;
    s->m.motion = -1;
    return NCP_OK;
}

void ncp_g52_free(struct ncp_analyzer *a)
{
    free(a->nurbs.pt);
    memset(&a->nurbs, 0, sizeof a->nurbs);
}
