/* The analyzer's ground floor (floor.c): what every handler stands on.
 *
 * A block's canonical calls go to its command slot, opened on the first call
 * and continued in a new slot when one fills; while cutter compensation holds
 * a move, calls are staged and offered to its queue instead, which keeps some
 * of them behind the move as rs274 does. An error is recorded once, with the
 * block's line, and returned as a status. The run loop (analyzer.c) and the
 * handlers call down to here; nothing here calls a handler. */
#ifndef NCP_ANALYZER_FLOOR_H
#define NCP_ANALYZER_FLOOR_H

#include "state.h"

/* Append one call to the block's slot (opening or continuing slots) and
 * return it, zeroed but for its kind, for the caller to fill. */
struct ncp_canon *ncp_an_emit(struct ncp_analyzer *a, enum ncp_canon_kind kind);
struct ncp_canon *ncp_an_emit_text(struct ncp_analyzer *a, enum ncp_canon_kind kind,
                                   const char *text, size_t len);
/* A call of six coordinates (STRAIGHT_*, SET_G92_OFFSET), which the canon's
 * view of the position follows. */
void ncp_an_emit6(struct ncp_analyzer *a, enum ncp_canon_kind kind, const double *p);
/* The block now answers for another line (a->line, set by the caller: a G7x
 * cycle's passes are its profile's return line's): later ops go to a new
 * slot of that line, so errors found when they execute name it. */
void ncp_an_reline(struct ncp_analyzer *a);
/* The block's error at col, rs274's message: returns NCP_ERR_SEMANTIC. */
int ncp_an_error(struct ncp_analyzer *a, uint16_t col, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* Hand a staged call on (to the compensation queue), if there is one; the
 * queue's sink, which appends what it lets out to the block's slot. The
 * check is inline: the run loop commits after every block. */
int ncp_an_commit_staged(struct ncp_analyzer *a);
static inline int ncp_an_commit(struct ncp_analyzer *a)
{
    return a->staged.pending ? ncp_an_commit_staged(a) : NCP_OK;
}
struct ncp_comp_sink ncp_an_comp_sink(struct ncp_analyzer *a);

/* The block's current slot, opening one (or a continuation) when needed with
 * room for text_need bytes of text; NULL once the sink has shut down. */
struct ncp_cmd *ncp_an_slot(struct ncp_analyzer *a, size_t text_need);
/* The slot out to the sink, if one is open (the run loop's, after every block). */
static inline void ncp_an_publish(struct ncp_analyzer *a)
{
    if (a->cmd) {
        /* only a machine (a run with busters to wait for) shows the codes:
         * a translation to text would pay for them on every block, in the
         * hot loop bench-parse measures */
        if (a->sai.sync)
            a->active_codes(a, &a->cmd->active);
        a->sink->publish(a->sink->ctx, a->cmd);
        a->cmd = NULL;
    }
}

#endif
