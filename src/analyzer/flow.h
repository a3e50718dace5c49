/* O-word control flow (module-internal header).
 * Serves the analyzer core the next block to interpret, in execution order:
 * it handles every O-word block itself (sub/endsub definitions are skipped and
 * indexed, call/return, if/elseif/else/endif, while/endwhile, do/while,
 * repeat/endrepeat, break, continue) and re-reads earlier blocks from the source
 * text (ncpar/blocks.h's ncp_block_reread) when a loop or call goes back; it returns
 * to the pre-lexed feed when execution reaches the block after the last one the
 * feed delivered. Subroutines may be defined after their call (it scans forward). */
#ifndef NCP_ANALYZER_FLOW_H
#define NCP_ANALYZER_FLOW_H

#include "ncpar/analyzer.h"
#include "params.h"

struct ncp_flow;

struct ncp_flow *ncp_flow_new(const struct ncp_block_feed *feed,
                              struct ncp_params *params,
                              const struct ncp_analyzer_cfg *cfg);
void ncp_flow_free(struct ncp_flow *f);
/* Parameter reads of O-word conditions, counts and values go through ops (the
 * analyzer's: it refuses #5420-#5428 under cutter compensation, as rs274 does);
 * by default they read the parameter table directly. */
void ncp_flow_set_param_ops(struct ncp_flow *f, struct ncp_param_ops ops);

/* Told when a call opens call level `level` (entered) and when a return or
 * endsub leaves it (left); M73's auto-restore hangs on the second. */
struct ncp_flow_frames {
    void *ctx;
    void (*entered)(void *ctx, int level);
    void (*left)(void *ctx, int level);
};
void ncp_flow_set_frame_hooks(struct ncp_flow *f, struct ncp_flow_frames hooks);

/* Fanuc-style calls (M98 lines): rs274 reads the whole line, even where it
 * skips, before it looks at the call: every word's value and the reader's
 * checks, then the P word ("Found 'm98' code with no P-word", P not an
 * integer), then, unless skipping, the block's word checks. The analyzer does
 * that here; *p is the sub's number, *l the L word (repeats) or -1 without
 * one. Without a reader the flow evaluates P and L itself. */
struct ncp_flow_m98_reader {
    void *ctx;
    int (*read)(void *ctx, const struct ncp_block *b, int skipping, int *p, int *l,
                struct ncp_diag *d);
};
void ncp_flow_set_m98_reader(struct ncp_flow *f, struct ncp_flow_m98_reader r);

/* Next non-O-word block to interpret. Returns NCP_OK and sets *out (valid until
 * the next call), NCP_END at the end of the program body, or an error with *d
 * filled (file order line/col). A plain block with a syntax error comes back
 * as a block (its err set), for the caller to report after the faults of the
 * words left of it, which rs274 reads first; an O-word line's, as that error
 * in *d; neither where rs274 would not read it (skipped text).
 * Block delete ('/') is off, as in rs274 -g: such blocks are served as usual. */
int ncp_flow_next(struct ncp_flow *f, const struct ncp_block **out,
                  struct ncp_diag *d);

/* rs274's lathe cycles (G70-G72) record their profile by running the line
 * "O<q> call" as if it had been read in place of the block being run: call
 * is that line, lexed by the caller. The subroutine's blocks then come from
 * ncp_flow_next, which reports its return (endsub or return) as
 * NCP_FLOW_RETURNED with *out set to that O-word block; the block after the
 * calling one comes next. Meanwhile a block with a syntax error comes back as
 * a block (rs274 reads some such lines differently there). */
#define NCP_FLOW_RETURNED 100
int ncp_flow_call_inline(struct ncp_flow *f, const struct ncp_block *call,
                         struct ncp_diag *d);

/* The text the last block served came from (the program, or a subroutine
 * file), and that file's name for diagnostics: NULL for the program's own. */
const struct ncp_source *ncp_flow_source(const struct ncp_flow *f);
const char *ncp_flow_file(const struct ncp_flow *f);
unsigned ncp_flow_file_tag(const struct ncp_flow *f); /* its ncp_diag_file_tag, 0 */

/* The error ncp_flow_next returned came from the program's closing '%',
 * reached while looking for a sub: rs274 ends the program there (FINISH)
 * before it reports the sub missing. */
int ncp_flow_ended_at_percent(const struct ncp_flow *f);

/* Current subroutine call depth (0 = main program): an M99 not first on its
 * line inside a sub is an error rs274 reports as a bug of its own. */
int ncp_flow_call_depth(const struct ncp_flow *f);

/* M2/M30 inside a subroutine, or errors: drop all frames. */
void ncp_flow_reset(struct ncp_flow *f);

#endif
