/* The lexer's ground floor: a block made ready to read, and a syntax error
 * stored in it. The block reader (lex_block.c) and every reader it calls
 * (lex_fast.c, lex_number.c, lex_expr.c, lex_text.c, lex_comment.c,
 * lex_oword.c) stand on it; it calls none of them. */
#include <stdarg.h>
#include <stdio.h>
#include "lex_internal.h"

int ncp_lex_fail(struct ncp_lexer *lx, int pos, const char *fmt, ...)
{
    struct ncp_diag *d = &lx->b->err;
    va_list ap;
    d->code = NCP_ERR_SYNTAX;
    d->line = lx->b->line;
    d->col = lx->col[pos];
    va_start(ap, fmt);
    vsnprintf(d->msg, sizeof d->msg, fmt, ap);
    va_end(ap);
    return NCP_ERR_SYNTAX;
}

void ncp_lex_init_block(struct ncp_block *b, size_t len, uint32_t line, uint64_t offset)
{
    b->offset = offset;
    b->line = line;
    b->length = (uint16_t)(len > 0xffff ? 0xffff : len);
    b->block_delete = 0;
    b->has_n = 0;
    b->words_only = 0;
    b->n_number = 0.0;
    b->err.code = NCP_OK;
    b->err.line = line;
    b->err.col = 0;
    b->err.file = NULL;
    b->err.msg[0] = '\0';
    b->n_words = b->n_assign = b->n_code = b->pool_used = 0;
    b->oword.kind = NCP_O_NONE;
    b->comment_kind = NCP_CMT_NONE;
    b->comment_off = b->comment_len = 0;
}
