/* Turns requests in a slot into printable calls. Only arcs need it today: the
 * analyzer knows the end point and the centre word or R, the executor finds
 * the centre, checks it the way rs274 does and reports its errors in rs274's
 * words. */
#include "ncpar/geom.h"
#include "ncpar/executor.h"
#include "format.h"

#include <math.h>
#include <string.h>

/* rs274 (interp_internal.hh) defaults, used when the analyzer leaves d[10] or
 * d[11] zero. RADIUS_TOLERANCE_* is not configurable in rs274, so it is not
 * carried by the op either. */
#define NCP_RADIUS_TOL_INCH 0.00005
#define NCP_RADIUS_TOL_MM (NCP_RADIUS_TOL_INCH * 25.4)
#define NCP_SPIRAL_ABS_TOL_INCH (2 * 0.001 * M_SQRT2)
#define NCP_SPIRAL_ABS_TOL_MM (2 * 0.01 * M_SQRT2)
#define NCP_SPIRAL_REL_TOL 0.001

#define NCP_ARC_F_INCHES 1u

static void ncp_arc_in_from_op(const struct ncp_canon *op, struct ncp_arc_in *in)
{
    int inches = (op->flags & NCP_ARC_F_INCHES) != 0;
    const struct ncp_canon_arc *q = &op->arc;
    in->start[0] = q->first_start;
    in->start[1] = q->second_start;
    in->end[0] = q->first_end;
    in->end[1] = q->second_end;
    in->radius_form = q->radius_form != 0;
    in->centre[0] = in->radius_form ? 0.0 : q->first_centre;
    in->centre[1] = in->radius_form ? 0.0 : q->second_centre;
    in->radius = in->radius_form ? q->radius : 0.0;
    in->ccw = q->dir > 0;
    in->turns = q->turns >= 1 ? q->turns : 1; /* zero means "no P word" */
    in->radius_tol = inches ? NCP_RADIUS_TOL_INCH : NCP_RADIUS_TOL_MM;
    in->spiral_abs_tol = q->tol_abs > 0 ? q->tol_abs
                       : inches ? NCP_SPIRAL_ABS_TOL_INCH : NCP_SPIRAL_ABS_TOL_MM;
    in->spiral_rel_tol = q->tol_rel > 0 ? q->tol_rel : NCP_SPIRAL_REL_TOL;
}

/* rs274 names the in-plane axes in its messages: XY, then YZ, then XZ as Z,X. */
static void ncp_plane_axes(int plane, char *a, char *b)
{
    static const char first[] = "XYZ", second[] = "YZX";
    int p = plane >= 0 && plane <= 2 ? plane : 0;
    *a = first[p];
    *b = second[p];
}

static int ncp_arc_error(const struct ncp_cmd *cmd, const struct ncp_canon *op, int status,
                         const struct ncp_arc_out *out, struct ncp_diag *g)
{
    char a, b;
    ncp_plane_axes(op->arc.plane, &a, &b);
    const struct ncp_canon_arc *q = &op->arc;
    switch (status) {
    case NCP_ARC_SAME_POINT:
        return ncp_diag_set(g, NCP_ERR_GEOMETRY, cmd->line, 0,
                            "Current point same as end point of arc");
    case NCP_ARC_R_TOO_SMALL:
        return ncp_diag_set(g, NCP_ERR_GEOMETRY, cmd->line, 0,
                            "Arc radius too small to reach end point");
    case NCP_ARC_ZERO_RADIUS:
        return ncp_diag_set(g, NCP_ERR_GEOMETRY, cmd->line, 0,
                            "Zero-radius arc: start=(%c%.4f,%c%.4f) center=(%c%.4f,%c%.4f) "
                            "end=(%c%.4f,%c%.4f) r1=%.4f r2=%.4f",
                            a, q->first_start, b, q->second_start, a, out->centre[0],
                            b, out->centre[1], a, q->first_end, b, q->second_end,
                            out->r1, out->r2);
    default:
        return ncp_diag_set(g, NCP_ERR_GEOMETRY, cmd->line, 0,
                            "Radius to end of arc differs from radius to start: "
                            "start=(%c%.4f,%c%.4f) center=(%c%.4f,%c%.4f) "
                            "end=(%c%.4f,%c%.4f) r1=%.4f r2=%.4f abs_err=%.4g rel_err=%.4f%%",
                            a, q->first_start, b, q->second_start, a, out->centre[0],
                            b, out->centre[1], a, q->first_end, b, q->second_end,
                            out->r1, out->r2,
                            out->abs_err, out->rel_err * 100);
    }
}

/* A G93 arc's feed rate op, filled in from the arc's length. */
static struct ncp_canon *ncp_inverse_feed_before(struct ncp_cmd *cmd, unsigned k)
{
    struct ncp_canon *prev = k > 0 ? &cmd->ops[k - 1] : NULL;
    if (prev && prev->kind == NCP_C_SET_FEED_RATE && (prev->flags & NCP_FEED_F_INVERSE_ARC))
        return prev;
    return NULL;
}

/* ARC_REQUEST fields -> ARC_FEED fields, in place. */
static int ncp_resolve_arc(const struct ncp_cmd *cmd, struct ncp_canon *op,
                           struct ncp_canon *feed_op, struct ncp_diag *g)
{
    struct ncp_arc_in in;
    struct ncp_arc_out out;
    ncp_arc_in_from_op(op, &in);
    int status = ncp_geom_arc_solve(&in, &out);
    if (status != NCP_ARC_OK)
        return ncp_arc_error(cmd, op, status, &out, g);

    double axis_end = op->arc.axis_end;
    double a = op->arc.abc[0], b = op->arc.abc[1], c = op->arc.abc[2];
    if (feed_op) {
        double rate = ncp_geom_arc_length(&in, &out, feed_op->feed_rate.arc_axis_start, axis_end) *
                      feed_op->feed_rate.rate;
        feed_op->feed_rate.rate = rate > 0.1 ? rate : 0.1;
        feed_op->feed_rate.arc_axis_start = 0.0;
        feed_op->flags &= (uint16_t)~NCP_FEED_F_INVERSE_ARC;
    }
    /* the request's numbers are all read: the call is written over it */
    memset(op, 0, sizeof *op);
    op->kind = NCP_C_ARC_FEED;
    op->arc_feed.first_end = in.end[0];
    op->arc_feed.second_end = in.end[1];
    op->arc_feed.first_axis = out.centre[0];
    op->arc_feed.second_axis = out.centre[1];
    op->arc_feed.rotation = out.rotation;
    op->arc_feed.axis_end = axis_end;
    op->arc_feed.abc[0] = a;
    op->arc_feed.abc[1] = b;
    op->arc_feed.abc[2] = c;
    return NCP_OK;
}

/* The error, if any, goes to *g: cmd->diag, or a slot of the caller's for a
 * command read where it stands in a packed record (no room for one there). */
static int resolve_into(struct ncp_cmd *cmd, struct ncp_diag *g)
{
    unsigned n_ops = cmd->n_ops;
    if (n_ops > NCP_CMD_MAX_OPS)
        n_ops = NCP_CMD_MAX_OPS;
    for (unsigned k = 0; k < n_ops; k++) {
        struct ncp_canon *op = &cmd->ops[k];
        if (op->kind != NCP_C_ARC_REQUEST)
            continue;
        struct ncp_canon *feed_op = ncp_inverse_feed_before(cmd, k);
        if (ncp_resolve_arc(cmd, op, feed_op, g) != NCP_OK) {
            /* rs274 sets the G93 rate only once the arc is known good */
            cmd->n_ops = (uint16_t)(feed_op ? k - 1 : k);
            g->file = ncp_diag_file_of_tag(NCP_CMD_FILE(cmd));
            cmd->flags |= NCP_CMD_F_ERROR;
            break;
        }
    }
    return cmd->flags & NCP_CMD_F_ERROR ? g->code : NCP_OK;
}

int ncp_exec_resolve(struct ncp_cmd *cmd)
{
    return resolve_into(cmd, &cmd->diag);
}

/* rs274's driver resets the canon twice as it exits, after any error. The
 * analyzer writes those calls behind its own errors; an error found here
 * (an arc that cannot be drawn) ends the program as well, after calls the
 * analyzer has long since moved past, so its two lines go behind the text of
 * the calls that still print. Text only: they are the driver's exit, nothing
 * for the machine to do. */
static const char exit_resets[] = "ON_RESET()\nON_RESET()\n";

static void exec_into(struct ncp_cmd *cmd, char *dst, struct ncp_diag *g)
{
    int had_error = (cmd->flags & NCP_CMD_F_ERROR) != 0;
    resolve_into(cmd, g);
    int failed_here = !had_error && (cmd->flags & NCP_CMD_F_ERROR);
    ncp_exec_format_diag(cmd, dst, g);
    if (failed_here && cmd->out_len + sizeof exit_resets - 1 <= NCP_CMD_OUT_MAX) {
        memcpy(dst + cmd->out_len, exit_resets, sizeof exit_resets - 1);
        cmd->out_len += (uint32_t)(sizeof exit_resets - 1);
    }
}

int ncp_exec_cmd(struct ncp_cmd *cmd)
{
    exec_into(cmd, cmd->out, &cmd->diag);
    return cmd->flags & NCP_CMD_F_ERROR ? cmd->diag.code : NCP_OK;
}

int ncp_exec_cmd_into(struct ncp_cmd *cmd, char *dst)
{
    exec_into(cmd, dst, &cmd->diag);
    return cmd->flags & NCP_CMD_F_ERROR ? cmd->diag.code : NCP_OK;
}

int ncp_exec_cmd_into_diag(struct ncp_cmd *cmd, char *dst, struct ncp_diag *diag)
{
    exec_into(cmd, dst, diag);
    return cmd->flags & NCP_CMD_F_ERROR ? diag->code : NCP_OK;
}
