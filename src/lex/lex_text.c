/* Line preparation, as rs274's read_text() + close_and_downcase(): reject
 * over-long lines, drop trailing white space, remove blanks and lower-case
 * letters outside comments, check that comments are closed and not nested.
 * Errors found here are reported by rs274 even on lines it then skips. */
#include <string.h>
#include "lex_internal.h"

static int is_c_space(unsigned char c)
{
    return c == ' ' || (c >= '\t' && c <= '\r');
}

static void finish(struct ncp_lexer *lx, int n, int endcol)
{
    lx->n = n;
    memset(lx->buf + n, 0, NCP_LEX_PAD);
    memset(lx->col + n, endcol > 255 ? 255 : endcol, NCP_LEX_PAD);
}

/* What close_and_downcase does with a byte outside comments. */
enum { K_COPY, K_DROP, K_UPPER, K_SPECIAL };

static const uint8_t kind_of[256] = {
    ['\0'] = K_SPECIAL, [' '] = K_DROP, ['\t'] = K_DROP, ['\r'] = K_DROP,
    ['('] = K_SPECIAL, [';'] = K_SPECIAL,
    ['A'] = K_UPPER, ['B'] = K_UPPER, ['C'] = K_UPPER, ['D'] = K_UPPER, ['E'] = K_UPPER,
    ['F'] = K_UPPER, ['G'] = K_UPPER, ['H'] = K_UPPER, ['I'] = K_UPPER, ['J'] = K_UPPER,
    ['K'] = K_UPPER, ['L'] = K_UPPER, ['M'] = K_UPPER, ['N'] = K_UPPER, ['O'] = K_UPPER,
    ['P'] = K_UPPER, ['Q'] = K_UPPER, ['R'] = K_UPPER, ['S'] = K_UPPER, ['T'] = K_UPPER,
    ['U'] = K_UPPER, ['V'] = K_UPPER, ['W'] = K_UPPER, ['X'] = K_UPPER, ['Y'] = K_UPPER,
    ['Z'] = K_UPPER,
};

static int bad_nul(struct ncp_lexer *lx, int n, size_t m)
{
    finish(lx, n, (int)m + 1);
    return ncp_lex_fail(lx, n, "Bad character '\\000' used");
}

/* Inside a comment starting at text[m] == '(': copies it through ')'. */
static int copy_comment(struct ncp_lexer *lx, const char *text, size_t len,
                        size_t *mp, int *np)
{
    size_t m = *mp;
    int n = *np, open = n;
    lx->buf[n] = '(';
    lx->col[n++] = (uint8_t)(m + 1);
    for (m++; m < len; m++) {
        char c = text[m];
        if (c == '\0')
            return bad_nul(lx, n, m);
        if (c == '(') {
            finish(lx, n, (int)m + 1);
            return ncp_lex_fail(lx, n, "Nested comment found");
        }
        lx->buf[n] = c;
        lx->col[n++] = (uint8_t)(m + 1);
        if (c == ')') {
            *mp = m;
            *np = n;
            return NCP_OK;
        }
    }
    finish(lx, n, (int)len + 1);
    return ncp_lex_fail(lx, open, "Unclosed comment found");
}

int ncp_lex_squeeze(struct ncp_lexer *lx, const char *text, size_t len)
{
    size_t m;
    int n = 0, rc;

    if (len >= NCP_LEX_TOO_LONG) {
        finish(lx, 0, 1);
        return ncp_diag_set(&lx->b->err, NCP_ERR_SYNTAX, lx->b->line, 0,
                            "Command too long");
    }
    while (len > 0 && is_c_space((unsigned char)text[len - 1]))
        len--;
    for (m = 0; m < len; m++) {
        unsigned char c = (unsigned char)text[m];
        switch (kind_of[c]) {
        case K_DROP:
            continue;
        case K_UPPER:
            c = (unsigned char)(c + 32);
            break;
        case K_SPECIAL:
            if (c == '\0')
                return bad_nul(lx, n, m);
            if (c == '(') {
                if ((rc = copy_comment(lx, text, len, &m, &n)))
                    return rc;
                continue;
            }
            /* ';': rs274 passes the rest of the line on literally */
            for (; m < len; m++) {
                if (text[m] == '\0')
                    return bad_nul(lx, n, m);
                lx->buf[n] = text[m];
                lx->col[n++] = (uint8_t)(m + 1);
            }
            finish(lx, n, (int)len + 1);
            return NCP_OK;
        default:
            break;
        }
        lx->buf[n] = (char)c;
        lx->col[n++] = (uint8_t)(m + 1);
    }
    finish(lx, n, (int)len + 1);
    return NCP_OK;
}
