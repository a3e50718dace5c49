/* The position parameters a block reads (#5420..#5428), kept by offsets.c:
 * inline, as every block ends here, and in offsets.c's own header rather
 * than state.h, since it calls offsets.c (and comp.c), which state.h's
 * users must not be made to depend on. */
#ifndef NCP_ANALYZER_OFFSETS_H
#define NCP_ANALYZER_OFFSETS_H

#include "stages.h"

#include <string.h>

double *ncp_offsets_param_pos(struct ncp_analyzer *a);
/* #5420..#5428 (and #<_x>...) read where the tool is: the current point, or
 * under cutter compensation the compensated one. Every block ends here, so
 * the common case (no compensation) stays one copy. */
static inline void ncp_offsets_sync_params(struct ncp_analyzer *a)
{
    double *p = a->par_pos ? a->par_pos : ncp_offsets_param_pos(a);
    if (a->comp.side != 0)
        ncp_comp_reported_pos(a, p);
    else
        memcpy(p, a->st.pos, sizeof a->st.pos);
}

#endif
