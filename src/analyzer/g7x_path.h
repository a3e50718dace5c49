/* The profile geometry of the lathe cycles G70 (finishing), G71/G72 (roughing
 * along Z / along X): a recorded profile of lines and arcs, its corner
 * fillets and chamfers, offsets, and the passes cut from it. Points are
 * complex numbers z + i*x, as rs274 keeps them, so the arithmetic (and with it
 * every tolerance decision) follows rs274 2.9's interp_g7x.cc.
 *
 * The module knows nothing of the interpreter: moves leave through a
 * ncp_g7x_out, whose calls may fail (their code is passed back unchanged). */
#ifndef NCP_ANALYZER_G7X_PATH_H
#define NCP_ANALYZER_G7X_PATH_H

#include <complex.h>

/* glibc defines CMPLX for GCC only: the same from its parts, for clang. */
#ifndef CMPLX
static inline double complex ncp_g7x_cmplx(double re, double im)
{
    union { double complex z; double d[2]; } u = {.d = {re, im}};
    return u.z;
}
#define CMPLX(re, im) ncp_g7x_cmplx((re), (im))
#endif

/* More than any hand-written profile; beyond it the cycle is refused. */
#define NCP_G7X_MAX_SEGS 20000

/* Status of the calls below besides NCP_OK and the ncp_g7x_out codes: a
 * geometry failure, its text in path->err (rs274 prefixes "G7X error: "). */
#define NCP_G7X_EGEOM (-1)

struct ncp_g7x_out {
    void *ctx;
    int (*line)(void *ctx, int rapid, double complex end);
    int (*arc)(void *ctx, int ccw, double complex centre, double complex end);
};

enum ncp_g7x_kind { NCP_G7X_LINE, NCP_G7X_ARC };
/* a corner (A fillet, C chamfer) waiting for its neighbours to shape it */
enum ncp_g7x_corner { NCP_G7X_PLAIN, NCP_G7X_FILLET, NCP_G7X_CHAMFER };

struct ncp_g7x_seg {
    unsigned char kind, corner;
    int ccw;
    double complex s, e, c;       /* start, end, centre (arcs) */
    double finish;                /* corner size until shaped */
};

struct ncp_g7x_path {
    struct ncp_g7x_seg *seg;
    int n, cap;
    int flip;                     /* bit 0 Z mirrored, 1 X mirrored, 2 rotated */
    char err[96];
};

void ncp_g7x_path_init(struct ncp_g7x_path *p);
void ncp_g7x_path_free(struct ncp_g7x_path *p);
/* Recording: a line, an arc, or a corner at point at. NCP_G7X_EGEOM when full. */
int ncp_g7x_add_line(struct ncp_g7x_path *p, double complex s, double complex e);
int ncp_g7x_add_arc(struct ncp_g7x_path *p, int ccw, double complex s, double complex c,
                    double complex e);
int ncp_g7x_add_corner(struct ncp_g7x_path *p, int corner, double size, double complex at);

/* G70: p passes from distance d to e off the profile, starting at start (z + i x). */
int ncp_g7x_finish(struct ncp_g7x_path *p, const struct ncp_g7x_out *out,
                   double complex start, double d, double e, double passes);
/* G71 (rotated = 0) / G72 (rotated = 1): roughing with subcycle 0 (everything),
 * 1 (no pockets) or 2 (pockets only), depth of cut i, retract r, final distance
 * d and displacement uw (w + i u). */
int ncp_g7x_rough(struct ncp_g7x_path *p, const struct ncp_g7x_out *out, int subcycle,
                  int rotated, double complex start, double complex uw, double d, double i,
                  double r);

#endif
