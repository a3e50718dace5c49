/* cnc-run run: the full NCK on a backend (default: the simulated machine). */
#ifndef NCPAR_CLI_RUN_H
#define NCPAR_CLI_RUN_H

#include "ncpar/feeder.h"
#include "ncpar/nck.h"

#include <stdio.h>

/* argv[0] is "run". Returns the process exit status (0, 1 usage, 2 program
 * error, 3 runtime fault or soft-limit violation). */
int ncp_cli_run(int argc, char **argv);

/* The interpreter a run hands to ncp_nck_run (ncp_nck_opts.interpret). */
struct ncp_cli_interp {
    const struct ncp_source *src;
    struct ncp_analyzer_cfg acfg;
    enum ncp_thread_mode mode;
};
int ncp_cli_interpret(void *ctx, const struct ncp_output *out, struct ncp_diag *d);

/* The summary and the error of one run, on f, named after prog. Returns the
 * exit status it stands for. */
int ncp_cli_run_report(const char *prog, const struct ncp_machine_cfg *cfg,
                       const struct ncp_nck_result *res, FILE *f);

#endif
