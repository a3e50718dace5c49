/* A call the program did not write but rs274 makes in its place (G71's
 * "O<Q> call", a remapped code's "o<sub> call"), lexed and run inline as
 * the block at hand. */
#include "floor.h"
#include "stages.h"
#include "ncpar/blocks.h"

#include <stdlib.h>

int ncp_an_call_text(struct ncp_analyzer *a, const char *text, size_t len, uint16_t col)
{
    struct ncp_block *b = malloc(sizeof *b);
    if (!b)
        return ncp_an_error(a, col, "out of memory");
    ncp_blocks_lex_text(text, len, a->line, a->blk->offset, b);
    b->length = 0; /* not text of the program: nothing to quote */
    b->oword.col = col;
    int rc = b->err.code;
    if (rc != NCP_OK)
        a->err = b->err;
    else
        rc = ncp_flow_call_inline(a->flow, b, &a->err);
    free(b);
    return rc;
}

int ncp_an_sub_next(struct ncp_analyzer *a, const struct ncp_block **b)
{
    struct ncp_diag d = {0};
    *b = NULL;
    int rc = ncp_flow_next(a->flow, b, &d);
    if (rc == NCP_END)
        return ncp_an_error(a, 0, "File ended with no percent sign or program end");
    if (rc != NCP_OK && rc != NCP_FLOW_RETURNED)
        a->err = d;
    return rc;
}
