/* Canonical calls (program coordinates and units) -> machine-space segments (mm).
 * machine = rotate_xy(program * scale + g92) + g5x + tool, offsets converted to mm
 * with the units in force when they were issued (as LinuxCNC's canon layer).
 * A B C are degrees in every unit system; U V W do not come in the calls. */
#include "ncpar/motion.h"
#include "nurbs_eval.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void ncp_canon_map_init(struct ncp_canon_map *m, const struct ncp_machine_cfg *cfg,
                        const double start[NCP_AXES], double feed_override)
{
    memset(m, 0, sizeof *m);
    m->cfg = cfg;
    m->scale = 1.0;
    m->feed_override = feed_override > 0 ? feed_override : 1.0;
    m->term = NCP_TERM_CONTINUOUS;   /* LinuxCNC starts in G64 */
    for (int i = 0; i < NCP_AXES; i++)
        m->pos[i] = start ? start[i] : 0;
}

static void to_machine(const struct ncp_canon_map *m, const double p[3], double out[3])
{
    double q[3];
    for (int i = 0; i < 3; i++)
        q[i] = p[i] * m->scale + m->g92[i];
    double th = m->rotation * (M_PI / 180.0);
    double c = cos(th), s = sin(th);
    double x = q[0] * c - q[1] * s, y = q[0] * s + q[1] * c;
    q[0] = x;
    q[1] = y;
    for (int i = 0; i < 3; i++)
        out[i] = q[i] + m->g5x[i] + m->tool[i];
}

void ncp_canon_map_to_program(const struct ncp_canon_map *m, const double machine[NCP_AXES],
                              double prog[3])
{
    double q[3];
    for (int i = 0; i < 3; i++)
        q[i] = machine[i] - m->g5x[i] - m->tool[i];
    double th = -m->rotation * (M_PI / 180.0);
    double c = cos(th), s = sin(th);
    double x = q[0] * c - q[1] * s, y = q[0] * s + q[1] * c;
    q[0] = x;
    q[1] = y;
    for (int i = 0; i < 3; i++)
        prog[i] = (q[i] - m->g92[i]) / m->scale;
}

/* The whole target: X Y Z from p, A B C from abc (NULL: where they are), the
 * rest where they are. */
static void to_machine_all(const struct ncp_canon_map *m, const double p[3], const double *abc,
                           double out[NCP_AXES])
{
    to_machine(m, p, out);
    for (int i = 3; i < NCP_AXES; i++)
        out[i] = m->pos[i];
    if (abc)
        for (int i = 3; i < NCP_CANON_AXES; i++)
            out[i] = abc[i - 3] + m->g92[i] + m->g5x[i] + m->tool[i];
}

/* A wrapped rotary axis turns the shorter way to its target modulo 360; its
 * position counts on across whole turns. (LinuxCNC's interpreter picks the
 * way from the sign of a G90 word; the calls carry no distance mode, so
 * the NCK takes the shorter one.) */
static void unwrap(const struct ncp_canon_map *m, double end[NCP_AXES])
{
    for (int i = 3; i < 6; i++)
        if (m->cfg->axis[i].wrapped)
            end[i] = m->pos[i] + remainder(end[i] - m->pos[i], 360.0);
}

/* A move of an axis the machine lacks is refused (before any motion, by
 * the batch check): the part would be cut without it. */
static int absent_axis(const struct ncp_canon_map *m, const double end[NCP_AXES], uint32_t line,
                       struct ncp_diag *d)
{
    for (int i = 0; i < NCP_AXES; i++)
        if (!(m->cfg->axis_mask & NCP_AXIS_BIT(i)) && fabs(end[i] - m->pos[i]) > 1e-9)
            return -ncp_diag_set(d, NCP_ERR_SEMANTIC, line, 0,
                                 "this move needs axis %c, which this machine does not have "
                                 "([TRAJ] COORDINATES lists the machine's axes)",
                                 NCP_AXIS_LETTERS[i]);
    return 0;
}

static double dot(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross(const double a[3], const double b[3], double o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

static int check_point(const struct ncp_canon_map *m, const double p[NCP_AXES],
                       uint32_t line, struct ncp_diag *d)
{
    for (int i = 0; i < NCP_AXES; i++) {
        const struct ncp_axis_cfg *a = &m->cfg->axis[i];
        if (!(m->cfg->axis_mask & NCP_AXIS_BIT(i)) || a->wrapped)
            continue;  /* absent axes never move; a wrapped one has no end */
        const char *u = ncp_axis_rotary(i) ? "deg" : "mm";
        /* a nanometre of slack: arc extremes are computed, not given */
        if (p[i] < a->min_limit - 1e-6)
            return ncp_diag_set(d, NCP_ERR_LIMIT, line, 0,
                                "soft limit: %c would go to %.4f %s, below its minimum %.4f %s",
                                NCP_AXIS_LETTERS[i], p[i], u, a->min_limit, u);
        if (p[i] > a->max_limit + 1e-6)
            return ncp_diag_set(d, NCP_ERR_LIMIT, line, 0,
                                "soft limit: %c would go to %.4f %s, above its maximum %.4f %s",
                                NCP_AXIS_LETTERS[i], p[i], u, a->max_limit, u);
    }
    return NCP_OK;
}

/* A box is convex, so a line is inside if its ends are; an arc also needs the
 * points where each axis has its extremes. */
static int check_arc(const struct ncp_canon_map *m, const struct ncp_seg *s, struct ncp_diag *d)
{
    double lo = fmin(0, s->angle), hi = fmax(0, s->angle);
    for (int i = 0; i < 3; i++) {
        double base = atan2(s->w[i], s->u[i]);
        for (int half = 0; half < 2; half++) {
            double b = base + half * M_PI;
            /* radius and height change linearly with the angle, so of all the
             * turns only the first and the last can hold an extreme */
            double first = b + 2 * M_PI * ceil((lo - b) / (2 * M_PI));
            double turns = floor((hi - first) / (2 * M_PI));
            for (int k = 0; k < 2 && turns >= 0; k++) {
                double phi = first + 2 * M_PI * (k ? turns : 0), p[NCP_AXES];
                ncp_seg_eval(s, s->length * (phi / s->angle), p, NULL);
                int r = check_point(m, p, s->line, d);
                if (r)
                    return r;
            }
        }
    }
    return check_point(m, s->end, s->line, d);
}

static void seg_common(const struct ncp_canon_map *m, struct ncp_seg *s, uint32_t line)
{
    memset(s, 0, sizeof *s);
    s->line = line;
    s->term = (uint8_t)m->term;
    s->tolerance = m->tolerance;
    s->merge_tol = m->term == NCP_TERM_CONTINUOUS ? m->merge_tol : 0;
    memcpy(s->start, m->pos, sizeof s->start);
    s->tool_z = m->tool[2];
}

/* The spindle's speed (rpm) with the tool at machine X = x_mm: under G96 the
 * surface speed (m/min, or ft/min in inches) over the circumference at that
 * radius, capped at D. */
static double spindle_rpm(const struct ncp_canon_map *m, double x_mm)
{
    if (m->css_max <= 0)
        return m->speed;
    double surface = m->speed * (m->scale == 1.0 ? 1000.0 : 304.8); /* mm per minute */
    double r = fabs(x_mm);
    double rpm = r > 0 ? surface / (2 * M_PI * r) : m->css_max;
    return rpm < m->css_max ? rpm : m->css_max;
}

/* A feed per turn (G95) or a synchronised move (G33, G33.1, G76) with the
 * spindle stopped: LinuxCNC's motion would wait for ever; refused instead. */
static int spindle_needed(const struct ncp_canon_map *m, uint32_t line, struct ncp_diag *d)
{
    if (m->spindle_dir != 0 || (m->sync_pitch <= 0 && !m->per_rev))
        return 0;
    return -ncp_diag_set(d, NCP_ERR_SEMANTIC, line, 0,
                         m->sync_pitch > 0
                             ? "spindle-synchronised move (G33/G33.1/G76) with the spindle "
                               "stopped: start it with M3 or M4 first"
                             : "feed per revolution (G95) with the spindle stopped: start it "
                               "with M3 or M4 first, or use G94");
}

/* Feed in mm/s of a move ending at machine X = x_mm (deg/s for a move of
 * rotary axes only: F is then degrees per minute, LinuxCNC's rule). A
 * synchronised move runs at its pitch whatever the override (rs274 turns it
 * off around them). G93's inverse time needs nothing here: the interpreter
 * sends it as the feed that makes the move take 1/F minutes, along the
 * length measured as here. */
static double feed_at(const struct ncp_canon_map *m, double x_mm, int angular)
{
    if (m->sync_pitch > 0)
        return m->sync_pitch * spindle_rpm(m, x_mm) / 60.0;
    double f = angular ? m->feed_deg : m->feed;
    double per_min = m->per_rev ? f * spindle_rpm(m, x_mm) : f;
    return per_min / 60.0 * m->feed_override;
}

/* What a corner after a move ending at x_mm is blended for: its feed at the
 * largest override, whatever the override now. */
static double blend_feed_at(const struct ncp_canon_map *m, double x_mm, int angular)
{
    if (m->sync_pitch > 0)
        return feed_at(m, x_mm, angular);
    return feed_at(m, x_mm, angular) / m->feed_override * NCP_FEED_OVERRIDE_MAX;
}

/* A rapid of rotary axes only: as fast as the slowest of them allows (the
 * planner's per-axis caps do the rest). */
static double rotary_rapid(const struct ncp_canon_map *m, const struct ncp_seg *s)
{
    double v = INFINITY;
    for (int i = 3; i < 6; i++)
        if (s->end[i] != s->start[i])
            v = fmin(v, m->cfg->axis[i].max_vel);
    return isfinite(v) ? v : m->cfg->max_linear_vel;
}

static int finite3(const double *v, int n)
{
    for (int i = 0; i < n; i++)
        if (!isfinite(v[i]))
            return 0;
    return 1;
}

/* A line from the current machine position to end_mm. */
static int line_to(struct ncp_canon_map *m, const double end_mm[NCP_AXES], int traverse,
                   uint32_t line, struct ncp_seg *s, struct ncp_diag *d)
{
    seg_common(m, s, line);
    s->kind = NCP_SEG_LINE;
    s->traverse = (uint8_t)traverse;
    memcpy(s->end, end_mm, sizeof s->end);
    if (!finite3(s->end, NCP_AXES))
        return -ncp_diag_set(d, NCP_ERR_GEOMETRY, line, 0, "move to a non-finite position");
    unwrap(m, s->end);
    int rc = absent_axis(m, s->end, line, d);
    if (rc)
        return rc;
    ncp_seg_set_length(s);
    if (s->length < 1e-9)
        return 0;  /* a null move: nothing to do */
    if (!traverse && spindle_needed(m, line, d))
        return -NCP_ERR_SEMANTIC;
    if (traverse)
        s->feed = s->angular ? rotary_rapid(m, s) : m->cfg->max_linear_vel;
    else if ((s->feed = feed_at(m, s->end[0], s->angular)) <= 0)
        return -ncp_diag_set(d, NCP_ERR_SEMANTIC, line, 0, "feed move with zero feed rate");
    s->blend_feed = traverse ? s->feed : blend_feed_at(m, s->end[0], s->angular);
    /* ADCAI's axes lag the rough path by their filters' delay, which no
     * spindle angle could follow: a thread would be cut wrong */
    if (!traverse && m->sync_pitch > 0 && m->cfg->nck == NCP_NCK_ADCAI)
        return -ncp_diag_set(d, NCP_ERR_SEMANTIC, line, 0,
                             "spindle-synchronised move (G33/G33.1/G76) under [PLANNER] NCK = "
                             "adcai: the axes' acc/dec filters cannot follow the spindle; run "
                             "this program with NCK = adcbi");
    if (!traverse && m->sync_pitch > 0) {
        s->sync = NCP_SYNC_THREAD;
        s->pitch = m->sync_pitch;
    } else if (!traverse && m->per_rev) {
        s->rev_rpm = spindle_rpm(m, s->end[0]);
    }
    int r = check_point(m, s->end, line, d);
    if (r)
        return -r;
    if ((r = ncp_kins_seg_check(m->cfg, s, d)) != 0)
        return r;
    memcpy(m->pos, s->end, sizeof m->pos);
    return 1;
}

static int straight(struct ncp_canon_map *m, const struct ncp_canon *op, int traverse,
                    uint32_t line, struct ncp_seg *s, struct ncp_diag *d)
{
    double end[NCP_AXES];
    to_machine_all(m, op->move.end, op->move.end + 3, end);
    return line_to(m, end, traverse, line, s, d);
}

/* G33.1: to the hole's bottom now, back to where it started next (more). */
static int rigid_tap(struct ncp_canon_map *m, const struct ncp_canon *op, uint32_t line,
                     struct ncp_seg *s, struct ncp_diag *d)
{
    double end[NCP_AXES];
    memcpy(m->more_back, m->pos, sizeof m->more_back);
    to_machine_all(m, op->rigid_tap.bottom, NULL, end);
    int rc = line_to(m, end, 0, line, s, d);
    if (rc == 1) {
        if (s->sync)
            s->sync = NCP_SYNC_TAP;
        m->more_left = 1;
        m->more_line = line;
    }
    return rc;
}

/* The next line of a curve (G5, G5.1, G5.3) whose points are in: 1, 0 when
 * none is. Lines of zero length (a degenerate curve) are passed over. */
static int nurbs_more(struct ncp_canon_map *m, struct ncp_seg *seg, struct ncp_diag *d)
{
    struct ncp_nurbs_stream *nb = &m->nurbs;
    uint32_t ready = ncp_nurbs_stream_ready(nb);
    while (nb->span < ready) {
        uint32_t span = nb->span;
        nb->step++;
        double t = span + (double)nb->step / NCP_SPLINE_STEPS;
        if (nb->step == NCP_SPLINE_STEPS) {
            nb->step = 0;
            nb->span++;
        }
        double p[3], end[NCP_AXES];
        ncp_nurbs_stream_point(nb, span, t, p);
        p[2] = m->more_z;
        to_machine_all(m, p, NULL, end);
        int rc = line_to(m, end, 0, m->more_line, seg, d);
        if (rc != 0) {
            if (rc < 0) { /* the run stops: nothing more of this curve */
                nb->received = nb->span = 0;
                m->more_kind = 0;
            }
            return rc;
        }
    }
    m->more_kind = 0;
    return 0;
}

/* G5.3: the curve's order and size now, its points in the NURBS_POINTS ops
 * that follow; each adds points and draws the spans they complete. */
static int nurbs_begin(struct ncp_canon_map *m, const struct ncp_canon *op, uint32_t line,
                       struct ncp_diag *d)
{
    if (ncp_nurbs_stream_begin(&m->nurbs, (uint32_t)op->nurbs.n_points, op->nurbs.order) != 0)
        return -ncp_diag_set(d, NCP_ERR_SEMANTIC, line, 0,
                             "NURBS of order L=%d with %d points: the NCK draws orders 3 to %d",
                             op->nurbs.order, op->nurbs.n_points, NCP_NURBS_MAX_ORDER);
    m->more_z = op->nurbs.end[2];
    m->more_line = line;
    return 0;
}

static int nurbs_points(struct ncp_canon_map *m, const struct ncp_canon *op, struct ncp_seg *s,
                        struct ncp_diag *d)
{
    int n = op->nurbs_points.n < NCP_NURBS_POINTS_PER_OP ? op->nurbs_points.n
                                                          : NCP_NURBS_POINTS_PER_OP;
    int rc = ncp_nurbs_stream_add(&m->nurbs, &op->nurbs_points.pt[0][0], n);
    if (rc == -1)
        return -ncp_diag_set(d, NCP_ERR_SEMANTIC, m->more_line, 0,
                             "NURBS control point with a weight P that is not above 0: "
                             "the machine cannot follow that curve");
    if (rc != 0)
        return -ncp_diag_set(d, NCP_ERR_SEMANTIC, m->more_line, 0,
                             "NURBS control points beyond the count G5.3 gave");
    m->more_kind = NCP_C_NURBS_POINTS;
    return nurbs_more(m, s, d);
}

/* The next line along a curve, or a tap's way out: 1, 0 when done. */
int ncp_canon_map_more(struct ncp_canon_map *m, struct ncp_seg *seg, struct ncp_diag *d)
{
    if (m->more_kind == NCP_C_NURBS_POINTS)
        return nurbs_more(m, seg, d);
    if (m->more_left > 0) { /* the tap's way back out */
        m->more_left = 0;
        int rc = line_to(m, m->more_back, 0, m->more_line, seg, d);
        if (rc == 1 && seg->sync)
            seg->sync = NCP_SYNC_TAP_OUT;
        return rc;
    }
    return 0;
}

/* G5/G5.1: the end, the start and the control points (program X Y). Their Bezier curve is the
 * one-span B-spline of those points (order = count), drawn as a G5.3 NURBS
 * with weights 1. The first line now. */
static int spline(struct ncp_canon_map *m, const struct ncp_canon *op, uint32_t line,
                  struct ncp_seg *s, struct ncp_diag *d)
{
    const struct ncp_canon_nurbs *q = &op->nurbs;
    int n = q->n_points == 4 ? 4 : 3;
    double pts[4][3] = {{q->start[0], q->start[1], 1}, {q->ctrl[0][0], q->ctrl[0][1], 1},
                        {q->ctrl[1][0], q->ctrl[1][1], 1}, {0, 0, 1}};
    pts[n - 1][0] = q->end[0];
    pts[n - 1][1] = q->end[1];
    ncp_nurbs_stream_begin(&m->nurbs, (uint32_t)n, n);
    if (ncp_nurbs_stream_add(&m->nurbs, &pts[0][0], n) != 0)
        return -ncp_diag_set(d, NCP_ERR_GEOMETRY, line, 0, "move to a non-finite position");
    m->more_z = q->end[2];
    m->more_line = line;
    m->more_kind = NCP_C_NURBS_POINTS;
    return nurbs_more(m, s, d);
}

/* Axis indices (machine X=0 Y=1 Z=2) of first, second and normal per plane. */
static const int plane_axes[3][3] = { { 0, 1, 2 }, { 1, 2, 0 }, { 2, 0, 1 } };

static int arc(struct ncp_canon_map *m, const struct ncp_canon *op, uint32_t line,
               struct ncp_seg *s, struct ncp_diag *d)
{
    seg_common(m, s, line);
    s->kind = NCP_SEG_ARC;
    const int *ax = plane_axes[m->plane];
    double pe[3] = { 0, 0, 0 }, pc[3] = { 0, 0, 0 };
    pe[ax[0]] = op->arc_feed.first_end;
    pe[ax[1]] = op->arc_feed.second_end;
    pe[ax[2]] = op->arc_feed.axis_end;
    pc[ax[0]] = op->arc_feed.first_axis;
    pc[ax[1]] = op->arc_feed.second_axis;
    pc[ax[2]] = op->arc_feed.axis_end;
    double c[3], n[3] = { 0, 0, 0 }, origin[3] = { 0, 0, 0 }, nm[3];
    to_machine_all(m, pe, op->arc_feed.abc, s->end);
    to_machine(m, pc, c);
    if (!finite3(s->end, NCP_AXES) || !finite3(c, 3) || abs(op->arc_feed.rotation) > 100000)
        return -ncp_diag_set(d, NCP_ERR_GEOMETRY, line, 0, "arc with a non-finite end or centre, or too many turns");
    unwrap(m, s->end);
    int absent = absent_axis(m, s->end, line, d);
    if (absent)
        return absent;
    /* the plane normal turns with the XY rotation like any direction does */
    n[ax[2]] = 1.0;
    to_machine(m, n, nm);
    to_machine(m, origin, n);
    for (int i = 0; i < 3; i++)
        nm[i] -= n[i];
    double nl = sqrt(dot(nm, nm));
    for (int i = 0; i < 3; i++)
        s->normal[i] = nm[i] / nl;
    double rs[3], re[3];
    for (int i = 0; i < 3; i++) {
        rs[i] = s->start[i] - c[i];
        re[i] = s->end[i] - c[i];
    }
    double hs = dot(rs, s->normal), he = dot(re, s->normal);
    for (int i = 0; i < 3; i++) {
        rs[i] -= hs * s->normal[i];
        re[i] -= he * s->normal[i];
        s->center[i] = c[i] + hs * s->normal[i];
    }
    s->axial = he - hs;
    s->r0 = sqrt(dot(rs, rs));
    s->r1 = sqrt(dot(re, re));
    /* a helix of zero radius (a bore whose tool fills the hole: rs274 sends
     * such arcs) is its axis: the straight move along it */
    if (s->r0 < 1e-9 && s->r1 < 1e-9) {
        double end[NCP_AXES];
        memcpy(end, s->end, sizeof end);
        return line_to(m, end, 0, line, s, d);
    }
    if (s->r0 < 1e-9 || s->r1 < 1e-9)
        return -ncp_diag_set(d, NCP_ERR_GEOMETRY, line, 0,
                             "arc with zero radius at one end (its centre is its start or end)");
    for (int i = 0; i < 3; i++)
        s->u[i] = rs[i] / s->r0;
    cross(s->normal, s->u, s->w);
    double a = atan2(dot(re, s->w), dot(re, s->u));
    int rot = op->arc_feed.rotation;
    if (rot > 0 && a <= 1e-12)
        a += 2 * M_PI;
    else if (rot < 0 && a >= -1e-12)
        a -= 2 * M_PI;
    int turns = rot > 0 ? rot - 1 : rot < 0 ? -rot - 1 : 0;
    a += (a > 0 ? 1 : -1) * 2 * M_PI * turns;
    s->angle = a;
    double arc_len = fabs(a) * 0.5 * (s->r0 + s->r1);
    s->length = sqrt(arc_len * arc_len + s->axial * s->axial);
    /* the arc sweeps its plane: both of the plane's axes must be there */
    for (int i = 0; i < 3; i++)
        if (!(m->cfg->axis_mask & NCP_AXIS_BIT(i)) && (fabs(s->u[i]) > 1e-12 ||
                                                        fabs(s->w[i]) > 1e-12))
            return -ncp_diag_set(d, NCP_ERR_SEMANTIC, line, 0,
                                 "this arc needs axis %c, which this machine does not have "
                                 "([TRAJ] COORDINATES lists the machine's axes)",
                                 NCP_AXIS_LETTERS[i]);
    if (spindle_needed(m, line, d))
        return -NCP_ERR_SEMANTIC;
    if ((s->feed = feed_at(m, s->end[0], 0)) <= 0)
        return -ncp_diag_set(d, NCP_ERR_SEMANTIC, line, 0, "arc move with zero feed rate");
    s->blend_feed = blend_feed_at(m, s->end[0], 0);
    int r = check_arc(m, s, d);
    if (r)
        return -r;
    if ((r = ncp_kins_seg_check(m->cfg, s, d)) != 0)
        return r;
    memcpy(m->pos, s->end, sizeof m->pos);
    return 1;
}

/* Lengths X Y Z in mm; A B C are degrees whatever the units. */
static void set6(double dst[6], const double src[6], double scale)
{
    for (int i = 0; i < 6; i++)
        dst[i] = src[i] * (i < 3 ? scale : 1.0);
}

static int state_op(struct ncp_canon_map *m, const struct ncp_canon *op)
{
    switch (op->kind) {
    case NCP_C_USE_LENGTH_UNITS:
        m->scale = op->units.mm == 0 ? 25.4 : 1.0;
        break;
    case NCP_C_SET_G5X_OFFSET:
        set6(m->g5x, op->offset.v, m->scale);
        break;
    case NCP_C_SET_G92_OFFSET:
        set6(m->g92, op->offset.v, m->scale);
        break;
    case NCP_C_USE_TOOL_LENGTH_OFFSET:
        set6(m->tool, op->tool_length.v, m->scale);
        break;
    case NCP_C_SET_XY_ROTATION:
        m->rotation = op->rotation.degrees;
        break;
    case NCP_C_SELECT_PLANE:
        m->plane = op->plane.plane >= 0 && op->plane.plane <= 2 ? op->plane.plane : 0;
        break;
    case NCP_C_SET_FEED_RATE:
        m->feed = op->feed_rate.rate * m->scale;
        m->feed_deg = op->feed_rate.rate;
        break;
    case NCP_C_SET_FEED_MODE:
        m->per_rev = op->feed_mode.per_rev == 1;
        break;
    case NCP_C_SET_SPINDLE_SPEED:
        m->speed = op->spindle_speed.speed;
        break;
    case NCP_C_START_SPINDLE_CLOCKWISE:
        m->spindle_dir = 1;
        break;
    case NCP_C_START_SPINDLE_COUNTERCLOCKWISE:
        m->spindle_dir = -1;
        break;
    case NCP_C_STOP_SPINDLE_TURNING:
    case NCP_C_ORIENT_SPINDLE:
        m->spindle_dir = 0;
        break;
    case NCP_C_SET_SPINDLE_MODE:
        m->css_max = op->spindle_mode.css_max > 0 ? op->spindle_mode.css_max : 0.0;
        break;
    case NCP_C_START_SPEED_FEED_SYNCH:
        m->sync_pitch = op->synch.per_rev * m->scale;
        break;
    case NCP_C_STOP_SPEED_FEED_SYNCH:
        m->sync_pitch = 0.0;
        break;
    case NCP_C_SET_MOTION_CONTROL_MODE:
        m->term = op->motion_control.mode == 0   ? NCP_TERM_STOP
                  : op->motion_control.mode == 1 ? NCP_TERM_EXACT_PATH
                                                 : NCP_TERM_CONTINUOUS;
        m->tolerance = op->motion_control.tolerance * m->scale;
        break;
    case NCP_C_SET_NAIVECAM_TOLERANCE:
        m->merge_tol = op->naivecam.tolerance * m->scale;
        break;
    default:
        break;
    }
    return 0;
}

int ncp_canon_map_op(struct ncp_canon_map *m, const struct ncp_canon *op, uint32_t line,
                     struct ncp_seg *seg, struct ncp_diag *d)
{
    switch (op->kind) {
    case NCP_C_STRAIGHT_TRAVERSE:
        return straight(m, op, 1, line, seg, d);
    case NCP_C_STRAIGHT_FEED:
    case NCP_C_STRAIGHT_PROBE:
        return straight(m, op, 0, line, seg, d);
    case NCP_C_ARC_FEED:
        return arc(m, op, line, seg, d);
    case NCP_C_RIGID_TAP:
        return rigid_tap(m, op, line, seg, d);
    case NCP_C_NURBS_FEED:
        if (op->nurbs.follow == NCP_NURBS_POINTS_FOLLOW)
            return nurbs_begin(m, op, line, d);
        return spline(m, op, line, seg, d);
    case NCP_C_NURBS_POINTS:
        return nurbs_points(m, op, seg, d);
    case NCP_C_DWELL:
        seg_common(m, seg, line);
        seg->kind = NCP_SEG_DWELL;
        seg->term = NCP_TERM_STOP;
        seg->dwell = op->dwell.seconds > 0 ? op->dwell.seconds : 0;
        memcpy(seg->end, m->pos, sizeof seg->end);
        return 1;
    default:
        return state_op(m, op);
    }
}
