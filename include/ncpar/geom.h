/* Geometry for the interpreter, in C++17 with Eigen behind a C interface
 * (no exceptions, no allocation cross it; fixed-size Eigen types only):
 * - arcs: centre and validity of a programmed arc and its length (the
 *   executor's arc resolution, the analyzer's cutter compensation);
 * - cutter compensation: the offset paths of rs274's comp1/comp2 (the
 *   analyzer's compensation queue).
 * Both follow rs274's exact floating-point recipe, so printed numbers agree
 * with it to the last digit. Coordinates are in the move's plane: "first" and
 * "second" are rs274's names (XY: x,y; YZ: y,z; XZ: z,x). */
#ifndef NCPAR_GEOM_H
#define NCPAR_GEOM_H

#ifdef __cplusplus
extern "C" {
#endif

/* ---- arcs (src/geom/arc.cpp) ------------------------------------------- */

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
int ncp_geom_arc_solve(const struct ncp_arc_in *in, struct ncp_arc_out *out);

/* Path length of a solved arc (helix when axis_start != axis_end), as rs274
 * computes it for inverse-time feed: the swept angle follows the rotation
 * sign and count, a full turn when start and end coincide. */
double ncp_geom_arc_length(const struct ncp_arc_in *in, const struct ncp_arc_out *out,
                      double axis_start, double axis_end);

/* ---- cutter compensation (src/geom/comp.cpp) --------------------------- *
 * Pure functions of rs274's interp_convert.cc comp1/comp2 paths. Side: 1
 * left, 2 right. */

#define NCP_COMP_LEFT 1
#define NCP_COMP_RIGHT 2

enum ncp_comp_status {
    NCP_COMP_OK = 0,
    NCP_COMP_E_ENTRY_SHORT,      /* straight entry move not longer than the radius */
    NCP_COMP_E_ENTRY_ARC_SHORT,  /* entry arc chord not longer than the radius */
    NCP_COMP_E_TOOL_TOO_BIG,     /* tool does not fit inside the arc */
    NCP_COMP_E_BUG,              /* rs274's own consistency check failed */
    NCP_COMP_E_ZERO_CORNER,      /* 0-degree inside corner */
    NCP_COMP_E_ARC_LINE_GOUGE,
    NCP_COMP_E_LINE_ARC_GOUGE,   /* also: arc end moved beyond its sweep */
    NCP_COMP_E_ARC_ARC_CENTRE,
    NCP_COMP_E_ARC_ARC_GOUGE,
    NCP_COMP_E_FEED_GOUGE,
    NCP_COMP_E_TRAVERSE_GOUGE,
    NCP_COMP_E_ARC_MISMATCH      /* moved arc end no longer on its circle */
};

/* rs274's message for a status (never NULL). */
const char *ncp_geom_comp_strerror(int status);

/* The move at the front of the compensation queue, already compensated: the
 * corner decisions look at its kind, turn, centre and end. */
struct ncp_comp_prev {
    int valid;               /* 0: queue empty */
    int is_arc;
    int turn;
    double centre[2], end[2];
};

/* First straight move after G41/G42 (comp1): end point and the "direction"
 * rs274 records for the later gouge check. */
int ncp_geom_comp_line_entry(int side, double r, const double cur[2], const double p[2],
                        double end[2], double dir[2]);

/* First arc after G41/G42 (comp1). centre/turn: the programmed arc from cur.
 * Gives the offset end and the shifted centre of the compensated arc. */
int ncp_geom_comp_arc_entry(int side, double r, const double cur[2], const double end[2],
                       const double centre[2], int turn, double spiral_abs_tol,
                       double new_end[2], double new_centre[2]);

enum ncp_comp_corner {
    NCP_CORNER_STRAIGHT = 0, /* tangent or collinear: nothing added */
    NCP_CORNER_CONVEX,       /* extra arc (G0: traverse) to mid */
    NCP_CORNER_CONVEX2,      /* arc move: extra arc around op to mid */
    NCP_CORNER_CONCAVE       /* queued moves end at mid instead */
};

struct ncp_comp_corner_out {
    int corner;              /* enum ncp_comp_corner */
    double mid[2];
    double end[2];           /* offset end of the new move */
};

/* Straight move after the first (comp2) with XY motion. cur: compensated
 * current point, op: programmed current point, p: programmed end. */
int ncp_geom_comp_line_next(int side, double r, const double cur[2], const double op[2],
                       const double p[2], const struct ncp_comp_prev *front,
                       struct ncp_comp_corner_out *out);

/* Arc move after the first (comp2): centre and turn of the programmed arc
 * from op to end, ccw 1 for G3. */
int ncp_geom_comp_arc_next(int side, double r, const double cur[2], const double op[2],
                      const double end[2], const double centre[2], int ccw, int turn,
                      const struct ncp_comp_prev *front, struct ncp_comp_corner_out *out);

/* Signed swept angle of an arc from p1 to p2 about c (rs274's find_turn). */
double ncp_geom_comp_find_turn(const double p1[2], const double c[2], int turn, const double p2[2]);

#ifdef __cplusplus
}
#endif

#endif
