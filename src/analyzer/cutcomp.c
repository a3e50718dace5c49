/* The sequential half of cutter compensation: rs274's queue of calls held back
 * until the next move fixes the corner. See cutcomp.h. */
#include "cutcomp.h"
#include "codes.h"
#include "ncpar/geom.h"

#include <math.h>
#include <string.h>

#define NCP_RADIUS_TOL_INCH 0.00005
#define NCP_RADIUS_TOL_MM (NCP_RADIUS_TOL_INCH * 25.4)
#define NCP_SPIRAL_ABS_TOL_INCH (2 * 0.001 * M_SQRT2)
#define NCP_SPIRAL_ABS_TOL_MM (2 * 0.01 * M_SQRT2)
#define NCP_SPIRAL_REL_TOL 0.001

void ncp_cutcomp_init(struct ncp_cutcomp *c, const struct ncp_comp_cfg *cfg)
{
    memset(c, 0, sizeof *c);
    if (cfg)
        c->cfg = *cfg;
    c->firstmove = 1;
}

void ncp_cutcomp_reset(struct ncp_cutcomp *c)
{
    c->side = 0;
    c->firstmove = 1;
    c->arc_not_allowed = 0;
    c->inv_pending = 0;
    c->n = 0;
    c->text_used = 0;
    c->endpoint_valid = 0;
}

int ncp_cutcomp_engaged(const struct ncp_cutcomp *c)
{
    return c->side != 0 && c->radius > 0.0;
}

void ncp_cutcomp_moved_to(struct ncp_cutcomp *c, double x, double y)
{
    if (c->plane == 2) { /* plane coords (z, x, y) */
        c->cur[1] = x;
        c->cur[2] = y;
    } else {
        c->cur[0] = x;
        c->cur[1] = y;
    }
}

static double ncp_spiral_tol(const struct ncp_cutcomp *c)
{
    if (c->inches)
        return c->cfg.spiral_abs_tol_inch > 0 ? c->cfg.spiral_abs_tol_inch : NCP_SPIRAL_ABS_TOL_INCH;
    return c->cfg.spiral_abs_tol_mm > 0 ? c->cfg.spiral_abs_tol_mm : NCP_SPIRAL_ABS_TOL_MM;
}

/* ---- emitting ---------------------------------------------------------- */

/* Lathe tools are controlled at their nose centre but the machine positions
 * their origin: shift by the radius according to the orientation. */
static double ncp_lathe_x(const struct ncp_cutcomp *c, double x)
{
    int o = c->orientation;
    if (c->plane != 2)
        return x;
    if (o == 2 || o == 6 || o == 1)
        x -= c->radius;
    if (o == 3 || o == 8 || o == 4)
        x += c->radius;
    return x;
}

static double ncp_lathe_z(const struct ncp_cutcomp *c, double z)
{
    int o = c->orientation;
    if (c->plane != 2)
        return z;
    if (o == 2 || o == 7 || o == 3)
        z -= c->radius;
    if (o == 1 || o == 5 || o == 4)
        z += c->radius;
    return z;
}

static int ncp_emit_entry(const struct ncp_cutcomp *c, const struct ncp_comp_entry *e,
                          const struct ncp_comp_sink *sink)
{
    if (e->kind == NCP_CQ_OTHER)
        return sink->emit(sink->ctx, &e->op, c->text + e->op.text_off, e->op.text_len);
    struct ncp_canon op = {0};
    if (e->kind == NCP_CQ_ARC) {
        op.kind = NCP_C_ARC_FEED;
        op.arc_feed.first_end = ncp_lathe_z(c, e->p[0]);
        op.arc_feed.second_end = ncp_lathe_x(c, e->p[1]);
        op.arc_feed.first_axis = ncp_lathe_z(c, e->centre[0]);
        op.arc_feed.second_axis = ncp_lathe_x(c, e->centre[1]);
        op.arc_feed.rotation = e->turn;
        op.arc_feed.axis_end = e->p[2];
        op.arc_feed.abc[0] = e->abc[0];
        op.arc_feed.abc[1] = e->abc[1];
        op.arc_feed.abc[2] = e->abc[2];
    } else {
        op.kind = e->kind == NCP_CQ_FEED ? NCP_C_STRAIGHT_FEED : NCP_C_STRAIGHT_TRAVERSE;
        if (c->plane == 2) {
            op.move.end[0] = ncp_lathe_x(c, e->p[1]);
            op.move.end[1] = e->p[2];
            op.move.end[2] = ncp_lathe_z(c, e->p[0]);
        } else {
            op.move.end[0] = e->p[0];
            op.move.end[1] = e->p[1];
            op.move.end[2] = e->p[2];
        }
        op.move.end[3] = e->abc[0];
        op.move.end[4] = e->abc[1];
        op.move.end[5] = e->abc[2];
    }
    return sink->emit(sink->ctx, &op, NULL, 0);
}

/* rs274's dequeue: everything out in order; the start point is forgotten. */
static int ncp_dequeue(struct ncp_cutcomp *c, const struct ncp_comp_sink *sink)
{
    c->endpoint_valid = 0;
    int rc = NCP_OK;
    for (unsigned k = 0; k < c->n && rc == NCP_OK; k++)
        rc = ncp_emit_entry(c, &c->q[k], sink);
    c->n = 0;
    c->text_used = 0;
    return rc;
}

static void ncp_set_endpoint(struct ncp_cutcomp *c, double x, double y)
{
    c->endpoint[0] = x;
    c->endpoint[1] = y;
    c->endpoint_valid = 1;
}

static int ncp_comp_fail(struct ncp_diag *d, uint32_t line, int status)
{
    return ncp_diag_set(d, NCP_ERR_GEOMETRY, line, 0, "%s", ncp_geom_comp_strerror(status));
}

/* Moves the end of every queued move to (x, y) (an inside corner), refusing
 * if that reverses a move or stretches an arc, then drains the queue. */
static int ncp_move_endpoint_and_flush(struct ncp_cutcomp *c, double x, double y,
                                       const struct ncp_comp_sink *sink, struct ncp_diag *d,
                                       uint32_t line)
{
    if (c->n == 0)
        return NCP_OK;
    const double to[2] = {x, y};
    for (unsigned k = 0; k < c->n; k++) {
        struct ncp_comp_entry *e = &c->q[k];
        if (e->kind == NCP_CQ_ARC) {
            double r1 = hypot(e->p[0] - e->centre[0], e->p[1] - e->centre[1]);
            double r2 = hypot(x - e->centre[0], y - e->centre[1]);
            double l2 = ncp_geom_comp_find_turn(c->endpoint, e->centre, e->turn, to);
            if (fabs(r1 - r2) > .01)
                return ncp_diag_set(d, NCP_ERR_GEOMETRY, line, 0,
                                    "%s r1 %f r2 %f", ncp_geom_comp_strerror(NCP_COMP_E_ARC_MISMATCH),
                                    r1, r2);
            double slack = c->inches ? .001 : .0254;
            if (e->original_turns != 0.0 && c->endpoint_valid &&
                fabs(l2) > fabs(e->original_turns) + slack)
                return ncp_comp_fail(d, line, NCP_COMP_E_LINE_ARC_GOUGE);
        } else if (e->kind == NCP_CQ_FEED || e->kind == NCP_CQ_TRAVERSE) {
            double dot = e->dir[0] * (x - c->endpoint[0]) + e->dir[1] * (y - c->endpoint[1]);
            if (c->endpoint_valid && dot < 0)
                return ncp_comp_fail(d, line, e->kind == NCP_CQ_FEED ? NCP_COMP_E_FEED_GOUGE
                                                                    : NCP_COMP_E_TRAVERSE_GOUGE);
        } else {
            continue;
        }
        e->p[0] = x;
        e->p[1] = y;
    }
    int rc = ncp_dequeue(c, sink);
    ncp_set_endpoint(c, x, y);
    return rc;
}

static struct ncp_comp_entry *ncp_push(struct ncp_cutcomp *c, struct ncp_diag *d, uint32_t line)
{
    if (c->n >= NCP_COMP_QUEUE_MAX) {
        ncp_diag_set(d, NCP_ERR_LIMIT, line, 0,
                     "Too many calls between two moves with cutter radius compensation on "
                     "(limit %d)", NCP_COMP_QUEUE_MAX);
        return NULL;
    }
    struct ncp_comp_entry *e = &c->q[c->n++];
    memset(e, 0, sizeof *e);
    return e;
}

static int ncp_push_straight(struct ncp_cutcomp *c, int traverse, const double dir[2],
                             double x, double y, double z, const double abc[3],
                             struct ncp_diag *d, uint32_t line)
{
    struct ncp_comp_entry *e = ncp_push(c, d, line);
    if (!e)
        return d->code;
    e->kind = traverse ? NCP_CQ_TRAVERSE : NCP_CQ_FEED;
    e->dir[0] = dir[0];
    e->dir[1] = dir[1];
    e->p[0] = x;
    e->p[1] = y;
    e->p[2] = z;
    memcpy(e->abc, abc, sizeof e->abc);
    return NCP_OK;
}

static int ncp_push_arc(struct ncp_cutcomp *c, double original_turns, const double end[2],
                        const double centre[2], int turn, double z, const double abc[3],
                        struct ncp_diag *d, uint32_t line)
{
    struct ncp_comp_entry *e = ncp_push(c, d, line);
    if (!e)
        return d->code;
    e->kind = NCP_CQ_ARC;
    e->original_turns = original_turns;
    e->p[0] = end[0];
    e->p[1] = end[1];
    e->p[2] = z;
    e->centre[0] = centre[0];
    e->centre[1] = centre[1];
    e->turn = turn;
    memcpy(e->abc, abc, sizeof e->abc);
    return NCP_OK;
}

/* ---- non-motion calls -------------------------------------------------- */

static int ncp_queueable(int kind)
{
    switch (kind) {
    case NCP_C_SET_FEED_RATE: case NCP_C_DWELL: case NCP_C_SET_FEED_MODE:
    case NCP_C_MIST_ON: case NCP_C_MIST_OFF: case NCP_C_FLOOD_ON: case NCP_C_FLOOD_OFF:
    case NCP_C_START_SPINDLE_CLOCKWISE: case NCP_C_START_SPINDLE_COUNTERCLOCKWISE:
    case NCP_C_STOP_SPINDLE_TURNING: case NCP_C_SET_SPINDLE_MODE:
    case NCP_C_SET_SPINDLE_SPEED: case NCP_C_COMMENT: case NCP_C_ORIENT_SPINDLE:
        return 1;
    default:
        return 0;
    }
}

int ncp_cutcomp_other(struct ncp_cutcomp *c, const struct ncp_canon *op, const char *text,
                      size_t len, const struct ncp_comp_sink *sink, struct ncp_diag *d,
                      uint32_t line)
{
    if (op->kind == NCP_C_SET_FEED_RATE && (op->flags & NCP_FEED_F_INVERSE_ARC) &&
        ncp_cutcomp_engaged(c)) {
        c->inv_feed = *op;
        c->inv_pending = 1;
        return NCP_OK;
    }
    if (c->n == 0 || !ncp_queueable(op->kind))
        return sink->emit(sink->ctx, op, text, len);
    if (len > NCP_COMP_TEXT_POOL - c->text_used)
        return ncp_diag_set(d, NCP_ERR_LIMIT, line, 0,
                            "Too much comment text between two moves with cutter radius "
                            "compensation on");
    struct ncp_comp_entry *e = ncp_push(c, d, line);
    if (!e)
        return d->code;
    e->kind = NCP_CQ_OTHER;
    e->op = *op;
    e->op.text_off = (uint16_t)c->text_used;
    e->op.text_len = (uint16_t)len;
    if (len)
        memcpy(c->text + c->text_used, text, len);
    c->text_used += len;
    return NCP_OK;
}

static int ncp_comment(struct ncp_cutcomp *c, const char *s, const struct ncp_comp_sink *sink,
                       struct ncp_diag *d, uint32_t line)
{
    struct ncp_canon op = {.kind = NCP_C_COMMENT};
    return ncp_cutcomp_other(c, &op, s, strlen(s), sink, d, line);
}

/* ---- modal switches ---------------------------------------------------- */

static int ncp_comp_radius(const struct ncp_comp_on_req *req, double *radius, int *orientation,
                           struct ncp_diag *d)
{
    int g = req->gcode / 10;
    if (req->gcode == NCP_G41_1 || req->gcode == NCP_G42_1) {
        if (!req->has_d)
            return ncp_diag_set(d, NCP_ERR_SEMANTIC, req->line, 0, "G%d.1 with no D word", g);
        *radius = req->d / 2;
        *orientation = 0;
        if (req->has_l) {
            if (req->plane != 2)
                return ncp_diag_set(d, NCP_ERR_SEMANTIC, req->line, 0,
                                    "G%d.1 with L word, but plane is not G18", g);
            *orientation = req->l;
        }
        return NCP_OK;
    }
    int toolno = -1;
    if (req->has_d) {
        double r = rint(req->d);
        if (fabs(r - req->d) >= .0001 || fabs(r) > 2e9)
            return ncp_diag_set(d, NCP_ERR_SEMANTIC, req->line, 0,
                                "G%d requires D word to be a whole number", g);
        toolno = (int)r;
        if (toolno < 0)
            return ncp_diag_set(d, NCP_ERR_SEMANTIC, req->line, 0,
                                "Negative d word tool radius index used");
    }
    double dia = 0.0;
    int orient = 0;
    if (req->tool && req->tool(req->tool_ctx, toolno, &dia, &orient) != 0)
        return ncp_diag_set(d, NCP_ERR_SEMANTIC, req->line, 0,
                            "Requested tool %d not found in the tool table", toolno);
    if (req->plane != 2 && orient != 0 && orient != 9)
        return ncp_diag_set(d, NCP_ERR_SEMANTIC, req->line, 0,
                            "G%d with lathe tool, but plane is not G18", g);
    *radius = dia / 2.0;
    *orientation = orient;
    return NCP_OK;
}

int ncp_cutcomp_on(struct ncp_cutcomp *c, const struct ncp_comp_on_req *req,
                   const struct ncp_comp_sink *sink, struct ncp_diag *d)
{
    if (req->plane != 0 && req->plane != 2)
        return ncp_diag_set(d, NCP_ERR_SEMANTIC, req->line, 0,
                            "Cutter radius compensation allowed only in XY, XZ planes");
    if (c->side != 0)
        return ncp_diag_set(d, NCP_ERR_SEMANTIC, req->line, 0,
                            "Cannot turn cutter radius comp on when on");
    double radius = 0.0;
    int orientation = 0;
    int rc = ncp_comp_radius(req, &radius, &orientation, d);
    if (rc != NCP_OK)
        return rc;
    int side = req->gcode == NCP_G41 || req->gcode == NCP_G41_1 ? NCP_COMP_LEFT : NCP_COMP_RIGHT;
    if (radius < 0.0) { /* a negative table entry cuts on the other side */
        radius = -radius;
        side = side == NCP_COMP_LEFT ? NCP_COMP_RIGHT : NCP_COMP_LEFT;
    }
    rc = ncp_comment(c, side == NCP_COMP_RIGHT ? "interpreter: cutter radius compensation on right"
                                               : "interpreter: cutter radius compensation on left",
                     sink, d, req->line);
    c->radius = radius;
    c->orientation = orientation;
    c->side = side;
    c->plane = req->plane;
    c->inches = req->inches;
    return rc;
}

int ncp_cutcomp_off(struct ncp_cutcomp *c, const struct ncp_comp_sink *sink,
                    struct ncp_diag *d, uint32_t line)
{
    int rc = ncp_comment(c, "interpreter: cutter radius compensation off", sink, d, line);
    if (rc != NCP_OK)
        return rc;
    if (ncp_cutcomp_engaged(c) && !c->firstmove) {
        rc = ncp_move_endpoint_and_flush(c, c->cur[0], c->cur[1], sink, d, line);
        if (rc != NCP_OK)
            return rc;
        rc = ncp_dequeue(c, sink);
        c->arc_not_allowed = 1;
    }
    c->side = 0;
    c->firstmove = 1;
    return rc;
}

int ncp_cutcomp_flush(struct ncp_cutcomp *c, const struct ncp_comp_sink *sink,
                      struct ncp_diag *d, uint32_t line)
{
    int rc = ncp_move_endpoint_and_flush(c, c->cur[0], c->cur[1], sink, d, line);
    if (rc != NCP_OK)
        return rc;
    return ncp_dequeue(c, sink);
}

void ncp_cutcomp_scale(struct ncp_cutcomp *c, double k, int inches)
{
    c->inches = inches;
    c->radius *= k;
    for (int i = 0; i < 3; i++) {
        c->cur[i] *= k;
        c->prog[i] *= k;
    }
    for (unsigned n = 0; n < c->n; n++) {
        struct ncp_comp_entry *e = &c->q[n];
        /* rs274 rescales its start point once per queued call, not once */
        c->endpoint[0] *= k;
        c->endpoint[1] *= k;
        if (e->kind == NCP_CQ_OTHER)
            continue;
        for (int i = 0; i < 3; i++)
            e->p[i] *= k;
        if (e->kind == NCP_CQ_ARC) {
            e->centre[0] *= k;
            e->centre[1] *= k;
        }
    }
}

int ncp_cutcomp_check_motion(struct ncp_cutcomp *c, int is_arc, struct ncp_diag *d,
                             uint32_t line)
{
    if (is_arc && c->arc_not_allowed)
        return ncp_diag_set(d, NCP_ERR_SEMANTIC, line, 0,
                            "The move just after exiting cutter compensation mode must be "
                            "straight, not an arc");
    if (!is_arc)
        c->arc_not_allowed = 0;
    return NCP_OK;
}

/* ---- moves ------------------------------------------------------------- */

static int ncp_tool_inside(int side, int ccw)
{
    return (side == NCP_COMP_LEFT && ccw) || (side == NCP_COMP_RIGHT && !ccw);
}

static struct ncp_comp_prev ncp_front(const struct ncp_cutcomp *c)
{
    struct ncp_comp_prev f = {0};
    if (c->n == 0)
        return f;
    const struct ncp_comp_entry *e = &c->q[0];
    f.valid = 1;
    f.is_arc = e->kind == NCP_CQ_ARC;
    f.turn = e->turn;
    memcpy(f.centre, e->centre, sizeof f.centre);
    memcpy(f.end, e->p, sizeof f.end);
    return f;
}

static int ncp_arc_fail(const struct ncp_cutcomp *c, const struct ncp_arc_in *in, int status,
                        const struct ncp_arc_out *out, struct ncp_diag *d, uint32_t line)
{
    char a = c->plane == 2 ? 'Z' : 'X', b = c->plane == 2 ? 'X' : 'Y';
    switch (status) {
    case NCP_ARC_SAME_POINT:
        return ncp_diag_set(d, NCP_ERR_GEOMETRY, line, 0, "Current point same as end point of arc");
    case NCP_ARC_R_TOO_SMALL:
        return ncp_diag_set(d, NCP_ERR_GEOMETRY, line, 0, "Arc radius too small to reach end point");
    case NCP_ARC_ZERO_RADIUS:
        return ncp_diag_set(d, NCP_ERR_GEOMETRY, line, 0,
                            "Zero-radius arc: start=(%c%.4f,%c%.4f) center=(%c%.4f,%c%.4f) "
                            "end=(%c%.4f,%c%.4f) r1=%.4f r2=%.4f",
                            a, in->start[0], b, in->start[1], a, out->centre[0], b,
                            out->centre[1], a, in->end[0], b, in->end[1], out->r1, out->r2);
    default:
        return ncp_diag_set(d, NCP_ERR_GEOMETRY, line, 0,
                            "Radius to end of arc differs from radius to start: "
                            "start=(%c%.4f,%c%.4f) center=(%c%.4f,%c%.4f) "
                            "end=(%c%.4f,%c%.4f) r1=%.4f r2=%.4f abs_err=%.4g rel_err=%.4f%%",
                            a, in->start[0], b, in->start[1], a, out->centre[0], b,
                            out->centre[1], a, in->end[0], b, in->end[1], out->r1, out->r2,
                            out->abs_err, out->rel_err * 100);
    }
}

/* Centre and turn of the programmed arc from start, with the tool-fit checks
 * rs274 makes around it (before it for R arcs, after it for centre arcs). */
static int ncp_comp_arc_solve(const struct ncp_cutcomp *c, const struct ncp_comp_move *m,
                              const double start[2], int check_fit, struct ncp_arc_in *in,
                              struct ncp_arc_out *out, struct ncp_diag *d)
{
    int ccw = m->motion == 3;
    memset(in, 0, sizeof *in);
    in->start[0] = start[0];
    in->start[1] = start[1];
    in->end[0] = m->end[0];
    in->end[1] = m->end[1];
    in->radius_form = m->radius_form != 0;
    in->centre[0] = m->centre[0];
    in->centre[1] = m->centre[1];
    in->radius = m->r;
    in->ccw = ccw;
    in->turns = m->turns >= 1 ? m->turns : 1;
    in->radius_tol = c->inches ? NCP_RADIUS_TOL_INCH : NCP_RADIUS_TOL_MM;
    in->spiral_abs_tol = ncp_spiral_tol(c);
    in->spiral_rel_tol = NCP_SPIRAL_REL_TOL;
    int inside = ncp_tool_inside(c->side, ccw);
    if (check_fit && in->radius_form && fabs(m->r) <= c->radius && inside)
        return ncp_comp_fail(d, m->line, NCP_COMP_E_TOOL_TOO_BIG);
    int st = ncp_geom_arc_solve(in, out);
    if (st != NCP_ARC_OK)
        return ncp_arc_fail(c, in, st, out, d, m->line);
    if (check_fit && !in->radius_form && out->r1 <= c->radius && inside)
        return ncp_comp_fail(d, m->line, NCP_COMP_E_TOOL_TOO_BIG);
    return NCP_OK;
}

/* G93: the arc's feed rate comes from the programmed arc's length, and is
 * queued like any feed rate, ahead of the corner decisions. */
static int ncp_comp_arc_feed(struct ncp_cutcomp *c, const struct ncp_arc_in *in,
                             const struct ncp_arc_out *out, double axis_end,
                             const struct ncp_comp_sink *sink, struct ncp_diag *d, uint32_t line)
{
    if (!c->inv_pending)
        return NCP_OK;
    struct ncp_canon op = c->inv_feed;
    c->inv_pending = 0;
    double rate = ncp_geom_arc_length(in, out, op.feed_rate.arc_axis_start, axis_end) *
                  op.feed_rate.rate;
    op.feed_rate.rate = rate > 0.1 ? rate : 0.1;
    op.feed_rate.arc_axis_start = 0.0;
    op.flags &= (uint16_t)~NCP_FEED_F_INVERSE_ARC;
    return ncp_cutcomp_other(c, &op, NULL, 0, sink, d, line);
}

static void ncp_comp_advance(struct ncp_cutcomp *c, const double cur[2], const double *prog3,
                             double z)
{
    c->cur[0] = cur[0];
    c->cur[1] = cur[1];
    c->cur[2] = z;
    memcpy(c->prog, prog3, sizeof c->prog);
}

static int ncp_bug_not_g0_g1(struct ncp_diag *d, uint32_t line)
{
    return ncp_diag_set(d, NCP_ERR_SEMANTIC, line, 0, "Bug code not g0 or g1");
}

static int ncp_line_first(struct ncp_cutcomp *c, const struct ncp_comp_move *m,
                          const struct ncp_comp_sink *sink, struct ncp_diag *d)
{
    (void)sink;
    double end[2], dir[2];
    int st = ncp_geom_comp_line_entry(c->side, c->radius, m->start, m->end, end, dir);
    if (st != NCP_COMP_OK)
        return ncp_comp_fail(d, m->line, st);
    ncp_set_endpoint(c, m->start[0], m->start[1]);
    if (m->motion == NCP_COMP_SYNCED)
        return ncp_bug_not_g0_g1(d, m->line);
    int rc = ncp_push_straight(c, m->motion == 0, dir, end[0], end[1], m->end[2], m->abc, d,
                               m->line);
    c->firstmove = 0;
    ncp_comp_advance(c, end, m->end, m->end[2]);
    return rc;
}

static int ncp_line_next(struct ncp_cutcomp *c, const struct ncp_comp_move *m,
                         const struct ncp_comp_sink *sink, struct ncp_diag *d)
{
    const double *op = c->prog, *p = m->end;
    double cur[2] = {c->cur[0], c->cur[1]};
    double dir[2] = {p[0] - op[0], p[1] - op[1]};
    int traverse = m->motion == 0;
    if (p[0] == op[0] && p[1] == op[1]) { /* no motion in the plane */
        if (m->motion == NCP_COMP_SYNCED)
            return ncp_bug_not_g0_g1(d, m->line);
        int rc = ncp_push_straight(c, traverse, dir, cur[0], cur[1], p[2], m->abc, d, m->line);
        ncp_comp_advance(c, cur, p, p[2]);
        return rc;
    }
    struct ncp_comp_prev front = ncp_front(c);
    struct ncp_comp_corner_out out;
    int st = ncp_geom_comp_line_next(c->side, c->radius, cur, op, p, &front, &out);
    if (st != NCP_COMP_OK)
        return ncp_comp_fail(d, m->line, st);
    int rc;
    if (out.corner == NCP_CORNER_CONVEX) {
        rc = ncp_move_endpoint_and_flush(c, cur[0], cur[1], sink, d, m->line);
        if (rc == NCP_OK && m->motion == NCP_COMP_SYNCED)
            return ncp_bug_not_g0_g1(d, m->line);
        if (rc == NCP_OK && traverse) {
            static const double none[2] = {0.0, 0.0};
            rc = ncp_push_straight(c, 1, none, out.mid[0], out.mid[1], c->cur[2], m->abc, d,
                                   m->line);
        } else if (rc == NCP_OK) {
            rc = ncp_push_arc(c, 0.0, out.mid, op, c->side == NCP_COMP_LEFT ? -1 : 1, c->cur[2],
                              m->abc, d, m->line);
        }
        if (rc == NCP_OK)
            rc = ncp_dequeue(c, sink);
        ncp_set_endpoint(c, out.mid[0], out.mid[1]);
    } else if (out.corner == NCP_CORNER_CONCAVE) {
        rc = ncp_move_endpoint_and_flush(c, out.mid[0], out.mid[1], sink, d, m->line);
    } else {
        rc = ncp_dequeue(c, sink);
        ncp_set_endpoint(c, cur[0], cur[1]);
    }
    if (rc != NCP_OK)
        return rc;
    rc = ncp_push_straight(c, traverse, dir, out.end[0], out.end[1], p[2], m->abc, d, m->line);
    ncp_comp_advance(c, out.end, p, p[2]);
    return rc;
}

static int ncp_arc_first(struct ncp_cutcomp *c, const struct ncp_comp_move *m,
                         const struct ncp_comp_sink *sink, struct ncp_diag *d)
{
    const double *s = m->start;
    if (hypot(m->end[0] - s[0], m->end[1] - s[1]) <= c->radius)
        return ncp_comp_fail(d, m->line, NCP_COMP_E_ENTRY_ARC_SHORT);
    struct ncp_arc_in in;
    struct ncp_arc_out arc;
    int rc = ncp_comp_arc_solve(c, m, s, 1, &in, &arc, d);
    if (rc == NCP_OK)
        rc = ncp_comp_arc_feed(c, &in, &arc, m->end[2], sink, d, m->line);
    if (rc != NCP_OK)
        return rc;
    double end[2], centre[2];
    int st = ncp_geom_comp_arc_entry(c->side, c->radius, s, m->end, arc.centre, arc.rotation,
                                ncp_spiral_tol(c), end, centre);
    if (st != NCP_COMP_OK)
        return ncp_comp_fail(d, m->line, st);
    c->firstmove = 0;
    if (c->orientation != 0 && c->orientation != 9) {
        /* a lathe tool first moves its origin so the arc stays an arc */
        static const double none[2] = {0.0, 0.0};
        rc = ncp_push_straight(c, 0, none, s[0], s[1], s[2], m->abc, d, m->line);
        ncp_set_endpoint(c, s[0], s[1]);
    }
    if (rc == NCP_OK)
        rc = ncp_push_arc(c, ncp_geom_comp_find_turn(s, arc.centre, arc.rotation, m->end), end,
                          centre, arc.rotation, m->end[2], m->abc, d, m->line);
    ncp_comp_advance(c, end, m->end, m->end[2]);
    return rc;
}

static int ncp_arc_next(struct ncp_cutcomp *c, const struct ncp_comp_move *m,
                        const struct ncp_comp_sink *sink, struct ncp_diag *d)
{
    double op[3], cur[2] = {c->cur[0], c->cur[1]};
    memcpy(op, c->prog, sizeof op);
    struct ncp_arc_in in;
    struct ncp_arc_out arc;
    int rc = ncp_comp_arc_solve(c, m, op, 0, &in, &arc, d);
    if (rc == NCP_OK)
        rc = ncp_comp_arc_feed(c, &in, &arc, m->end[2], sink, d, m->line);
    if (rc != NCP_OK)
        return rc;
    struct ncp_comp_prev front = ncp_front(c);
    struct ncp_comp_corner_out out;
    int st = ncp_geom_comp_arc_next(c->side, c->radius, cur, op, m->end, arc.centre, m->motion == 3,
                               arc.rotation, &front, &out);
    if (st != NCP_COMP_OK)
        return ncp_comp_fail(d, m->line, st);
    if (out.corner == NCP_CORNER_CONCAVE) {
        rc = ncp_move_endpoint_and_flush(c, out.mid[0], out.mid[1], sink, d, m->line);
    } else if (out.corner == NCP_CORNER_CONVEX2) {
        rc = ncp_dequeue(c, sink);
        if (rc == NCP_OK)
            rc = ncp_push_arc(c, 0.0, out.mid, op, c->side == NCP_COMP_LEFT ? -1 : 1, c->cur[2],
                              m->abc, d, m->line);
        if (rc == NCP_OK)
            rc = ncp_dequeue(c, sink);
        ncp_set_endpoint(c, out.mid[0], out.mid[1]);
    } else {
        rc = ncp_dequeue(c, sink);
        ncp_set_endpoint(c, cur[0], cur[1]);
    }
    if (rc != NCP_OK)
        return rc;
    rc = ncp_push_arc(c, ncp_geom_comp_find_turn(op, arc.centre, arc.rotation, m->end), out.end,
                      arc.centre, arc.rotation, m->end[2], m->abc, d, m->line);
    ncp_comp_advance(c, out.end, m->end, m->end[2]);
    return rc;
}

int ncp_cutcomp_move(struct ncp_cutcomp *c, const struct ncp_comp_move *m,
                     const struct ncp_comp_sink *sink, struct ncp_diag *d)
{
    c->inches = m->inches;
    if (m->motion == 0 || m->motion == 1 || m->motion == NCP_COMP_SYNCED) {
        c->inv_pending = 0;
        if (m->g53)
            return ncp_diag_set(d, NCP_ERR_SEMANTIC, m->line, 0,
                                "Cannot use g53 with cutter radius comp");
        return c->firstmove ? ncp_line_first(c, m, sink, d) : ncp_line_next(c, m, sink, d);
    }
    return c->firstmove ? ncp_arc_first(c, m, sink, d) : ncp_arc_next(c, m, sink, d);
}
