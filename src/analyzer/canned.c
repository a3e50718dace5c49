/* Canned cycles G73 G81 G82 G83 G85 G89 in any of the three planes: sticky
 * R/Z/P/Q values, L repeats, G98/G99 retract, incremental positioning, all
 * expanded into traverses, feeds and dwells as rs274 does. */
#include "floor.h"
#include "stages.h"

#include <math.h>
#include <string.h>

static const int ncp_cyc_axes[3][3] = {
    {NCP_X, NCP_Y, NCP_Z}, {NCP_Y, NCP_Z, NCP_X}, {NCP_Z, NCP_X, NCP_Y}};
static const char *const ncp_cyc_no_depth[3] = {
    "Z value unspecified in xy plane canned cycle",
    "X value unspecified in yz plane canned cycle",
    "Y value unspecified in xz plane canned cycle"};
static const char *const ncp_cyc_r_low[3] = {
    "R less than z in cycle in xy plane",
    "R less than x in cycle in yz plane",
    "R less than y in cycle in xz plane"};

/* rs274's retract between pecks (G73/G83): 0.010 inch, in program units. */
#define NCP_PECK_CLEARANCE_INCH 0.010

struct ncp_cyc {
    struct ncp_analyzer *a;
    const int *ax;        /* first, second, normal axis */
    double pos[NCP_NAX];  /* the point being moved */
};

static void ncp_cyc_move(struct ncp_cyc *c, enum ncp_canon_kind kind, double p1, double p2,
                         double n)
{
    c->pos[c->ax[0]] = p1;
    c->pos[c->ax[1]] = p2;
    c->pos[c->ax[2]] = n;
    ncp_an_emit6(c->a, kind, c->pos);
}

#define TRAV(c, x, y, z) ncp_cyc_move(c, NCP_C_STRAIGHT_TRAVERSE, x, y, z)
#define FEED(c, x, y, z) ncp_cyc_move(c, NCP_C_STRAIGHT_FEED, x, y, z)

static void ncp_cyc_dwell(struct ncp_cyc *c, double t)
{
    ncp_an_emit(c->a, NCP_C_DWELL)->dwell.seconds = t;
}

static void ncp_cyc_peck(struct ncp_cyc *c, int motion, double x, double y, double r,
                         double clear, double bottom, double delta)
{
    const double clr = ncp_user_len(c->a, NCP_PECK_CLEARANCE_INCH);
    /* Depth by repeated subtraction, as rs274 steps it: r - k * delta would
     * round differently and end a peck early or late. */
    double d = r - delta;
    while (d > bottom) {
        FEED(c, x, y, d);
        if (motion == NCP_G83)
            TRAV(c, x, y, r);
        TRAV(c, x, y, d + clr);
        d -= delta;
    }
    FEED(c, x, y, bottom);
    TRAV(c, x, y, clear);
}

static void ncp_cyc_spindle_on(struct ncp_cyc *c)
{
    ncp_an_emit(c->a, c->a->st.m.spindle_dir > 0 ? NCP_C_START_SPINDLE_CLOCKWISE
                                                 : NCP_C_START_SPINDLE_COUNTERCLOCKWISE);
}

static void ncp_cyc_orient(struct ncp_cyc *c)
{
    ncp_an_emit(c->a, NCP_C_STOP_SPINDLE_TURNING);
    /* rs274 passes its CANON_DIRECTION value: 2 clockwise, 3 counterclockwise */
    ncp_an_emit(c->a, NCP_C_ORIENT_SPINDLE)->orient.direction = c->a->st.m.spindle_dir > 0 ? 2 : 3;
}

/* G87 back boring: out to the offset point, down, back in, cut up to the
 * middle level and down again, out, and up. */
static void ncp_cyc_g87(struct ncp_cyc *c, double x, double y, const double *ijk_abs,
                        double r, double clear, double bottom)
{
    double ox = ijk_abs[0], oy = ijk_abs[1], mid = ijk_abs[2];
    TRAV(c, ox, oy, r);
    ncp_cyc_orient(c);
    TRAV(c, ox, oy, bottom);
    TRAV(c, x, y, bottom);
    ncp_cyc_spindle_on(c);
    FEED(c, x, y, mid);
    FEED(c, x, y, bottom);
    ncp_cyc_orient(c);
    TRAV(c, ox, oy, bottom);
    TRAV(c, ox, oy, clear);
    TRAV(c, x, y, clear);
    ncp_cyc_spindle_on(c);
}

static void ncp_cyc_body(struct ncp_cyc *c, int motion, double x, double y, double r,
                         double clear, double bottom, double p, double q)
{
    switch (motion) {
    case NCP_G86:
        FEED(c, x, y, bottom);
        ncp_cyc_dwell(c, p);
        ncp_an_emit(c->a, NCP_C_STOP_SPINDLE_TURNING);
        TRAV(c, x, y, clear);
        ncp_cyc_spindle_on(c);
        break;
    case NCP_G84:
    case NCP_G74: {
        /* tapping, right hand (G84) or left hand (G74): overrides off, the
         * spindle reversed to come out, then turned back and restored. In
         * G18/G19 at the hole, where rs274 2.9 feeds to the plane's
         * coordinates taken as X Y Z (docs/differences-from-rs274.md). */
        enum ncp_canon_kind in = motion == NCP_G84 ? NCP_C_START_SPINDLE_CLOCKWISE
                                               : NCP_C_START_SPINDLE_COUNTERCLOCKWISE;
        enum ncp_canon_kind out = motion == NCP_G84 ? NCP_C_START_SPINDLE_COUNTERCLOCKWISE
                                                : NCP_C_START_SPINDLE_CLOCKWISE;
        ncp_an_emit(c->a, NCP_C_DISABLE_FEED_OVERRIDE);
        ncp_an_emit(c->a, NCP_C_DISABLE_SPEED_OVERRIDE);
        FEED(c, x, y, bottom);
        ncp_an_emit(c->a, NCP_C_STOP_SPINDLE_TURNING);
        ncp_an_emit(c->a, out);
        ncp_cyc_dwell(c, p);
        FEED(c, x, y, clear);
        ncp_an_emit(c->a, NCP_C_STOP_SPINDLE_TURNING);
        ncp_an_emit(c->a, in);
        if (c->a->st.m.feed_override)
            ncp_an_emit(c->a, NCP_C_ENABLE_FEED_OVERRIDE);
        if (c->a->st.m.speed_override)
            ncp_an_emit(c->a, NCP_C_ENABLE_SPEED_OVERRIDE);
        break;
    }
    case NCP_G88:
        FEED(c, x, y, bottom);
        ncp_cyc_dwell(c, p);
        ncp_an_emit(c->a, NCP_C_STOP_SPINDLE_TURNING);
        ncp_an_emit(c->a, NCP_C_PROGRAM_STOP);
        ncp_cyc_spindle_on(c);
        break;
    case NCP_G81:
        FEED(c, x, y, bottom);
        TRAV(c, x, y, clear);
        break;
    case NCP_G82:
        FEED(c, x, y, bottom);
        ncp_cyc_dwell(c, p);
        TRAV(c, x, y, clear);
        break;
    case NCP_G85:
        FEED(c, x, y, bottom);
        FEED(c, x, y, r);
        TRAV(c, x, y, clear);
        break;
    case NCP_G89:
        FEED(c, x, y, bottom);
        ncp_cyc_dwell(c, p);
        FEED(c, x, y, clear);
        break;
    default:
        ncp_cyc_peck(c, motion, x, y, r, clear, bottom, q);
        break;
    }
}

/* Sticky P/Q: required on the first block of a cycle, remembered after.
 * rs274 keeps -1 as its "no word" marker, so P-1/Q-1 count as missing. */
static int ncp_cyc_pq(struct ncp_analyzer *a, int motion, double *p, double *q)
{
    struct ncp_state *s = &a->st;
    const struct ncp_words *w = &a->w;
    uint16_t col = NCP_MOTION_COL(w);
    int first = s->m.motion != motion;
    int hp = NCP_HAS(w, 'P') && w->v[NCP_LETTER('P')] != -1.0;
    int hq = NCP_HAS(w, 'Q') && w->v[NCP_LETTER('Q')] != -1.0;
    *p = hp ? w->v[NCP_LETTER('P')] : s->cycle_p;
    *q = hq ? w->v[NCP_LETTER('Q')] : s->cycle_q;
    if ((motion == NCP_G82 || motion == NCP_G86 || motion == NCP_G88 || motion == NCP_G89) &&
        first && !hp)
        return ncp_an_error(a, col, "Dwell time p word missing with g%d", motion / 10);
    if ((motion == NCP_G83 || motion == NCP_G73) && first && !hq)
        return ncp_an_error(a, col, "Q word missing with g%d", motion / 10);
    return NCP_OK;
}

static int ncp_cyc_spindle_check(struct ncp_analyzer *a, int motion)
{
    const struct ncp_words *w = &a->w;
    uint16_t col = NCP_MOTION_COL(w);
    if ((motion == NCP_G86 || motion == NCP_G87 || motion == NCP_G88) && a->st.m.spindle_dir == 0)
        return ncp_an_error(a, col, "Spindle not turning in g%d", motion / 10);
    return NCP_OK;
}

/* The tapping cycles want the spindle turning their way; rs274 looks at the
 * hole, after the moves that bring the tap over it. */
static int ncp_cyc_tap_check(struct ncp_analyzer *a, int motion)
{
    uint16_t col = NCP_MOTION_COL(&a->w);
    int dir = a->st.m.spindle_dir, want = motion == NCP_G84 ? 1 : -1;
    if (dir == 0)
        return ncp_an_error(a, col, "Spindle not turning in G%d", motion / 10);
    if (dir != want)
        return ncp_an_error(a, col, "Spindle turning %s in G%d",
                            motion == NCP_G84 ? "counterclockwise" : "clockwise", motion / 10);
    return NCP_OK;
}

/* G87's I J K, sticky, each bound to its own axis (I to X, J to Y, K to Z)
 * in every plane, as rs274 binds them: the two of the plane's axes offset
 * the point, the normal axis's one is the middle level, absolute even in G91
 * (rs274 adds the bottom level there). ijk[] comes back in the cycle's axis
 * order: first, second, normal. */
static int ncp_cyc_g87_words(struct ncp_analyzer *a, const int *ax, double bottom,
                             double *ijk)
{
    struct ncp_state *s = &a->st;
    const struct ncp_words *w = &a->w;
    uint16_t col = NCP_MOTION_COL(w);
    static const char l[3] = {'I', 'J', 'K'};
    static const char *const miss[3] = {"I word missing with g87", "J word missing with g87",
                                        "K word missing with g87"};
    double by_letter[3];
    for (int k = 0; k < 3; k++) {
        if (s->m.motion != NCP_G87 && !NCP_HAS(w, l[k]))
            return ncp_an_error(a, col, "%s", miss[k]);
        by_letter[k] = NCP_HAS(w, l[k]) ? w->v[NCP_LETTER(l[k])] : s->cycle_ijk[k];
        s->cycle_ijk[k] = by_letter[k];
    }
    for (int k = 0; k < 3; k++)
        ijk[k] = by_letter[ax[k]]; /* ax[] holds NCP_X..NCP_Z only */
    if (s->m.incremental)
        ijk[2] += bottom;
    return NCP_OK;
}

static int ncp_cyc_checks(struct ncp_analyzer *a, int motion, double *r, int *l)
{
    struct ncp_state *s = &a->st;
    const struct ncp_words *w = &a->w;
    uint16_t col = NCP_MOTION_COL(w);
    if (s->feed == 0.0)
        return ncp_an_error(a, col, "Cannot feed with zero feed rate");
    if (s->m.feed_mode == 1)
        return ncp_an_error(a, col, "Cannot use inverse time feed with canned cycles");
    if (s->m.comp_side != 0)
        return ncp_an_error(a, col, "Cannot use canned cycles with cutter compensation on");
    if (NCP_HAS(w, 'R'))
        *r = w->v[NCP_LETTER('R')];
    else if (s->m.motion == motion)
        *r = s->cycle_r;
    else
        return ncp_an_error(a, col, "R clearance plane unspecified in cycle");
    *l = NCP_HAS(w, 'L') ? ncp_trunc_int_round(w->v[NCP_LETTER('L')]) : 1;
    if (NCP_HAS(w, 'L') && *l == 0)
        return ncp_an_error(a, w->col[NCP_LETTER('L')], "Cannot do zero repeats of cycle");
    static const char uvw[] = "UVW";
    for (int k = 0; k < 3; k++)
        if (NCP_HAS(w, uvw[k]))
            return ncp_an_error(a, w->col[NCP_LETTER(uvw[k])],
                                "Cannot put a %c in a canned cycle in the %s plane", uvw[k],
                                s->m.plane == 0 ? "XY" : s->m.plane == 1 ? "YZ" : "XZ");
    return NCP_OK;
}

static void ncp_cyc_motion_mode(struct ncp_analyzer *a, int on)
{
    const struct ncp_modal *m = &a->st.m;
    if (m->control == 1)
        return;
    struct ncp_canon *op = ncp_an_emit(a, NCP_C_SET_MOTION_CONTROL_MODE);
    if (on) {
        op->motion_control.mode = 1;
        return;
    }
    op->motion_control.mode = m->control;
    op->motion_control.tolerance = m->p_tol;
    ncp_an_emit(a, NCP_C_SET_NAIVECAM_TOLERANCE)->naivecam.tolerance = m->q_tol;
}

int ncp_canned_run(struct ncp_analyzer *a, int motion)
{
    struct ncp_state *s = &a->st;
    const struct ncp_words *w = &a->w;
    int pl = s->m.plane;
    const int *ax = ncp_cyc_axes[pl];
    double r = 0.0, p, q;
    int l = 1;
    int rc = ncp_cyc_checks(a, motion, &r, &l);
    if (rc != NCP_OK)
        return rc;
    char nl = ncp_axis_letter[ax[2]];
    int has_n = NCP_HAS(w, nl);
    if (s->m.motion != motion && !has_n)
        return ncp_an_error(a, NCP_MOTION_COL(w),
                            "%s", ncp_cyc_no_depth[pl]);
    double depth = has_n ? w->v[NCP_LETTER(nl)] : s->cycle_cc;
    double cur = s->pos[ax[2]];
    if (!s->cycle_il_flag) {
        s->cycle_il = cur;
        s->cycle_il_flag = 1;
    }
    double old_cc = s->cycle_il;
    double aa, bb, ai = 0.0, bi = 0.0, cc, rr;
    char l1 = ncp_axis_letter[ax[0]], l2 = ncp_axis_letter[ax[1]];
    int polar = pl == 0 && (w->has & NCP_POLAR_BITS) != 0;
    double rad_inc = 0.0, th_inc = 0.0;
    if (!s->m.incremental) {
        rr = r;
        cc = depth;
        aa = NCP_HAS(w, l1) ? w->v[NCP_LETTER(l1)] : s->pos[ax[0]];
        bb = NCP_HAS(w, l2) ? w->v[NCP_LETTER(l2)] : s->pos[ax[1]];
        if (polar) {
            double rad = NCP_HAS(w, '@') ? w->v[NCP_LETTER('@')]
                                         : hypot(s->pos[NCP_Y], s->pos[NCP_X]);
            double th = NCP_HAS(w, '^') ? w->v[NCP_LETTER('^')] * M_PI / 180.0
                                        : atan2(s->pos[NCP_Y], s->pos[NCP_X]);
            aa = rad * cos(th);
            bb = rad * sin(th);
        }
    } else {
        if (polar) {
            rad_inc = NCP_HAS(w, '@') ? w->v[NCP_LETTER('@')] : 0.0;
            th_inc = NCP_HAS(w, '^') ? w->v[NCP_LETTER('^')] * M_PI / 180.0 : 0.0;
        }
        ai = NCP_HAS(w, l1) ? w->v[NCP_LETTER(l1)] : 0.0;
        bi = NCP_HAS(w, l2) ? w->v[NCP_LETTER(l2)] : 0.0;
        rr = r + old_cc;
        cc = rr + depth;
        aa = s->pos[ax[0]];
        bb = s->pos[ax[1]];
    }
    if (rr < cc)
        return ncp_an_error(a, NCP_MOTION_COL(w),
                            "%s", ncp_cyc_r_low[pl]);
    struct ncp_cyc c = {a, ax, {0}};
    memcpy(c.pos, s->pos, sizeof c.pos);
    /* rotary axes of the block take effect with the cycle's moves */
    if (old_cc < rr) {
        TRAV(&c, s->pos[ax[0]], s->pos[ax[1]], rr);
        old_cc = rr;
        cur = old_cc;
    }
    double clear = s->m.retract_r ? rr : old_cc;
    ncp_cyc_motion_mode(a, 1);
    rc = ncp_cyc_pq(a, motion, &p, &q);
    double ijk[3] = {0}; /* read by G87 only, which sets them */
    if (rc == NCP_OK)
        rc = ncp_cyc_spindle_check(a, motion);
    if (rc == NCP_OK && motion == NCP_G87)
        rc = ncp_cyc_g87_words(a, ax, cc, ijk);
    if (rc != NCP_OK)
        return rc;
    for (int rep = l; rep > 0; rep--) {
        aa += ai;
        bb += bi;
        if (rad_inc != 0.0 || th_inc != 0.0) {
            if (aa == 0.0 && bb == 0.0)
                return ncp_an_error(a, w->line_col, "Incremental motion with polar coordinates is indeterminate when at the origin");
            if (rad_inc != 0.0) {
                double th = atan2(bb, aa), rad = hypot(bb, aa) + rad_inc;
                aa = rad * cos(th);
                bb = rad * sin(th);
            }
            if (th_inc != 0.0) {
                double th = atan2(bb, aa) + th_inc, rad = hypot(bb, aa);
                aa = rad * cos(th);
                bb = rad * sin(th);
            }
        }
        if (rep == l && cur > rr) {
            TRAV(&c, aa, bb, cur);
            TRAV(&c, aa, bb, rr);
        } else {
            TRAV(&c, aa, bb, clear);
            if (clear > rr)
                TRAV(&c, aa, bb, rr);
        }
        if ((motion == NCP_G83 || motion == NCP_G73) && q <= 0.0)
            return ncp_an_error(a, NCP_MOTION_COL(w),
                                "Negative or zero q value used");
        if ((motion == NCP_G84 || motion == NCP_G74) &&
            (rc = ncp_cyc_tap_check(a, motion)) != NCP_OK)
            return rc;
        if (motion == NCP_G87) {
            double off[3] = {aa + ijk[0], bb + ijk[1], ijk[2]};
            ncp_cyc_g87(&c, aa, bb, off, rr, clear, cc);
        } else {
            ncp_cyc_body(&c, motion, aa, bb, rr, clear, cc, p, q);
        }
    }
    ncp_cyc_motion_mode(a, 0);
    memcpy(s->pos, c.pos, sizeof c.pos);
    s->pos[ax[0]] = aa;
    s->pos[ax[1]] = bb;
    s->pos[ax[2]] = clear;
    s->cycle_cc = depth;
    s->cycle_r = r;
    s->cycle_l = l;
    if (motion == NCP_G82 || motion == NCP_G84 || motion == NCP_G74 || motion == NCP_G86 ||
        motion == NCP_G88 || motion == NCP_G89)
        s->cycle_p = p;
    if (motion == NCP_G83 || motion == NCP_G73)
        s->cycle_q = q;
    s->m.motion = motion;
    return NCP_OK;
}
