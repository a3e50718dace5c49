/* The machine INI as the front ends load it (run, serve). */
#include "machine.h"

#include "ncpar/analyzer.h"

#include <stdio.h>
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

int ncp_cli_check_tool_table(const char *path)
{
    struct ncp_diag d;
    memset(&d, 0, sizeof d);
    if (!path || ncp_tool_table_check(path, stderr, &d) == NCP_OK)
        return 0;
    fprintf(stderr, "%s: error: %s\n", path, d.msg);
    return -1;
}
