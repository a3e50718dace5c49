/* O-word lines, as rs274's read_o(): o<name> or o<number> (the number may be
 * any integer value, kept as its decimal text when constant: "o0100" is "100"),
 * then a control keyword, then the keyword's bracketed expressions. Only
 * comments may follow. The kind and name are stored before anything that can
 * fail, so a block with an error still says which O-word it was (rs274 does
 * not read the rest of O-lines it is skipping). */
#include <stdio.h>
#include <string.h>
#include "lex_internal.h"

static const struct {
    const char *kw;
    uint8_t kind;
} keywords[] = {
    /* rs274's order: first match wins ("elseif" before "else") */
    { "sub", NCP_O_SUB }, { "endsub", NCP_O_ENDSUB }, { "call", NCP_O_CALL },
    { "do", NCP_O_DO }, { "while", NCP_O_WHILE }, { "repeat", NCP_O_REPEAT },
    { "if", NCP_O_IF }, { "elseif", NCP_O_ELSEIF }, { "else", NCP_O_ELSE },
    { "endif", NCP_O_ENDIF }, { "break", NCP_O_BREAK },
    { "continue", NCP_O_CONTINUE }, { "endwhile", NCP_O_ENDWHILE },
    { "endrepeat", NCP_O_ENDREPEAT }, { "return", NCP_O_RETURN },
};

static int read_keyword(struct ncp_lexer *lx)
{
    size_t i;
    for (i = 0; i < sizeof keywords / sizeof keywords[0]; i++) {
        size_t n = strlen(keywords[i].kw);
        if (strncmp(lx->buf + lx->pos, keywords[i].kw, n) == 0) {
            lx->pos += (int)n;
            return keywords[i].kind;
        }
    }
    return NCP_O_NONE;
}

static int read_number_name(struct ncp_lexer *lx, struct ncp_oword *o)
{
    struct ncp_block *b = lx->b;
    struct ncp_lex_val v;
    int pos = lx->pos, rc, len;
    char tmp[16];

    if ((rc = ncp_lex_integer_value(lx, &v)))
        return rc;
    if (!v.is_const) {
        ncp_lex_to_expr(lx, &v, &o->num);
        o->name_computed = 1;
        return NCP_OK;
    }
    len = snprintf(tmp, sizeof tmp, "%d", ncp_trunc_int(v.k));
    if (b->pool_used + len + 1 > NCP_BLOCK_POOL)
        return ncp_lex_fail(lx, pos, "Line too complex");
    o->name_off = b->pool_used;
    o->name_len = (uint16_t)len;
    memcpy(b->pool + b->pool_used, tmp, (size_t)len + 1);
    b->pool_used = (uint16_t)(b->pool_used + len + 1);
    return NCP_OK;
}

static int bracketed(struct ncp_lexer *lx, struct ncp_expr *e)
{
    struct ncp_lex_val v;
    int rc = ncp_lex_expression(lx, &v);
    if (!rc)
        ncp_lex_to_expr(lx, &v, e);
    return rc;
}

static int required_cond(struct ncp_lexer *lx, struct ncp_oword *o, const char *kw)
{
    if (lx->buf[lx->pos] != '[')
        return ncp_lex_fail(lx, lx->pos, "Left bracket missing after '%s'", kw);
    o->has_cond = 1;
    return bracketed(lx, &o->cond);
}

static int call_args(struct ncp_lexer *lx, struct ncp_oword *o)
{
    int rc;
    while (lx->buf[lx->pos] == '[' || lx->buf[lx->pos] == '(') {
        if (lx->buf[lx->pos] == '(') {
            if ((rc = ncp_lex_comment(lx)))
                return rc;
            continue;
        }
        if (o->nargs >= NCP_OWORD_MAX_ARGS)
            return ncp_lex_fail(lx, lx->pos, "Too many subroutine parameters");
        if ((rc = bracketed(lx, &o->args[o->nargs])))
            return rc;
        o->nargs++;
    }
    return NCP_OK;
}

static int arguments(struct ncp_lexer *lx, struct ncp_oword *o)
{
    switch (o->kind) {
    case NCP_O_ENDSUB:
    case NCP_O_RETURN:
        if (lx->buf[lx->pos] != '[')
            return NCP_OK;
        o->has_cond = 1;
        return bracketed(lx, &o->cond);
    case NCP_O_CALL: return call_args(lx, o);
    case NCP_O_WHILE: return required_cond(lx, o, "while");
    case NCP_O_REPEAT: return required_cond(lx, o, "repeat");
    case NCP_O_IF: return required_cond(lx, o, "if");
    case NCP_O_ELSEIF: return required_cond(lx, o, "elseif");
    default: return NCP_OK;
    }
}

/* Only comments may follow; rs274 does not act on comments of O-lines. */
static int rest_of_line(struct ncp_lexer *lx)
{
    while (lx->pos < lx->n) {
        char c = lx->buf[lx->pos];
        int rc;
        if (c == ';')
            break;
        if (c != '(')
            return ncp_lex_fail(lx, lx->pos, "Unexpected character after O-word");
        if ((rc = ncp_lex_comment(lx)))
            return rc;
    }
    lx->cmt_pos = -1;
    return NCP_OK;
}

int ncp_lex_oword(struct ncp_lexer *lx)
{
    struct ncp_oword *o = &lx->b->oword;
    int opos = lx->pos, rc;

    o->col = lx->col[opos];
    o->tail_col = 0;
    o->nargs = 0;
    o->has_cond = 0;
    o->name_off = o->name_len = 0;
    o->name_computed = 0;
    lx->pos++;
    if (lx->buf[lx->pos] == '<')
        rc = ncp_lex_read_name(lx, &o->name_off, &o->name_len);
    else
        rc = read_number_name(lx, o);
    if (rc)
        return rc;
    o->kind = (uint8_t)read_keyword(lx);
    if (o->kind == NCP_O_NONE) {
        char next = lx->buf[lx->pos];
        if (next != '(' && next != ';' && next != '\0')
            return ncp_lex_fail(lx, lx->pos, "Unknown control command in o word");
        /* a bare O-word: a Fanuc-style subroutine's first line */
        o->kind = NCP_O_FANUC;
        return rest_of_line(lx);
    }
    if ((rc = arguments(lx, o)))
        return rc;
    return rest_of_line(lx);
}
