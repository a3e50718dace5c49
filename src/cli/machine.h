/* The machine INI as the front ends load it. */
#ifndef NCPAR_CLI_MACHINE_H
#define NCPAR_CLI_MACHINE_H

#include "ncpar/analyzer.h"
#include "ncpar/config.h"

/* The defaults, then path over them (NULL: the defaults alone). On an error
 * prints PATH:LINE: error: ... and returns -1. */
int ncp_cli_load_machine(const char *path, struct ncp_machine_cfg *cfg);

/* --config or --ini (parse's name for it) given as arg: one INI, the
 * machine's with its [RS274NGC], so a second different one is refused
 * (-1 after saying so, who naming the command). */
int ncp_cli_set_config(const char *who, const char **config, const char *arg);

/* A tool table given (NULL: none): a warning per line the interpreter will
 * skip; -1 after printing the error when it cannot be read. */
int ncp_cli_check_tool_table(const char *path);

/* cfg's [RS274NGC] PARAMETER_FILE read (*out malloc'd; NULL when the INI
 * names none), and made with the defaults when it does not exist. Returns
 * 0; 2 for a malformed file (PATH:LINE: error: ... printed), 1 when it
 * cannot be read or made. */
int ncp_cli_load_vars(const char *who, const struct ncp_machine_cfg *cfg,
                      struct ncp_var_file **out);

#endif
