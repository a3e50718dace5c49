/* Coordinate offsets and units: G20/G21, G54..G59.3, G10 L2/L20, G92 family,
 * G52, G43/G43.1/G43.2/G49, G28/G30 and their .1 forms, and the numbered parameters
 * that mirror them. Parameters hold rs274's user unit (inch); the state holds
 * program units. */
#include "floor.h"
#include "offsets.h"
#include "stages.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static int ncp_is_linear(int ax)
{
    return ax < NCP_A || ax > NCP_C;
}

static double ncp_to_user(const struct ncp_analyzer *a, int ax, double v)
{
    return ncp_is_linear(ax) ? ncp_to_user_len(a, v) : v;
}

static double *ncp_par(struct ncp_analyzer *a, int index)
{
    return ncp_params_slot(a->params, index);
}

/* #5420.. current position: kept after each block (#5400 follows the
 * spindle's tool table entry, see ncp_tools_sync_params). #5220 is written
 * only where the system changes, as rs274 writes it, so a program's own
 * `#5220 = 3` reads back until the next G54..G59.3 or program end. */
double *ncp_offsets_param_pos(struct ncp_analyzer *a)
{
    /* numbered parameters are one array: #5420..#5428 are one copy */
    _Static_assert(5420 + NCP_NAX <= NCP_PARAMS_MAX, "#5420.. are numbered parameters");
    a->par_pos = ncp_par(a, 5420);
    return a->par_pos;
}

/* rs274 reads back what the canon did before it reads the block after a
 * probe (set_probe_data) or a tool change: the current point becomes the
 * canon's (U, V, W read 0 there), and after a probe #5061-#5069 hold the
 * tripped point and #5070 the probe input, which the stand-in reports as 0. */
static void ncp_offsets_take_position(struct ncp_analyzer *a)
{
    memcpy(a->st.pos, a->sai.pos, sizeof a->sai.pos);
    for (int ax = 6; ax < NCP_NAX; ax++)
        a->st.pos[ax] = 0.0;
}

/* A queue buster on a machine: wait for its answer and take the machine's
 * results in place of the stand-in's (the trip point, the probe input, where
 * the axes stopped, M66's #5399). */
static int ncp_offsets_ask_machine(struct ncp_analyzer *a, int *tripped)
{
    struct ncp_machine_sync ms;
    memset(&ms, 0, sizeof ms);
    if (a->sai.sync(a->sai.sync_ctx, &ms) != 0)
        return ncp_an_error(a, 0, "the run was stopped while the interpreter waited for "
                                  "the machine");
    if (ms.what & NCP_SYNC_PROBE)
        memcpy(a->sai.probed, ms.probed, sizeof a->sai.probed);
    if (ms.what & (NCP_SYNC_PROBE | NCP_SYNC_POSITION))
        for (int k = 0; k < 3; k++)
            a->sai.pos[k] = ms.pos[k];
    if (ms.what & NCP_SYNC_INPUT) {
        double *result = ncp_params_slot(a->params, 5399);
        if (result)
            *result = ms.input;
    }
    *tripped = ms.tripped;
    return NCP_OK;
}

int ncp_offsets_resync(struct ncp_analyzer *a)
{
    if (!(a->st.toolchange_flag | a->sai.probe_flag | a->sai.input_flag))
        return NCP_OK;
    int tripped = 0;
    if ((a->sai.probe_flag | a->sai.input_flag | a->sai.change_flag) && a->sai.sync) {
        int rc = ncp_offsets_ask_machine(a, &tripped);
        if (rc != NCP_OK)
            return rc;
    }
    a->sai.input_flag = 0;
    a->sai.change_flag = 0;
    if (!(a->st.toolchange_flag | a->sai.probe_flag))
        return NCP_OK;   /* M66 alone: rs274 reads no position back */
    if (a->sai.probe_flag) {
        a->sai.probe_flag = 0;
        for (int k = 0; k <= 9; k++) {
            double *par = ncp_params_slot(a->params, 5061 + k);
            if (par)
                *par = k < 6 ? a->sai.probed[k] : k == 9 ? tripped : 0.0;
        }
    }
    ncp_offsets_take_position(a);
    ncp_offsets_sync_params(a); /* before this block's expressions read #5420.. */
    if (a->st.toolchange_flag) {
        a->st.toolchange_flag = 0;
        ncp_tools_sync_params(a, 1);
    }
    return NCP_OK;
}

static void ncp_emit_g92(struct ncp_analyzer *a)
{
    ncp_an_emit6(a, NCP_C_SET_G92_OFFSET, a->st.g92);
}

static void ncp_emit_tlo_values(struct ncp_analyzer *a, const double *v)
{
    struct ncp_canon *op = ncp_an_emit(a, NCP_C_USE_TOOL_LENGTH_OFFSET);
    memcpy(op->tool_length.v, v, NCP_NAX * sizeof(double));
}

int ncp_offsets_units(struct ncp_analyzer *a, int inches)
{
    ncp_an_emit(a, NCP_C_USE_LENGTH_UNITS)->units.mm = inches ? 0 : 1;
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
    }
    s->m.comp_radius *= k;
    ncp_cutcomp_scale(&a->comp, k, inches);
    /* rs274 reloads the tool offset and the feed rate from its canon, which
     * keeps them as last set, unconverted: s->tlo and s->feed already are. */
    s->m.inches = inches;
    return NCP_OK;
}

static void ncp_load_origin(struct ncp_analyzer *a, int origin, double *out)
{
    for (int ax = 0; ax < NCP_NAX; ax++)
        out[ax] = ncp_frame_user(a, ax, 5201 + 20 * origin + ax);
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
    double here[NCP_NAX];
    ncp_frame_current_in(a, origin, 0, here);
    memcpy(s->pos, here, sizeof here);
    ncp_load_origin(a, origin, s->g5x);
    s->rotation = ncp_frame_param(a, 5210 + 20 * origin);
    s->m.origin = origin;
    *ncp_par(a, 5220) = origin;
    struct ncp_canon *op = ncp_an_emit(a, NCP_C_SET_G5X_OFFSET);
    op->offset.index = origin;
    memcpy(op->offset.v, s->g5x, sizeof op->offset.v);
    ncp_sai_g5x(a, s->g5x);
    ncp_emit_g92(a);
    ncp_an_emit(a, NCP_C_SET_XY_ROTATION)->rotation.degrees = s->rotation;
    return NCP_OK;
}

/* The tool table entry of tool h for G43 H / G43.2 H. */
static int ncp_tlo_tool_index(struct ncp_analyzer *a, int h, int *idx)
{
    *idx = ncp_tools_find(a, h);
    if (*idx < 0) {
        const struct ncp_words *w = &a->w;
        uint16_t col = NCP_HAS(w, 'H') ? w->col[NCP_LETTER('H')] : w->gcol[NCP_GG_TLO];
        return ncp_an_error(a, col, "Requested tool %d not found in the tool table", h);
    }
    return NCP_OK;
}

/* G43.2: the current offset plus tool H's, into nw. LinuxCNC 2.9's rs274
 * (the reference here) checks for H and axis words as later versions do but
 * has no axis-word form: without H it looks up tool -1 and fails. */
static int ncp_offsets_tlo_add(struct ncp_analyzer *a, double *nw)
{
    const struct ncp_words *w = &a->w;
    int has_h = NCP_HAS(w, 'H'), axes = (w->has & NCP_AXIS_LETTERS) != 0;
    if (has_h && axes)
        return ncp_an_error(a, w->gcol[NCP_GG_TLO], "G43.2: Can not have both H and axis words");
    if (!has_h && !axes)
        return ncp_an_error(a, w->gcol[NCP_GG_TLO], "G43.2: No axes specified and H word missing");
    int idx;
    int rc = ncp_tlo_tool_index(a, has_h ? ncp_trunc_int_round(w->v[NCP_LETTER('H')]) : -1, &idx);
    if (rc != NCP_OK)
        return rc;
    memcpy(nw, a->st.tlo, NCP_NAX * sizeof *nw);
    for (int ax = 0; ax < NCP_NAX; ax++) {
        double u = ncp_tool_offset(a, idx, ax);
        nw[ax] += ncp_is_linear(ax) ? ncp_tool_len(a, u) : u;
    }
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
    if (g == NCP_G43) {
        int idx = -1;
        if (NCP_HAS(w, 'H')) {
            int rc = ncp_tlo_tool_index(a, ncp_trunc_int_round(w->v[NCP_LETTER('H')]), &idx);
            if (rc != NCP_OK)
                return rc;
        } else if (s->toolchange_flag) {
            idx = s->current_pocket; /* M6/M61 earlier in this block */
        } else {
            idx = 0; /* the spindle's entry */
        }
        for (int ax = 0; ax < NCP_NAX; ax++) {
            double u = ncp_tool_offset(a, idx, ax);
            nw[ax] = ncp_is_linear(ax) ? ncp_tool_len(a, u) : u;
        }
    } else if (g == NCP_G43_1) {
        memcpy(nw, s->tlo, sizeof nw);
        for (int ax = 0; ax < NCP_NAX; ax++)
            ncp_axis_word(w, ax, &nw[ax]);
    } else if (g == NCP_G43_2) {
        int rc = ncp_offsets_tlo_add(a, nw);
        if (rc != NCP_OK)
            return rc;
    }
    ncp_emit_tlo_values(a, nw);
    /* the X/Y change of the offset is a machine-frame vector */
    double dx = s->tlo[NCP_X] - nw[NCP_X], dy = s->tlo[NCP_Y] - nw[NCP_Y];
    ncp_rotate(&dx, &dy, -s->rotation);
    s->pos[NCP_X] += dx;
    s->pos[NCP_Y] += dy;
    for (int ax = NCP_Z; ax < NCP_NAX; ax++)
        s->pos[ax] += s->tlo[ax] - nw[ax];
    memcpy(s->tlo, nw, sizeof nw);
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


/* G92 sets the point to read as the words; G52 sets the offset itself. */
static void ncp_g92_words(struct ncp_analyzer *a, int g52)
{
    struct ncp_state *s = &a->st;
    for (int ax = 0; ax < NCP_NAX; ax++) {
        double v;
        if (!ncp_axis_word(&a->w, ax, &v))
            continue;
        if (g52) {
            s->pos[ax] += s->g92[ax] - v;
            s->g92[ax] = v;
        } else {
            s->g92[ax] = s->pos[ax] + s->g92[ax] - v;
            s->pos[ax] = v;
        }
    }
}

static int ncp_g92(struct ncp_analyzer *a, int g)
{
    struct ncp_state *s = &a->st;
    if (s->m.comp_side != 0)
        return ncp_an_error(a, a->w.gcol[NCP_GG_NONMODAL],
                            "Cannot change axis offsets with cutter radius comp");
    if (g == NCP_G92 || g == NCP_G52) {
        ncp_g92_words(a, g == NCP_G52);
        ncp_emit_g92(a);
        ncp_store_g92_params(a, 1);
        return NCP_OK;
    }
    double *applied = ncp_par(a, 5210);
    if (g == NCP_G92_1 || g == NCP_G92_2) {
        for (int ax = 0; ax < NCP_NAX; ax++) {
            s->pos[ax] = s->pos[ax] + s->g92[ax];
            s->g92[ax] = 0.0;
        }
        if (g == NCP_G92_1)
            ncp_store_g92_params(a, 0);
    } else {
        for (int ax = 0; ax < NCP_NAX; ax++) {
            double v = ncp_frame_user(a, ax, 5211 + ax);
            s->pos[ax] = s->pos[ax] + s->g92[ax] - v;
            s->g92[ax] = v;
        }
    }
    if (applied)
        *applied = g == 923;
    ncp_emit_g92(a);
    return NCP_OK;
}

/* G28/G30: optional intermediate point, then the stored home, as traverses. */
static int ncp_home(struct ncp_analyzer *a, int g)
{
    struct ncp_state *s = &a->st;
    const struct ncp_words *w = &a->w;
    double mid[NCP_NAX], home[NCP_NAX], end[NCP_NAX];
    int rc = ncp_motion_ends(a, 0, mid);
    if (rc != NCP_OK)
        return rc;
    if (s->m.comp_side != 0)
        return ncp_an_error(a, w->gcol[NCP_GG_NONMODAL],
                            "Cannot use G28 or G30 with cutter radius compensation");
    int base = g == NCP_G28 ? 5161 : 5181;
    for (int ax = 0; ax < NCP_NAX; ax++)
        home[ax] = ncp_frame_user(a, ax, base + ax);
    ncp_frame_relative(a, home, end);
    if (w->has & NCP_AXIS_LETTERS) {
        for (int ax = 0; ax < NCP_NAX; ax++) {
            double v;
            if (!ncp_axis_word(w, ax, &v))
                end[ax] = mid[ax];
        }
    }
    ncp_an_emit6(a, NCP_C_STRAIGHT_TRAVERSE, mid);
    ncp_an_emit6(a, NCP_C_STRAIGHT_TRAVERSE, end);
    memcpy(s->pos, end, sizeof end);
    return NCP_OK;
}

/* G28.1/G30.1: the current point in machine coordinates. */
static int ncp_home_store(struct ncp_analyzer *a, int g)
{
    const struct ncp_state *s = &a->st;
    if (s->m.comp_side != 0)
        return ncp_an_error(a, a->w.gcol[NCP_GG_NONMODAL],
                            "Cannot set reference point with cutter compensation in effect");
    int base = g == NCP_G28_1 ? 5161 : 5181;
    double m[NCP_NAX];
    m[NCP_X] = s->pos[NCP_X] + s->g92[NCP_X];
    m[NCP_Y] = s->pos[NCP_Y] + s->g92[NCP_Y];
    ncp_rotate(&m[NCP_X], &m[NCP_Y], s->rotation);
    m[NCP_X] = m[NCP_X] + s->tlo[NCP_X] + s->g5x[NCP_X];
    m[NCP_Y] = m[NCP_Y] + s->tlo[NCP_Y] + s->g5x[NCP_Y];
    for (int ax = NCP_Z; ax < NCP_NAX; ax++)
        m[ax] = s->pos[ax] + s->tlo[ax] + s->g5x[ax] + s->g92[ax];
    for (int ax = 0; ax < NCP_NAX; ax++) {
        double *p = ncp_par(a, base + ax);
        if (p)
            *p = ncp_to_user(a, ax, m[ax]);
    }
    return NCP_OK;
}

int ncp_offsets_modal0(struct ncp_analyzer *a, int g)
{
    switch (g) {
    case NCP_G10: return ncp_g10_run(a);
    case NCP_G28: case NCP_G30: return ncp_home(a, g);
    case NCP_G28_1: case NCP_G30_1: return ncp_home_store(a, g);
    default: return ncp_g92(a, g);
    }
}
