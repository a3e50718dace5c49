/* One run of the NCK (nck_run.h): the interpreter a run hands the NCK, in
 * the thread mode of --mode, and the summary and error of its end. */
#include "nck_run.h"

#include "ncpar/config.h"
#include "ncpar/pipeline.h"

#include <stdint.h>
#include <stdio.h>
#include <string.h>

int ncp_cli_interpret(void *ctx, const struct ncp_output *out, struct ncp_diag *d)
{
    struct ncp_cli_interp *ic = ctx;
    struct ncp_run_stats st;
    memset(&st, 0, sizeof st);
    if (ic->mode == NCP_MODE_SERIAL)
        return ncp_serial_run(ic->src, &ic->acfg, out, &st, d);
    struct ncp_thread_map map;
    ncp_thread_map_default(&map, ic->mode, 2, 1);
    return ncp_pipeline_run(ic->src, &map, &ic->acfg, out, &st, d);
}

int ncp_cli_run_report(const char *prog, const struct ncp_machine_cfg *cfg,
                       const struct ncp_nck_result *res, FILE *f)
{
    if (res->limit_violation) {
        /* the machine's limits are a block's, not a word's: column 1 */
        fprintf(f, "%s:%u:%u: error: %s (checked before motion: nothing moved)\n",
                res->diag.file ? res->diag.file : prog, res->diag.line,
                res->diag.col ? (unsigned)res->diag.col : 1u, res->diag.msg);
        return RUN_FAULT;
    }
    if (res->refused) {
        fprintf(f, "%s:%u:%u: error: %s (found before motion: nothing moved)\n",
                res->diag.file ? res->diag.file : prog, res->diag.line,
                res->diag.col ? (unsigned)res->diag.col : 1u, res->diag.msg);
        return RUN_PROGRAM;
    }
    if (res->interrupted && res->lat.cycles == 0) {
        fprintf(f, "%s: stopped while checking the program before motion (nothing moved)\n",
                prog);
        return RUN_OK;
    }
    int drive_fault = res->status == RUN_FAULT && res->diag.code == NCP_ERR_IO && !res->fault;
    if (drive_fault && res->lat.cycles == 0) {
        fprintf(f, "%s: error: drive start-up failed: %s (nothing moved)\n", prog,
                res->diag.msg);
        return RUN_FAULT;
    }
    ncp_nck_print_summary(res, prog, f);
    if (drive_fault) {
        fprintf(f, "%s:%u: error: drive fault: %s; controlled stop of all axes\n", prog,
                res->diag.line, res->diag.msg);
    } else if (res->fault) {
        fprintf(f,
                "%s:%u: error: following error on %c: %.4f mm exceeds FERROR %.4f mm; servo stopped\n",
                prog, res->fault_line, NCP_AXIS_LETTERS[res->fault_axis], res->fault_err,
                cfg->axis[res->fault_axis].ferror);
    } else if (res->inject.trip) {
        char why[300];
        ncp_inject_trip_text(&cfg->inject, &res->inject, cfg->servo_period, why, sizeof why);
        fprintf(f, "%s:%u: error: %s\n", prog, res->inject.trip_line, why);
    } else if (res->status != RUN_OK && res->diag.line) {
        fprintf(f, "%s:%u:%u: error: %s (motion stopped after the last good block)\n",
                res->diag.file ? res->diag.file : prog, res->diag.line, res->diag.col ? (unsigned)res->diag.col : 1u, res->diag.msg);
    } else if (res->home_failed) {
        fprintf(f, "%s: error: %s (the program did not run)\n", prog, res->diag.msg);
    } else if (res->status != RUN_OK) {
        fprintf(f, "%s: error: %s\n", prog, res->diag.msg);
    }
    return res->status;
}
