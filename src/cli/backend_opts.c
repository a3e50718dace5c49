#include "backend_opts.h"
#include "key_opts.h"

#include "ncpar/backend.h"
#include "ncpar/dist.h"
#include "ncpar/msg.h"

#include <stdio.h>
#include <string.h>

/* The distributed NCK at the INI's or --dp's point. */
static int apply_lcm(const struct ncp_cli_backend_opts *o, struct ncp_machine_cfg *cfg)
{
    if (o->dp)
        cfg->lcm.dp = o->dp;
    if (o->lcm_url) {
        struct ncp_msg_url u;
        struct ncp_diag d;
        memset(&d, 0, sizeof d);
        if (strlen(o->lcm_url) >= sizeof cfg->lcm.url || ncp_msg_parse_url(o->lcm_url, &u, &d))
            return fprintf(stderr, "%s: --lcm-url: %s\n", o->who, d.msg[0] ? d.msg : "too long"),
                   -1;
        snprintf(cfg->lcm.url, sizeof cfg->lcm.url, "%s", o->lcm_url);
    }
    if (o->virtual_clock)
        return fprintf(stderr, "%s: --backend lcm runs with its axes in real time: it needs "
                               "--clock real\n", o->who), -1;
    if (cfg->nck == NCP_NCK_ADCAI && cfg->lcm.dp == 5)
        return fprintf(stderr, "%s: --backend lcm: [PLANNER] NCK = adcai has no DP 5: its fine "
                               "setpoints (fineIPObuf) are DP 4; choose --dp 1, 2, 3 or 4 (the "
                               "INI's [LCM] DP defaults to 5)\n", o->who), -1;
    if (cfg->nck == NCP_NCK_ADCAI ? !ncp_dist_adcai_dp(cfg->lcm.dp)
                                  : cfg->lcm.dp < 1 || cfg->lcm.dp > 5)
        return fprintf(stderr, "%s: --backend lcm: [PLANNER] NCK = %s has no DP %d (ADCBI: DP "
                               "1-5; ADCAI: DP 1-4)\n", o->who,
                       cfg->nck == NCP_NCK_ADCAI ? "adcai" : "adcbi", cfg->lcm.dp), -1;
    return ncp_cli_apply_key_file(o->who, o->key_file, cfg) || ncp_cli_check_key(o->who, cfg)
               ? -1
               : 0;
}

int ncp_cli_apply_backend(const struct ncp_cli_backend_opts *o, struct ncp_machine_cfg *cfg)
{
    const char *b = o->backend;
    struct ncp_diag d;
    memset(&d, 0, sizeof d);
    if (b && !strcmp(b, "lcm")) {
        cfg->backend = NCP_BACKEND_LCM;
    } else if (b) {
        int spec = ncp_backend_spec(b, cfg, &d);
        if (spec > 0)
            return fprintf(stderr, "%s: --backend is sim, socketcan[:IFACE] or lcm, not '%s'\n",
                           o->who, b), -1;
        if (spec < 0)
            return fprintf(stderr, "%s: %s\n", o->who, d.msg), -1;
    }
    if (cfg->backend == NCP_BACKEND_LCM)
        return apply_lcm(o, cfg);
    if (o->dp)
        return fprintf(stderr, "%s: --dp goes with --backend lcm (or [EMCMOT] BACKEND = lcm)\n",
                       o->who), -1;
    if (cfg->backend == NCP_BACKEND_SIM)
        return 0;
    if (o->virtual_clock)
        return fprintf(stderr, "%s: --backend socketcan drives real hardware: it needs --clock "
                               "real\n", o->who), -1;
    if (ncp_socketcan_check_cfg(cfg, &d) != NCP_OK)
        return fprintf(stderr, "%s: error: %s\n", o->config ? o->config : o->who, d.msg), -1;
    return 0;
}
