/* ncp_lex_block(): one line -> one parsed block, following rs274's
 * read_items()/read_one_item(): optional '/', optional N word, then either an
 * O-word line or a sequence of items (letter words, parameter settings,
 * comments, a ';' tail). Only what rs274's reader itself rejects is an error
 * here; what the words mean is the analyzer's business. */
#include <stddef.h>
#include <string.h>
#include "lex_internal.h"
#include "lex_math.h"

static int is_digit(char c)
{
    return c >= '0' && c <= '9';
}

static int unsigned_integer(struct ncp_lexer *lx, double *out)
{
    double v = 0.0;
    int start = lx->pos;
    while (is_digit(lx->buf[lx->pos]))
        v = v * 10.0 + (lx->buf[lx->pos++] - '0');
    if (lx->pos == start)
        return ncp_lex_fail(lx, start, "Bad format unsigned integer");
    *out = v;
    return NCP_OK;
}

/* N word; "N10.5" is allowed and means line 10 */
static int line_number(struct ncp_lexer *lx)
{
    double frac;
    int rc;
    lx->pos++;
    if ((rc = unsigned_integer(lx, &lx->b->n_number)))
        return rc;
    lx->b->has_n = 1;
    if (lx->buf[lx->pos] == '.') {
        lx->pos++;
        return unsigned_integer(lx, &frac);
    }
    return NCP_OK;
}

static int duplicate(struct ncp_lexer *lx, char c, uint32_t *seen)
{
    uint32_t bit;
    if (c == 'g' || c == 'm' || c == '@' || c == '^')
        return NCP_OK; /* rs274 checks these by modal group, or not at all */
    bit = (c == '$') ? (1u << 26) : (1u << (c - 'a'));
    if (*seen & bit) {
        if (c == '$')
            return ncp_lex_fail(lx, lx->pos, "Multiple spindle choice ($) words on one line");
        if (c >= 'u' && c <= 'w')
            return ncp_lex_fail(lx, lx->pos, "Multiple %c words on one line", c - 32);
        return ncp_lex_fail(lx, lx->pos, "Multiple %c words on one line", c);
    }
    *seen |= bit;
    return NCP_OK;
}

/* A plain number: the common case, read without the general value reader.
 * (A literal of at most 252 characters is always finite.) */
static int plain_number(const struct ncp_lexer *lx)
{
    char c = lx->buf[lx->pos];
    if (c == '+' || c == '-')
        c = lx->buf[lx->pos + 1];
    return is_digit(c) || c == '.';
}

static int word(struct ncp_lexer *lx, char c, uint32_t *seen)
{
    struct ncp_block *b = lx->b;
    struct ncp_lex_val v;
    struct ncp_word *w;
    int pos = lx->pos, rc;

    if ((rc = duplicate(lx, c, seen)))
        return rc;
    if (b->n_words >= NCP_BLOCK_MAX_WORDS)
        return ncp_lex_fail(lx, pos, "Too many words on one line (more than %d)",
                            NCP_BLOCK_MAX_WORDS);
    lx->pos++;
    w = &b->words[b->n_words];
    if (plain_number(lx)) {
        if ((rc = ncp_lex_number(lx, &w->v.value)))
            return rc;
        w->v.start = w->v.len = 0;
        w->v.is_const = 1;
    } else {
        if ((rc = ncp_lex_real_value(lx, &v)))
            return rc;
        ncp_lex_to_expr(lx, &v, &w->v);
    }
    w->letter = (c >= 'a' && c <= 'z') ? (char)(c - 32) : c;
    w->col = lx->col[pos];
    b->n_words++;
    return NCP_OK;
}

static int expect_equal(struct ncp_lexer *lx)
{
    if (lx->buf[lx->pos] != '=')
        return ncp_lex_fail(lx, lx->pos, "Equal sign missing in parameter setting");
    lx->pos++;
    return NCP_OK;
}

/* #n=value, #[expr]=value, #<name>=value */
static int assignment(struct ncp_lexer *lx)
{
    struct ncp_block *b = lx->b;
    struct ncp_assign *a;
    struct ncp_lex_val v;
    int pos = lx->pos, rc;

    if (b->n_assign >= NCP_BLOCK_MAX_ASSIGN)
        return ncp_lex_fail(lx, pos, "Too many parameter settings on one line (more than %d)",
                            NCP_BLOCK_MAX_ASSIGN);
    a = &b->assign[b->n_assign];
    a->col = lx->col[pos];
    lx->pos++;
    if (lx->buf[lx->pos] == '<') {
        a->kind = NCP_ASSIGN_NAMED;
        if ((rc = ncp_lex_read_name(lx, &a->name_off, &a->name_len)))
            return rc;
        a->index.is_const = 1;
        a->index.value = 0.0;
        a->index.start = a->index.len = 0;
    } else {
        a->kind = NCP_ASSIGN_NUMBERED;
        a->name_off = a->name_len = 0;
        if ((rc = ncp_lex_integer_value(lx, &v)))
            return rc;
        if (v.is_const && (v.k < 1.0 || v.k >= NCP_LEX_PARAM_MAX))
            return ncp_lex_fail(lx, pos, "Parameter number out of range");
        /* rs274 refuses the target as it reads it, before the value, so
         * #5421=[1/0] is a read-only error, not a division by zero */
        if (v.is_const && ncp_param_readonly(ncp_trunc_int_round(v.k)))
            return ncp_lex_fail(lx, pos, "Parameter is readonly");
        ncp_lex_to_expr(lx, &v, &a->index);
    }
    if ((rc = expect_equal(lx)) || (rc = ncp_lex_real_value(lx, &v)))
        return rc;
    ncp_lex_to_expr(lx, &v, &a->value);
    b->n_assign++;
    return NCP_OK;
}

static int bad_character(struct ncp_lexer *lx, unsigned char c)
{
    if (c > ' ' && c <= 'z')
        return ncp_lex_fail(lx, lx->pos, "Bad character '%c' used", c);
    return ncp_lex_fail(lx, lx->pos, "Bad character '\\%03o' used", c);
}

static int items(struct ncp_lexer *lx)
{
    uint32_t seen = 0;
    int rc;
    while (lx->pos < lx->n) {
        unsigned char c = (unsigned char)lx->buf[lx->pos];
        if (c >= 'a' && c <= 'z') {
            /* canonical output carries XYZABC only, as rs274 -g: U V W are
             * rejected there the same way */
            if (c == 'n' || c == 'o' || c == 'v' ||
                ((c == 'u' || c == 'w') && !lx->uw_words))
                return bad_character(lx, c);
            rc = word(lx, (char)c, &seen);
        } else if (c == '#') {
            rc = assignment(lx);
        } else if (c == '(') {
            rc = ncp_lex_comment(lx);
        } else if (c == ';') {
            return NCP_OK;
        } else if (c == '$' || c == '@' || c == '^') {
            rc = word(lx, (char)c, &seen);
        } else {
            return bad_character(lx, c);
        }
        if (rc)
            return rc;
    }
    return NCP_OK;
}

/* rs274's read_items() reads the value of an M first on the line (after '/'
 * and N) before anything else: M98 there makes the line a Fanuc-style call,
 * read from three characters on (so "m098" leaves "8" behind, a bad
 * character, as in rs274); M99 there is marked, and lexed as usual. A value
 * that cannot be read leaves the line to the usual reader; one that depends
 * on parameters is marked M_VALUE and lexed as usual, for the flow to decide
 * with the parameters of the moment (lx->fanuc_m is its decision). */
static int fanuc_m(struct ncp_lexer *lx)
{
    struct ncp_block *b = lx->b;
    int pos = lx->pos;
    uint16_t code_mark = b->n_code, pool_mark = b->pool_used;
    struct ncp_lex_val v;
    lx->pos++;
    int rc = ncp_lex_integer_value(lx, &v);
    int m = rc == NCP_OK && v.is_const ? ncp_trunc_int(v.k) : -1;
    int by_value = rc == NCP_OK && !v.is_const;
    if (lx->fanuc_m)
        m = lx->fanuc_m;
    b->err.code = NCP_OK;
    b->err.col = 0;
    b->err.msg[0] = '\0';
    b->n_code = code_mark;
    b->pool_used = pool_mark;
    lx->pos = pos;
    if (m != 98 && m != 99 && !by_value)
        return items(lx);
    /* the fields the packed form carries, padding included, all set */
    memset(&b->oword, 0, offsetof(struct ncp_oword, args));
    b->oword.col = lx->col[pos];
    if (m != 98 && m != 99) {
        b->oword.kind = NCP_O_M_VALUE;
        return items(lx);
    }
    b->oword.kind = (uint8_t)(m == 98 ? NCP_O_M98 : NCP_O_M99);
    if (m == 98) {
        lx->pos = pos + 3 < lx->n ? pos + 3 : lx->n;
        return items(lx);
    }
    /* in a sub, rs274 allows only comments after the three characters */
    for (int k = pos + 3; k < lx->n && lx->buf[k] != ';';) {
        if (lx->buf[k] != '(') {
            b->oword.tail_col = lx->col[k];
            break;
        }
        while (k < lx->n && lx->buf[k] != ')')
            k++;
        k++;
    }
    return items(lx);
}

int ncp_lex_block(const char *text, size_t len, uint32_t line, uint64_t offset,
                  struct ncp_block *out)
{
    if (ncp_lex_fast(text, len, line, offset, out))
        return NCP_OK;
    return ncp_lex_block_general(text, len, line, offset, out);
}

int ncp_lex_line(const char *text, size_t avail, uint32_t line, uint64_t offset,
                 struct ncp_block *out, size_t *next)
{
    if (ncp_lex_fast_line(text, avail, line, offset, out, next))
        return NCP_OK;
    const char *nl = memchr(text, '\n', avail);
    size_t len = nl ? (size_t)(nl - text) : avail;
    *next = len + (nl ? 1 : 0);
    if (len > 0 && text[len - 1] == '\r')
        len--;
    return ncp_lex_block_general(text, len, line, offset, out);
}

static int lex_general(const char *text, size_t len, uint32_t line, uint64_t offset,
                       struct ncp_block *out, int uw_words, int fanuc)
{
    struct ncp_lexer lx;
    int rc;

    ncp_lex_init_block(out, len, line, offset);
    lx.b = out;
    lx.pos = 0;
    lx.depth = 0;
    lx.cmt_pos = -1;
    lx.cmt_len = 0;
    lx.uw_words = uw_words;
    lx.fanuc_m = fanuc;
    if ((rc = ncp_lex_squeeze(&lx, text, len)))
        return rc;
    if (lx.buf[0] == '/') {
        out->block_delete = 1;
        lx.pos++;
    }
    if (lx.buf[lx.pos] == 'n' && (rc = line_number(&lx)))
        return rc;
    if (lx.buf[lx.pos] == 'o')
        rc = ncp_lex_oword(&lx);
    else if (lx.buf[lx.pos] == 'm')
        rc = fanuc_m(&lx);
    else
        rc = items(&lx);
    if (rc)
        return rc;
    ncp_lex_store_comment(&lx);
    return NCP_OK;
}

int ncp_lex_block_general(const char *text, size_t len, uint32_t line, uint64_t offset,
                          struct ncp_block *out)
{
    return lex_general(text, len, line, offset, out, 0, 0);
}

int ncp_lex_block_profile(const char *text, size_t len, uint32_t line, uint64_t offset,
                          struct ncp_block *out)
{
    return lex_general(text, len, line, offset, out, 1, 0);
}

int ncp_lex_block_fanuc(const char *text, size_t len, uint32_t line, uint64_t offset, int m,
                        struct ncp_block *out)
{
    return lex_general(text, len, line, offset, out, 0, m == 98 || m == 99 ? m : 0);
}
