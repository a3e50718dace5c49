/* Executor: completes one command slot independently of every other slot:
 * resolves its arc requests (centre from R, radius check with rs274's
 * tolerances, rotation count: the arithmetic is in ncpar/geom.h) and formats
 * the canonical text. Offsets and cutter compensation are the analyzer's. */
#ifndef NCPAR_EXECUTOR_H
#define NCPAR_EXECUTOR_H

#include <stddef.h>
#include <stdio.h>
#include "ncpar/canon.h"

/* Resolve requests in cmd->ops (ARC_REQUEST -> ARC_FEED, ...). On a geometry error
 * fills cmd->diag, sets NCP_CMD_F_ERROR and truncates n_ops to the ops before the
 * failing one. Returns the slot's error code: diag.code with NCP_CMD_F_ERROR, else
 * NCP_OK. */
int ncp_exec_resolve(struct ncp_cmd *cmd);

/* Format cmd->ops as rs274 -g lines (without counter and N column), each ending in
 * '\n', into cmd->out / cmd->out_len. Lines are never cut: if the next line does
 * not fit NCP_CMD_OUT_MAX (only absurd magnitudes or pool-sized texts can do that)
 * n_ops is truncated before it, NCP_CMD_F_ERROR set and diag (unless the slot
 * already had an error) gets NCP_ERR_LIMIT. NONE and unresolved requests print nothing. */
void ncp_exec_format(struct ncp_cmd *cmd);
/* The same text written to dst (NCP_CMD_OUT_MAX bytes of room) instead of
 * cmd->out: a thread that formats and writes a command itself can format
 * into its output buffer. cmd->out_len is set as ncp_exec_format sets it. */
void ncp_exec_format_into(struct ncp_cmd *cmd, char *dst);

/* The text of cmd's PRINT calls (a line each) to f, as rs274 writes them to
 * its stdout: the canonical text has none of it. Returns 0, or -1 when f
 * refused a write. */
int ncp_exec_write_prints(const struct ncp_cmd *cmd, FILE *f);

/* Both, as an executor thread does; and both with the text into dst. */
int ncp_exec_cmd(struct ncp_cmd *cmd);
int ncp_exec_cmd_into(struct ncp_cmd *cmd, char *dst);
/* ncp_exec_cmd_into with an error found here written to *diag, cmd->diag
 * left alone: for a command executed where it stands in a packed record of
 * the pipeline's ring, which ends at its calls (the bytes where a slot has
 * its diag belong to the records after it). Returns diag->code with
 * NCP_CMD_F_ERROR, else NCP_OK. */
int ncp_exec_cmd_into_diag(struct ncp_cmd *cmd, char *dst, struct ncp_diag *diag);

/* Longest "%.4f" text of any double (DBL_MAX has 309 integer digits) + NUL. */
#define NCP_FMT_FIXED4_MAX 328

/* Fast fixed-point "%.4f": writes into buf, returns length (NUL written too).
 * Byte-identical to printf's %.4f for every double (NaN and inf included).
 * buf must hold NCP_FMT_FIXED4_MAX bytes; 32 suffice when |v| < 1e14. */
size_t ncp_fmt_fixed4(char *buf, double v);

#endif
