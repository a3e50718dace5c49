/* Running a remapped M code as rs274 -i does (convert_remapped_code and
 * add_parameters): in the code's step of the line, "O<ngc> call" is run as
 * if read there, the argspec's words become the sub's local parameters
 * (#<p>, #<q>; with '@' positional #1, #2 instead), the sub's blocks run,
 * and at its return the line goes on with its next step. */
#include "floor.h"
#include "state.h"

#include "ncpar/blocks.h"

#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Codes whose built-in step runs when used inside their own remap (rs274's
 * find_remappings): the body may then call M6 to change the tool itself. */
static int builtin_in_own_remap(int m)
{
    return m == 0 || m == 1 || m == 60 || m == 6 || m == 61 || m == 7 || m == 8 || m == 9 ||
           (m >= 62 && m <= 68);
}

static int remap_in_progress(const struct ncp_analyzer *a, const struct ncp_remap *r)
{
    for (int k = 0; k < a->remap_level; k++)
        if (a->remap_running[k] == r)
            return 1;
    return 0;
}

struct remap_arg {
    char name;
    double value;
};

/* The argspec's words of the block, in its order; missing required ones are
 * an error worded as rs274's ("user-defined M400: missing: P"). */
static int remap_args(struct ncp_analyzer *a, const struct ncp_remap *r, uint16_t col,
                      struct remap_arg *args, int *n)
{
    const struct ncp_words *w = &a->w;
    char missing[64] = "", extra[32] = "";
    size_t nm = 0;
    *n = 0;
    for (const char *s = r->argspec; *s && *n < 26; s++) {
        int c = toupper((unsigned char)*s);
        if (c < 'A' || c > 'Z')
            continue;
        int seen = 0;
        for (int k = 0; k < *n; k++)
            seen |= args[k].name == tolower(c);
        if (seen)
            continue;
        if (NCP_HAS(w, c)) {
            args[*n].name = (char)tolower(c);
            args[(*n)++].value = w->v[NCP_LETTER(c)];
        } else if (isupper((unsigned char)*s) && !strchr(missing, c) && nm + 3 < sizeof missing) {
            if (nm)
                missing[nm++] = ',';
            missing[nm++] = (char)c;
            missing[nm] = '\0';
        }
    }
    if (strchr(r->argspec, '>')) {
        if (a->st.feed > 0.0 && *n < 26) {
            args[*n].name = 'f';
            args[(*n)++].value = a->st.feed;
        } else {
            strcat(extra, "F>0,");
        }
    }
    if (strchr(r->argspec, '^')) {
        if (a->st.speed > 0.0 && *n < 26) {
            args[*n].name = 's';
            args[(*n)++].value = a->st.speed;
        } else {
            strcat(extra, "S>0,");
        }
    }
    if (nm || extra[0])
        return ncp_an_error(a, col, "user-defined %s:%s%s%s", r->code, nm ? " missing: " : "",
                            missing, extra);
    return NCP_OK;
}

/* "O<ngc> call", with the arguments in brackets when the argspec has '@'
 * (rs274 writes them with four decimals). */
static int remap_call(struct ncp_analyzer *a, const struct ncp_remap *r, uint16_t col,
                      const struct remap_arg *args, int n)
{
    char text[1024];
    int len = snprintf(text, sizeof text, "o<%s> call", r->ngc);
    int positional = strchr(r->argspec, '@') != NULL;
    for (int k = 0; positional && k < n && len > 0 && (size_t)len < sizeof text; k++)
        len += snprintf(text + len, sizeof text - (size_t)len, " [%.4f]", args[k].value);
    if (len <= 0 || (size_t)len >= sizeof text)
        return ncp_an_error(a, col, "user-defined %s: call too long", r->code);
    struct ncp_block *b = malloc(sizeof *b);
    if (!b)
        return ncp_an_error(a, col, "out of memory");
    ncp_blocks_lex_text(text, (size_t)len, a->line, a->blk->offset, b);
    b->length = 0; /* not text of the program: nothing to quote */
    b->oword.col = col;
    int rc = b->err.code;
    if (rc != NCP_OK)
        a->err = b->err;
    else
        rc = ncp_flow_call_inline(a->flow, b, &a->err);
    free(b);
    for (int k = 0; rc == NCP_OK && !positional && k < n; k++)
        rc = ncp_params_set_named(a->params, &args[k].name, 1, args[k].value, &a->err);
    return rc;
}

/* The sub's blocks, each as the run loop runs one, up to its return. */
static int remap_body(struct ncp_analyzer *a)
{
    for (;;) {
        const struct ncp_block *b = NULL;
        struct ncp_diag d = {0};
        int rc = ncp_flow_next(a->flow, &b, &d);
        if (rc == NCP_FLOW_RETURNED)
            return NCP_OK;
        if (rc == NCP_END)
            return ncp_an_error(a, 0, "File ended with no percent sign or program end");
        if (rc != NCP_OK) {
            a->err = d;
            return rc;
        }
        a->blk = b;
        a->line = b->line;
        a->file_tag = ncp_flow_file_tag(a->flow);
        ncp_an_reline(a);
        if (b->err.code != NCP_OK) {
            a->err = b->err;
            return b->err.code;
        }
        rc = ncp_m7x_pending(a);
        if (rc == NCP_OK)
            rc = a->execute(a, b);
        if (rc == NCP_OK || rc == NCP_END) {
            int c = ncp_an_commit(a);
            if (c != NCP_OK)
                rc = c;
        }
        if (rc != NCP_OK)
            return rc; /* an error, or M2/M30 in the sub: the program ends */
    }
}

int ncp_remap_step(struct ncp_analyzer *a, int slot, int *ran)
{
    *ran = 0;
    const struct ncp_remap *r = ncp_remap_of_m(a->remaps, a->w.m[slot]);
    if (!r || !r->remappable || (builtin_in_own_remap(r->m) && remap_in_progress(a, r)))
        return NCP_OK;
    *ran = 1;
    uint16_t col = a->w.mcol[slot];
    if (a->remap_level >= NCP_REMAP_DEPTH)
        return ncp_an_error(a, col, "Too many nested remaps");
    struct remap_arg args[26];
    int n = 0;
    int rc = remap_args(a, r, col, args, &n);
    if (rc != NCP_OK)
        return rc;
    /* the sub's blocks overwrite the block in hand: kept for the line's
     * later steps */
    struct ncp_words *saved = malloc(sizeof *saved);
    if (!saved)
        return ncp_an_error(a, col, "out of memory");
    *saved = a->w;
    const struct ncp_block *blk = a->blk;
    uint32_t line = a->line;
    unsigned tag = a->file_tag;
    rc = remap_call(a, r, col, args, n);
    if (rc == NCP_OK) {
        a->remap_running[a->remap_level++] = r;
        rc = remap_body(a);
        a->remap_level--;
    }
    if (rc == NCP_OK) {
        a->w = *saved;
        a->blk = blk;
        a->line = line;
        a->file_tag = tag;
        ncp_an_reline(a);
    }
    free(saved);
    return rc;
}
