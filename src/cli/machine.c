/* The machine INI as the front ends load it (run, serve). */
#include "machine.h"

#include <stdio.h>
#include <string.h>

int ncp_cli_load_machine(const char *path, struct ncp_machine_cfg *cfg)
{
    struct ncp_diag d;
    memset(&d, 0, sizeof d);
    ncp_machine_cfg_default(cfg);
    if (!path || ncp_machine_cfg_load(cfg, path, &d) == NCP_OK)
        return 0;
    if (d.line)
        fprintf(stderr, "%s:%u: error: %s\n", path, d.line, d.msg);
    else
        fprintf(stderr, "error: %s\n", d.msg);
    return -1;
}
