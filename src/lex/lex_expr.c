/* Values and expressions, read the way rs274 reads them (read_real_value,
 * read_real_expression, read_operation, read_unary, read_parameter), but
 * compiled instead of evaluated: constant sub-expressions fold at once with the
 * shared arithmetic of lex_math.h, anything that reads a parameter becomes
 * postfix bytecode in the block. Operands of the operator being reduced are
 * always the last two values compiled, so their code is contiguous at the end
 * of the block's code array. */
#include <string.h>
#include "lex_internal.h"
#include "lex_math.h"

#define OP_RBRACKET (-1)

static int emit(struct ncp_lexer *lx, int op, int pos, double k)
{
    struct ncp_block *b = lx->b;
    struct ncp_bc_ins *ins;
    if (b->n_code >= NCP_BLOCK_MAX_CODE)
        return ncp_lex_fail(lx, pos, "Expression too complex (more than %d operations)",
                            NCP_BLOCK_MAX_CODE);
    ins = &b->code[b->n_code++];
    ins->op = (uint8_t)op;
    ins->pad = 0;
    ins->a = ins->b = 0;
    ins->col = lx->col[pos];
    ins->k = k;
    return NCP_OK;
}

/* Gives a constant operand its CONST instruction at code position `at`. */
static int insert_const(struct ncp_lexer *lx, int at, int pos, double k)
{
    struct ncp_block *b = lx->b;
    int tail = b->n_code - at;
    int rc = emit(lx, NCP_BC_CONST, pos, k);
    if (rc)
        return rc;
    if (tail > 0) {
        struct ncp_bc_ins c = b->code[b->n_code - 1];
        memmove(&b->code[at + 1], &b->code[at], (size_t)tail * sizeof c);
        b->code[at] = c;
    }
    return NCP_OK;
}

static int fold_error(struct ncp_lexer *lx, int pos, const char *msg)
{
    return ncp_lex_fail(lx, pos, "%s", msg);
}

static int binary(struct ncp_lexer *lx, int op, int pos, struct ncp_lex_val *l,
                  const struct ncp_lex_val *r)
{
    int rc;
    if (l->is_const && r->is_const) {
        const char *err = ncp_math_binary(op, &l->k, r->k);
        return err ? fold_error(lx, pos, err) : NCP_OK;
    }
    if (l->is_const) {
        if ((rc = insert_const(lx, r->start, pos, l->k)))
            return rc;
        l->start = r->start;
        l->is_const = 0;
    } else if (r->is_const && (rc = emit(lx, NCP_BC_CONST, pos, r->k))) {
        return rc;
    }
    return emit(lx, op, pos, 0.0);
}

static int unary(struct ncp_lexer *lx, int op, int pos, struct ncp_lex_val *v)
{
    if (v->is_const) {
        const char *err = ncp_math_unary(op, &v->k);
        return err ? fold_error(lx, pos, err) : NCP_OK;
    }
    return emit(lx, op, pos, 0.0);
}

static int precedence(int op)
{
    switch (op) {
    case OP_RBRACKET: return 1;
    case NCP_BC_AND: case NCP_BC_OR: case NCP_BC_XOR: return 2;
    case NCP_BC_EQ: case NCP_BC_NE: case NCP_BC_GT:
    case NCP_BC_GE: case NCP_BC_LT: case NCP_BC_LE: return 3;
    case NCP_BC_ADD: case NCP_BC_SUB: return 4;
    case NCP_BC_POW: return 6;
    default: return 5; /* * / mod */
    }
}

/* Two-letter operators: `first` was read, `next` decides. */
static int word_op(struct ncp_lexer *lx, const char *rest, int op, int pos,
                   const char *fail)
{
    size_t n = strlen(rest);
    if (strncmp(lx->buf + lx->pos, rest, n) != 0) {
        ncp_lex_fail(lx, pos, "%s", fail);
        return -2;
    }
    lx->pos += (int)n;
    return op;
}

/* Returns the operator (an ncp_bc_op or OP_RBRACKET), or -2 after storing
 * an error. */
static int read_operation(struct ncp_lexer *lx, int open)
{
    int pos = lx->pos;
    char c = lx->buf[lx->pos++];
    int r;
    switch (c) {
    case '+': return NCP_BC_ADD;
    case '-': return NCP_BC_SUB;
    case '/': return NCP_BC_DIV;
    case ']': return OP_RBRACKET;
    case '*':
        if (lx->buf[lx->pos] == '*') {
            lx->pos++;
            return NCP_BC_POW;
        }
        return NCP_BC_MUL;
    case 'a':
        r = word_op(lx, "nd", NCP_BC_AND, pos, "Unknown operation name starting with a");
        break;
    case 'm':
        r = word_op(lx, "od", NCP_BC_MOD, pos, "Unknown operation name starting with m");
        break;
    case 'o':
        r = word_op(lx, "r", NCP_BC_OR, pos, "Unknown operation name starting with o");
        break;
    case 'x':
        r = word_op(lx, "or", NCP_BC_XOR, pos, "Unknown operation name starting with x");
        break;
    case 'e':
        r = word_op(lx, "q", NCP_BC_EQ, pos, "Unknown operation name starting with e");
        break;
    case 'n':
        r = word_op(lx, "e", NCP_BC_NE, pos, "Unknown operation name starting with n");
        break;
    case 'g':
        if (lx->buf[lx->pos] == 't') {
            lx->pos++;
            return NCP_BC_GT;
        }
        r = word_op(lx, "e", NCP_BC_GE, pos, "Unknown operation name starting with g");
        break;
    case 'l':
        if (lx->buf[lx->pos] == 't') {
            lx->pos++;
            return NCP_BC_LT;
        }
        r = word_op(lx, "e", NCP_BC_LE, pos, "Unknown operation name starting with l");
        break;
    case '\0':
        lx->pos--;
        ncp_lex_fail(lx, open, "Unclosed expression");
        return -2;
    default:
        ncp_lex_fail(lx, pos, "Unknown operation");
        return -2;
    }
    return r;
}

/* [ v op v op ... ]: rs274's operator-precedence reduction, left to right
 * within a level; the precedence levels bound the stacks. */
int ncp_lex_expression(struct ncp_lexer *lx, struct ncp_lex_val *out)
{
    struct ncp_lex_val vals[8];
    int ops[8], opos[8];
    int nops = 0, open = lx->pos, rc;

    lx->pos++;
    if ((rc = ncp_lex_real_value(lx, &vals[0])))
        return rc;
    for (;;) {
        int pos = lx->pos;
        int op = read_operation(lx, open);
        if (op == -2)
            return NCP_ERR_SYNTAX;
        while (nops > 0 && precedence(ops[nops - 1]) >= precedence(op)) {
            nops--;
            if ((rc = binary(lx, ops[nops], opos[nops], &vals[nops], &vals[nops + 1])))
                return rc;
        }
        if (op == OP_RBRACKET)
            break;
        ops[nops] = op;
        opos[nops] = pos;
        nops++;
        if ((rc = ncp_lex_real_value(lx, &vals[nops])))
            return rc;
    }
    *out = vals[0];
    return NCP_OK;
}

int ncp_lex_read_name(struct ncp_lexer *lx, uint16_t *off, uint16_t *len)
{
    struct ncp_block *b = lx->b;
    int start = ++lx->pos, end = start;
    while (end < lx->n && lx->buf[end] != '>')
        end++;
    if (end >= lx->n)
        return ncp_lex_fail(lx, start - 1, "Named parameter not terminated");
    if (b->pool_used + (end - start) + 1 > NCP_BLOCK_POOL)
        return ncp_lex_fail(lx, start - 1, "Too many names on one line");
    *off = b->pool_used;
    *len = (uint16_t)(end - start);
    memcpy(b->pool + b->pool_used, lx->buf + start, (size_t)(end - start));
    b->pool[b->pool_used + (end - start)] = '\0';
    b->pool_used = (uint16_t)(b->pool_used + (end - start) + 1);
    lx->pos = end + 1;
    return NCP_OK;
}

static int named_ref(struct ncp_lexer *lx, int op, int pos, struct ncp_lex_val *v)
{
    uint16_t off = 0, len = 0;
    int rc = ncp_lex_read_name(lx, &off, &len);
    if (rc)
        return rc;
    v->is_const = 0;
    v->start = lx->b->n_code;
    if ((rc = emit(lx, op, pos, 0.0)))
        return rc;
    lx->b->code[lx->b->n_code - 1].a = off;
    lx->b->code[lx->b->n_code - 1].b = len;
    return NCP_OK;
}

/* Checks a constant parameter number now, as rs274 does while reading. */
static int const_index(struct ncp_lexer *lx, int pos, double k, int *index)
{
    const char *err = ncp_math_to_int(k, index);
    if (err)
        return fold_error(lx, pos, err);
    return NCP_OK;
}

/* #n, ##n, #[expr], #<name> as a value */
static int parameter(struct ncp_lexer *lx, struct ncp_lex_val *v)
{
    int pos = lx->pos, rc, index = 0;
    lx->pos++;
    if (lx->buf[lx->pos] == '<')
        return named_ref(lx, NCP_BC_NAMED, pos, v);
    if ((rc = ncp_lex_real_value(lx, v)))
        return rc;
    if (v->is_const) {
        if ((rc = const_index(lx, pos + 1, v->k, &index)))
            return rc;
        if (index < 1 || index >= NCP_LEX_PARAM_MAX)
            return ncp_lex_fail(lx, pos, "Parameter number out of range");
        v->is_const = 0;
        v->start = lx->b->n_code;
        if ((rc = emit(lx, NCP_BC_CONST, pos, (double)index)))
            return rc;
    }
    return emit(lx, NCP_BC_PARAM, pos, 0.0);
}

/* EXISTS[#<name>] (or EXISTS[#n]: 1 when n is a valid parameter number) */
static int exists_arg(struct ncp_lexer *lx, int fpos, struct ncp_lex_val *v)
{
    int rc, index = 0, pos;
    lx->pos++;
    pos = lx->pos;
    if (lx->buf[pos] != '#')
        return ncp_lex_fail(lx, pos, "Expected # reading parameter");
    lx->pos++;
    if (lx->buf[lx->pos] == '<') {
        if ((rc = named_ref(lx, NCP_BC_EXISTS, fpos, v)))
            return rc;
    } else {
        if ((rc = ncp_lex_real_value(lx, v)))
            return rc;
        /* rs274 reads the number as any parameter's, computed or not, and
         * asks only whether it is a valid one */
        if (!v->is_const) {
            if ((rc = emit(lx, NCP_BC_EXISTS_NUM, pos + 1, 0.0)))
                return rc;
        } else if ((rc = const_index(lx, pos + 1, v->k, &index)))
            return rc;
        else
            v->k = (index >= 1 && index < NCP_LEX_PARAM_MAX) ? 1.0 : 0.0;
    }
    if (lx->buf[lx->pos] != ']')
        return ncp_lex_fail(lx, lx->pos, "Expected ] reading bracketed parameter");
    lx->pos++;
    return NCP_OK;
}

static int match(struct ncp_lexer *lx, const char *rest)
{
    size_t n = strlen(rest);
    if (strncmp(lx->buf + lx->pos, rest, n) != 0)
        return 0;
    lx->pos += (int)n;
    return 1;
}

#define OP_EXISTS 1000

/* Name of a unary function; returns its op or -2 after storing an error. */
static int unary_name(struct ncp_lexer *lx)
{
    int pos = lx->pos;
    char c = lx->buf[lx->pos++];
    const char *fail = "Unknown word where unary operation could be";
    switch (c) {
    case 'a':
        if (match(lx, "bs")) return NCP_BC_ABS;
        if (match(lx, "cos")) return NCP_BC_ACOS;
        if (match(lx, "sin")) return NCP_BC_ASIN;
        if (match(lx, "tan")) return NCP_BC_ATAN2;
        fail = "Unknown word starting with a";
        break;
    case 'c':
        if (match(lx, "os")) return NCP_BC_COS;
        fail = "Unknown word starting with c";
        break;
    case 'e':
        if (match(lx, "xp")) return NCP_BC_EXP;
        if (match(lx, "xists")) return OP_EXISTS;
        fail = "Unknown word starting with e";
        break;
    case 'f':
        if (match(lx, "ix")) return NCP_BC_FIX;
        if (match(lx, "up")) return NCP_BC_FUP;
        fail = "Unknown word starting with f";
        break;
    case 'l':
        if (match(lx, "n")) return NCP_BC_LN;
        fail = "Unknown word starting with l";
        break;
    case 'r':
        if (match(lx, "ound")) return NCP_BC_ROUND;
        fail = "Unknown word starting with r";
        break;
    case 's':
        if (match(lx, "in")) return NCP_BC_SIN;
        if (match(lx, "qrt")) return NCP_BC_SQRT;
        fail = "Unknown word starting with s";
        break;
    case 't':
        if (match(lx, "an")) return NCP_BC_TAN;
        fail = "Unknown word starting with t";
        break;
    default:
        break;
    }
    ncp_lex_fail(lx, pos, "%s", fail);
    return -2;
}

static int unary_call(struct ncp_lexer *lx, struct ncp_lex_val *v)
{
    int pos = lx->pos, rc;
    int op = unary_name(lx);
    struct ncp_lex_val rhs;
    if (op == -2)
        return NCP_ERR_SYNTAX;
    if (lx->buf[lx->pos] != '[')
        return ncp_lex_fail(lx, lx->pos, "Left bracket missing after unary operation name");
    if (op == OP_EXISTS)
        return exists_arg(lx, pos, v);
    if ((rc = ncp_lex_expression(lx, v)))
        return rc;
    if (op != NCP_BC_ATAN2)
        return unary(lx, op, pos, v);
    if (lx->buf[lx->pos] != '/')
        return ncp_lex_fail(lx, lx->pos, "Slash missing after first atan argument");
    lx->pos++;
    if (lx->buf[lx->pos] != '[')
        return ncp_lex_fail(lx, lx->pos, "Left bracket missing after slash with atan");
    if ((rc = ncp_lex_expression(lx, &rhs)))
        return rc;
    return binary(lx, NCP_BC_ATAN2, pos, v, &rhs);
}

static int is_digit(char c)
{
    return c >= '0' && c <= '9';
}

static int real_value(struct ncp_lexer *lx, struct ncp_lex_val *v)
{
    int pos = lx->pos, rc;
    char c = lx->buf[pos], c1 = lx->buf[pos + 1];

    v->k = 0.0;
    v->start = 0;
    v->is_const = 1;

    if (c == '\0')
        return ncp_lex_fail(lx, pos, "No characters found in reading real value");
    if (c == '[') {
        rc = ncp_lex_expression(lx, v);
    } else if (c == '#') {
        rc = parameter(lx, v);
    } else if ((c == '+' || c == '-') && c1 && !is_digit(c1) && c1 != '.') {
        lx->pos++;
        rc = ncp_lex_real_value(lx, v);
        if (!rc && c == '-')
            rc = unary(lx, NCP_BC_NEG, pos, v);
    } else if (c >= 'a' && c <= 'z') {
        rc = unary_call(lx, v);
    } else {
        v->is_const = 1;
        v->start = 0;
        rc = ncp_lex_number(lx, &v->k);
    }
    if (rc)
        return rc;
    if (v->is_const) {
        const char *err = ncp_math_finite(v->k);
        if (err)
            return fold_error(lx, pos, err);
    } else {
        struct ncp_bc_ins *last = &lx->b->code[lx->b->n_code - 1];
        if (last->op >= NCP_BC_NEG)
            last->pad |= NCP_LEX_CHECK_FINITE;
    }
    return NCP_OK;
}

int ncp_lex_real_value(struct ncp_lexer *lx, struct ncp_lex_val *v)
{
    int rc;
    if (lx->depth >= NCP_LEX_MAX_DEPTH)
        return ncp_lex_fail(lx, lx->pos, "Expression nested too deeply (more than %d levels)",
                            NCP_LEX_MAX_DEPTH);
    lx->depth++;
    rc = real_value(lx, v);
    lx->depth--;
    return rc;
}

/* rs274's read_integer_value: a value that must be close to an integer. A
 * constant is checked and rounded now; computed ones are rounded at run time. */
int ncp_lex_integer_value(struct ncp_lexer *lx, struct ncp_lex_val *v)
{
    int pos = lx->pos, rc, i = 0;
    if ((rc = ncp_lex_real_value(lx, v)))
        return rc;
    if (v->is_const) {
        if ((rc = const_index(lx, pos, v->k, &i)))
            return rc;
        v->k = (double)i;
    }
    return NCP_OK;
}

void ncp_lex_to_expr(const struct ncp_lexer *lx, const struct ncp_lex_val *v,
                     struct ncp_expr *e)
{
    e->is_const = v->is_const;
    if (v->is_const) {
        e->value = v->k;
        e->start = e->len = 0;
    } else {
        e->value = 0.0;
        e->start = v->start;
        e->len = (uint16_t)(lx->b->n_code - v->start);
    }
}
