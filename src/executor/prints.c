/* (PRINT,...) text: rs274 writes it to its stdout as it runs the block, not
 * to the canonical stream, so the calls travel with the command (in program
 * order, through every layout) and whoever takes the command out writes them
 * where its user looks. Each carries its line end, so only slots with text
 * can hold one. */
#include "ncpar/executor.h"

int ncp_exec_write_prints(const struct ncp_cmd *cmd, FILE *f)
{
    if (cmd->text_used == 0)
        return 0;
    for (unsigned k = 0; k < cmd->n_ops && k < NCP_CMD_MAX_OPS; k++) {
        const struct ncp_canon *op = &cmd->ops[k];
        if (op->kind != NCP_C_PRINT)
            continue;
        size_t off = op->text_off, len = op->text_len;
        if (off > NCP_CMD_TEXT_POOL || len > NCP_CMD_TEXT_POOL - off)
            continue;
        if (len && fwrite(cmd->text + off, 1, len, f) != len)
            return -1;
    }
    return 0;
}
