/* Comments. rs274 keeps only the last (...) comment of a line and then looks
 * at it as convert_comment() does: leading white space skipped, a
 * case-insensitive keyword with a comma (MSG, DEBUG, PRINT, LOG, LOGOPEN,
 * LOGAPPEND, ABORT) selects an action and the text after the comma is kept
 * verbatim; LOGCLOSE must be the whole comment. An empty "()" does nothing. */
#include <string.h>
#include "lex_internal.h"

int ncp_lex_comment(struct ncp_lexer *lx)
{
    const char *close = memchr(lx->buf + lx->pos, ')', (size_t)(lx->n - lx->pos));
    /* lex_text.c made sure every '(' outside a ';' tail is closed */
    if (!close)
        return ncp_lex_fail(lx, lx->pos, "Unclosed comment found");
    lx->cmt_pos = lx->pos + 1;
    lx->cmt_len = (int)(close - (lx->buf + lx->cmt_pos));
    lx->pos = (int)(close - lx->buf) + 1;
    return NCP_OK;
}

static int is_c_space(unsigned char c)
{
    return c == ' ' || (c >= '\t' && c <= '\r');
}

static int has_prefix(const char *s, int len, const char *kw)
{
    int i;
    for (i = 0; kw[i]; i++) {
        char c;
        if (i >= len)
            return 0;
        c = s[i];
        if (c >= 'A' && c <= 'Z')
            c = (char)(c + 32);
        if (c != kw[i])
            return 0;
    }
    return i;
}

static const struct {
    const char *kw;
    uint8_t kind;
} keywords[] = {
    { "msg,", NCP_CMT_MSG },
    { "debug,", NCP_CMT_DEBUG },
    { "print,", NCP_CMT_PRINT },
    { "log,", NCP_CMT_LOG },
    { "logopen,", NCP_CMT_LOGOPEN },
    { "logappend,", NCP_CMT_LOGAPPEND },
    /* Python hooks: rs274 without its Python plugin does nothing with them */
    { "py,", NCP_CMT_NONE },
    { "pyrun,", NCP_CMT_NONE },
    { "pyreload", NCP_CMT_NONE },
    { "abort,", NCP_CMT_ABORT },
};

static uint8_t classify(const char **text, int *len)
{
    size_t i;
    for (i = 0; i < sizeof keywords / sizeof keywords[0]; i++) {
        int n = has_prefix(*text, *len, keywords[i].kw);
        if (n) {
            *text += n;
            *len -= n;
            return keywords[i].kind;
        }
    }
    if (*len == 8 && has_prefix(*text, *len, "logclose")) {
        *len = 0;
        return NCP_CMT_LOGCLOSE;
    }
    return NCP_CMT_PLAIN;
}

void ncp_lex_store_comment(struct ncp_lexer *lx)
{
    struct ncp_block *b = lx->b;
    const char *text;
    int len = lx->cmt_len;
    uint8_t kind;

    if (lx->cmt_pos < 0 || len == 0)
        return;
    text = lx->buf + lx->cmt_pos;
    while (len > 0 && is_c_space((unsigned char)*text)) {
        text++;
        len--;
    }
    kind = classify(&text, &len);
    if (kind == NCP_CMT_NONE)
        return;
    /* the pool holds at most the line's text plus one NUL per name */
    if (b->pool_used + len + 1 > NCP_BLOCK_POOL)
        len = NCP_BLOCK_POOL - b->pool_used - 1;
    b->comment_kind = kind;
    b->comment_off = b->pool_used;
    b->comment_len = (uint16_t)len;
    memcpy(b->pool + b->pool_used, text, (size_t)len);
    b->pool[b->pool_used + len] = '\0';
    b->pool_used = (uint16_t)(b->pool_used + len + 1);
}
