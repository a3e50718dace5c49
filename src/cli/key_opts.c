#include "key_opts.h"

#include <stdio.h>
#include <string.h>

#include "ncpar/auth.h"

int ncp_cli_apply_key_file(const char *who, const char *path, struct ncp_machine_cfg *cfg)
{
    if (path == NULL)
        return 0;
    if (!*path || snprintf(cfg->lcm.key_file, sizeof cfg->lcm.key_file, "%s", path) >=
                      (int)sizeof cfg->lcm.key_file)
        return fprintf(stderr, "%s: --key-file: a path of 1 to %zu characters\n", who,
                       sizeof cfg->lcm.key_file - 1),
               -1;
    return 0;
}

int ncp_cli_check_key(const char *who, const struct ncp_machine_cfg *cfg)
{
    struct ncp_diag d;
    memset(&d, 0, sizeof d);
    struct ncp_auth *a = ncp_auth_open(NULL, cfg->lcm.key_file, 1, &d);
    if (a == NULL)
        return fprintf(stderr, "%s: error: %s\n", who, d.msg), -1;
    ncp_auth_free(a);
    return 0;
}
