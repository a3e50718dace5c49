/* Motion tests that feed the NCK from real G-code: the interpreter callback
 * (serial reference) over a program in memory or on disk, and a whole run of
 * a program text on the virtual clock, read back as its trace. Include after
 * <cmocka.h>. */
#ifndef NCP_TEST_GCODE_SRC_H
#define NCP_TEST_GCODE_SRC_H

#include <stdio.h>
#include <string.h>

#include "ncpar/analyzer.h"
#include "ncpar/feeder.h"
#include "ncpar/pipeline.h"
#include "ncpar/nck.h"
#include "trace_rows.h"

struct gcode_ctx {
    struct ncp_source src;
    struct ncp_analyzer_cfg acfg;
};

static inline int gcode_run(void *ctx, const struct ncp_output *out, struct ncp_diag *d)
{
    struct gcode_ctx *g = ctx;
    struct ncp_run_stats st;
    return ncp_serial_run(&g->src, &g->acfg, out, &st, d);
}

/* The trace of PROG run on cfg with the virtual clock (the run must succeed);
 * caller frees the rows. */
static inline struct row *run_text(const char *text, const struct ncp_machine_cfg *cfg, size_t *n,
                            struct ncp_nck_result *res)
{
    struct gcode_ctx g;
    struct ncp_diag d;
    memset(&g, 0, sizeof g);
    assert_int_equal(ncp_source_from_memory(&g.src, text, strlen(text), "t.ngc", &d), NCP_OK);
    FILE *f = tmpfile();
    assert_non_null(f);
    struct ncp_nck_opts o = { .cfg = cfg, .interpret = gcode_run, .interp_ctx = &g,
                              .virtual_clock = 1, .feed_override = 1.0, .trace = f };
    assert_int_equal(ncp_nck_run(&o, res), 0);
    struct row *r = read_trace(f, n);
    fclose(f);
    ncp_source_close(&g.src);
    return r;
}

/* A program with every kind of corner the planner handles: G64 P blends
 * between lines and arcs (G2/G3 by centre), G61 exact stops, a G64 P change
 * and a helix; shared by the motion tests that check limits and tolerances. */
static const char corners_prog[] =
    "G21 G90 G17 G64 P0.05\n"
    "G0 X0 Y0 Z5\n"
    "G1 Z-1 F600\n"
    "G1 X40 F4000\n"
    "G1 X60 Y20\n"
    "G3 X60 Y60 I0 J20\n"
    "G2 X40 Y80 I-20 J0\n"
    "G1 X0 Y80\n"
    "G61 G1 X0 Y40\n"
    "G1 X-10 Y30\n"
    "G64 P0.2 G1 X-10 Y0\n"
    "G2 X-10 Y0 Z-4 I10 J0 F2000\n"
    "G0 Z5\n"
    "M2\n";

#endif
