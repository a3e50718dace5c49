/* G5.3 NURBS for the NCK: control points arrive in program order (NURBS_POINTS
 * ops) and each knot span is drawn as soon as its points are in, so the curve
 * needs a window of order + NCP_NURBS_POINTS_PER_OP points, never the whole
 * list: memory stays fixed on the RT side whatever the curve's length. */
#ifndef NCP_MOTION_NURBS_EVAL_H
#define NCP_MOTION_NURBS_EVAL_H

#include "ncpar/motion.h"

/* Start a curve of `count` points and order `order`. 0, or -1 when the order
 * is beyond what the window holds (NCP_NURBS_MAX_ORDER). */
int ncp_nurbs_stream_begin(struct ncp_nurbs_stream *nb, uint32_t count, int order);

/* Take n points (x y weight each). 0, -1 when a weight is not > 0 (no curve
 * then: the denominator could vanish), -2 when more points come than begun. */
int ncp_nurbs_stream_add(struct ncp_nurbs_stream *nb, const double *xyw, int n);

/* Spans [0, ready) can be drawn now. */
uint32_t ncp_nurbs_stream_ready(const struct ncp_nurbs_stream *nb);

/* The curve at parameter t in [span, span + 1] of a ready span (LinuxCNC's
 * knots: order zeros, 1, 2, ..., count - order + 1 each once, then order
 * times count - order + 1): program x y. */
void ncp_nurbs_stream_point(const struct ncp_nurbs_stream *nb, uint32_t span, double t, double xy[2]);

#endif
