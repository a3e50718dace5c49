/* The last step of every command, the same in the serial reference, the
 * output thread and the analyzer writing inline (module-internal header). */
#ifndef NCP_PIPELINE_EMIT_H
#define NCP_PIPELINE_EMIT_H

#include "ncpar/canon.h"
#include "ncpar/pipeline.h"

/* Hands a completed slot to the output; 1 when the run stops after it: its
 * error (copied to *err), the program's end, or a failed emit (*emit_failed). */
static inline int ncp_emit_cmd(const struct ncp_cmd *c, const struct ncp_output *out,
                               struct ncp_diag *err, int *emit_failed)
{
    int stop = 0;
    if (out && out->emit(out->ctx, c) != 0) {
        *emit_failed = 1;
        stop = 1;
    }
    if (c->flags & NCP_CMD_F_ERROR) {
        *err = c->diag;
        stop = 1;
    }
    return stop || (c->flags & NCP_CMD_F_END);
}

#endif
