/* Start-up state and the stop codes M0 M1 M60 M2 M30 (the end-of-program
 * reset rs274 performs: back to G54, XY plane, G90, G94, F0, spindle off,
 * coolant off, feed override on). */
#include "floor.h"
#include "offsets.h"
#include "stages.h"

#include <string.h>

void ncp_state_init(struct ncp_analyzer *a)
{
    struct ncp_state *s = &a->st;
    memset(s, 0, sizeof *s);
    s->m.motion = NCP_G80;
    s->m.origin = 1;
    s->m.control = 2;
    s->m.retract_r = 1;
    s->m.arc_incremental = 1;
    s->m.feed_override = 1;
    s->m.speed_override = 1;
    s->m.feed_hold = 1;
    s->selected_pocket = 0; /* rs274: tool 0 (the spindle's entry) selected */
    s->selected_pocket_no = -1;
    s->selected_tool = 0;
    s->current_pocket = 1; /* rs274 -g starts with pocket 1 as the current one */
    /* and #<_current_pocket> reads that entry's P (1 with no table) */
    s->current_pocket_no = a->n_tools > 1 ? a->tools[1].pocket : 1;
    s->current_tool = 0;
    double *p = ncp_params_slot(a->params, 5599);
    if (p)
        *p = 1.0;
    p = ncp_params_slot(a->params, 5220);
    if (p)
        *p = 1.0;
}

/* Back to G54 (and its rotation); the current point stays put on the machine. */
static void ncp_stop_reset_origin(struct ncp_analyzer *a)
{
    struct ncp_state *s = &a->st;
    ncp_rotate(&s->pos[NCP_X], &s->pos[NCP_Y], s->rotation);
    for (int ax = 0; ax < NCP_NAX; ax++) {
        s->pos[ax] += s->g5x[ax];
        s->g5x[ax] = ncp_frame_user(a, ax, 5221 + ax);
    }
    s->rotation = ncp_frame_param(a, 5230);
    for (int ax = 0; ax < NCP_NAX; ax++)
        s->pos[ax] -= s->g5x[ax];
    ncp_rotate(&s->pos[NCP_X], &s->pos[NCP_Y], -s->rotation);
    s->m.origin = 1;
    double *p = ncp_params_slot(a->params, 5220);
    if (p)
        *p = 1.0;
    struct ncp_canon *op = ncp_an_emit(a, NCP_C_SET_G5X_OFFSET);
    op->offset.index = 1;
    memcpy(op->offset.v, s->g5x, sizeof op->offset.v);
    ncp_sai_g5x(a, s->g5x);
    ncp_an_emit(a, NCP_C_SET_XY_ROTATION)->rotation.degrees = s->rotation;
}

static int ncp_stop_end(struct ncp_analyzer *a, int m)
{
    struct ncp_state *s = &a->st;
    ncp_stop_reset_origin(a);
    if (s->m.plane != 0) {
        ncp_an_emit(a, NCP_C_SELECT_PLANE);
        s->m.plane = 0;
    }
    s->m.incremental = 0;
    s->m.feed_mode = 0;
    ncp_an_emit(a, NCP_C_SET_FEED_MODE);
    s->feed = NCP_HAS(&a->w, 'F') ? a->w.v[NCP_LETTER('F')] : 0.0;
    ncp_an_emit(a, NCP_C_SET_FEED_RATE);
    if (!s->m.feed_override) {
        ncp_an_emit(a, NCP_C_ENABLE_FEED_OVERRIDE);
        s->m.feed_override = 1;
    }
    s->m.comp_side = 0;
    ncp_an_emit(a, NCP_C_STOP_SPINDLE_TURNING);
    s->m.spindle_dir = 0;
    s->m.speed_override = 1;
    ncp_an_emit(a, NCP_C_SET_SPINDLE_MODE);
    s->m.motion = NCP_G1;
    if (s->m.mist) {
        ncp_an_emit(a, NCP_C_MIST_OFF);
        s->m.mist = 0;
    }
    if (s->m.flood) {
        ncp_an_emit(a, NCP_C_FLOOD_OFF);
        s->m.flood = 0;
    }
    if (m == NCP_M30)
        ncp_an_emit(a, NCP_C_PALLET_SHUTTLE);
    ncp_an_emit(a, NCP_C_PROGRAM_END);
    if (a->src && a->src->has_percent && a->src->end >= a->src->len)
        ncp_an_emit_text(a, NCP_C_COMMENT, "interpreter: percent sign missing from end of file",
                         sizeof "interpreter: percent sign missing from end of file" - 1);
    ncp_offsets_sync_params(a);
    ncp_flow_reset(a->flow);
    return NCP_END;
}

/* M99 in the main program ends it as M2 does (rs274 -g does not loop back
 * to the start); in a sub, M99 first on its line returns (flow.c), so one
 * that gets here stood after other words, which rs274 calls a bug of its own. */
int ncp_stop_run(struct ncp_analyzer *a, int m)
{
    int rc = ncp_comp_stop(a, m == NCP_M2 || m == NCP_M30 || m == NCP_M99);
    if (rc != NCP_OK)
        return rc;
    if (m == NCP_M99 && ncp_flow_call_depth(a->flow) > 0)
        return ncp_an_error(a, a->w.mcol[NCP_MG_STOP],
                            "Bug:  Reached convert_stop() from M99 as subprogram return");
    switch (m) {
    case NCP_M0:
        ncp_an_emit(a, NCP_C_PROGRAM_STOP);
        return NCP_OK;
    case NCP_M1:
        ncp_an_emit(a, NCP_C_OPTIONAL_PROGRAM_STOP);
        return NCP_OK;
    case NCP_M60:
        ncp_an_emit(a, NCP_C_PALLET_SHUTTLE);
        ncp_an_emit(a, NCP_C_PROGRAM_STOP);
        return NCP_OK;
    default:
        return ncp_stop_end(a, m);
    }
}
