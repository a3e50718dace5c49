/* --backend, --dp and --lcm-url of cnc-run run and serve, over the INI's
 * [EMCMOT] BACKEND and [LCM] DP, URL: one reading for both, so that what
 * run accepts on a machine is what serve accepts on it. */
#ifndef NCPAR_CLI_BACKEND_OPTS_H
#define NCPAR_CLI_BACKEND_OPTS_H

#include "ncpar/config.h"

struct ncp_cli_backend_opts {
    const char *who;         /* "cnc-run run": the start of every message */
    const char *config;      /* the INI's path for messages, NULL: built-in */
    const char *backend;     /* --backend as given, NULL: the INI's */
    int dp;                  /* --dp, 0: the INI's [LCM] DP */
    const char *lcm_url;     /* NULL: the INI's [LCM] URL */
    const char *key_file;    /* NULL: the INI's [LCM] KEY_FILE */
    int virtual_clock;
};

/* Into cfg->backend and what it needs; a point the variant does not have,
 * a virtual clock on real axes or a CAN axis without its keys is refused
 * here, before anything is opened. The lcm backend's key is checked (made
 * when missing). DP 1's program is the caller's. 0, or -1 after a message
 * to stderr. */
int ncp_cli_apply_backend(const struct ncp_cli_backend_opts *o, struct ncp_machine_cfg *cfg);

#endif
