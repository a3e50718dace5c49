/* --key-file of cnc-run serve and run: over the INI's [LCM] KEY_FILE, and
 * the key checked before anything starts (ncpar/auth.h). */
#ifndef NCPAR_CLI_KEY_OPTS_H
#define NCPAR_CLI_KEY_OPTS_H

#include "ncpar/config.h"

/* path NULL: the INI's stays. 0, or -1 after a message to stderr. */
int ncp_cli_apply_key_file(const char *who, const char *path, struct ncp_machine_cfg *cfg);
/* The key the transport will use, made when missing: 0, or -1 after a
 * message naming the file (and its mode when others may read it). */
int ncp_cli_check_key(const char *who, const struct ncp_machine_cfg *cfg);

#endif
