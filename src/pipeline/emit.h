/* The last step of every command, the same in the serial reference, the
 * output thread and the analyzer writing inline (module-internal header). */
#ifndef NCP_PIPELINE_EMIT_H
#define NCP_PIPELINE_EMIT_H

#include "ncpar/canon.h"
#include "ncpar/executor.h"
#include "ncpar/pipeline.h"

/* Whether the run stops after slot c, whose output call returned `failed`:
 * its error (copied to *err), the program's end, or a failed emit. */
static inline int ncp_emit_stop(const struct ncp_cmd *c, int failed, struct ncp_diag *err,
                                int *emit_failed)
{
    int stop = 0;
    if (failed) {
        *emit_failed = 1;
        stop = 1;
    }
    if (c->flags & NCP_CMD_F_ERROR) {
        *err = c->diag;
        stop = 1;
    }
    return stop || (c->flags & NCP_CMD_F_END);
}

/* Hands a completed slot to the output; 1 when the run stops after it. */
static inline int ncp_emit_cmd(const struct ncp_cmd *c, const struct ncp_output *out,
                               struct ncp_diag *err, int *emit_failed)
{
    return ncp_emit_stop(c, out && out->emit(out->ctx, c) != 0, err, emit_failed);
}

/* Executes slot c and hands it on, its text formatted straight into the
 * output's buffer when the output offers one. */
static inline int ncp_exec_emit_cmd(struct ncp_cmd *c, const struct ncp_output *out,
                                    struct ncp_diag *err, int *emit_failed)
{
    char *dst = out && out->reserve ? out->reserve(out->ctx) : NULL;
    if (!dst) {
        ncp_exec_cmd(c);
        return ncp_emit_cmd(c, out, err, emit_failed);
    }
    ncp_exec_cmd_into(c, dst);
    return ncp_emit_stop(c, out->commit(out->ctx, c) != 0, err, emit_failed);
}

#endif
