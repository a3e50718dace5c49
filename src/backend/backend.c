/* Backend selection by the machine configuration. */
#include "ncpar/backend.h"

#include <string.h>

int ncp_backend_open(struct ncp_backend *b, const struct ncp_machine_cfg *cfg, FILE *log,
                     struct ncp_diag *d)
{
    memset(b, 0, sizeof *b);
    switch (cfg->backend) {
    case NCP_BACKEND_SIM: return ncp_backend_open_sim(b, cfg, d);
    case NCP_BACKEND_SOCKETCAN: return ncp_backend_open_socketcan(b, cfg, log, d);
    case NCP_BACKEND_LCM: return ncp_backend_open_lcm(b, cfg, d);
    }
    return ncp_diag_set(d, NCP_ERR_SEMANTIC, 0, 0, "unknown backend %d", (int)cfg->backend);
}

int ncp_backend_spec(const char *spec, struct ncp_machine_cfg *cfg, struct ncp_diag *d)
{
    if (!spec || !strcmp(spec, "sim")) {
        cfg->backend = NCP_BACKEND_SIM;
        return 0;
    }
    if (strncmp(spec, "socketcan", 9) != 0 || (spec[9] != 0 && spec[9] != ':'))
        return 1;
    if (spec[9] == ':') {
        const char *ifc = spec + 10;
        if (!*ifc || strlen(ifc) >= sizeof cfg->can.interface || strpbrk(ifc, " \t/:")) {
            ncp_diag_set(d, NCP_ERR_SEMANTIC, 0, 0, "--backend socketcan: bad interface name '%s'",
                         ifc);
            return -1;
        }
        snprintf(cfg->can.interface, sizeof cfg->can.interface, "%s", ifc);
    }
    cfg->backend = NCP_BACKEND_SOCKETCAN;
    return 0;
}
