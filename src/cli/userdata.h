/* What serve keeps for its user when the machine INI names no file for it:
 * the job history, under the XDG data folder ($XDG_DATA_HOME, else
 * ~/.local/share), where desktop programs keep theirs. */
#ifndef NCPAR_CLI_USERDATA_H
#define NCPAR_CLI_USERDATA_H

#include <stddef.h>

/* $XDG_DATA_HOME/ncpar/history.jsonl (or ~/.local/share/...), its folder
 * made (0700) if missing. 0, or -1 with why (no $HOME, the folder cannot
 * be made, the path too long). */
int ncp_cli_default_history(char *out, size_t len, char *why, size_t wl);

#endif
