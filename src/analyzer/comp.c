/* The analyzer side of cutter radius compensation: G40/G41/G42/G41.1/G42.1,
 * moves while it is engaged, and the flush at stop codes. The queue and the
 * geometry live in cutcomp.c; here we translate state and words into its
 * requests and keep the programmed/compensated points straight. */
#include "floor.h"
#include "stages.h"

#include <math.h>
#include <string.h>

/* Plane order of the comp module: XY -> (x, y, z), XZ -> (z, x, y). */
static void ncp_comp_plane(int plane, const double *xyz, double *p)
{
    if (plane == 2) {
        p[0] = xyz[NCP_Z];
        p[1] = xyz[NCP_X];
        p[2] = xyz[NCP_Y];
    } else {
        p[0] = xyz[NCP_X];
        p[1] = xyz[NCP_Y];
        p[2] = xyz[NCP_Z];
    }
}

/* Tool diameter for G41/G42 D (or the spindle's tool), in program units. */
static int ncp_comp_tool(void *ctx, int toolno, double *dia, int *orient)
{
    const struct ncp_analyzer *a = ctx;
    int idx = toolno < 0 ? 0 : ncp_tools_find(a, toolno);
    if (idx < 0)
        return -1;
    *dia = ncp_tool_len(a, a->tools[idx].diameter);
    *orient = a->tools[idx].orientation;
    return 0;
}

int ncp_comp_gcode(struct ncp_analyzer *a, int g)
{
    const struct ncp_words *w = &a->w;
    struct ncp_comp_sink sink = ncp_an_comp_sink(a);
    int rc = ncp_an_commit(a);
    if (rc != NCP_OK)
        return rc;
    if (g == NCP_G40) {
        rc = ncp_cutcomp_off(&a->comp, &sink, &a->err, a->line);
        a->st.m.comp_side = 0;
        return rc;
    }
    struct ncp_comp_on_req req = {
        .gcode = g, .plane = a->st.m.plane, .inches = a->st.m.inches,
        .has_d = NCP_HAS(w, 'D'), .d = w->v[NCP_LETTER('D')],
        .has_l = NCP_HAS(w, 'L'), .l = (int)w->v[NCP_LETTER('L')],
        .line = a->line, .tool = ncp_comp_tool, .tool_ctx = a,
    };
    rc = ncp_cutcomp_on(&a->comp, &req, &sink, &a->err);
    if (rc == NCP_OK)
        a->st.m.comp_side = a->comp.side;
    return rc;
}

int ncp_comp_move_straight(struct ncp_analyzer *a, int motion, const double *end, int g53)
{
    struct ncp_comp_sink sink = ncp_an_comp_sink(a);
    int rc = ncp_an_commit(a);
    if (rc != NCP_OK)
        return rc;
    struct ncp_comp_move m = {
        .motion = motion == NCP_G33 || motion == NCP_G33_1 || motion == NCP_G76 ? NCP_COMP_SYNCED
                                                                                : motion / 10,
        .inches = a->st.m.inches,
        .g53 = g53,
        .line = a->line,
        .turns = 1};
    ncp_comp_plane(a->comp.plane, a->st.pos, m.start);
    ncp_comp_plane(a->comp.plane, end, m.end);
    m.abc[0] = end[NCP_A];
    m.abc[1] = end[NCP_B];
    m.abc[2] = end[NCP_C];
    return ncp_cutcomp_move(&a->comp, &m, &sink, &a->err);
}

int ncp_comp_move_arc(struct ncp_analyzer *a, const struct ncp_canon *req, const double *end)
{
    struct ncp_comp_sink sink = ncp_an_comp_sink(a);
    int rc = ncp_an_commit(a);
    if (rc != NCP_OK)
        return rc;
    struct ncp_comp_move m = {.motion = req->arc.dir > 0 ? 3 : 2, .inches = a->st.m.inches,
                              .line = a->line, .turns = req->arc.turns};
    ncp_comp_plane(a->comp.plane, a->st.pos, m.start);
    ncp_comp_plane(a->comp.plane, end, m.end);
    m.abc[0] = end[NCP_A];
    m.abc[1] = end[NCP_B];
    m.abc[2] = end[NCP_C];
    m.radius_form = req->arc.radius_form;
    m.r = req->arc.radius;
    m.centre[0] = req->arc.first_centre;
    m.centre[1] = req->arc.second_centre;
    return ncp_cutcomp_move(&a->comp, &m, &sink, &a->err);
}

/* M0 M1 M2 M30 M60: the pending move goes out first; M2/M30 end comp. */
int ncp_comp_stop(struct ncp_analyzer *a, int reset)
{
    struct ncp_comp_sink sink = ncp_an_comp_sink(a);
    int rc = ncp_an_commit(a);
    if (rc == NCP_OK)
        rc = ncp_cutcomp_flush(&a->comp, &sink, &a->err, a->line);
    if (reset) {
        ncp_cutcomp_reset(&a->comp);
        a->st.m.comp_side = 0;
    }
    return rc;
}

/* The current point as rs274 reports it (#<_x>, #5420..): while compensation
 * moves the tool, the compensated point of the plane, where the tool is,
 * not the programmed one; before the first move after G41/G42 nothing is
 * compensated yet. */
void ncp_comp_reported_pos(const struct ncp_analyzer *a, double *pos)
{
    const struct ncp_cutcomp *c = &a->comp;
    memcpy(pos, a->st.pos, sizeof a->st.pos);
    if (!ncp_cutcomp_engaged(c) || c->firstmove)
        return;
    if (c->plane == 2) {
        pos[NCP_Z] = c->cur[0];
        pos[NCP_X] = c->cur[1];
    } else {
        pos[NCP_X] = c->cur[0];
        pos[NCP_Y] = c->cur[1];
    }
}
