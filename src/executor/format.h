/* Formatting with the error kept apart from the slot (module-internal
 * header). */
#ifndef NCP_EXECUTOR_FORMAT_H
#define NCP_EXECUTOR_FORMAT_H

#include "ncpar/executor.h"

/* ncp_exec_format_into, a line that does not fit reported in *g instead of
 * cmd->diag: the command may stand in a packed record, which ends at its
 * calls. */
void ncp_exec_format_diag(struct ncp_cmd *cmd, char *dst, struct ncp_diag *g);

#endif
