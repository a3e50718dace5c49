/* Running a remapped M or G code, T, S or F as rs274 -i does (convert_remapped_code and
 * add_parameters): in the code's step of the line, "O<ngc> call" is run as
 * if read there, the argspec's words become the sub's local parameters
 * (#<p>, #<q>; with '@' positional #1, #2 instead), the sub's blocks run,
 * and at its return the line goes on with its next step. */
#include "floor.h"
#include "stages.h"

#include "ncpar/blocks.h"

#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int remap_in_progress(const struct ncp_analyzer *a, const struct ncp_remap *r)
{
    for (int k = 0; k < a->remap_level; k++)
        if (a->remap_frames[k].r == r)
            return 1;
    return 0;
}

static int m_remap_in_progress(const struct ncp_analyzer *a, int m)
{
    const struct ncp_remap *r = ncp_remap_of_m(a->remaps, m);
    return r && remap_in_progress(a, r);
}

/* The code runs built in rather than remapped (rs274 2.9's find_remappings):
 * M6, M61 and M62-M68 inside their own remap, so that the body may change
 * the tool itself; a stop code (group 4) inside any remap of M0, M1 or M60,
 * which rs274 notes for the epilog. Others (M9, M400...) remap again. */
static int runs_built_in(struct ncp_analyzer *a, const struct ncp_remap *r)
{
    if (r->group == 4 && (m_remap_in_progress(a, 0) || m_remap_in_progress(a, 1) ||
                          m_remap_in_progress(a, 60))) {
        ncp_remap_note_builtin(a);
        return 1;
    }
    return (r->m == 6 || r->m == 61 || (r->m >= 62 && r->m <= 68)) && remap_in_progress(a, r);
}

struct remap_arg {
    char name;
    double value;
};

/* The argspec's words of the block, in its order; missing required ones are
 * an error worded as rs274's ("user-defined M400: missing: P"). */
static int remap_args(struct ncp_analyzer *a, const struct ncp_remap *r, uint16_t col,
                      struct remap_arg *args, int *n)
{
    const struct ncp_words *w = &a->w;
    char missing[64] = "";
    const char *no_feed = "", *no_speed = "";
    size_t nm = 0;
    *n = 0;
    for (const char *s = r->argspec; *s && *n < 26; s++) {
        int c = toupper((unsigned char)*s);
        if (c < 'A' || c > 'Z')
            continue;
        int seen = 0;
        for (int k = 0; k < *n; k++)
            seen |= args[k].name == tolower(c);
        if (seen)
            continue;
        if (NCP_HAS(w, c)) {
            args[*n].name = (char)tolower(c);
            args[(*n)++].value = w->v[NCP_LETTER(c)];
        } else if (isupper((unsigned char)*s) && !strchr(missing, c) && nm + 3 < sizeof missing) {
            if (nm)
                missing[nm++] = ',';
            missing[nm++] = (char)c;
            missing[nm] = '\0';
        }
    }
    if (strchr(r->argspec, '>')) {
        if (a->st.feed > 0.0 && *n < 26) {
            args[*n].name = 'f';
            args[(*n)++].value = a->st.feed;
        } else {
            no_feed = "F>0,";
        }
    }
    if (strchr(r->argspec, '^')) {
        if (a->st.speed > 0.0 && *n < 26) {
            args[*n].name = 's';
            args[(*n)++].value = a->st.speed;
        } else {
            no_speed = "S>0,";
        }
    }
    if (nm || *no_feed || *no_speed)
        return ncp_an_error(a, col, "user-defined %s:%s%s%s%s", r->code,
                            nm ? " missing: " : "", missing, no_feed, no_speed);
    return NCP_OK;
}

/* "O<ngc> call", with the arguments in brackets when the argspec has '@'
 * (rs274 writes them with four decimals). */
static int remap_call(struct ncp_analyzer *a, const struct ncp_remap *r, uint16_t col,
                      const struct remap_arg *args, int n)
{
    char text[1024];
    int len = snprintf(text, sizeof text, "o<%s> call", r->ngc);
    int positional = strchr(r->argspec, '@') != NULL;
    for (int k = 0; positional && k < n && len > 0 && (size_t)len < sizeof text; k++)
        len += snprintf(text + len, sizeof text - (size_t)len, " [%.4f]", args[k].value);
    if (len <= 0 || (size_t)len >= sizeof text)
        return ncp_an_error(a, col, "user-defined %s: call too long", r->code);
    int rc = ncp_an_call_text(a, text, (size_t)len, col);
    for (int k = 0; rc == NCP_OK && !positional && k < n; k++)
        rc = ncp_params_set_named(a->params, &args[k].name, 1, args[k].value, &a->err);
    return rc;
}

/* The sub's blocks, each as the run loop runs one, up to its return. */
static int remap_body(struct ncp_analyzer *a)
{
    for (;;) {
        const struct ncp_block *b;
        int rc = ncp_an_sub_next(a, &b);
        if (rc == NCP_FLOW_RETURNED)
            return NCP_OK;
        if (rc != NCP_OK)
            return rc;
        a->blk = b;
        a->line = b->line;
        a->file_tag = ncp_flow_file_tag(a->flow);
        a->remap_builtin[a->remap_level] = 0; /* a new line at this level */
        ncp_an_reline(a);
        if (b->err.code != NCP_OK) {
            a->err = b->err;
            return b->err.code;
        }
        rc = ncp_m7x_pending(a);
        if (rc == NCP_OK)
            rc = a->execute(a, b);
        if (rc == NCP_OK || rc == NCP_END) {
            int c = ncp_an_commit(a);
            if (c != NCP_OK)
                rc = c;
        }
        if (rc != NCP_OK)
            return rc; /* an error, or M2/M30 in the sub: the program ends */
    }
}

/* ---------------------------------------------------------------------
 * stdglue.py's prologs and epilogs, as LinuxCNC 2.9 ships them
 * --------------------------------------------------------------------- */

static int glue_prolog(struct ncp_analyzer *a, struct ncp_remap_frame *fr, uint16_t col)
{
    struct ncp_state *s = &a->st;
    const char *names[4];
    double values[4];
    int n = 0;
    if (fr->r->prolog == NCP_GLUE_PREPARE) {
        if (!NCP_HAS(&a->w, 'T'))
            return ncp_an_error(a, col, "T requires a tool number");
        int tool = ncp_trunc_int_round(a->w.v[NCP_LETTER('T')]);
        double pocket = -1; /* T0: an unload */
        if (tool) {
            int idx = ncp_tools_find(a, tool);
            if (idx < 0)
                return ncp_an_error(a, col, "T%d: pocket not found", tool);
            pocket = a->tools[idx].pocket; /* find_tool_pocket: the P number */
        }
        fr->tool = tool;
        fr->pocket = pocket;
        names[n] = "tool", values[n++] = tool;
        names[n] = "pocket", values[n++] = pocket;
    } else if (fr->r->prolog == NCP_GLUE_SETTOOL) {
        if (!NCP_HAS(&a->w, 'Q'))
            return ncp_an_error(a, col, "M61 requires a Q parameter");
        double q = a->w.v[NCP_LETTER('Q')];
        int tool = (int)q; /* Python's int(): towards zero */
        if (tool < -1e-6)
            return ncp_an_error(a, col, "M61: Q value < 0");
        int idx = ncp_tools_find(a, tool);
        if (idx < 0)
            return ncp_an_error(a, col, "M61 failed: requested tool %d not in table", tool);
        fr->tool = tool;
        /* find_tool_pocket: the P number (T0: the spindle entry's) */
        fr->pocket = a->tools[idx].pocket;
        names[n] = "tool", values[n++] = fr->tool;
        names[n] = "pocket", values[n++] = fr->pocket;
    } else if (fr->r->prolog == NCP_GLUE_SETSPEED || fr->r->prolog == NCP_GLUE_SETFEED) {
        int speed = fr->r->prolog == NCP_GLUE_SETSPEED;
        char c = speed ? 'S' : 'F';
        if (!NCP_HAS(&a->w, c))
            return ncp_an_error(a, col, "%c requires a value", c);
        fr->value = a->w.v[NCP_LETTER(c)];
        names[n] = speed ? "speed" : "feed", values[n++] = fr->value;
    } else if (fr->r->prolog == NCP_GLUE_CHANGE) {
        if (s->selected_pocket < 0)
            return ncp_an_error(a, col, "M6: no tool prepared");
        if (s->m.comp_side != 0)
            return ncp_an_error(a, col, "Cannot change tools with cutter radius compensation on");
        fr->selected_pocket = s->selected_pocket;
        /* stdglue's current_tool: the spindle entry's tool, -1 empty */
        names[n] = "tool_in_spindle", values[n++] = a->tool_no[0] > 0 ? a->tool_no[0] : -1;
        names[n] = "selected_tool", values[n++] = s->selected_tool;
        names[n] = "current_pocket", values[n++] = s->current_pocket;
        names[n] = "selected_pocket", values[n++] = s->selected_pocket;
    }
    int rc = NCP_OK;
    for (int k = 0; rc == NCP_OK && k < n; k++)
        rc = ncp_params_set_named(a->params, names[k], strlen(names[k]), values[k], &a->err);
    return rc;
}

/* After the sub's return; builtin is the controlling line's builtin_used. */
static int glue_epilog(struct ncp_analyzer *a, const struct ncp_remap_frame *fr, uint16_t col,
                       int builtin)
{
    struct ncp_state *s = &a->st;
    double value = 0, returned = 0;
    struct ncp_diag ignore;
    ncp_params_get_named(a->params, "_value", 6, &value, &ignore);
    ncp_params_get_named(a->params, "_value_returned", 15, &returned, &ignore);
    if (returned == 0.0)
        return ncp_an_error(a, col, "the %s remap procedure %s did not return a value",
                            fr->r->code, fr->r->ngc);
    if (fr->r->epilog == NCP_GLUE_SETSPEED && value < -1e-6) /* TOLERANCE_EQUAL */
        return ncp_an_error(a, col, "S: remap procedure returned %f", value);
    if (builtin)
        return NCP_OK;
    if (fr->r->epilog == NCP_GLUE_SETSPEED) {
        s->speed = fr->value;
        ncp_an_emit(a, NCP_C_SET_SPINDLE_SPEED)->spindle_speed.speed = s->speed;
        return NCP_OK;
    }
    if (fr->r->epilog == NCP_GLUE_SETFEED) {
        s->feed = fr->value;
        ncp_an_emit(a, NCP_C_SET_FEED_RATE)->feed_rate.rate = s->feed;
        return NCP_OK;
    }
    if (fr->r->epilog == NCP_GLUE_PREPARE) {
        if (value <= 0)
            return ncp_an_error(a, col, "T%d: aborted (return code %.1f)", (int)fr->tool, value);
        s->selected_tool = (int)fr->tool;
        s->selected_pocket = (int)fr->pocket;
        int idx = s->selected_pocket;
        s->selected_pocket_no = idx >= 0 && idx < a->n_tools ? a->tools[idx].pocket : -1;
        struct ncp_canon *c = ncp_an_emit(a, NCP_C_SELECT_TOOL);
        c->tool.tool = c->tool.number = s->selected_tool;
        return NCP_OK;
    }
    if (fr->r->epilog == NCP_GLUE_SETTOOL) {
        if (value <= 0)
            return ncp_an_error(a, col, "M61 aborted (return code %.1f)", value);
        /* stdglue sets the spindle's tool number and current_pocket to the
         * P number, and CHANGE_TOOL_NUMBER(P): the entry's offsets stay */
        int pocket = (int)fr->pocket;
        a->tool_no[0] = (int)fr->tool;
        s->current_tool = (int)fr->tool;
        s->current_pocket = pocket;
        s->current_pocket_no = pocket >= 0 && pocket < a->n_tools ? a->tools[pocket].pocket : -1;
        struct ncp_canon *c = ncp_an_emit(a, NCP_C_CHANGE_TOOL_NUMBER);
        c->tool.tool = pocket;
        c->tool.number = (int)fr->tool;
        ncp_tools_sync_params(a, 1); /* set_tool_parameters() */
        return NCP_OK;
    }
    if (value <= 0)
        return ncp_an_error(a, col, "M6 aborted (return code %.1f)", value);
    int pocket = (int)fr->selected_pocket;
    struct ncp_canon *c = ncp_an_emit(a, NCP_C_CHANGE_TOOL);
    c->tool.tool = pocket;
    c->tool.number = pocket > 0 && pocket < a->n_tools ? a->tool_no[pocket] : a->tool_no[0];
    if (pocket > 0 && pocket < a->n_tools)
        ncp_tools_copy(a, 0, pocket);
    s->current_pocket = pocket;
    s->current_pocket_no = pocket >= 0 && pocket < a->n_tools ? a->tools[pocket].pocket : -1;
    s->current_tool = a->tool_no[0];
    s->selected_pocket = -1;
    s->selected_pocket_no = -1;
    s->selected_tool = -1;
    ncp_tools_sync_params(a, 1); /* set_tool_parameters() */
    s->toolchange_flag = 1;
    a->sai.change_flag = 1;
    return NCP_OK;
}

/* Remap r of the block's code at col: the call, the prolog, the sub, the
 * epilog, and the line goes on. */
static int remap_run(struct ncp_analyzer *a, const struct ncp_remap *r, uint16_t col)
{
    if (a->remap_level + 1 >= NCP_REMAP_MAX_NESTED)
        return ncp_an_error(a, col, "maximum nesting of remapped blocks exceeded");
    struct remap_arg args[26];
    int n = 0;
    int rc = remap_args(a, r, col, args, &n);
    if (rc != NCP_OK)
        return rc;
    /* the sub's blocks overwrite the block in hand: kept for the line's
     * later steps */
    struct ncp_words *saved = malloc(sizeof *saved);
    if (!saved)
        return ncp_an_error(a, col, "out of memory");
    *saved = a->w;
    const struct ncp_block *blk = a->blk;
    uint32_t line = a->line;
    unsigned tag = a->file_tag;
    struct ncp_remap_frame *fr = &a->remap_frames[a->remap_level];
    memset(fr, 0, sizeof *fr);
    fr->r = r;
    rc = remap_call(a, r, col, args, n);
    if (rc == NCP_OK)
        rc = glue_prolog(a, fr, col);
    if (rc == NCP_OK) {
        a->remap_level++;
        rc = remap_body(a);
        a->remap_level--;
    }
    if (rc == NCP_OK) {
        a->w = *saved;
        a->blk = blk;
        a->line = line;
        a->file_tag = tag;
        ncp_an_reline(a);
        if (r->epilog != NCP_GLUE_NONE)
            rc = glue_epilog(a, fr, col, a->remap_builtin[a->remap_level]);
    }
    free(saved);
    return rc;
}

int ncp_remap_step(struct ncp_analyzer *a, int slot, int *ran)
{
    *ran = 0;
    const struct ncp_remap *r = ncp_remap_of_m(a->remaps, a->w.m[slot]);
    if (!r || !r->remappable || runs_built_in(a, r))
        return NCP_OK;
    *ran = 1;
    return remap_run(a, r, a->w.mcol[slot]);
}

int ncp_remap_letter_step(struct ncp_analyzer *a, char letter, int *ran)
{
    const struct ncp_remaps *rs = a->remaps;
    int k = letter == 'T' ? rs->t : letter == 'S' ? rs->s : rs->f;
    *ran = 0;
    if (k < 0)
        return NCP_OK;
    const struct ncp_remap *r = &rs->r[k];
    if (remap_in_progress(a, r)) { /* the built-in code, noted for the epilog */
        ncp_remap_note_builtin(a);
        return NCP_OK;
    }
    *ran = 1;
    return remap_run(a, r, a->w.col[NCP_LETTER(letter)]);
}

int ncp_remap_g_step(struct ncp_analyzer *a, int motion, int *ran)
{
    const struct ncp_remap *r = ncp_remap_of_g(a->remaps, motion);
    *ran = 0;
    if (!r)
        return NCP_OK;
    *ran = 1;
    if (!r->remappable)
        return ncp_an_error(a, NCP_MOTION_COL(&a->w), "Bug unknown motion code");
    return remap_run(a, r, NCP_MOTION_COL(&a->w));
}
