/* Writing the tool table back after G10 L1/L10/L11 (ncpar/analyzer.h), as
 * LinuxCNC does, but line by line: what the operator wrote (comments, the
 * order, the lines of tools nobody changed) stays as written. Entry k of
 * the interpreter is the k-th line the loader kept (tools.c), so the file
 * must have the lines the interpreter loaded; against a baseline (the
 * entries as last loaded or written), only the tools this interpreter
 * changed are written, so another writer's changes to other tools (a
 * second NC channel on the same table) are kept. */
#include "num_text.h"
#include "save_whole.h"
#include "stages.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* as the file would write it (num_text.h): no rewrite for a last bit */
static int same(double a, double b)
{
    return fabs(a - b) <= 1e-12 * fmax(1, fabs(b));
}

/* Entry k of a against t, more, no (a line's, or another analyzer's). */
static int same_entry(const struct ncp_analyzer *a, int k, const struct ncp_tool_entry *t,
                      const double *more, int no)
{
    const struct ncp_tool_entry *e = &a->tools[k];
    int eq = no == a->tool_no[k] && t->pocket == e->pocket && t->orientation == e->orientation &&
             same(t->z_offset, e->z_offset) && same(t->x_offset, e->x_offset) &&
             same(t->diameter, e->diameter) && same(t->frontangle, e->frontangle) &&
             same(t->backangle, e->backangle);
    for (int i = 0; eq && i < 7; i++)
        eq = same(more[i], a->tool_more[k][i]);
    return eq;
}

/* LinuxCNC's order: T P, the offsets X Y Z A B C U V W, D I J Q, the
 * comment; a zero is left out, as LinuxCNC leaves it. */
static size_t format_entry(const struct ncp_analyzer *a, int k, const char *comment,
                           size_t clen, char *out, size_t cap)
{
    static const char letters[] = "XYZABCUVW";
    const struct ncp_tool_entry *e = &a->tools[k];
    size_t n = (size_t)snprintf(out, cap, "T%d P%d", a->tool_no[k], e->pocket);
    char num[48];
    for (int ax = 0; ax < 9; ax++) {
        double v = ncp_tool_offset(a, k, ax);
        if (v != 0) {
            ncp_num_text(num, sizeof num, v, 1);
            n += (size_t)snprintf(out + n, cap - n, " %c%s", letters[ax], num);
        }
    }
    const struct { char c; double v; int plus; } rest[] = {
        { 'D', e->diameter, 0 }, { 'I', e->frontangle, 1 }, { 'J', e->backangle, 1 },
    };
    for (size_t i = 0; i < sizeof rest / sizeof rest[0]; i++) {
        if (rest[i].v != 0) {
            ncp_num_text(num, sizeof num, rest[i].v, rest[i].plus);
            n += (size_t)snprintf(out + n, cap - n, " %c%s", rest[i].c, num);
        }
    }
    if (e->orientation)
        n += (size_t)snprintf(out + n, cap - n, " Q%d", e->orientation);
    if (clen)
        n += (size_t)snprintf(out + n, cap - n, " %.*s", (int)clen, comment);
    return n < cap ? n : cap - 1;
}

char *ncp_analyzer_tool_table_text(const struct ncp_analyzer *a, const struct ncp_analyzer *base,
                                   const char *old, size_t len, size_t *out_len, int *changed)
{
    /* a rewritten line is at most 9 offsets, D I J Q of 40 characters each
     * and its comment */
    size_t cap = len + (size_t)a->n_tools * 640 + 1, n = 0;
    char *out = malloc(cap);
    if (!out)
        return NULL;
    *changed = 0;
    int k = 1;
    const char *p = old, *end = old + len;
    while (p < end) {
        const char *nl = memchr(p, '\n', (size_t)(end - p));
        const char *le = nl ? nl : end;
        struct ncp_tool_entry t;
        double more[7];
        int no;
        if (k < a->n_tools && ncp_tools_read_line(p, le, &t, more, &no)) {
            int kept = base && k < base->n_tools
                           ? same_entry(a, k, &base->tools[k], base->tool_more[k],
                                        base->tool_no[k])
                           : same_entry(a, k, &t, more, no);
            if (!kept) {
                const char *semi = memchr(p, ';', (size_t)(le - p));
                size_t clen = semi ? (size_t)(le - semi) : 0;
                while (clen && (semi[clen - 1] == '\r' || semi[clen - 1] == ' '))
                    clen--;
                n += format_entry(a, k, semi, clen, out + n, clen + 640);
                p = le;   /* the newline, if any, is copied below */
                *changed = 1;
            }
            k++;
        }
        size_t rest = (size_t)((nl ? nl + 1 : end) - p);
        memcpy(out + n, p, rest);
        n += rest;
        p += rest;
    }
    out[n] = '\0';
    *out_len = n;
    return out;
}

int ncp_analyzer_save_tool_table(const struct ncp_analyzer *a, const struct ncp_analyzer *base,
                                 const char *path, int *written, struct ncp_diag *d)
{
    *written = 0;
    size_t len;
    char *old = ncp_tools_read_file(path, &len, d);
    if (!old)
        return d->code;
    size_t n;
    int changed;
    char *text = ncp_analyzer_tool_table_text(a, base, old, len, &n, &changed);
    free(old);
    if (!text)
        return ncp_diag_set(d, NCP_ERR_IO, 0, 0, "tool table %s: out of memory", path);
    int rc = changed ? ncp_save_whole(path, text, n, "tool table", d) : NCP_OK;
    *written = changed && rc == NCP_OK;
    free(text);
    return rc;
}

int ncp_analyzer_same_tools(const struct ncp_analyzer *a, const struct ncp_analyzer *b)
{
    if (a->n_tools != b->n_tools)
        return 0;
    for (int k = 0; k < a->n_tools; k++)
        if (!same_entry(a, k, &b->tools[k], b->tool_more[k], b->tool_no[k]))
            return 0;
    return 1;
}

void ncp_analyzer_copy_tools(struct ncp_analyzer *dst, const struct ncp_analyzer *src)
{
    dst->n_tools = src->n_tools;
    memcpy(dst->tool_no, src->tool_no, (size_t)src->n_tools * sizeof src->tool_no[0]);
    memcpy(dst->tools, src->tools, (size_t)src->n_tools * sizeof src->tools[0]);
    memcpy(dst->tool_more, src->tool_more, (size_t)src->n_tools * sizeof src->tool_more[0]);
}
