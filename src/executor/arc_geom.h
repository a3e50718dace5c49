/* Arc centre and validity, with rs274's exact floating-point recipe so the
 * printed centres agree to the last printed digit. C interface to C++/Eigen
 * code: no exceptions, no allocation cross it. Coordinates are in the arc's
 * plane: "first" and "second" are rs274's names (XY: x,y; YZ: y,z; XZ: z,x). */
#ifndef NCPAR_EXECUTOR_ARC_GEOM_H
#define NCPAR_EXECUTOR_ARC_GEOM_H

#ifdef __cplusplus
extern "C" {
#endif

enum ncp_arc_status {
    NCP_ARC_OK = 0,
    NCP_ARC_SAME_POINT,      /* R form with start == end */
    NCP_ARC_R_TOO_SMALL,     /* R form: end point out of reach */
    NCP_ARC_ZERO_RADIUS,     /* centre form: start or end on the centre */
    NCP_ARC_RADIUS_DIFFERS   /* centre form: start and end radii disagree */
};

struct ncp_arc_in {
    double start[2], end[2];
    double centre[2];        /* centre form: absolute centre */
    double radius;           /* R form: signed R word (negative = long arc) */
    int radius_form;         /* 0 centre form, 1 R form */
    int ccw;                 /* 1 G3, 0 G2 */
    int turns;               /* P word, >= 1 */
    double radius_tol;       /* minimum radius / R reach slack (rs274 RADIUS_TOLERANCE_*) */
    double spiral_abs_tol;   /* |r2 - r1| allowed (CENTER_ARC_RADIUS_TOLERANCE_*) */
    double spiral_rel_tol;   /* |r2 - r1| / max(r1, r2) allowed (SPIRAL_RELATIVE_TOLERANCE) */
};

struct ncp_arc_out {
    double centre[2];
    int rotation;            /* rs274's turn: +P ccw, -P cw */
    double r1, r2;           /* centre form: radii to start and end (for messages) */
    double abs_err, rel_err; /* centre form: |r1 - r2| and that over max(r1, r2) */
};

/* Returns enum ncp_arc_status; out->centre is valid for the message even on a
 * centre-form error. */
int ncp_arc_solve(const struct ncp_arc_in *in, struct ncp_arc_out *out);

/* Path length of a solved arc (helix when axis_start != axis_end), as rs274
 * computes it for inverse-time feed: the swept angle follows the rotation
 * sign and count, a full turn when start and end coincide. */
double ncp_arc_length(const struct ncp_arc_in *in, const struct ncp_arc_out *out,
                      double axis_start, double axis_end);

#ifdef __cplusplus
}
#endif

#endif
