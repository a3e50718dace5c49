/* The analyzer's ground floor: the slot a block's calls go to, the staging
 * of calls while cutter compensation holds a move, and the block's error.
 * Every handler emits through here; nothing here calls a handler. */
#include "floor.h"
#include "stages.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

struct ncp_cmd *ncp_an_slot(struct ncp_analyzer *a, size_t text_need)
{
    uint16_t cont = 0;
    if (a->cmd && a->cmd->n_ops < NCP_CMD_MAX_OPS &&
        a->cmd->text_used + text_need <= NCP_CMD_TEXT_POOL)
        return a->cmd;
    if (a->cmd) {
        cont = NCP_CMD_F_CONT;
        ncp_an_publish(a);
    }
    if (a->stopped)
        return NULL;
    struct ncp_cmd *c = a->sink->acquire(a->sink->ctx);
    if (!c) {
        a->stopped = 1;
        return NULL;
    }
    c->cmd_id = a->next_id++;
    c->line = a->line;
    c->flags = (uint16_t)(cont | a->file_tag << NCP_CMD_FILE_SHIFT);
    a->cmd = c;
    return c;
}

void ncp_an_reline(struct ncp_analyzer *a)
{
    if (a->cmd && (a->cmd->line != a->line || NCP_CMD_FILE(a->cmd) != a->file_tag))
        ncp_an_publish(a);
}

/* Append a finished op (and its text) to the block's slot. */
static int ncp_an_append(void *ctx, const struct ncp_canon *src, const char *text, size_t len)
{
    struct ncp_analyzer *a = ctx;
    if (len > NCP_CMD_TEXT_POOL)
        len = NCP_CMD_TEXT_POOL;
    struct ncp_cmd *c = ncp_an_slot(a, len);
    if (!c)
        return NCP_OK;
    struct ncp_canon *op = &c->ops[c->n_ops++];
    *op = *src;
    ncp_sai_op(a, op);
    op->text_off = 0;
    op->text_len = 0;
    if (len) {
        memcpy(c->text + c->text_used, text, len);
        op->text_off = c->text_used;
        op->text_len = (uint16_t)len;
        c->text_used = (uint16_t)(c->text_used + len);
    }
    return NCP_OK;
}

struct ncp_comp_sink ncp_an_comp_sink(struct ncp_analyzer *a)
{
    struct ncp_comp_sink s = {a, ncp_an_append};
    return s;
}

/* While compensation holds a queued move, ops are staged and then offered to
 * its queue, which keeps some of them behind the move as rs274 does. */
int ncp_an_commit_staged(struct ncp_analyzer *a)
{
    struct ncp_staged *st = &a->staged;
    st->pending = 0;
    struct ncp_comp_sink sink = ncp_an_comp_sink(a);
    int rc = ncp_cutcomp_other(&a->comp, &st->op, st->text, st->len, &sink, &a->err, a->line);
    if (rc != NCP_OK && a->err.code == NCP_OK)
        a->err.code = (uint16_t)rc;
    return rc;
}

static struct ncp_canon *ncp_an_stage(struct ncp_analyzer *a, enum ncp_canon_kind kind,
                                      const char *text, size_t len)
{
    ncp_an_commit(a);
    struct ncp_staged *st = &a->staged;
    memset(&st->op, 0, sizeof st->op);
    st->op.kind = (uint16_t)kind;
    if (len > sizeof st->text)
        len = sizeof st->text;
    if (len)
        memcpy(st->text, text, len);
    st->len = len;
    st->pending = 1;
    return &st->op;
}

struct ncp_canon *ncp_an_emit(struct ncp_analyzer *a, enum ncp_canon_kind kind)
{
    if (a->comp.n != 0 || a->staged.pending)
        return ncp_an_stage(a, kind, NULL, 0);
    struct ncp_cmd *c = ncp_an_slot(a, 0);
    struct ncp_canon *op = c ? &c->ops[c->n_ops++] : &a->scratch;
    memset(op, 0, sizeof *op);
    op->kind = (uint16_t)kind;
    return op;
}

struct ncp_canon *ncp_an_emit_text(struct ncp_analyzer *a, enum ncp_canon_kind kind,
                                   const char *text, size_t len)
{
    if (a->comp.n != 0 || a->staged.pending)
        return ncp_an_stage(a, kind, text, len);
    if (len > NCP_CMD_TEXT_POOL)
        len = NCP_CMD_TEXT_POOL;
    struct ncp_cmd *c = ncp_an_slot(a, len);
    struct ncp_canon *op = c ? &c->ops[c->n_ops++] : &a->scratch;
    memset(op, 0, sizeof *op);
    op->kind = (uint16_t)kind;
    if (c) {
        memcpy(c->text + c->text_used, text, len);
        op->text_off = c->text_used;
        op->text_len = (uint16_t)len;
        c->text_used = (uint16_t)(c->text_used + len);
    }
    return op;
}

void ncp_an_emit6(struct ncp_analyzer *a, enum ncp_canon_kind kind, const double *p)
{
    struct ncp_canon *op = ncp_an_emit(a, kind);
    if (kind == NCP_C_SET_G92_OFFSET) {
        memcpy(op->offset.v, p, sizeof op->offset.v);
        ncp_sai_g92(a, p);
    } else {
        memcpy(op->move.end, p, sizeof op->move.end);
        ncp_sai_move(a, p);
    }
}

int ncp_an_error(struct ncp_analyzer *a, uint16_t col, const char *fmt, ...)
{
    a->err.code = NCP_ERR_SEMANTIC;
    a->err.line = a->line;
    a->err.col = col;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(a->err.msg, sizeof a->err.msg, fmt, ap);
    va_end(ap);
    return NCP_ERR_SEMANTIC;
}
