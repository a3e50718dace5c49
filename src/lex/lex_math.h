/* Expression arithmetic shared by constant folding (lex time) and
 * ncp_expr_eval() (analyzer time). Both paths call these same inline functions,
 * so a folded constant is bit-identical to the value the bytecode would give.
 * The formulas follow rs274's evaluation exactly, including where it computes in
 * x87 long double (trig functions and the degree conversions). */
#ifndef NCP_LEX_MATH_H
#define NCP_LEX_MATH_H

#include <limits.h>
#include <math.h>
#include "ncpar/lex.h"

/* EQ/NE treat numbers closer than this as equal. The installed rs274 (2.9)
 * uses 0.0001 and plain comparisons for LE/GE; later sources use 1e-6 and a
 * tolerance in LE/GE too. We follow the installed oracle. */
#define NCP_LEX_EQ_TOL 0.0001

/* Parameter numbers rs274 accepts: 1 .. NCP_LEX_PARAM_MAX-1. */
#define NCP_LEX_PARAM_MAX 5602

/* Flag in ncp_bc_ins.pad: the instruction ends an rs274 "real value", whose
 * result must be finite (rs274 checks NaN/inf there and nowhere else). */
#define NCP_LEX_CHECK_FINITE 0x01

/* rs274 converts with a 32-bit cvttsd2si: out-of-range values become INT_MIN.
 * C leaves that undefined, so spell it out. */
static inline int ncp_math_trunc_int(double t)
{
    return ncp_trunc_int(t);
}

/* rs274's "integer value": within 0.0001 of an integer, else an error. */
static inline const char *ncp_math_to_int(double v, int *out)
{
    return ncp_rs274_int(v, out) == 0 ? 0 : "Non integer value for integer";
}

static inline const char *ncp_math_finite(double v)
{
    if (isnan(v))
        return "Calculation resulted in 'not a number'";
    if (isinf(v))
        return "Calculation resulted in 'infinity'";
    return 0;
}

static inline double ncp_math_to_deg(double rad)
{
    /* rs274: (rad * 180.0) in double, then divided by M_PIl in long double */
    return (double)((long double)(rad * 180.0) / M_PIl);
}

static inline long double ncp_math_to_rad(double deg)
{
    return ((long double)deg * M_PIl) / 180.0L;
}

/* *l = *l op r; returns an error message or NULL. */
static inline const char *ncp_math_binary(int op, double *l, double r)
{
    double x = *l;
    switch (op) {
    case NCP_BC_POW:
        if (x < 0.0 && floor(r) != r)
            return "Attempt to raise negative to non integer power";
        x = pow(x, r);
        break;
    case NCP_BC_MUL: x = x * r; break;
    case NCP_BC_DIV:
        if (r == 0.0)
            return "Attempt to divide by zero";
        x = x / r;
        break;
    case NCP_BC_MOD:
        x = fmod(x, r);
        if (x < 0.0)
            x = x + fabs(r);
        break;
    case NCP_BC_ADD: x = x + r; break;
    case NCP_BC_SUB: x = x - r; break;
    case NCP_BC_EQ: x = (fabs(x - r) < NCP_LEX_EQ_TOL) ? 1.0 : 0.0; break;
    case NCP_BC_NE: x = (fabs(x - r) >= NCP_LEX_EQ_TOL) ? 1.0 : 0.0; break;
    case NCP_BC_GT: x = (x > r) ? 1.0 : 0.0; break;
    case NCP_BC_GE: x = (x >= r) ? 1.0 : 0.0; break;
    case NCP_BC_LT: x = (x < r) ? 1.0 : 0.0; break;
    case NCP_BC_LE: x = (x <= r) ? 1.0 : 0.0; break;
    case NCP_BC_AND: x = (x == 0.0 || r == 0.0) ? 0.0 : 1.0; break;
    case NCP_BC_OR: x = (x != 0.0 || r != 0.0) ? 1.0 : 0.0; break;
    case NCP_BC_XOR: x = ((x == 0.0) != (r == 0.0)) ? 1.0 : 0.0; break;
    case NCP_BC_ATAN2: x = ncp_math_to_deg(atan2(x, r)); break;
    default:
        return "Unknown operation";
    }
    *l = x;
    return 0;
}

/* *v = op(*v); returns an error message or NULL. */
static inline const char *ncp_math_unary(int op, double *v)
{
    double x = *v;
    switch (op) {
    case NCP_BC_NEG: x = -x; break;
    case NCP_BC_ABS:
        if (x < 0.0)
            x = -1.0 * x; /* keeps -0.0 as rs274 does */
        break;
    case NCP_BC_ACOS:
        if (x < -1.0 || x > 1.0)
            return "Argument to acos out of range";
        x = ncp_math_to_deg(acos(x));
        break;
    case NCP_BC_ASIN:
        if (x < -1.0 || x > 1.0)
            return "Argument to asin out of range";
        x = ncp_math_to_deg(asin(x));
        break;
    case NCP_BC_COS: x = (double)cosl(ncp_math_to_rad(x)); break;
    case NCP_BC_SIN: x = (double)sinl(ncp_math_to_rad(x)); break;
    case NCP_BC_TAN: x = (double)tanl(ncp_math_to_rad(x)); break;
    case NCP_BC_EXP: x = exp(x); break;
    case NCP_BC_FIX: x = floor(x); break;
    case NCP_BC_FUP: x = ceil(x); break;
    case NCP_BC_LN:
        if (x <= 0.0)
            return "Zero or negative argument to ln";
        x = log(x);
        break;
    case NCP_BC_ROUND:
        x = (double)ncp_math_trunc_int(x + ((x < 0.0) ? -0.5 : 0.5));
        break;
    case NCP_BC_SQRT:
        if (x < 0.0)
            return "Negative argument to sqrt";
        x = sqrt(x);
        break;
    case NCP_BC_EXISTS_NUM: {
        int index;
        const char *err = ncp_math_to_int(x, &index);
        if (err)
            return err;
        x = (index >= 1 && index < NCP_LEX_PARAM_MAX) ? 1.0 : 0.0;
        break;
    }
    default:
        return "Unknown operation";
    }
    *v = x;
    return 0;
}

#endif
