/* Kinematics: the machine's joints (what the servos drive) from its axes
 * (the Cartesian pose the planner and interpolator work in), and back. In
 * C++17 with Eigen behind a C interface (src/kins/); no allocation and no
 * exceptions, so both directions run on the position loop every period.
 *
 * Joints are numbered like the axes, X Y Z A B C U V W (joint i drives what
 * axis i names on a trivial machine); an axis a transform does not involve
 * passes through unchanged.
 *
 * Table-rotary-tilting machines follow LinuxCNC's xyzac-trt and xyzbc-trt
 * kinematics modules: the tool stays vertical and the work turns on a table
 * rotating about Z (C) carried by a table tilting about X (A) or Y (B).
 * rot_point is the point the C axis turns about (x/y/z-rot-point), offset the
 * tilting axis's pivot relative to it (y/z-offset for A, x/z-offset for B).
 * tool_z is the tool length along the tool axis (LinuxCNC's tool-offset pin,
 * fed from motion.tooloffset.z): the axes' Z includes it as G43 applied it,
 * the transform takes it off to turn the tool tip, not the spindle nose. */
#ifndef NCPAR_KINS_H
#define NCPAR_KINS_H

#ifdef __cplusplus
extern "C" {
#endif

#define NCP_KINS_JOINTS 9

enum ncp_kins_type { NCP_KINS_TRIVIAL = 0, NCP_KINS_XYZAC_TRT, NCP_KINS_XYZBC_TRT };

struct ncp_kins {
    int type;                 /* enum ncp_kins_type */
    double rot_point[3];      /* x/y/z-rot-point, mm */
    double offset[3];         /* x/y/z-offset, mm */
};

/* "trivkins", "xyzac-trt", "xyzbc-trt" (any case) -> enum, else -1. */
int ncp_kins_parse(const char *name);
/* The name LinuxCNC gives the module (never NULL). */
const char *ncp_kins_name(int type);
/* The rotary axis that tilts the table (3 A, 4 B), -1 for trivkins. */
int ncp_kins_tilt_axis(int type);

/* Axes -> joints and joints -> axes; pos and joint may not alias. */
void ncp_kins_inverse(const struct ncp_kins *k, double tool_z, const double pos[NCP_KINS_JOINTS],
                      double joint[NCP_KINS_JOINTS]);
void ncp_kins_forward(const struct ncp_kins *k, double tool_z,
                      const double joint[NCP_KINS_JOINTS], double pos[NCP_KINS_JOINTS]);

#ifdef __cplusplus
}
#endif

#endif
