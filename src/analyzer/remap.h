/* LinuxCNC's REMAP of M and G codes, T, S and F (module-internal header): the
 * code runs an O-word subroutine (ngc=NAME, NAME.ngc) in its step of the line
 * (a G code in the motion's), with the
 * words its argspec names as the sub's local parameters (#<p>, #<q>...), as
 * rs274 -i runs it. Built only when the configuration has REMAP lines: a
 * program without them pays one NULL test per M word. */
#ifndef NCP_ANALYZER_REMAP_H
#define NCP_ANALYZER_REMAP_H

#include "ncpar/analyzer.h"

#define NCP_REMAP_M_MAX 1000 /* rs274 remaps M0..M999 */
#define NCP_REMAP_G_MAX 1000 /* and G0..G99.9 (code x10) */
#define NCP_REMAP_DEPTH 16   /* room for remaps running inside remaps */
#define NCP_REMAP_MAX_NESTED 10 /* rs274's MAX_NESTED_REMAPS: the 10th is refused */
#define NCP_G_REMAPPED (-2)     /* in ncp_remaps.g_group: the code has a REMAP line */

/* The stdglue.py prologs and epilogs LinuxCNC ships for tool changes,
 * built in (their Python is not run): T with prepare_*, M6 with change_*,
 * M61 with settool_*, S with setspeed_*, F with setfeed_*. */
enum ncp_glue {
    NCP_GLUE_NONE, NCP_GLUE_PREPARE, NCP_GLUE_CHANGE, NCP_GLUE_SETTOOL, NCP_GLUE_SETSPEED,
    NCP_GLUE_SETFEED,
};

struct ncp_remap {
    char code[16];      /* as written: "M400", "T" */
    int m;              /* -1 for G, T, S, F */
    int g;              /* G code x10 (G88.1: 881), -1 for the others */
    enum ncp_glue prolog, epilog;
    int group;          /* rs274's modal group: M 4..10, G 1 */
    int remappable;     /* rs274 runs it (else it only moves the code's group: a
                           G code ncpar knows runs built in, in the motion group) */
    char argspec[64];
    char ngc[128];
};

struct ncp_remaps {
    struct ncp_remap *r;
    int n;
    int16_t by_m[NCP_REMAP_M_MAX]; /* index into r, -1 none */
    int16_t by_g[NCP_REMAP_G_MAX]; /* the same for G codes x10 */
    int n_g;                       /* how many G codes are remapped */
    int8_t g_group[NCP_REMAP_G_MAX]; /* with n_g: the G code table the words read */
    int t, s, f;                   /* T's, S's, F's remap, -1 none */
};

/* A remap running: what its prolog gave the sub (stdglue's params, which
 * its epilog reads back) */
struct ncp_remap_frame {
    const struct ncp_remap *r;
    double tool, pocket;          /* prepare_prolog, settool_prolog */
    double selected_pocket;       /* change_prolog */
    double value;                 /* setspeed_prolog, setfeed_prolog */
};

/* Reads cfg's REMAP lines; *out NULL when there are none. An error names the
 * INI file and line (d->file, d->line). */
int ncp_remaps_new(const struct ncp_analyzer_cfg *cfg, struct ncp_remaps **out,
                   struct ncp_diag *d);
void ncp_remaps_free(struct ncp_remaps *rs);

/* The remap of M code m, or NULL. */
static inline const struct ncp_remap *ncp_remap_of_m(const struct ncp_remaps *rs, int m)
{
    return rs && m >= 0 && m < NCP_REMAP_M_MAX && rs->by_m[m] >= 0 ? &rs->r[rs->by_m[m]] : NULL;
}

/* The remap of G code g (x10), or NULL. */
static inline const struct ncp_remap *ncp_remap_of_g(const struct ncp_remaps *rs, int g)
{
    return rs && g >= 0 && g < NCP_REMAP_G_MAX && rs->by_g[g] >= 0 ? &rs->r[rs->by_g[g]] : NULL;
}

#endif
