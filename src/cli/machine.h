/* The machine INI as the front ends load it. */
#ifndef NCPAR_CLI_MACHINE_H
#define NCPAR_CLI_MACHINE_H

#include "ncpar/config.h"

/* The defaults, then path over them (NULL: the defaults alone). On an error
 * prints PATH:LINE: error: ... and returns -1. */
int ncp_cli_load_machine(const char *path, struct ncp_machine_cfg *cfg);

/* A tool table given (NULL: none): a warning per line the interpreter will
 * skip; -1 after printing the error when it cannot be read. */
int ncp_cli_check_tool_table(const char *path);

#endif
