/* Motion tests that feed the NCK from real G-code: the interpreter callback
 * (serial reference) over a program in memory or on disk. */
#ifndef NCP_TEST_GCODE_SRC_H
#define NCP_TEST_GCODE_SRC_H

#include "ncpar/analyzer.h"
#include "ncpar/feeder.h"
#include "ncpar/pipeline.h"

struct gcode_ctx {
    struct ncp_source src;
    struct ncp_analyzer_cfg acfg;
};

static int gcode_run(void *ctx, const struct ncp_output *out, struct ncp_diag *d)
{
    struct gcode_ctx *g = ctx;
    struct ncp_run_stats st;
    return ncp_serial_run(&g->src, &g->acfg, out, &st, d);
}

#endif
