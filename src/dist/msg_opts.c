/* The LCM transport's options from the machine INI's [LCM] section: one
 * place, so the NCK's service, the HLC, the clock probes and every LLC seal
 * and check with the same key and keep to the same interface. */
#include "ncpar/auth.h"
#include "ncpar/dist.h"
#include "ncpar/msg.h"

#include <string.h>

int ncp_dist_msg_opts(const struct ncp_lcm_cfg *l, struct ncp_dist_msg_opts *o,
                      struct ncp_diag *d)
{
    memset(o, 0, sizeof *o);
    if (ncp_auth_key_path(o->key_file, sizeof o->key_file, NULL, l->key_file, d) != 0)
        return NCP_ERR_IO;
    o->opts.url = l->url;
    o->opts.prefix = l->prefix;
    o->opts.key_file = o->key_file;
    o->opts.interface = l->interface;
    o->opts.encrypt_public = l->status_needs_key;
    o->opts.max_age_ms = l->max_age_ms;
    return NCP_OK;
}
