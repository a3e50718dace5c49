/* The front ends' stop signals. */
#ifndef NCPAR_CLI_SIGNALS_H
#define NCPAR_CLI_SIGNALS_H

/* SIGINT and SIGTERM call on_stop(signal): an explicit handler, so that a
 * SIGINT inherited as ignored (a background job of a script) still stops us. */
void ncp_cli_catch_stop_signals(void (*on_stop)(int));

#endif
