/* cnc-run serve: the NCK as a service on LCM. */
#ifndef NCPAR_CLI_SERVE_H
#define NCPAR_CLI_SERVE_H

/* argv[0] is "serve". Returns the process exit status (0, 1 usage or set-up,
 * 3 a fault happened while serving). */
int ncp_cli_serve(int argc, char **argv);

#endif
