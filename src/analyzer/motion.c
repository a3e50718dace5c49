/* G0/G1 (and G53), G2/G3 arc requests, G80 and the dispatch to canned cycles.
 * End points are in program coordinates; arcs are resolved by the executor. */
#include "floor.h"
#include "stages.h"

#include <math.h>
#include <string.h>

/* Polar words (@ radius, ^ angle in degrees) replace X/Y in the XY plane. */
static int ncp_motion_polar(struct ncp_analyzer *a, double *end)
{
    const struct ncp_words *w = &a->w;
    const struct ncp_state *s = &a->st;
    int hr = NCP_HAS(w, '@'), ht = NCP_HAS(w, '^');
    uint16_t col = w->col[NCP_LETTER(hr ? '@' : '^')];
    double r = w->v[NCP_LETTER('@')], t = w->v[NCP_LETTER('^')] * M_PI / 180.0;
    double x = end[NCP_X], y = end[NCP_Y];
    if (NCP_HAS(w, 'X'))
        return ncp_an_error(a, w->col[NCP_LETTER('X')], "Cannot specify both polar coordinate and X word");
    if (NCP_HAS(w, 'Y'))
        return ncp_an_error(a, w->col[NCP_LETTER('Y')], "Cannot specify both polar coordinate and Y word");
    if (!s->m.incremental) {
        if (hr && !ht) {
            if (x == 0.0 && y == 0.0)
                return ncp_an_error(a, col, "Must specify angle in polar coordinate if at the origin");
            t = atan2(y, x);
        } else if (!hr) {
            r = hypot(y, x);
        }
    } else {
        if (x == 0.0 && y == 0.0)
            return ncp_an_error(a, col, hr ? "Incremental motion with polar coordinates is indeterminate when at the origin"
                                           : "G91 motion with polar coordinates is indeterminate when at the origin");
        /* two separate steps, as rs274 rounds them */
        if (hr) {
            double th = atan2(y, x), rad = hypot(y, x) + r;
            x = rad * cos(th);
            y = rad * sin(th);
        }
        if (ht) {
            double th = atan2(y, x) + t, rad = hypot(y, x);
            x = rad * cos(th);
            y = rad * sin(th);
        }
        end[NCP_X] = x;
        end[NCP_Y] = y;
        return NCP_OK;
    }
    end[NCP_X] = r * cos(t);
    end[NCP_Y] = r * sin(t);
    return NCP_OK;
}

/* The block's end point: absolute, incremental, or G53 machine coordinates. */
int ncp_motion_ends(struct ncp_analyzer *a, int g53, double *end)
{
    const struct ncp_state *s = &a->st;
    const struct ncp_words *w = &a->w;
    if (g53) {
        if (w->has & NCP_POLAR_BITS)
            return ncp_an_error(a, w->line_col, "Cannot use polar coordinates with G53");
        double word[NCP_NAX];
        uint32_t given = 0;
        for (int ax = 0; ax < NCP_NAX; ax++) {
            int l = ncp_axis_slot[ax];
            word[ax] = w->v[l];
            given |= ((w->has >> l) & 1u) << ax;
        }
        ncp_frame_g53(a, word, given, end);
        return NCP_OK;
    }
    int incremental = s->m.incremental;
    for (int ax = 0; ax < NCP_NAX; ax++) {
        int l = ncp_axis_slot[ax];
        if (!((w->has >> l) & 1u))
            end[ax] = s->pos[ax];
        else if (incremental)
            end[ax] = s->pos[ax] + w->v[l];
        else
            end[ax] = w->v[l];
    }
    if (w->has & NCP_POLAR_BITS)
        return ncp_motion_polar(a, end);
    return NCP_OK;
}

static double ncp_straight_length(const double *p, const double *q)
{
    double l = 0.0, r = 0.0;
    for (int ax = 0; ax < NCP_NAX; ax++) {
        double d = q[ax] - p[ax];
        if (ax >= NCP_A && ax <= NCP_C)
            r += d * d;
        else
            l += d * d;
    }
    return l > 0.0 ? sqrt(l) : sqrt(r);
}

/* G1 and G2/G3 (G7x passes too) in G95 need the S word's speed, turning or
 * not: rs274 checks the speed it was given, after the feed rate. */
static const char ncp_zero_speed_per_rev[] =
    "Cannot feed with zero spindle speed in feed per rev mode";

int ncp_motion_straight(struct ncp_analyzer *a, int motion)
{
    struct ncp_state *s = &a->st;
    const struct ncp_words *w = &a->w;
    double end[NCP_NAX];
    int g53 = w->g[NCP_GG_NONMODAL] == NCP_G53;
    int rc = ncp_cutcomp_check_motion(&a->comp, 0, &a->err, a->line);
    if (rc == NCP_OK)
        rc = ncp_motion_ends(a, g53, end);
    if (rc != NCP_OK)
        return rc;
    if (motion == NCP_G0) {
        if (ncp_cutcomp_engaged(&a->comp))
            rc = ncp_comp_move_straight(a, motion, end, g53);
        else
            ncp_an_emit6(a, NCP_C_STRAIGHT_TRAVERSE, end);
    } else {
        if (s->m.feed_mode == 1) {
            if (!NCP_HAS(w, 'F'))
                return ncp_an_error(a, NCP_MOTION_COL(w),
                                    "F word missing with inverse time g1 move");
            double rate = ncp_straight_length(s->pos, end) * w->v[NCP_LETTER('F')];
            s->feed = rate < 0.1 ? 0.1 : rate; /* what #<_feed> reads afterwards */
            ncp_an_emit(a, NCP_C_SET_FEED_RATE)->feed_rate.rate = s->feed;
        } else if (s->feed == 0.0) {
            return ncp_an_error(a, NCP_MOTION_COL(w),
                                "Cannot do g1 with zero feed rate");
        } else if (s->m.feed_mode == 2 && s->speed == 0.0) {
            return ncp_an_error(a, NCP_MOTION_COL(w), "%s", ncp_zero_speed_per_rev);
        }
        if (ncp_cutcomp_engaged(&a->comp))
            rc = ncp_comp_move_straight(a, motion, end, g53);
        else
            ncp_an_emit6(a, NCP_C_STRAIGHT_FEED, end);
    }
    if (rc != NCP_OK)
        return rc;
    memcpy(s->pos, end, sizeof end);
    s->m.motion = motion;
    return NCP_OK;
}

/* Plane -> (first, second, helix) axes and the centre-offset letters. */
static const int ncp_plane_axes[3][3] = {
    {NCP_X, NCP_Y, NCP_Z}, {NCP_Y, NCP_Z, NCP_X}, {NCP_Z, NCP_X, NCP_Y}};
static const char ncp_plane_ijk[3][2] = {{'I', 'J'}, {'J', 'K'}, {'K', 'I'}};
static const char *const ncp_plane_missing[3] = {
    "X and y words missing for arc in xy plane",
    "Y and z words missing for arc in yz plane",
    "X and z words missing for arc in xz plane"};

/* Only for #<_feed> after a G93 arc (the executor computes the printed
 * rate): arc length as rs274 measures it, centre from IJK or R. */
static double ncp_request_arc_length(const struct ncp_canon *q)
{
    double x1 = q->arc.first_start, y1 = q->arc.second_start;
    double x2 = q->arc.first_end, y2 = q->arc.second_end, cx, cy;
    int ccw = q->arc.dir > 0;
    if (q->arc.radius_form) {
        double r = q->arc.radius, ar = fabs(r);
        double mx = (x1 + x2) / 2, my = (y1 + y2) / 2;
        double half = hypot(mx - x2, my - y2);
        if (ar == 0.0)
            return 0.0;
        if (half / ar > 1 - 1e-12)
            half = ar;
        double th = atan2(y2 - y1, x2 - x1) + ((!ccw && r > 0) || (ccw && r < 0) ? -M_PI_2 : M_PI_2);
        double off = ar * cos(asin(half / ar));
        cx = mx + off * cos(th);
        cy = my + off * sin(th);
    } else {
        cx = q->arc.first_centre;
        cy = q->arc.second_centre;
    }
    int turn = (q->arc.turns > 0 ? q->arc.turns : 1) * (ccw ? 1 : -1);
    double alpha = atan2(y1 - cy, x1 - cx), beta = atan2(y2 - cy, x2 - cx), theta;
    if (turn > 0) {
        if (beta <= alpha)
            beta += 2 * M_PI;
        theta = beta - alpha + (turn - 1) * 2 * M_PI;
    } else {
        if (alpha <= beta)
            alpha += 2 * M_PI;
        theta = beta - alpha + (turn + 1) * 2 * M_PI;
    }
    double rad = hypot(cx - x1, cy - y1);
    return fabs(rad * theta);
}

int ncp_arc_run(struct ncp_analyzer *a, int motion, const double *end)
{
    struct ncp_state *s = &a->st;
    const struct ncp_words *w = &a->w;
    int pl = s->m.plane;
    const int *ax = ncp_plane_axes[pl];
    uint16_t col = NCP_MOTION_COL(w);
    int crc = ncp_cutcomp_check_motion(&a->comp, 1, &a->err, a->line);
    if (crc != NCP_OK)
        return crc;
    int has_ijk = (w->has & ((1u << NCP_LETTER('I')) | (1u << NCP_LETTER('J')) |
                             (1u << NCP_LETTER('K')))) != 0;
    int has_r = NCP_HAS(w, 'R');
    if (!NCP_HAS(w, ncp_axis_letter[ax[0]]) && !NCP_HAS(w, ncp_axis_letter[ax[1]]) && has_r)
        return ncp_an_error(a, col, "%s", ncp_plane_missing[pl]);
    if (!has_r && !has_ijk)
        return ncp_an_error(a, col, "R i j k words all missing for arc");
    if (has_r && has_ijk)
        return ncp_an_error(a, col, "Mixed radius ijk format for arc");
    if (s->m.feed_mode == 1) {
        if (!NCP_HAS(w, 'F'))
            return ncp_an_error(a, col, "F word missing with inverse time arc move");
    } else if (s->feed == 0.0) {
        return ncp_an_error(a, col, "Cannot make arc with zero feed rate");
    } else if (s->m.feed_mode == 2 && s->speed == 0.0) {
        return ncp_an_error(a, col, "%s", ncp_zero_speed_per_rev);
    }
    if (s->m.feed_mode == 1) {
        struct ncp_canon *f = ncp_an_emit(a, NCP_C_SET_FEED_RATE);
        f->flags = NCP_FEED_F_INVERSE_ARC;
        f->feed_rate.rate = w->v[NCP_LETTER('F')];
        f->feed_rate.arc_axis_start = s->pos[ax[2]];
    }
    /* the request is filled where it goes: the block's slot, or here for the
     * compensation queue */
    struct ncp_canon req;
    int comp = ncp_cutcomp_engaged(&a->comp);
    struct ncp_canon *op = comp ? &req : ncp_an_emit(a, NCP_C_ARC_REQUEST);
    if (comp) {
        memset(&req, 0, sizeof req);
        req.kind = NCP_C_ARC_REQUEST;
    }
    op->arc.first_start = s->pos[ax[0]];
    op->arc.second_start = s->pos[ax[1]];
    op->arc.first_end = end[ax[0]];
    op->arc.second_end = end[ax[1]];
    op->arc.axis_end = end[ax[2]];
    op->arc.abc[0] = end[NCP_A];
    op->arc.abc[1] = end[NCP_B];
    op->arc.abc[2] = end[NCP_C];
    if (has_r) {
        op->arc.radius = w->v[NCP_LETTER('R')];
        op->arc.radius_form = 1;
    } else {
        double o1 = NCP_HAS(w, ncp_plane_ijk[pl][0]) ? w->v[NCP_LETTER(ncp_plane_ijk[pl][0])] : 0;
        double o2 = NCP_HAS(w, ncp_plane_ijk[pl][1]) ? w->v[NCP_LETTER(ncp_plane_ijk[pl][1])] : 0;
        if (s->m.arc_incremental) {
            o1 += s->pos[ax[0]];
            o2 += s->pos[ax[1]];
        }
        op->arc.first_centre = o1;
        op->arc.second_centre = o2;
    }
    op->arc.dir = motion == NCP_G3 ? 1 : -1;
    op->arc.turns = NCP_HAS(w, 'P') ? ncp_trunc_int_round(w->v[NCP_LETTER('P')]) : 1;
    op->arc.plane = pl;
    op->flags = s->m.inches ? 1 : 0;
    if (s->m.feed_mode == 1) {
        double len = ncp_request_arc_length(op), dz = end[ax[2]] - s->pos[ax[2]];
        if (dz != 0.0)
            len = hypot(len, dz);
        double rate = len * w->v[NCP_LETTER('F')];
        s->feed = rate < 0.1 ? 0.1 : rate;
    }
    if (comp) {
        int rc = ncp_comp_move_arc(a, op, end);
        if (rc != NCP_OK)
            return rc;
    } else {
        ncp_sai_move(a, end);
    }
    memcpy(s->pos, end, NCP_NAX * sizeof(double));
    s->m.motion = motion;
    return NCP_OK;
}

int ncp_motion_arc(struct ncp_analyzer *a, int motion)
{
    double end[NCP_NAX];
    int rc = ncp_motion_ends(a, 0, end);
    if (rc != NCP_OK)
        return rc;
    return ncp_arc_run(a, motion, end);
}

/* G38.2 (toward, error if no trip), G38.3 (toward), G38.4 (away, error if no
 * release), G38.5 (away): rs274's checks, then the probe move between the
 * probe switching calls. rs274 leaves its current point alone here: it reads
 * the canon's (backed off, see sai.c) at the next block, with the results. */
int ncp_motion_probe(struct ncp_analyzer *a, int motion)
{
    struct ncp_state *s = &a->st;
    uint16_t col = NCP_MOTION_COL(&a->w);
    if (s->m.comp_side != 0)
        return ncp_an_error(a, col, "Cannot probe with cutter radius comp on");
    if (s->feed == 0.0)
        return ncp_an_error(a, col, "Cannot probe with zero feed rate");
    if (s->m.feed_mode == 2)
        return ncp_an_error(a, col, "Cannot probe with feed per rev mode");
    double end[NCP_NAX];
    int rc = ncp_motion_ends(a, 0, end);
    if (rc != NCP_OK)
        return rc;
    int errors_if_missed = (motion - NCP_G38_2) % 2 == 0;
    if (errors_if_missed) {
        int same = 1;
        for (int ax = 0; ax < NCP_NAX; ax++)
            same &= end[ax] == s->pos[ax];
        if (same)
            return ncp_an_error(a, col, "Start point too close to probe point");
    }
    ncp_an_emit(a, NCP_C_TURN_PROBE_ON);
    struct ncp_canon *op = ncp_an_emit(a, NCP_C_STRAIGHT_PROBE);
    memcpy(op->move.end, end, 6 * sizeof(double));
    op->flags = (uint16_t)((motion >= NCP_G38_4 ? NCP_PROBE_F_AWAY : 0) |
                           (errors_if_missed ? NCP_PROBE_F_ERROR : 0));
    ncp_sai_probe(a, end);
    ncp_an_emit(a, NCP_C_TURN_PROBE_OFF);
    s->m.motion = motion;
    return NCP_OK;
}

/* G33 (a straight feed locked to the spindle, K the distance per turn),
 * G33.1 (rigid tapping to the end and back: rs274 keeps its current point)
 * and G76 (the threading cycle: its checks here, its passes in g76.c).
 * Under cutter compensation rs274 hands all three to its compensation code,
 * which knows only G0 and G1 (see ncp_cutcomp_move). */
int ncp_motion_synced(struct ncp_analyzer *a, int motion)
{
    struct ncp_state *s = &a->st;
    double end[NCP_NAX];
    int rc = ncp_motion_ends(a, 0, end);
    if (rc != NCP_OK)
        return rc;
    s->m.motion = motion;
    if (ncp_cutcomp_engaged(&a->comp)) {
        rc = ncp_comp_move_straight(a, motion, end, 0);
        if (rc == NCP_OK)
            memcpy(s->pos, end, sizeof end);
        return rc;
    }
    uint16_t col = NCP_MOTION_COL(&a->w);
    if (s->m.spindle_dir == 0)
        return ncp_an_error(a, col, motion == NCP_G33   ? "Spindle not turning in G33"
                                    : motion == NCP_G33_1 ? "Spindle not turning in G33.1"
                                                    : "Chosen spindle (0) not turning in G76");
    if (motion == NCP_G76) {
        for (int ax = NCP_A; ax < NCP_NAX; ax++)
            if (end[ax] != s->pos[ax])
                return ncp_an_error(a, col, "Cannot move rotary axes with G76");
        return ncp_g76_cycle(a, end);
    }
    struct ncp_canon *sync = ncp_an_emit(a, NCP_C_START_SPEED_FEED_SYNCH);
    sync->synch.per_rev = a->w.v[NCP_LETTER('K')];
    if (motion == NCP_G33) {
        ncp_an_emit6(a, NCP_C_STRAIGHT_FEED, end);
        memcpy(s->pos, end, sizeof end);
    } else {
        memcpy(ncp_an_emit(a, NCP_C_RIGID_TAP)->rigid_tap.bottom, end, 3 * sizeof(double));
    }
    ncp_an_emit(a, NCP_C_STOP_SPEED_FEED_SYNCH);
    return NCP_OK;
}

/* G5 (cubic: P Q, I J optional) and G5.1 (quadratic: I J) splines in the XY
 * plane, with rs274 2.9's checks in its order. rs274 -g prints only
 * NURBS_FEED(order, ...), no control point. The current point moves to the
 * end and the motion mode stays what it was; rs274's canon puts its own X
 * and Y at 0 (what a probe backs off from, or a tool change reads back,
 * shows it: measured with rs274 2.9 from several start and end points). */
int ncp_motion_spline(struct ncp_analyzer *a, int motion)
{
    struct ncp_state *s = &a->st;
    const struct ncp_words *w = &a->w;
    uint16_t col = NCP_MOTION_COL(w);
    if (s->m.comp_side != 0)
        return ncp_an_error(a, col, "Cannot convert spline with cutter radius compensation");
    if (s->m.feed_mode == 0 && s->feed == 0.0)
        return ncp_an_error(a, col, "Cannot make arc with zero feed rate");
    if (s->m.feed_mode == 1 && !NCP_HAS(w, 'F'))
        return ncp_an_error(a, col, "F word missing with inverse time arc move");
    if (s->m.plane != 0)
        return ncp_an_error(a, col, "Splines must be in the XY plane");
    if (NCP_HAS(w, 'Z') || NCP_HAS(w, 'A') || NCP_HAS(w, 'B') || NCP_HAS(w, 'C'))
        return ncp_an_error(a, col, "Splines may not have motion in Z, A, B, or C");
    if (motion == NCP_G5_1) {
        if (!NCP_HAS(w, 'I') || !NCP_HAS(w, 'J'))
            return ncp_an_error(a, col, "Must specify both I and J with G5.1");
    } else {
        if (NCP_HAS(w, 'I') != NCP_HAS(w, 'J'))
            return ncp_an_error(a, col, "Must specify both I and J, or neither");
        if (!NCP_HAS(w, 'P') || !NCP_HAS(w, 'Q'))
            return ncp_an_error(a, col, "Must specify both P and Q with G5");
    }
    double end[NCP_NAX];
    int rc = ncp_motion_ends(a, 0, end);
    if (rc != NCP_OK)
        return rc;
    /* the control points ride along for the NCK (rs274 -g prints none): start,
     * start + IJ, [end + PQ,] end; a G5 without I J continues the last G5's
     * direction (-P, -Q), as LinuxCNC draws it */
    struct ncp_canon *op = ncp_an_emit(a, NCP_C_NURBS_FEED);
    op->nurbs.n_points = motion == NCP_G5_1 ? 3 : 4;
    memcpy(op->nurbs.end, end, sizeof op->nurbs.end);
    double i = NCP_HAS(w, 'I') ? w->v[NCP_LETTER('I')] : -s->g5_pq[0];
    double j = NCP_HAS(w, 'J') ? w->v[NCP_LETTER('J')] : -s->g5_pq[1];
    op->nurbs.start[0] = s->pos[NCP_X];
    op->nurbs.start[1] = s->pos[NCP_Y];
    op->nurbs.ctrl[0][0] = s->pos[NCP_X] + i;
    op->nurbs.ctrl[0][1] = s->pos[NCP_Y] + j;
    if (motion == NCP_G5) {
        s->g5_pq[0] = w->v[NCP_LETTER('P')];
        s->g5_pq[1] = w->v[NCP_LETTER('Q')];
        op->nurbs.ctrl[1][0] = end[NCP_X] + s->g5_pq[0];
        op->nurbs.ctrl[1][1] = end[NCP_Y] + s->g5_pq[1];
    }
    a->sai.pos[NCP_X] = a->sai.pos[NCP_Y] = 0.0;
    memcpy(s->pos, end, sizeof end);
    return NCP_OK;
}
