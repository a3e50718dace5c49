/* The corner blends of blend.c: parabolas at a corner between two lines,
 * even or uneven, and the cut where an arc meets a line. Read by the
 * look-ahead (planner.c) and the band search (edge.c). */
#ifndef NCP_MOTION_BLEND_H
#define NCP_MOTION_BLEND_H

#include "ncpar/motion.h"

/* blend.c: the parabola joining prev's end to cur's start within prev's G64 P,
 * trimming at most max_trim off either line, and the length trimmed off both.
 * Returns 0 when the corner is not blended. */
int ncp_blend_corner(const struct ncp_seg *prev, const struct ncp_seg *cur, double max_trim,
                     struct ncp_seg *arc, double *trim);

/* blend.c: the uneven parabola (ncp_seg_ratio) at that corner whose exit
 * runs rho times its entry, as large as prev's G64 P and the lines allow; the
 * lengths trimmed off prev's end and cur's start. 0 when not possible (no P). */
int ncp_blend_corner_ratio(const struct ncp_seg *prev, const struct ncp_seg *cur, double rho,
                           struct ncp_seg *blend, double *trim_prev, double *trim_cur);

/* blend.c: the same with the trim off prev given (r0; rho r0 off cur), as
 * far as the lines allow, whatever P says. */
int ncp_blend_corner_ratio_at(const struct ncp_seg *prev, const struct ncp_seg *cur, double rho,
                              double r0, struct ncp_seg *blend, double *trim_prev, double *trim_cur);

/* blend.c: the corner points of the blends ncp_blend_corner_ratio_at makes
 * at one corner (at rho 1 ncp_blend_corner's, prev's P aside), set up once
 * for many trims r0: the same numbers to the bit. ncp_blend_fan_init is 0
 * where that corner has no such blend; ncp_blend_fan_at gives the trim off
 * prev (*trim_prev of ncp_blend_corner_ratio_at), 0 where r0 gives no
 * blend. u1, u2: the lines' directions; c: the blend's centre. */
struct ncp_blend_fan {
    double u1[3], u2[3], c[3], rho, room;
};
int ncp_blend_fan_init(struct ncp_blend_fan *f, const struct ncp_seg *prev,
                       const struct ncp_seg *cur, double rho);
double ncp_blend_fan_at(const struct ncp_blend_fan *f, double r0, double start[3], double end[3]);

/* blend.c: the same where one side is an arc in a plane and the other a line
 * (in that plane, or leaving it under a G64 P: ncp_blend_line_leaves): the
 * arc gives up arc_trim of its length, the line what the blend needs;
 * prev_out and cur_out are the trimmed segments. 0 when the cut gives no
 * blend or leaves prev's G64 P. */
int ncp_blend_arc_corner(const struct ncp_seg *prev, const struct ncp_seg *cur, double arc_trim,
                         struct ncp_seg *arc, struct ncp_seg *prev_out, struct ncp_seg *cur_out);
/* blend.c: 1 where line (of some length) leaves arc's plane; its blend with
 * the arc then ends in a slight kink where the line takes over. */
int ncp_blend_line_leaves(const struct ncp_seg *arc, const struct ncp_seg *line);

#endif
