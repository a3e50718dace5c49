/* The analyzer's run loop and its output: one slot per block that produces
 * calls, consecutive cmd_ids, errors carried in program order. */
#include "floor.h"
#include "stages.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct ncp_analyzer *ncp_analyzer_new(const struct ncp_analyzer_cfg *cfg,
                                      struct ncp_diag *d)
{
    ncp_words_init();
    struct ncp_analyzer *a = calloc(1, sizeof *a);
    if (!a) {
        ncp_diag_set(d, NCP_ERR_IO, 0, 0, "out of memory");
        return NULL;
    }
    if (cfg)
        a->cfg = *cfg;
    a->params = ncp_params_new();
    if (!a->params) {
        ncp_diag_set(d, NCP_ERR_IO, 0, 0, "out of memory");
        free(a);
        return NULL;
    }
    ncp_params_set_predef(a->params, ncp_predef_lookup, a);
    a->pops = ncp_predef_ops(a);
    if (ncp_tools_load(a, a->cfg.tool_table_path, d) != NCP_OK) {
        ncp_analyzer_free(a);
        return NULL;
    }
    if (ncp_remaps_new(&a->cfg, &a->remaps, d) != NCP_OK) {
        ncp_analyzer_free(a);
        return NULL;
    }
    ncp_words_use_remaps(a);
    ncp_user_m_scan(a);
    ncp_state_init(a);
    if (a->cfg.params_in)
        ncp_an_take_params(a, a->cfg.params_in);
    a->execute = ncp_an_execute;
    a->active_codes = ncp_analyzer_active_codes;
    ncp_cutcomp_init(&a->comp, NULL);
    ncp_m7x_reset(a);
    return a;
}

void ncp_analyzer_free(struct ncp_analyzer *a)
{
    if (!a)
        return;
    if (a->cfg.params_out)
        for (int k = 1; k < NCP_VAR_PARAMS; k++)
            if (a->cfg.params_out->listed[k])
                a->cfg.params_out->value[k] = *ncp_params_slot(a->params, k);
    if (a->cfg.tools_out)
        ncp_analyzer_copy_tools(a->cfg.tools_out, a);
    if (a->flow)
        ncp_flow_free(a->flow);
    ncp_m7x_free(a);
    ncp_g52_free(a);
    ncp_remaps_free(a->remaps);
    ncp_params_free(a->params);
    free(a);
}

/* rs274's start-up calls: the frames of its parameters (G54 and zeros
 * without a parameter file), after which its canon's position, and so the
 * current point, is the machine's zero in program coordinates. */
static void ncp_an_preamble(struct ncp_analyzer *a)
{
    struct ncp_state *s = &a->st;
    ncp_an_emit(a, NCP_C_USE_LENGTH_UNITS)->units.mm = 1;
    struct ncp_canon *op = ncp_an_emit(a, NCP_C_SET_G5X_OFFSET);
    op->offset.index = s->m.origin;
    memcpy(op->offset.v, s->g5x, sizeof op->offset.v);
    if (a->cfg.params_in)
        ncp_sai_g5x(a, s->g5x);
    ncp_an_emit6(a, NCP_C_SET_G92_OFFSET, s->g92);
    ncp_an_emit(a, NCP_C_SET_XY_ROTATION)->rotation.degrees = s->rotation;
    if (a->cfg.params_in) {
        static const double zero[NCP_NAX];
        double at[NCP_NAX] = { 0 };
        if (a->cfg.start_machine)
            for (int ax = 0; ax < NCP_NAX; ax++)
                at[ax] = a->cfg.start_machine[ax];
        ncp_frame_relative(a, a->cfg.start_machine ? at : zero, s->pos);
        memcpy(a->sai.pos, s->pos, sizeof a->sai.pos);
    }
    ncp_an_emit(a, NCP_C_SET_FEED_REFERENCE)->feed_reference.xyz = 1;
    ncp_an_emit(a, NCP_C_ON_RESET);
}

/* rs274's driver resets the canon twice when it exits, whatever the outcome
 * (once when it was given an INI). */
static void ncp_an_finish(struct ncp_analyzer *a, uint16_t flag)
{
    if (flag & NCP_CMD_F_ERROR)
        a->staged.pending = 0;
    else
        ncp_an_commit(a);
    /* whatever compensation still holds is never output, as in rs274 */
    ncp_cutcomp_reset(&a->comp);
    if (!a->cfg.resident) {
        ncp_an_emit(a, NCP_C_ON_RESET);
        if (!a->cfg.ini_given)
            ncp_an_emit(a, NCP_C_ON_RESET);
    }
    struct ncp_cmd *c = ncp_an_slot(a, 0);
    if (c) {
        c->flags |= flag;
        if (flag & NCP_CMD_F_ERROR)
            c->diag = a->err;
    }
    ncp_an_publish(a);
}

/* rs274 at the end of the text without M2/M30: a closing '%' ends the program
 * (FINISH), anything else is an error. */
/* rs274 names the last line it read. */
static uint32_t ncp_an_last_line(const struct ncp_source *src)
{
    uint32_t line = src->begin_line;
    size_t end = src->end;
    if (end > src->begin && src->text[end - 1] == '\n')
        end--;
    for (size_t k = src->begin; k < end; k++)
        line += src->text[k] == '\n';
    return line;
}

static int ncp_an_eof(struct ncp_analyzer *a, const struct ncp_source *src)
{
    if (src)
        a->line = ncp_an_last_line(src);
    if (a->cfg.resident)
        return NCP_END;
    if (src && src->has_percent && src->end < src->len) {
        ncp_an_emit_text(a, NCP_C_RAW_TEXT, "FINISH()", 8);
        return NCP_END;
    }
    if (src && src->has_percent)
        return ncp_an_error(a, 0, "File ended with no percent sign");
    return ncp_an_error(a, 0, "File ended with no percent sign or program end");
}

/* An M98 line as rs274's read_o and parse_line read it (the flow's reader):
 * every word's value and the reader's checks, then its P, then, unless
 * skipping, the block's word checks, where P and L are M98's. Nothing of the
 * line is executed (rs274 does not set its parameters either). */
static int ncp_an_read_m98(void *ctx, const struct ncp_block *b, int skipping, int *p,
                           int *l, struct ncp_diag *d)
{
    struct ncp_analyzer *a = ctx;
    struct ncp_words *w = &a->w;
    a->blk = b;
    a->line = b->line;
    int rc = ncp_words_collect(a, b);
    if (rc == NCP_OK && !NCP_HAS(w, 'P'))
        rc = ncp_an_error(a, b->oword.col, "Found 'm98' code with no P-word");
    if (rc == NCP_OK && ncp_rs274_int(w->v[NCP_LETTER('P')], p) != 0)
        rc = ncp_an_error(a, w->col[NCP_LETTER('P')], "Non integer value for integer");
    if (rc == NCP_OK && !skipping) {
        w->m98 = 1;
        rc = ncp_modal_check(a);
        w->m98 = 0;
    }
    *l = -1;
    if (rc == NCP_OK && NCP_HAS(w, 'L'))
        rc = ncp_integer_word(a, w->v[NCP_LETTER('L')], w->col[NCP_LETTER('L')], l);
    if (rc != NCP_OK)
        *d = a->err;
    return rc;
}

static int ncp_an_block(struct ncp_analyzer *a, const struct ncp_block *b)
{
    a->blk = b;
    a->line = b->line;
    a->file_tag = ncp_flow_file_tag(a->flow);
    if (b->err.code != NCP_OK) {
        /* rs274 meets the faults of the words left of the lexer's first */
        memset(&a->err, 0, sizeof a->err);
        int rc = b->err.col > 0 ? ncp_words_fault_before(a, b, b->err.col) : NCP_OK;
        if (rc != NCP_OK)
            return rc;
        a->err = b->err;
        return b->err.code;
    }
    if (a->remaps) /* a new line of the program: its builtin_used is clear */
        a->remap_builtin[0] = 0;
    /* rs274 -g runs with the block delete switch off: '/' lines execute */
    int rc = ncp_m7x_pending(a);
    if (rc == NCP_OK)
        rc = ncp_an_execute(a, b);
    if (rc == NCP_OK || rc == NCP_END) {
        int c = ncp_an_commit(a);
        if (c != NCP_OK)
            rc = c;
    }
    return rc;
}

int ncp_analyzer_run(struct ncp_analyzer *a, const struct ncp_block_feed *feed,
                     const struct ncp_cmd_sink *sink)
{
    a->sink = sink;
    a->src = feed->src;
    a->cmd = NULL;
    a->next_id = 0;
    a->stopped = 0;
    a->line = 0;
    a->file_tag = 0;
    memset(&a->err, 0, sizeof a->err);
    if (a->flow)
        ncp_flow_free(a->flow);
    a->flow = ncp_flow_new(feed, a->params, &a->cfg);
    if (!a->flow) {
        ncp_diag_set(&a->err, NCP_ERR_IO, 0, 0, "out of memory");
        ncp_an_finish(a, NCP_CMD_F_ERROR);
        return NCP_ERR_IO;
    }
    ncp_flow_set_param_ops(a->flow, a->pops);
    ncp_flow_set_frame_hooks(a->flow, ncp_m7x_hooks(a));
    ncp_flow_set_m98_reader(a->flow,
                            (struct ncp_flow_m98_reader){ .ctx = a, .read = ncp_an_read_m98 });
    ncp_m7x_reset(a);
    ncp_cutcomp_init(&a->comp, NULL);
    a->staged.pending = 0;
    if (!a->cfg.resident) {
        ncp_an_preamble(a);
        ncp_an_publish(a);
    }

    uint32_t last_line = 0;
    int rc;
    for (;;) {
        const struct ncp_block *b = NULL;
        struct ncp_diag d; /* filled by flow only on errors: no per-block memset */
        d.code = NCP_OK;
        d.line = 0;
        d.col = 0;
        d.file = NULL;
        d.msg[0] = '\0';
        rc = ncp_flow_next(a->flow, &b, &d);
        if (rc == NCP_END) {
            a->line = last_line;
            rc = ncp_an_eof(a, feed->src);
            break;
        }
        if (rc != NCP_OK) {
            if (ncp_flow_ended_at_percent(a->flow))
                ncp_an_emit_text(a, NCP_C_RAW_TEXT, "FINISH()", 8);
            a->err = d;
            break;
        }
        last_line = b->line;
        rc = ncp_an_block(a, b);
        if (rc != NCP_OK)
            break;
        ncp_an_publish(a);
        if (a->stopped)
            break;
    }
    /* A resident interpreter's last line may have been a queue buster (an
     * MDI M6, M66 or probe): its answer is this run's, so it is read back
     * now; the next run's job has none to give for it */
    if (rc == NCP_END && a->cfg.resident && a->sai.sync) {
        int synced = ncp_offsets_resync(a);
        if (synced != NCP_OK)
            rc = synced;
    }
    if (rc == NCP_END) {
        ncp_an_finish(a, NCP_CMD_F_END);
        return NCP_END;
    }
    if (a->err.code == NCP_OK)
        ncp_diag_set(&a->err, rc ? (enum ncp_status)rc : NCP_ERR_SEMANTIC, a->line, 0,
                     "internal error");
    /* the error is in the block last served, whichever file that came from */
    a->err.file = ncp_flow_file(a->flow);
    ncp_flow_reset(a->flow);
    ncp_an_finish(a, NCP_CMD_F_ERROR);
    return a->err.code;
}

void ncp_analyzer_set_position(struct ncp_analyzer *a, const double pos[3])
{
    for (int k = 0; k < 3; k++) {
        a->st.pos[k] = pos[k];
        a->sai.pos[k] = pos[k];
    }
}

void ncp_analyzer_set_sync(struct ncp_analyzer *a, ncp_machine_sync_fn fn, void *ctx)
{
    a->sai.sync = fn;
    a->sai.sync_ctx = ctx;
}

/* rs274's init from its parameter file: the values, then the frames they
 * hold (the preamble emits them). */
void ncp_an_take_params(struct ncp_analyzer *a, const struct ncp_var_file *vf)
{
    struct ncp_state *s = &a->st;
    for (int k = 1; k < NCP_VAR_PARAMS; k++)
        if (vf->listed[k])
            *ncp_params_slot(a->params, k) = vf->value[k];
    int origin = (int)ncp_frame_param(a, 5220);
    s->m.origin = origin >= 1 && origin <= 9 ? origin : 1;
    for (int ax = 0; ax < NCP_NAX; ax++) {
        s->g5x[ax] = ncp_frame_user(a, ax, 5201 + 20 * s->m.origin + ax);
        s->g92[ax] = ncp_frame_param(a, 5210) != 0.0 ? ncp_frame_user(a, ax, 5211 + ax) : 0.0;
    }
    s->rotation = ncp_frame_param(a, 5210 + 20 * s->m.origin);
}

double ncp_analyzer_param(const struct ncp_analyzer *a, int index)
{
    if (index < 1 || index >= NCP_PARAMS_MAX)
        return 0.0;
    return *ncp_params_slot(a->params, index);
}

void ncp_analyzer_set_param(struct ncp_analyzer *a, int index, double v)
{
    if (index >= 1 && index < NCP_PARAMS_MAX)
        *ncp_params_slot(a->params, index) = v;
}
