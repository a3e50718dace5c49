/* The machine INI as the front ends load it (run, serve). */
#include "machine.h"

#include "ncpar/analyzer.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int ncp_cli_load_machine(const char *path, struct ncp_machine_cfg *cfg)
{
    struct ncp_diag d;
    memset(&d, 0, sizeof d);
    ncp_machine_cfg_default(cfg);
    if (!path || ncp_machine_cfg_load(cfg, path, &d) == NCP_OK)
        return 0;
    /* the message names the file for callers without a line; here the
     * PATH:LINE prefix says it once */
    size_t n = strlen(path);
    const char *msg = d.msg;
    if (!strncmp(msg, path, n) && !strncmp(msg + n, ": ", 2))
        msg += n + 2;
    if (d.line)
        fprintf(stderr, "%s:%u: error: %s\n", path, d.line, msg);
    else
        fprintf(stderr, "%s: error: %s\n", path, msg);
    return -1;
}

int ncp_cli_set_config(const char *who, const char **config, const char *arg)
{
    if (*config && strcmp(*config, arg) != 0)
        return fprintf(stderr, "%s: --config and --ini name one INI, the machine's with its "
                               "[RS274NGC]: not '%s' and '%s'\n", who, *config, arg), -1;
    *config = arg;
    return 0;
}

int ncp_cli_check_tool_table(const char *path)
{
    struct ncp_diag d;
    memset(&d, 0, sizeof d);
    if (!path || ncp_tool_table_check(path, stderr, &d) == NCP_OK)
        return 0;
    fprintf(stderr, "%s: error: %s\n", path, d.msg);
    return -1;
}

int ncp_cli_load_vars(const char *who, const struct ncp_machine_cfg *cfg,
                      struct ncp_var_file **out)
{
    *out = NULL;
    const char *path = cfg->op.parameter_file;
    if (!path[0])
        return 0;
    struct ncp_var_file *vf = malloc(sizeof *vf);
    if (!vf)
        return fprintf(stderr, "%s: out of memory\n", who), 1;
    struct ncp_diag d;
    memset(&d, 0, sizeof d);
    int existed = 0;
    if (ncp_var_file_read(path, vf, &existed, &d) != NCP_OK) {
        if (d.line)
            fprintf(stderr, "%s:%u: error: %s\n", path, d.line, d.msg);
        else
            fprintf(stderr, "%s: error: %s\n", who, d.msg);
        free(vf);
        return d.line ? 2 : 1;
    }
    /* made at once, as LinuxCNC does: a folder it cannot be written to is
     * found now, not after the operator's first touch-off */
    if (!existed && ncp_var_file_write(path, vf, &d) != NCP_OK) {
        fprintf(stderr, "%s: error: %s ([RS274NGC] PARAMETER_FILE)\n", who, d.msg);
        free(vf);
        return 1;
    }
    *out = vf;
    return 0;
}
