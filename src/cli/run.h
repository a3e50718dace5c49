/* cnc-run run: the full NCK on a backend (default: the simulated machine). */
#ifndef NCPAR_CLI_RUN_H
#define NCPAR_CLI_RUN_H

/* argv[0] is "run". Returns the process exit status (0, 1 usage, 2 program
 * error, 3 runtime fault or soft-limit violation). */
int ncp_cli_run(int argc, char **argv);

#endif
