/* Executor: completes one command slot independently of every other slot:
 * arc geometry (centre from R, radius check with rs274's tolerances, rotation
 * count), cutter-compensation offset geometry, and the canonical text. */
#ifndef NCPAR_EXECUTOR_H
#define NCPAR_EXECUTOR_H

#include <stddef.h>
#include "ncpar/canon.h"

/* Resolve requests in cmd->ops (ARC_REQUEST -> ARC_FEED, ...). On a geometry error
 * fills cmd->diag, sets NCP_CMD_F_ERROR and truncates n_ops to the ops before the
 * failing one. Returns cmd->diag.code. */
int ncp_exec_resolve(struct ncp_cmd *cmd);

/* Format cmd->ops as rs274 -g lines (without counter and N column), each ending in
 * '\n', into cmd->out / cmd->out_len. */
void ncp_exec_format(struct ncp_cmd *cmd);

/* Both, as an executor thread does. */
int ncp_exec_cmd(struct ncp_cmd *cmd);

/* Fast fixed-point "%.4f": writes into buf (>= 32 bytes), returns length.
 * Byte-identical to printf's %.4f for every finite double. */
size_t ncp_fmt_fixed4(char *buf, double v);

#endif
