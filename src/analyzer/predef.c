/* Read-only predefined named parameters (#<_x>, #<_metric>, ...) answered
 * from the analyzer state, installed as the params module's hook. */
#include "stages.h"

#include <stdlib.h>
#include <string.h>
#include <strings.h>

enum ncp_predef {
    P_X, P_Y, P_Z, P_A, P_B, P_C, P_U, P_V, P_W,
    P_LINE, P_MOTION, P_PLANE, P_CCOMP, P_METRIC, P_IMPERIAL, P_ABSOLUTE, P_INCREMENTAL,
    P_INVERSE, P_UPM, P_UPR, P_COORD, P_TOOL_OFFSET, P_RETRACT_R, P_RETRACT_OLD,
    P_IJK_ABS, P_SPINDLE_ON, P_SPINDLE_CW, P_MIST, P_FLOOD, P_SPEED_OVR, P_FEED_OVR,
    P_ADAPTIVE, P_FEED_HOLD, P_FEED, P_RPM, P_CUR_TOOL, P_CUR_POCKET, P_SEL_TOOL,
    P_SEL_POCKET, P_RPM_MODE, P_CSS_MODE, P_LATHE_DIA, P_LATHE_RAD, P_CALL_LEVEL,
    P_VMAJOR, P_VMINOR, P_TASK, P_REMAP_LEVEL, P_METRIC_MACHINE, P_ABS_X, P_ABS_Y, P_ABS_Z, P_ABS_A, P_ABS_B, P_ABS_C, P__N
};

static const char *const ncp_predef_names[P__N] = {
    "_x", "_y", "_z", "_a", "_b", "_c", "_u", "_v", "_w",
    "_line", "_motion_mode", "_plane", "_ccomp", "_metric", "_imperial", "_absolute",
    "_incremental", "_inverse_time", "_units_per_minute", "_units_per_rev",
    "_coord_system", "_tool_offset", "_retract_r_plane", "_retract_old_z",
    "_ijk_absolute_mode", "_spindle_on", "_spindle_cw", "_mist", "_flood",
    "_speed_override", "_feed_override", "_adaptive_feed", "_feed_hold", "_feed", "_rpm",
    "_current_tool", "_current_pocket", "_selected_tool", "_selected_pocket",
    "_spindle_rpm_mode", "_spindle_css_mode", "_lathe_diameter_mode",
    "_lathe_radius_mode", "_call_level", "_vmajor", "_vminor", "_task", "_remap_level",
    "_metric_machine",
    "_abs_x", "_abs_y", "_abs_z", "_abs_a", "_abs_b", "_abs_c",
};

static double ncp_predef_value(const struct ncp_analyzer *a, int k)
{
    const struct ncp_state *s = &a->st;
    const struct ncp_modal *m = &s->m;
    double pos[NCP_NAX];
    if (k <= P_W) {
        ncp_comp_reported_pos(a, pos);
        return pos[k];
    }
    if (k >= P_ABS_X) {
        double mach[NCP_NAX];
        ncp_comp_reported_pos(a, pos);
        ncp_frame_absolute_of(a, pos, mach);
        return mach[k - P_ABS_X];
    }
    switch (k) {
    case P_LINE: return a->line;
    case P_MOTION: return m->motion; /* -1 after G5.3, as rs274 */
    case P_PLANE: return m->plane == 0 ? NCP_G17 : m->plane == 1 ? NCP_G19 : NCP_G18;
    case P_CCOMP: return m->comp_side == 0 ? NCP_G40 : m->comp_side == 1 ? NCP_G41 : NCP_G42;
    case P_METRIC: return !m->inches;
    case P_IMPERIAL: return m->inches;
    case P_ABSOLUTE: return !m->incremental;
    case P_INCREMENTAL: return m->incremental;
    case P_INVERSE: return m->feed_mode == 1;
    case P_UPM: return m->feed_mode == 0;
    case P_UPR: return m->feed_mode == 2;
    case P_COORD: return m->origin <= 6 ? NCP_G53 + 10 * m->origin : NCP_G59 + (m->origin - 6);
    case P_TOOL_OFFSET: return s->tlo[NCP_Z] != 0.0 || s->tlo[NCP_X] != 0.0;
    case P_RETRACT_R: return m->retract_r;
    case P_RETRACT_OLD: return !m->retract_r;
    case P_IJK_ABS: return !m->arc_incremental;
    case P_SPINDLE_ON: return m->spindle_dir != 0;
    case P_SPINDLE_CW: return m->spindle_dir == 1;
    case P_MIST: return m->mist;
    case P_FLOOD: return m->flood;
    case P_SPEED_OVR: return m->speed_override;
    case P_FEED_OVR: return m->feed_override;
    case P_ADAPTIVE: return m->adaptive;
    case P_FEED_HOLD: return m->feed_hold;
    case P_FEED: return s->feed;
    case P_RPM: return s->speed;
    case P_CUR_TOOL: return ncp_frame_param(a, 5400); /* the spindle entry's tool */
    case P_CUR_POCKET: return s->current_pocket_no;
    case P_SEL_TOOL: return s->selected_tool;
    case P_SEL_POCKET: return s->selected_pocket_no;
    case P_RPM_MODE: return !m->css;
    case P_CSS_MODE: return m->css;
    case P_LATHE_DIA: return m->lathe_diameter;
    case P_LATHE_RAD: return !m->lathe_diameter;
    case P_CALL_LEVEL: return a->flow ? ncp_flow_call_depth(a->flow) : 0;
    case P_VMAJOR: return 2.9;
    case P_REMAP_LEVEL: return a->remap_level;
    /* rs274 without a machine behind it: the canon answers no unit */
    case P_METRIC_MACHINE: return -1;
    case P_VMINOR: /* 2.9.0: 0, as for names not listed */
    default: return 0;
    }
}

/* #<_ini[section]key>: the INI's value, the names compared without case as
 * LinuxCNC's INI reader does; a key that is not there, or not a number, is
 * undefined. */
static int ncp_predef_ini(const struct ncp_analyzer *a, const char *name, size_t len,
                          double *out)
{
    const char *close = memchr(name, ']', len);
    if (!close || a->cfg.n_ini_vars <= 0)
        return 0;
    size_t slen = (size_t)(close - (name + 5)), klen = len - (size_t)(close + 1 - name);
    for (int k = 0; k < a->cfg.n_ini_vars; k++) {
        const struct ncp_ini_var *v = &a->cfg.ini_vars[k];
        if (strlen(v->section) != slen || strncasecmp(v->section, name + 5, slen) != 0 ||
            strlen(v->key) != klen || strncasecmp(v->key, close + 1, klen) != 0)
            continue;
        char *end;
        double d = strtod(v->value, &end);
        if (end == v->value)
            return 0;
        *out = d;
        return 1;
    }
    return 0;
}

int ncp_predef_lookup(void *ctx, const char *name, size_t len, double *out)
{
    const struct ncp_analyzer *a = ctx;
    if (len < 2 || name[0] != '_')
        return 0;
    if (len > 5 && strncasecmp(name, "_ini[", 5) == 0)
        return ncp_predef_ini(a, name, len, out);
    for (int k = 0; k < P__N; k++) {
        const char *n = ncp_predef_names[k];
        if (strlen(n) == len && memcmp(n, name, len) == 0) {
            *out = ncp_predef_value(a, k);
            return 1;
        }
    }
    return 0;
}

/* rs274 reads back a probe's or a tool change's results, and runs an M73
 * restore a return left, as it reads the next line, O-word lines too; those
 * never reach ncp_an_block, so any parameter read catches up first (nothing
 * in the probing, changing or returning block itself reads after that). */
static int ncp_predef_catch_up(struct ncp_analyzer *a, struct ncp_diag *d)
{
    int rc = ncp_m7x_pending(a);
    if (rc != NCP_OK)
        return ncp_diag_set(d, (enum ncp_status)rc, 0, 0, "%s", a->err.msg);
    rc = ncp_offsets_resync(a);
    if (rc != NCP_OK)
        return ncp_diag_set(d, (enum ncp_status)rc, 0, 0, "%s", a->err.msg);
    return NCP_OK;
}

/* Numbered reads through the analyzer: rs274 refuses the current position
 * (#5420..#5428) while cutter compensation is on. */
static int ncp_predef_get_numbered(void *ctx, int index, double *out, struct ncp_diag *d)
{
    struct ncp_analyzer *a = ctx;
    int rc = ncp_predef_catch_up(a, d);
    if (rc != NCP_OK)
        return rc;
    if (index >= 5420 && index <= 5428 && a->st.m.comp_side != 0)
        return ncp_diag_set(d, NCP_ERR_SEMANTIC, 0, 0,
                            "Cannot read current position with cutter radius compensation on");
    return ncp_params_get(a->params, index, out, d);
}

static int ncp_predef_get_named(void *ctx, const char *name, size_t len, double *out,
                                struct ncp_diag *d)
{
    struct ncp_analyzer *a = ctx;
    int rc = ncp_predef_catch_up(a, d);
    if (rc != NCP_OK)
        return rc;
    return ncp_params_get_named(a->params, name, len, out, d);
}

static int ncp_predef_exists(void *ctx, const char *name, size_t len)
{
    const struct ncp_analyzer *a = ctx;
    return ncp_params_exists(a->params, name, len);
}

struct ncp_param_ops ncp_predef_ops(struct ncp_analyzer *a)
{
    return (struct ncp_param_ops){ .ctx = a, .get_numbered = ncp_predef_get_numbered,
                                   .get_named = ncp_predef_get_named,
                                   .exists_named = ncp_predef_exists };
}
