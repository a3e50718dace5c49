/* One run of the NCK, as cnc-run run makes it for its program and for each
 * of its --channel programs: the interpreter it hands the NCK and the report
 * of its end. The ground floor of run.c and channels.c: it calls neither. */
#ifndef NCPAR_CLI_NCK_RUN_H
#define NCPAR_CLI_NCK_RUN_H

#include "ncpar/feeder.h"
#include "ncpar/nck.h"

#include <stdio.h>

/* cnc-run run's exit statuses (run.h) */
enum { RUN_OK = 0, RUN_USAGE = 1, RUN_PROGRAM = 2, RUN_FAULT = 3 };

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
