/* Executor: completes one command slot independently of every other slot:
 * arc geometry (centre from R, radius check with rs274's tolerances, rotation
 * count), cutter-compensation offset geometry, and the canonical text. */
#ifndef NCPAR_EXECUTOR_H
#define NCPAR_EXECUTOR_H

#include <stddef.h>
#include <stdio.h>
#include "ncpar/canon.h"

/* Resolve requests in cmd->ops (ARC_REQUEST -> ARC_FEED, ...). On a geometry error
 * fills cmd->diag, sets NCP_CMD_F_ERROR and truncates n_ops to the ops before the
 * failing one. Returns the slot's error code: diag.code with NCP_CMD_F_ERROR, else
 * NCP_OK. */
int ncp_exec_resolve(struct ncp_cmd *cmd);

/* Format cmd->ops as rs274 -g lines (without counter and N column), each ending in
 * '\n', into cmd->out / cmd->out_len. Lines are never cut: if the next line does
 * not fit NCP_CMD_OUT_MAX (only absurd magnitudes or pool-sized texts can do that)
 * n_ops is truncated before it, NCP_CMD_F_ERROR set and diag (unless the slot
 * already had an error) gets NCP_ERR_LIMIT. NONE and unresolved requests print nothing. */
void ncp_exec_format(struct ncp_cmd *cmd);
/* The same text written to dst (NCP_CMD_OUT_MAX bytes of room) instead of
 * cmd->out: a thread that formats and writes a command itself can format
 * into its output buffer. cmd->out_len is set as ncp_exec_format sets it. */
void ncp_exec_format_into(struct ncp_cmd *cmd, char *dst);

/* The text of cmd's PRINT calls (a line each) to f, as rs274 writes them to
 * its stdout: the canonical text has none of it. Returns 0, or -1 when f
 * refused a write. */
int ncp_exec_write_prints(const struct ncp_cmd *cmd, FILE *f);

/* Both, as an executor thread does; and both with the text into dst. */
int ncp_exec_cmd(struct ncp_cmd *cmd);
int ncp_exec_cmd_into(struct ncp_cmd *cmd, char *dst);

/* Longest "%.4f" text of any double (DBL_MAX has 309 integer digits) + NUL. */
#define NCP_FMT_FIXED4_MAX 328

/* Fast fixed-point "%.4f": writes into buf, returns length (NUL written too).
 * Byte-identical to printf's %.4f for every double (NaN and inf included).
 * buf must hold NCP_FMT_FIXED4_MAX bytes; 32 suffice when |v| < 1e14. */
size_t ncp_fmt_fixed4(char *buf, double v);

/* ---- Design, not implemented: cutter-compensation requests --------------
 *
 * rs274 compensates with a one-move delay: a compensated move's end point is
 * only final once the next move is known (corner arc, inside-corner retreat,
 * arc/line intersection), and it then rewrites the queued previous move. In
 * convert_straight_comp2 the compensated start it works from is the offset end
 * of the previous programmed move, so each compensated output move is a
 * function of a window of three PROGRAMMED moves (k-2, k-1, k) plus side and
 * radius (to be confirmed for the arc_comp paths before implementing): start of
 * k-1 from the (k-2, k-1) corner, end of k-1 and any corner arc from the
 * (k-1, k) corner. That keeps slots independent:
 *
 *   NCP_C_COMP_REQUEST, three consecutive ops, i[0] = role:
 *     0 "before" (k-2), 1 "emit" (k-1), 2 "after" (k; absent at G40 / end)
 *   per op: d[0..1] programmed end in the plane, d[2..3] arc centre,
 *           d[4] axis end, d[5..7] a b c, d[8] tool radius (> 0),
 *           i[1] motion (0 G0, 1 G1, 2 arc), i[2] arc turn (signed),
 *           i[3] side (1 left, 2 right) | entry flag (first move after G41/G42,
 *           rs274's comp1: offset from the uncompensated start),
 *           flags bit 0 inches (tolerances as for ARC_REQUEST).
 *   The executor replaces the three ops by the output of move k-1: an optional
 *   corner ARC_FEED (or STRAIGHT_TRAVERSE for G0, as rs274 does) and the
 *   compensated STRAIGHT_FEED / STRAIGHT_TRAVERSE / ARC_FEED; compaction keeps
 *   ops after the request in order. Errors use rs274's messages ("... can't fit
 *   in without gouging", "Zero degree inside corner ...", "Cutter gouging with
 *   cutter radius comp") and col 0.
 *
 * The analyzer's share stays sequential and cheap: keep the last two programmed
 * moves, emit move k-1's request when move k is parsed (so its slot carries
 * k-1's output), and hold non-motion calls issued between them (rs274 queues
 * SET_FEED_RATE, COMMENT, spindle/coolant calls) so they come out after k-1,
 * in the same slot. Geometry (atan2 with long double quarter turns, hypot,
 * concave test against TOLERANCE_CONCAVE_CORNER) follows interp_convert.cc's
 * convert_straight_comp1/2 and convert_arc_comp1/2, and lives in
 * src/executor/comp_geom.cpp next to arc_geom.cpp.
 *
 * As built: the window is not bounded by three moves (Z-only moves and queued
 * calls ride along, inside corners rewrite every queued move, gouge checks use
 * the start of the previous compensated move, entry arcs shift their centre,
 * G20/G21 rescale the queue), so no COMP_REQUEST exists: the analyzer runs
 * rs274's queue itself (src/analyzer/cutcomp.h, a few atan2/hypot per move)
 * and the per-move geometry lives in src/executor/comp_geom.cpp. */

#endif
