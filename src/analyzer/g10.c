/* G10: L2/L20 write a coordinate system (origin and XY rotation R), L1/L10/L11
 * write a tool table entry, L0 reloads the table. Stored values are in rs274's
 * user unit (inch). L20 and L10/L11 measure from the current point, which goes
 * through the rotation of the systems involved (see frames.c). */
#include "floor.h"
#include "stages.h"

#include <stdio.h>
#include <string.h>


static double ncp_g10_to_user(const struct ncp_analyzer *a, int ax, double prog)
{
    return ax >= NCP_A && ax <= NCP_C ? prog : ncp_to_user_len(a, prog);
}

static void ncp_g10_store(struct ncp_analyzer *a, int index, double v)
{
    double *p = ncp_params_slot(a->params, index);
    if (p)
        *p = v;
}

static void ncp_g10_comment(struct ncp_analyzer *a, const char *text)
{
    ncp_an_emit_text(a, NCP_C_COMMENT, text, strlen(text));
}

/* L20: the origin that makes the current point read as the given X/Y in the
 * (rotated) system; both are taken through the rotation r. */
static void ncp_g10_l20_xy(struct ncp_analyzer *a, int p, double r, const double *cur, double *nw)
{
    const struct ncp_words *w = &a->w;
    double ox = cur[NCP_X], oy = cur[NCP_Y], x = cur[NCP_X], y = cur[NCP_Y], v;
    if (ncp_axis_word(w, NCP_X, &v))
        x = v;
    if (ncp_axis_word(w, NCP_Y, &v))
        y = v;
    ncp_rotate(&ox, &oy, r);
    ncp_rotate(&x, &y, r);
    nw[NCP_X] = ox + ncp_frame_user(a, NCP_X, 5201 + 20 * p) - x;
    nw[NCP_Y] = oy + ncp_frame_user(a, NCP_Y, 5202 + 20 * p) - y;
    ncp_g10_store(a, 5201 + 20 * p, ncp_to_user_len(a, nw[NCP_X]));
    ncp_g10_store(a, 5202 + 20 * p, ncp_to_user_len(a, nw[NCP_Y]));
}

/* The system in use gets its new origin and rotation: the current point stays
 * where it is on the machine. */
static void ncp_g10_refresh(struct ncp_analyzer *a, int p, double r, const double *nw)
{
    struct ncp_state *s = &a->st;
    ncp_rotate(&s->pos[NCP_X], &s->pos[NCP_Y], s->rotation);
    for (int ax = 0; ax < NCP_NAX; ax++) {
        s->pos[ax] += s->g5x[ax];
        s->g5x[ax] = nw[ax];
        s->pos[ax] -= nw[ax];
    }
    struct ncp_canon *op = ncp_an_emit(a, NCP_C_SET_G5X_OFFSET);
    op->offset.index = p;
    memcpy(op->offset.v, s->g5x, sizeof op->offset.v);
    ncp_sai_g5x(a, s->g5x);
    ncp_rotate(&s->pos[NCP_X], &s->pos[NCP_Y], -r);
    s->rotation = r;
    ncp_an_emit(a, NCP_C_SET_XY_ROTATION)->rotation.degrees = r;
}

static int ncp_g10_origin(struct ncp_analyzer *a, int l)
{
    struct ncp_state *s = &a->st;
    const struct ncp_words *w = &a->w;
    uint16_t col = w->gcol[NCP_GG_NONMODAL];
    if (NCP_HAS(w, 'I') || NCP_HAS(w, 'J'))
        return ncp_an_error(a, col, "I J words not allowed with G10 L2");
    int p = ncp_trunc_int(w->v[NCP_LETTER('P')] + 0.0001);
    if (p == 0)
        p = s->m.origin;
    if (s->m.comp_side != 0 && p == s->m.origin)
        return ncp_an_error(a, col, "Cannot change the active coordinate system with cutter radius compensation on");
    double cur[NCP_NAX], nw[NCP_NAX], r, v;
    ncp_frame_current_in(a, p, 0, cur);
    if (NCP_HAS(w, 'R')) {
        if (l == 20)
            return ncp_an_error(a, col, "R not allowed in G10 L20");
        r = w->v[NCP_LETTER('R')];
        ncp_g10_store(a, 5210 + 20 * p, r);
    } else {
        r = ncp_frame_param(a, 5210 + 20 * p);
    }
    int first = NCP_Z;
    if (l == 20) {
        ncp_g10_l20_xy(a, p, r, cur, nw);
        if (p == s->m.origin) {
            /* the refresh below then starts from the unrotated point */
            ncp_rotate(&s->pos[NCP_X], &s->pos[NCP_Y], s->rotation);
            s->rotation = 0.0;
        }
    } else {
        first = NCP_X;
    }
    for (int ax = first; ax < NCP_NAX; ax++) {
        int index = 5201 + 20 * p + ax;
        if (ncp_axis_word(w, ax, &v)) {
            nw[ax] = l == 20 ? cur[ax] + ncp_frame_user(a, ax, index) - v : v;
            ncp_g10_store(a, index, ncp_g10_to_user(a, ax, nw[ax]));
        } else {
            nw[ax] = ncp_frame_user(a, ax, index);
        }
    }
    if (p == s->m.origin)
        ncp_g10_refresh(a, p, r, nw);
    else
        ncp_g10_comment(a, "interpreter: setting coordinate system origin");
    return NCP_OK;
}

/* rs274 prints this call's offsets in its user unit (inch). */
static void ncp_g10_emit_entry(struct ncp_analyzer *a, int shown, int idx)
{
    const struct ncp_tool_entry *t = &a->tools[idx];
    double o[NCP_NAX];
    for (int ax = 0; ax < NCP_NAX; ax++)
        o[ax] = ncp_tool_offset(a, idx, ax);
    char buf[320];
    int n = snprintf(buf, sizeof buf,
                     "SET_TOOL_TABLE_ENTRY(%d, %d, %.4f %.4f %.4f %.4f %.4f %.4f %.4f %.4f %.4f, "
                     "%.4f, %.4f, %d)",
                     shown, a->tool_no[idx], o[0], o[1], o[2], o[3], o[4], o[5], o[6], o[7], o[8],
                     t->frontangle, t->backangle, t->orientation);
    if (n > 0)
        ncp_an_emit_text(a, NCP_C_RAW_TEXT, buf, (size_t)n < sizeof buf ? (size_t)n : sizeof buf - 1);
}

/* Keep the part of the stored X/Y offset that lies along the rotated axis
 * not given (`drop` is the given one), add the measured one along the other. */
static void ncp_g10_tool_one_axis(struct ncp_analyzer *a, int idx, int drop, double r, double *t)
{
    double o[2] = {ncp_user_len(a, ncp_tool_offset(a, idx, NCP_X)),
                   ncp_user_len(a, ncp_tool_offset(a, idx, NCP_Y))};
    ncp_rotate(&o[0], &o[1], -r);
    o[drop] = 0.0;
    ncp_rotate(&o[0], &o[1], r);
    t[1 - drop] = 0.0;
    ncp_rotate(&t[0], &t[1], r);
    ncp_tool_set_offset(a, idx, NCP_X, ncp_to_user_len(a, t[0] + o[0]));
    ncp_tool_set_offset(a, idx, NCP_Y, ncp_to_user_len(a, t[1] + o[1]));
}

/* L10/L11: the offsets that make the current point read as the given values
 * in the active system (L10) or in G59.3 without G92 (L11). */
static void ncp_g10_tool_measured(struct ncp_analyzer *a, int l, int idx)
{
    const struct ncp_words *w = &a->w;
    int dest = l == 11 ? 9 : a->st.m.origin;
    double t[NCP_NAX], v;
    ncp_frame_current_in(a, dest, 1, t);
    if (l == 11 && ncp_frame_param(a, 5210) != 0.0)
        for (int ax = 0; ax < NCP_NAX; ax++)
            t[ax] += ncp_frame_user(a, ax, 5211 + ax);
    double r = ncp_frame_param(a, 5210 + 20 * dest);
    int hx = ncp_axis_word(w, NCP_X, &v), hy = NCP_HAS(w, 'Y');
    if (hx)
        t[NCP_X] -= v;
    if (ncp_axis_word(w, NCP_Y, &v))
        t[NCP_Y] -= v;
    if (hx && hy) {
        ncp_rotate(&t[NCP_X], &t[NCP_Y], r);
        ncp_tool_set_offset(a, idx, NCP_X, ncp_to_user_len(a, t[NCP_X]));
        ncp_tool_set_offset(a, idx, NCP_Y, ncp_to_user_len(a, t[NCP_Y]));
    } else if (hx || hy) {
        ncp_g10_tool_one_axis(a, idx, hx ? 0 : 1, r, t);
    }
    for (int ax = NCP_Z; ax < NCP_NAX; ax++)
        if (ncp_axis_word(w, ax, &v))
            ncp_tool_set_offset(a, idx, ax, ncp_g10_to_user(a, ax, t[ax] - v));
}

static int ncp_g10_tool(struct ncp_analyzer *a, int l)
{
    const struct ncp_words *w = &a->w;
    uint16_t col = w->gcol[NCP_GG_NONMODAL];
    int p = ncp_trunc_int_round(w->v[NCP_LETTER('P')]);
    int idx = ncp_tools_find(a, p);
    if (idx < 0)
        return ncp_an_error(a, col, "Requested tool %d not found in the tool table", p);
    uint32_t used = NCP_AXIS_LETTERS | (1u << NCP_LETTER('R')) | (1u << NCP_LETTER('Q')) |
                    (1u << NCP_LETTER('I')) | (1u << NCP_LETTER('J'));
    if (!(w->has & used))
        return ncp_an_error(a, col, "G10 L1 without offsets has no effect");
    struct ncp_tool_entry *t = &a->tools[idx];
    double v;
    if (l == 1) {
        for (int ax = 0; ax < NCP_NAX; ax++)
            if (ncp_axis_word(w, ax, &v))
                ncp_tool_set_offset(a, idx, ax, ncp_g10_to_user(a, ax, v));
    } else {
        ncp_g10_tool_measured(a, l, idx);
    }
    if (NCP_HAS(w, 'R'))
        t->diameter = ncp_to_user_len(a, w->v[NCP_LETTER('R')]) * 2.0;
    if (NCP_HAS(w, 'I'))
        t->frontangle = w->v[NCP_LETTER('I')];
    if (NCP_HAS(w, 'J'))
        t->backangle = w->v[NCP_LETTER('J')];
    /* rs274 reads Q-1 as "no Q" */
    if (NCP_HAS(w, 'Q') && w->v[NCP_LETTER('Q')] != -1.0) {
        double q = w->v[NCP_LETTER('Q')];
        int qi = ncp_trunc_int_round(q);
        if (q - qi > 0.0001 || qi - q > 0.0001)
            return ncp_an_error(a, col, "Q number in G10 is not an integer");
        if (qi > 9)
            return ncp_an_error(a, col, "Invalid tool orientation");
        t->orientation = qi;
    }
    ncp_g10_emit_entry(a, idx, idx);
    if (idx == a->st.current_pocket) {
        ncp_tools_copy(a, 0, idx);
        ncp_g10_emit_entry(a, 0, idx);
    }
    ncp_tools_sync_params(a, 0);
    return NCP_OK;
}

/* L0: the tool table is reloaded; like a tool change, the next block starts
 * from the canon's position. */
static int ncp_g10_reload(struct ncp_analyzer *a)
{
    if (a->tool_no[0] > 0)
        return ncp_an_error(a, a->w.gcol[NCP_GG_NONMODAL], "G10 L0 not allowed with loaded tool <%d>",
                            a->tool_no[0]);
    a->st.toolchange_flag = 1;
    ncp_an_emit_text(a, NCP_C_RAW_TEXT, "RELOAD_TOOLDATA()", sizeof "RELOAD_TOOLDATA()" - 1);
    return NCP_OK;
}

int ncp_g10_run(struct ncp_analyzer *a)
{
    const struct ncp_words *w = &a->w;
    int l = ncp_trunc_int_round(w->v[NCP_LETTER('L')]);
    if (l == 0)
        return ncp_g10_reload(a);
    if (l == 2 || l == 20)
        return ncp_g10_origin(a, l);
    if (l == 1 || l == 10 || l == 11)
        return ncp_g10_tool(a, l);
    return ncp_an_error(a, w->gcol[NCP_GG_NONMODAL], "G10 L%d is not supported", l);
}
