/* Comments: COMMENT, MSG, DEBUG/LOG with parameter substitution (#5, #<name>,
 * %d %f %.Nf formats, as rs274 expands them), LOGOPEN/LOGAPPEND/LOGCLOSE.
 * PRINT is a call of its own that prints nothing in the canonical stream:
 * rs274 writes it to its stdout, cnc-run to stderr. */
#include "floor.h"
#include "stages.h"

#include <ctype.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#define NCP_EXPAND_MAX 512
/* The longest value text rs274 puts in a message: longer ones (a %f of
 * -1e21, a %d of 1e30) come out as ######, whatever the sign. */
#define NCP_VALUE_TEXT_MAX 29

struct ncp_expand {
    char buf[NCP_EXPAND_MAX];
    size_t n;
};

static void ncp_put(struct ncp_expand *e, const char *s, size_t len)
{
    if (len > sizeof e->buf - e->n)
        len = sizeof e->buf - e->n;
    memcpy(e->buf + e->n, s, len);
    e->n += len;
}

/* A "%d", "%f" or "%.Nf" directive: sets fmt and returns chars used, 0 if none. */
static size_t ncp_fmt_directive(const char *s, const char *end, char *fmt, struct ncp_expand *e)
{
    if (s + 1 >= end) {
        ncp_put(e, "%", 1);
        return 1;
    }
    if (s[1] == 'd') {
        memcpy(fmt, "%.0f", sizeof "%.0f");
        return 2;
    }
    if (s[1] == 'f') {
        memcpy(fmt, "%.4f", sizeof "%.4f");
        return 2;
    }
    if (s[1] == '.') {
        if (s + 3 < end && isdigit((unsigned char)s[2]) && s[3] == 'f') {
            fmt[0] = '%';
            fmt[1] = '.';
            fmt[2] = s[2];
            fmt[3] = 'f';
            fmt[4] = '\0';
            return 4;
        }
        ncp_put(e, ".", 1);
        return 2;
    }
    ncp_put(e, "%", 1);
    return 1;
}

static size_t ncp_param_ref(struct ncp_analyzer *a, const char *s, const char *end,
                            const char *fmt, struct ncp_expand *e)
{
    const char *p = s + 1;
    double v = 0.0;
    int found = 0;
    if (p < end && isdigit((unsigned char)*p)) {
        /* rs274 takes every digit and converts them as atoi does: a long
         * (saturating past 2^63-1) cut to its low 32 bits, so #4294967297
         * reads #1, while #2147483648 and longer runs read nothing. */
        uint64_t big = 0;
        int sat = 0;
        while (p < end && isdigit((unsigned char)*p)) {
            unsigned dg = (unsigned)(*p++ - '0');
            if (big > ((uint64_t)INT64_MAX - dg) / 10)
                sat = 1;
            else
                big = big * 10 + dg;
        }
        uint32_t low = sat ? UINT32_MAX : (uint32_t)big;
        double *slot = low < NCP_PARAMS_MAX ? ncp_params_slot(a->params, (int)low) : NULL;
        if (slot) {
            v = *slot;
            found = 1;
        }
    } else if (p < end && *p == '<') {
        char name[256];
        size_t n = 0;
        p++;
        while (p < end && *p != '>' && *p != ')') {
            if (!isspace((unsigned char)*p) && n < sizeof name - 1)
                name[n++] = (char)tolower((unsigned char)*p);
            p++;
        }
        if (p < end && *p == '>')
            p++;
        struct ncp_diag d;
        found = ncp_params_get_named(a->params, name, n, &v, &d) == NCP_OK;
    } else {
        ncp_put(e, "#", 1);
        return 1;
    }
    char val[NCP_VALUE_TEXT_MAX + 1];
    /* rs274 prints anything within its equality tolerance of zero as 0 */
    int n = found ? snprintf(val, sizeof val, fmt, fabs(v) < 0.0001 ? 0.0 : v) : -1;
    if (n < 0 || n > NCP_VALUE_TEXT_MAX)
        ncp_put(e, "######", 6);
    else
        ncp_put(e, val, (size_t)n);
    return (size_t)(p - s);
}

static void ncp_expand(struct ncp_analyzer *a, const char *s, size_t len, struct ncp_expand *e)
{
    const char *end = s + len;
    char fmt[8] = "%lf";
    e->n = 0;
    while (s < end) {
        if (*s == '%')
            s += ncp_fmt_directive(s, end, fmt, e);
        else if (*s == '#')
            s += ncp_param_ref(a, s, end, fmt, e);
        else
            ncp_put(e, s++, 1);
    }
}

int ncp_comment_run(struct ncp_analyzer *a)
{
    const struct ncp_block *b = a->blk;
    size_t off = b->comment_off < NCP_BLOCK_POOL ? b->comment_off : NCP_BLOCK_POOL;
    size_t len = b->comment_len <= NCP_BLOCK_POOL - off ? b->comment_len : 0;
    const char *t = b->pool + off;
    struct ncp_expand e;
    switch (b->comment_kind) {
    case NCP_CMT_PLAIN:
        while (len && isspace((unsigned char)*t)) {
            t++;
            len--;
        }
        ncp_an_emit_text(a, NCP_C_COMMENT, t, len);
        break;
    case NCP_CMT_MSG:
        ncp_an_emit_text(a, NCP_C_MESSAGE, t, len);
        break;
    case NCP_CMT_DEBUG: {
        double *on = ncp_params_slot(a->params, 5599);
        if (on && *on <= 0.0)
            break;
        ncp_expand(a, t, len, &e);
        ncp_an_emit_text(a, NCP_C_MESSAGE, e.buf, e.n);
        break;
    }
    case NCP_CMT_PRINT:
        /* with its line end, so that an empty one still has text to carry */
        ncp_expand(a, t, len, &e);
        if (e.n == sizeof e.buf)
            e.n--;
        e.buf[e.n++] = '\n';
        ncp_an_emit_text(a, NCP_C_PRINT, e.buf, e.n);
        break;
    case NCP_CMT_LOG:
        ncp_expand(a, t, len, &e);
        ncp_an_emit_text(a, NCP_C_LOG, e.buf, e.n);
        break;
    case NCP_CMT_LOGOPEN:
        ncp_an_emit_text(a, NCP_C_LOGOPEN, t, len);
        break;
    case NCP_CMT_LOGAPPEND:
        ncp_an_emit_text(a, NCP_C_LOGAPPEND, t, len);
        break;
    case NCP_CMT_LOGCLOSE:
        ncp_an_emit(a, NCP_C_LOGCLOSE);
        break;
    case NCP_CMT_ABORT:
        ncp_expand(a, t, len, &e);
        return ncp_an_error(a, 0, "%.*s", (int)e.n, e.buf);
    default:
        break;
    }
    return NCP_OK;
}
