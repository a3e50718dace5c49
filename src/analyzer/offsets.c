/* Coordinate offsets and units: G20/G21, G54..G59.3, G10 L2/L20, G92 family,
 * G52, G43/G43.1/G49, G28/G30 and their .1 forms, and the numbered parameters
 * that mirror them. Parameters hold rs274's user unit (inch); the state holds
 * program units. */
#include "state.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static const char ncp_axis_letters[NCP_NAX] = {'X', 'Y', 'Z', 'A', 'B', 'C', 'U', 'V', 'W'};

static int ncp_is_linear(int ax)
{
    return ax < NCP_A || ax > NCP_C;
}

double ncp_user_len(const struct ncp_analyzer *a, double user)
{
    return a->st.m.inches ? user : user * NCP_MM_PER_INCH;
}

/* Tool table lengths go through mm inside rs274, and the round trip's
 * rounding shows in inch programs (0.125 in -> 0.12499999999999999 in). */
double ncp_tool_len(const struct ncp_analyzer *a, double user)
{
    double mm = user * NCP_MM_PER_INCH;
    return a->st.m.inches ? mm * (1.0 / NCP_MM_PER_INCH) : mm;
}

double ncp_to_user_len(const struct ncp_analyzer *a, double prog)
{
    return a->st.m.inches ? prog : prog / NCP_MM_PER_INCH;
}

static double ncp_from_user(const struct ncp_analyzer *a, int ax, double v)
{
    return ncp_is_linear(ax) ? ncp_user_len(a, v) : v;
}

static double ncp_to_user(const struct ncp_analyzer *a, int ax, double v)
{
    return ncp_is_linear(ax) ? ncp_to_user_len(a, v) : v;
}

static double *ncp_par(struct ncp_analyzer *a, int index)
{
    return ncp_params_slot(a->params, index);
}

/* #5420.. current position, #5400 tool, #5220 system: kept after each block. */
void ncp_offsets_sync_params(struct ncp_analyzer *a)
{
    if (!a->par_pos[0]) {
        for (int ax = 0; ax < NCP_NAX; ax++)
            a->par_pos[ax] = ncp_par(a, 5420 + ax);
        a->par_tool = ncp_par(a, 5400);
        a->par_origin = ncp_par(a, 5220);
        if (!a->par_pos[0] || !a->par_tool || !a->par_origin)
            return;
    }
    for (int ax = 0; ax < NCP_NAX; ax++)
        if (a->par_pos[ax])
            *a->par_pos[ax] = a->st.pos[ax];
    *a->par_tool = a->st.current_tool;
    *a->par_origin = a->st.m.origin;
}

static void ncp_emit_g5x(struct ncp_analyzer *a)
{
    struct ncp_canon *op = ncp_an_emit(a, NCP_C_SET_G5X_OFFSET);
    op->i[0] = a->st.m.origin;
    memcpy(op->d, a->st.g5x, 6 * sizeof(double));
    ncp_sai_g5x(a, a->st.g5x);
    ncp_an_emit(a, NCP_C_SET_XY_ROTATION)->d[0] = a->st.rotation;
}

static void ncp_emit_g92(struct ncp_analyzer *a)
{
    ncp_an_emit6(a, NCP_C_SET_G92_OFFSET, a->st.g92);
}

static void ncp_emit_tlo(struct ncp_analyzer *a)
{
    struct ncp_canon *op = ncp_an_emit(a, NCP_C_USE_TOOL_LENGTH_OFFSET);
    memcpy(op->d, a->st.tlo, NCP_NAX * sizeof(double));
}

int ncp_offsets_units(struct ncp_analyzer *a, int inches)
{
    ncp_an_emit(a, NCP_C_USE_LENGTH_UNITS)->i[0] = inches ? 0 : 1;
    ncp_sai_units(a, inches);
    if (inches == a->st.m.inches)
        return NCP_OK;
    double k = inches ? 1.0 / NCP_MM_PER_INCH : NCP_MM_PER_INCH;
    struct ncp_state *s = &a->st;
    for (int ax = 0; ax < NCP_NAX; ax++) {
        if (!ncp_is_linear(ax))
            continue;
        s->pos[ax] *= k;
        s->g5x[ax] *= k;
        s->g92[ax] *= k;
        s->tlo[ax] *= k;
    }
    s->m.comp_radius *= k;
    ncp_cutcomp_scale(&a->comp, k, inches);
    s->feed *= k;
    s->m.inches = inches;
    return NCP_OK;
}

static void ncp_load_origin(struct ncp_analyzer *a, int origin, double *out)
{
    for (int ax = 0; ax < NCP_NAX; ax++) {
        double *p = ncp_par(a, 5201 + 20 * origin + ax);
        out[ax] = ncp_from_user(a, ax, p ? *p : 0.0);
    }
}

int ncp_offsets_coord(struct ncp_analyzer *a, int origin)
{
    struct ncp_state *s = &a->st;
    if (s->m.comp_side != 0)
        return ncp_an_error(a, a->w.gcol[NCP_GG_COORD],
                            "Cannot change coordinate systems with cutter radius compensation on");
    if (origin == s->m.origin) {
        ncp_an_emit_text(a, NCP_C_COMMENT, "interpreter: continuing to use same coordinate system",
                         sizeof "interpreter: continuing to use same coordinate system" - 1);
        return NCP_OK;
    }
    double nw[NCP_NAX];
    ncp_load_origin(a, origin, nw);
    for (int ax = 0; ax < NCP_NAX; ax++) {
        s->pos[ax] += s->g5x[ax] - nw[ax];
        s->g5x[ax] = nw[ax];
    }
    double *r = ncp_par(a, 5210 + 20 * origin);
    s->rotation = r ? *r : 0.0;
    s->m.origin = origin;
    struct ncp_canon *op = ncp_an_emit(a, NCP_C_SET_G5X_OFFSET);
    op->i[0] = origin;
    memcpy(op->d, s->g5x, 6 * sizeof(double));
    ncp_sai_g5x(a, s->g5x);
    ncp_emit_g92(a);
    ncp_an_emit(a, NCP_C_SET_XY_ROTATION)->d[0] = s->rotation;
    return NCP_OK;
}

int ncp_offsets_tlo(struct ncp_analyzer *a, int g)
{
    struct ncp_state *s = &a->st;
    const struct ncp_words *w = &a->w;
    if (s->m.comp_side != 0)
        return ncp_an_error(a, w->gcol[NCP_GG_TLO],
                            "Cannot change tool offset with cutter radius compensation on");
    double nw[NCP_NAX] = {0};
    if (g == 430) {
        int idx = -1;
        if (NCP_HAS(w, 'H')) {
            int h = ncp_trunc_int_round(w->v[NCP_LETTER('H')]);
            idx = ncp_tools_find(a, h);
            if (idx < 0)
                return ncp_an_error(a, w->col[NCP_LETTER('H')],
                                    "Requested tool %d not found in the tool table", h);
        } else if (s->toolchange_flag) {
            idx = s->current_pocket; /* M6/M61 earlier in this block */
        } else {
            idx = 0; /* the spindle's entry */
        }
        {
            nw[NCP_X] = ncp_tool_len(a, a->tools[idx].x_offset);
            nw[NCP_Z] = ncp_tool_len(a, a->tools[idx].z_offset);
        }
    } else if (g == 431) {
        memcpy(nw, s->tlo, sizeof nw);
        for (int ax = 0; ax < NCP_NAX; ax++) {
            int l = NCP_LETTER(ncp_axis_letters[ax]);
            if ((w->has >> l) & 1u)
                nw[ax] = w->v[l];
        }
    } else if (g == 432) {
        return ncp_an_error(a, w->gcol[NCP_GG_TLO], "G43.2 is not supported");
    }
    for (int ax = 0; ax < NCP_NAX; ax++) {
        s->pos[ax] += s->tlo[ax] - nw[ax];
        s->tlo[ax] = nw[ax];
    }
    ncp_emit_tlo(a);
    return NCP_OK;
}

static void ncp_store_g92_params(struct ncp_analyzer *a, int applied)
{
    for (int ax = 0; ax < NCP_NAX; ax++) {
        double *p = ncp_par(a, 5211 + ax);
        if (p)
            *p = ncp_to_user(a, ax, a->st.g92[ax]);
    }
    double *p = ncp_par(a, 5210);
    if (p)
        *p = applied;
}

static int ncp_word_axis(const struct ncp_words *w, int ax, double *v)
{
    int l = NCP_LETTER(ncp_axis_letters[ax]);
    if (!((w->has >> l) & 1u))
        return 0;
    *v = w->v[l];
    return 1;
}

static void ncp_set_g92(struct ncp_analyzer *a, const double *nw)
{
    for (int ax = 0; ax < NCP_NAX; ax++) {
        a->st.pos[ax] += a->st.g92[ax] - nw[ax];
        a->st.g92[ax] = nw[ax];
    }
}

static int ncp_g92(struct ncp_analyzer *a, int g)
{
    struct ncp_state *s = &a->st;
    double nw[NCP_NAX];
    memcpy(nw, s->g92, sizeof nw);
    if (s->m.comp_side != 0)
        return ncp_an_error(a, a->w.gcol[NCP_GG_NONMODAL],
                            "Cannot change axis offsets with cutter radius comp");
    if (g == 920) {
        for (int ax = 0; ax < NCP_NAX; ax++) {
            double v;
            if (ncp_word_axis(&a->w, ax, &v))
                nw[ax] = s->pos[ax] + s->g92[ax] - v;
        }
        ncp_set_g92(a, nw);
        ncp_store_g92_params(a, 1);
    } else if (g == 520) {
        for (int ax = 0; ax < NCP_NAX; ax++) {
            double v;
            if (ncp_word_axis(&a->w, ax, &v))
                nw[ax] = v;
        }
        ncp_set_g92(a, nw);
        ncp_store_g92_params(a, 1);
    } else if (g == 921 || g == 922) {
        memset(nw, 0, sizeof nw);
        ncp_set_g92(a, nw);
        if (g == 921)
            ncp_store_g92_params(a, 0);
        else if (ncp_par(a, 5210))
            *ncp_par(a, 5210) = 0;
    } else {
        for (int ax = 0; ax < NCP_NAX; ax++) {
            double *p = ncp_par(a, 5211 + ax);
            nw[ax] = ncp_from_user(a, ax, p ? *p : 0.0);
        }
        ncp_set_g92(a, nw);
        if (ncp_par(a, 5210))
            *ncp_par(a, 5210) = 1;
    }
    ncp_emit_g92(a);
    return NCP_OK;
}

/* G10 L2 / L20: write a coordinate system; refresh it when it is the active one. */
static int ncp_g10_origin(struct ncp_analyzer *a, int l, int p)
{
    struct ncp_state *s = &a->st;
    if (p == 0)
        p = s->m.origin;
    if (p != s->m.origin)
        ncp_an_emit_text(a, NCP_C_COMMENT, "interpreter: setting coordinate system origin",
                         sizeof "interpreter: setting coordinate system origin" - 1);
    double nw[NCP_NAX];
    ncp_load_origin(a, p, nw);
    for (int ax = 0; ax < NCP_NAX; ax++) {
        double v;
        if (!ncp_word_axis(&a->w, ax, &v))
            continue;
        nw[ax] = l == 2 ? v : s->pos[ax] + s->g5x[ax] - v;
        if (l == 20 && p != s->m.origin)
            nw[ax] = s->pos[ax] + s->g5x[ax] + s->g92[ax] - s->g92[ax] - v;
        double *par = ncp_par(a, 5201 + 20 * p + ax);
        if (par)
            *par = ncp_to_user(a, ax, nw[ax]);
    }
    if (NCP_HAS(&a->w, 'R')) {
        double *par = ncp_par(a, 5210 + 20 * p);
        if (par)
            *par = a->w.v[NCP_LETTER('R')];
    }
    if (p == s->m.origin) {
        for (int ax = 0; ax < NCP_NAX; ax++) {
            s->pos[ax] += s->g5x[ax] - nw[ax];
            s->g5x[ax] = nw[ax];
        }
        double *r = ncp_par(a, 5210 + 20 * p);
        s->rotation = r ? *r : 0.0;
        ncp_emit_g5x(a);
    }
    return NCP_OK;
}

/* rs274 prints this call's offsets in its user unit (inch). */
static void ncp_emit_tool_entry(struct ncp_analyzer *a, int shown, int idx)
{
    const struct ncp_tool_entry *t = &a->tools[idx];
    char buf[256];
    int n = snprintf(buf, sizeof buf,
                     "SET_TOOL_TABLE_ENTRY(%d, %d, %.4f %.4f %.4f %.4f %.4f %.4f %.4f %.4f %.4f, "
                     "%.4f, %.4f, %d)",
                     shown, a->tool_no[idx], t->x_offset, 0.0, t->z_offset, 0.0, 0.0, 0.0, 0.0,
                     0.0, 0.0, t->frontangle, t->backangle, t->orientation);
    if (n > 0)
        ncp_an_emit_text(a, NCP_C_RAW_TEXT, buf, (size_t)n < sizeof buf ? (size_t)n : sizeof buf - 1);
}

static int ncp_g10_tool(struct ncp_analyzer *a, int l, int p)
{
    const struct ncp_words *w = &a->w;
    int idx = ncp_tools_find(a, p);
    if (idx < 0)
        return ncp_an_error(a, w->gcol[NCP_GG_NONMODAL],
                            "Requested tool %d not found in the tool table", p);
    struct ncp_tool_entry *t = &a->tools[idx];
    double v;
    if (l == 1) {
        if (ncp_word_axis(w, NCP_Z, &v))
            t->z_offset = ncp_to_user_len(a, v);
        if (ncp_word_axis(w, NCP_X, &v))
            t->x_offset = ncp_to_user_len(a, v);
    } else {
        double mz = a->st.pos[NCP_Z] + a->st.g5x[NCP_Z] + a->st.g92[NCP_Z] + a->st.tlo[NCP_Z];
        double mx = a->st.pos[NCP_X] + a->st.g5x[NCP_X] + a->st.g92[NCP_X] + a->st.tlo[NCP_X];
        if (ncp_word_axis(w, NCP_Z, &v))
            t->z_offset = ncp_to_user_len(a, mz - v - a->st.g5x[NCP_Z] - a->st.g92[NCP_Z]);
        if (ncp_word_axis(w, NCP_X, &v))
            t->x_offset = ncp_to_user_len(a, mx - v - a->st.g5x[NCP_X] - a->st.g92[NCP_X]);
    }
    if (NCP_HAS(w, 'R'))
        t->diameter = 2.0 * ncp_to_user_len(a, w->v[NCP_LETTER('R')]);
    if (NCP_HAS(w, 'I'))
        t->frontangle = w->v[NCP_LETTER('I')];
    if (NCP_HAS(w, 'J'))
        t->backangle = w->v[NCP_LETTER('J')];
    if (NCP_HAS(w, 'Q'))
        t->orientation = ncp_trunc_int_round(w->v[NCP_LETTER('Q')]);
    ncp_emit_tool_entry(a, idx, idx);
    if (idx == a->st.current_pocket) {
        a->tools[0] = *t;
        a->tool_no[0] = a->tool_no[idx];
        ncp_emit_tool_entry(a, 0, idx);
    }
    return NCP_OK;
}

static int ncp_g10(struct ncp_analyzer *a)
{
    const struct ncp_words *w = &a->w;
    int l = ncp_trunc_int_round(w->v[NCP_LETTER('L')]);
    int p = (int)w->v[NCP_LETTER('P')]; /* rs274 truncates */
    if (l == 2 || l == 20)
        return ncp_g10_origin(a, l, p);
    if (l == 1 || l == 10)
        return ncp_g10_tool(a, l, p);
    return ncp_an_error(a, w->gcol[NCP_GG_NONMODAL], "G10 L%d is not supported", l);
}

/* G28/G30: optional intermediate point, then the stored home, as traverses. */
static int ncp_home(struct ncp_analyzer *a, int g)
{
    struct ncp_state *s = &a->st;
    const struct ncp_words *w = &a->w;
    if (s->m.comp_side != 0)
        return ncp_an_error(a, w->gcol[NCP_GG_NONMODAL],
                            "Cannot use G28 or G30 with cutter radius compensation");
    int base = g == 280 ? 5161 : 5181;
    double mid[NCP_NAX], end[NCP_NAX];
    int rc = ncp_motion_ends(a, 0, mid);
    if (rc != NCP_OK)
        return rc;
    int any = (w->has & NCP_AXIS_LETTERS) != 0;
    for (int ax = 0; ax < NCP_NAX; ax++) {
        double *p = ncp_par(a, base + ax);
        double home = ncp_from_user(a, ax, p ? *p : 0.0);
        double v;
        end[ax] = home - s->g5x[ax] - s->g92[ax] - s->tlo[ax];
        if (any && !ncp_word_axis(w, ax, &v))
            end[ax] = mid[ax];
    }
    ncp_an_emit6(a, NCP_C_STRAIGHT_TRAVERSE, mid);
    ncp_an_emit6(a, NCP_C_STRAIGHT_TRAVERSE, end);
    memcpy(s->pos, end, sizeof end);
    return NCP_OK;
}

static int ncp_home_store(struct ncp_analyzer *a, int g)
{
    int base = g == 281 ? 5161 : 5181;
    for (int ax = 0; ax < NCP_NAX; ax++) {
        double *p = ncp_par(a, base + ax);
        double m = a->st.pos[ax] + a->st.g5x[ax] + a->st.g92[ax] + a->st.tlo[ax];
        if (p)
            *p = ncp_to_user(a, ax, m);
    }
    return NCP_OK;
}

int ncp_offsets_modal0(struct ncp_analyzer *a, int g)
{
    switch (g) {
    case 100: return ncp_g10(a);
    case 280: case 300: return ncp_home(a, g);
    case 281: case 301: return ncp_home_store(a, g);
    default: return ncp_g92(a, g);
    }
}
