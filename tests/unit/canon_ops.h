/* Canonical calls built by hand for the motion tests (the interpreter's output
 * without the interpreter). Include after <string.h> and ncpar/motion.h. */
#ifndef NCP_TEST_CANON_OPS_H
#define NCP_TEST_CANON_OPS_H

static inline struct ncp_canon op6(int kind, double x, double y, double z)
{
    struct ncp_canon c;
    memset(&c, 0, sizeof c);
    c.kind = (uint16_t)kind; /* the first three numbers of any kind, by position */
    c.raw.d[0] = x;
    c.raw.d[1] = y;
    c.raw.d[2] = z;
    return c;
}

static inline struct ncp_canon op_feed(double f)
{
    return op6(NCP_C_SET_FEED_RATE, f, 0, 0);
}

/* SET_MOTION_CONTROL_MODE: 0 exact stop, 1 exact path, 2 continuous within tol */
static inline struct ncp_canon op_mode(int mode, double tol)
{
    struct ncp_canon c = op6(NCP_C_SET_MOTION_CONTROL_MODE, 0, 0, 0);
    c.motion_control.mode = mode;
    c.motion_control.tolerance = tol;
    return c;
}

/* ARC_FEED in the XY plane */
static inline struct ncp_canon op_arc(double x, double y, double cx, double cy, int rot, double z)
{
    struct ncp_canon c = op6(NCP_C_ARC_FEED, x, y, cx);
    c.arc_feed.second_axis = cy;
    c.arc_feed.axis_end = z;
    c.arc_feed.rotation = rot;
    return c;
}

static inline struct ncp_canon op_dwell(double s)
{
    struct ncp_canon c = op6(NCP_C_DWELL, 0, 0, 0);
    c.dwell.seconds = s;
    return c;
}

#endif
