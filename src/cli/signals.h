/* The front ends' signals. */
#ifndef NCPAR_CLI_SIGNALS_H
#define NCPAR_CLI_SIGNALS_H

/* SIGINT and SIGTERM call on_stop(signal): an explicit handler, so that a
 * SIGINT inherited as ignored (a background job of a script) still stops us. */
void ncp_cli_catch_stop_signals(void (*on_stop)(int));

/* A program file mapped by the feeder and cut short while read (SIGBUS):
 * "PROG: error: input changed while reading", exit 2. SIGHUP, SIGPIPE and,
 * with stops_too, SIGINT and SIGTERM end the process as they would, but
 * without leaving temporary output files behind (outfile.h). */
void ncp_cli_catch_input_faults(const char *prog, int stops_too);

#endif
