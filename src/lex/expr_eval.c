/* ncp_expr_eval(): runs a block's postfix bytecode. The arithmetic is the
 * same inline code constant folding used (lex_math.h), so run-time and
 * lex-time results agree to the bit. */
#include "lex_math.h"

#define EVAL_STACK NCP_BLOCK_MAX_CODE

static int fail(struct ncp_diag *d, const struct ncp_block *b,
                const struct ncp_bc_ins *ins, const char *msg)
{
    return ncp_diag_set(d, NCP_ERR_SEMANTIC, b->line, ins->col, "%s", msg);
}

/* A callback filled d; point it at this instruction. */
static int relocate(struct ncp_diag *d, const struct ncp_block *b,
                    const struct ncp_bc_ins *ins, int rc)
{
    if (d->code == NCP_OK)
        d->code = (uint16_t)(rc ? rc : NCP_ERR_SEMANTIC);
    d->line = b->line;
    d->col = ins->col;
    return d->code;
}

static int param(const struct ncp_block *b, const struct ncp_bc_ins *ins,
                 const struct ncp_param_ops *p, double *top, struct ncp_diag *d)
{
    int index, rc;
    const char *err = ncp_math_to_int(*top, &index);
    if (err)
        return fail(d, b, ins, err);
    if (index < 1 || index >= NCP_LEX_PARAM_MAX)
        return fail(d, b, ins, "Parameter number out of range");
    d->code = NCP_OK;
    rc = p->get_numbered(p->ctx, index, top, d);
    return rc ? relocate(d, b, ins, rc) : NCP_OK;
}

static int name_ok(const struct ncp_block *b, const struct ncp_bc_ins *ins)
{
    return (size_t)ins->a + ins->b < sizeof b->pool;
}

int ncp_expr_eval(const struct ncp_block *b, const struct ncp_expr *e,
                  const struct ncp_param_ops *p, double *out, struct ncp_diag *d)
{
    double st[EVAL_STACK + 1];
    int sp = 0, rc;
    unsigned i, end;
    const char *err;

    if (e->is_const) {
        *out = e->value;
        return NCP_OK;
    }
    end = (unsigned)e->start + e->len;
    if (end > NCP_BLOCK_MAX_CODE || e->len == 0)
        return ncp_diag_set(d, NCP_ERR_SEMANTIC, b->line, 0, "Bad expression code");
    for (i = e->start; i < end; i++) {
        const struct ncp_bc_ins *ins = &b->code[i];
        int op = ins->op;
        if (op <= NCP_BC_EXISTS) {
            if (sp >= EVAL_STACK)
                return fail(d, b, ins, "Bad expression code");
            if (op == NCP_BC_CONST) {
                st[sp++] = ins->k;
                continue;
            }
            if (op == NCP_BC_PARAM) {
                if (sp < 1)
                    return fail(d, b, ins, "Bad expression code");
                if ((rc = param(b, ins, p, &st[sp - 1], d)))
                    return rc;
                continue;
            }
            if (!name_ok(b, ins))
                return fail(d, b, ins, "Bad expression code");
            if (op == NCP_BC_EXISTS) {
                st[sp++] = p->exists_named(p->ctx, b->pool + ins->a, ins->b) ? 1.0 : 0.0;
                continue;
            }
            d->code = NCP_OK;
            rc = p->get_named(p->ctx, b->pool + ins->a, ins->b, &st[sp], d);
            if (rc)
                return relocate(d, b, ins, rc);
            sp++;
            continue;
        }
        if (op == NCP_BC_NOT || op > NCP_BC_EXISTS_NUM || sp < 1)
            return fail(d, b, ins, "Bad expression code");
        if ((op >= NCP_BC_POW && op <= NCP_BC_XOR) || op == NCP_BC_ATAN2) {
            if (sp < 2)
                return fail(d, b, ins, "Bad expression code");
            sp--;
            err = ncp_math_binary(op, &st[sp - 1], st[sp]);
        } else {
            err = ncp_math_unary(op, &st[sp - 1]);
        }
        if (!err && (ins->pad & NCP_LEX_CHECK_FINITE))
            err = ncp_math_finite(st[sp - 1]);
        if (err)
            return fail(d, b, ins, err);
    }
    if (sp != 1)
        return ncp_diag_set(d, NCP_ERR_SEMANTIC, b->line, 0, "Bad expression code");
    *out = st[0];
    return NCP_OK;
}
