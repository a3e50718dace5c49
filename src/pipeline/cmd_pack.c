/* Packed commands (see cmd_pack.h). */
#include "cmd_pack.h"

#include <stdint.h>
#include <string.h>

#define UNIT NCP_CMD_UNIT


static unsigned ops_of(const struct ncp_cmd *c)
{
    return c->n_ops < NCP_CMD_MAX_OPS ? c->n_ops : NCP_CMD_MAX_OPS;
}

static unsigned text_of(const struct ncp_cmd *c)
{
    return c->text_used < NCP_CMD_TEXT_POOL ? c->text_used : NCP_CMD_TEXT_POOL;
}

static size_t msg_of(const struct ncp_cmd *c)
{
    return c->flags & NCP_CMD_F_ERROR ? strnlen(c->diag.msg, NCP_DIAG_MSG_MAX - 1) : 0;
}

static size_t bytes_of(const struct ncp_cmd *c, size_t msg)
{
    size_t n = sizeof(struct ncp_packed_cmd_head) + ops_of(c) * sizeof c->ops[0] + text_of(c);
    if (c->flags & NCP_CMD_F_ERROR)
        n += offsetof(struct ncp_diag, msg) + msg;
    return (n + UNIT - 1) / UNIT * UNIT;
}

/* Most commands are calls only (a motion, a modal change): no error, no
 * text, so no padding either (head and calls are whole units). */
static int calls_only(const struct ncp_cmd *c)
{
    return !(c->flags & NCP_CMD_F_ERROR) && c->text_used == 0 && c->n_ops <= NCP_CMD_MAX_OPS;
}

_Static_assert(sizeof(struct ncp_packed_cmd_head) % UNIT == 0 && sizeof(struct ncp_canon) % UNIT == 0,
               "a calls-only record needs no padding");

/* The record's size, and the length of its error text (0 without one). */
static size_t record_bytes(const struct ncp_cmd *c, size_t *msg)
{
    *msg = 0;
    if (calls_only(c))
        return sizeof(struct ncp_packed_cmd_head) + c->n_ops * sizeof c->ops[0];
    *msg = msg_of(c);
    return bytes_of(c, *msg);
}

size_t ncp_cmd_packed_size(const struct ncp_cmd *c)
{
    size_t msg;
    return record_bytes(c, &msg);
}

/* One call at a time, each a copy of constant size: the compiler makes it a
 * few vector moves, where one copy of n_ops * size is a `rep movs` whose
 * start-up costs more than a call's worth of moves (one call is the rule). */
#define OP_BYTES sizeof(struct ncp_canon)
static void copy_ops(void *dst, const void *src, unsigned n)
{
    unsigned char *d = dst;
    const unsigned char *s = src;
    for (unsigned i = 0; i < n; i++)
        memcpy(d + (size_t)i * OP_BYTES, s + (size_t)i * OP_BYTES, OP_BYTES);
}

/* The command is written where its record goes: its head and calls already
 * stand where the record wants them, and only the error and the text (rare)
 * move down behind the calls. */
_Static_assert(offsetof(struct ncp_cmd, cmd_id) == offsetof(struct ncp_packed_cmd_head, cmd_id) &&
                   offsetof(struct ncp_cmd, line) == offsetof(struct ncp_packed_cmd_head, line) &&
                   offsetof(struct ncp_cmd, n_ops) == offsetof(struct ncp_packed_cmd_head, n_ops) &&
                   offsetof(struct ncp_cmd, flags) == offsetof(struct ncp_packed_cmd_head, flags) &&
                   offsetof(struct ncp_cmd, text_used) ==
                       offsetof(struct ncp_packed_cmd_head, text_used) &&
                   offsetof(struct ncp_cmd, ops) == sizeof(struct ncp_packed_cmd_head),
               "a command's head and calls are its record's");
/* each part moves down, never onto a part still to move */
_Static_assert(offsetof(struct ncp_cmd, text) >= offsetof(struct ncp_cmd, diag) + sizeof(struct ncp_diag),
               "the text follows the error");

size_t ncp_cmd_pack_general(struct ncp_cmd *c)
{
    size_t msg, total = record_bytes(c, &msg);
    unsigned char *base = (unsigned char *)c;
    uint16_t n_ops = (uint16_t)ops_of(c), text_used = (uint16_t)text_of(c);
    uint16_t units = (uint16_t)(total / UNIT);
    uint32_t msg_len = (uint32_t)msg;
    unsigned char *p = base + sizeof(struct ncp_packed_cmd_head) + n_ops * sizeof c->ops[0];
    if (c->flags & NCP_CMD_F_ERROR) {
        memmove(p, &c->diag, offsetof(struct ncp_diag, msg));
        p += offsetof(struct ncp_diag, msg);
        memmove(p, c->diag.msg, msg);
        p += msg;
    }
    if (text_used)
        memmove(p, c->text, text_used);
    p += text_used;
    size_t pad = total - (size_t)(p - base);
    if (pad)
        memset(p, 0, pad);
    /* the head's own fields last: units and msg_len lie over out_len */
    memcpy(base + offsetof(struct ncp_packed_cmd_head, n_ops), &n_ops, sizeof n_ops);
    memcpy(base + offsetof(struct ncp_packed_cmd_head, text_used), &text_used, sizeof text_used);
    memcpy(base + offsetof(struct ncp_packed_cmd_head, units), &units, sizeof units);
    memcpy(base + offsetof(struct ncp_packed_cmd_head, msg_len), &msg_len, sizeof msg_len);
    return total;
}


void ncp_cmd_unpack(const void *src, struct ncp_cmd *c)
{
    struct ncp_packed_cmd_head h;
    const unsigned char *p = src;
    memcpy(&h, p, sizeof h);
    p += sizeof h;
    c->cmd_id = h.cmd_id;
    c->line = h.line;
    c->n_ops = h.n_ops;
    c->flags = h.flags;
    c->text_used = h.text_used;
    c->out_len = 0;
    copy_ops(c->ops, p, h.n_ops);
    p += h.n_ops * sizeof c->ops[0];
    if (h.flags & NCP_CMD_F_ERROR) {
        memcpy(&c->diag, p, offsetof(struct ncp_diag, msg));
        p += offsetof(struct ncp_diag, msg);
        memcpy(c->diag.msg, p, h.msg_len);
        c->diag.msg[h.msg_len] = '\0';
        p += h.msg_len;
    }
    if (h.text_used)
        memcpy(c->text, p, h.text_used);
}


void ncp_cmd_copy_calls(const struct ncp_cmd *src, struct ncp_cmd *dst)
{
    unsigned n = ops_of(src);
    dst->cmd_id = src->cmd_id;
    dst->line = src->line;
    dst->n_ops = (uint16_t)n;
    dst->flags = src->flags;
    dst->text_used = 0;
    dst->out_len = src->out_len;
    copy_ops(dst->ops, src->ops, n);
}


