/* The analyzer core's stages (module-internal): what each file of
 * src/analyzer offers the others, a few lines a file, over the state of
 * state.h. A file that calls another's stage includes this; one that only
 * reads the state, state.h. */
#ifndef NCP_ANALYZER_STAGES_H
#define NCP_ANALYZER_STAGES_H

#include "state.h"

/* comp.c: the analyzer side of cutter compensation */
int ncp_comp_gcode(struct ncp_analyzer *a, int g);
int ncp_comp_move_straight(struct ncp_analyzer *a, int motion, const double *end, int g53);
int ncp_comp_move_arc(struct ncp_analyzer *a, const struct ncp_canon *req, const double *end);
int ncp_comp_stop(struct ncp_analyzer *a, int reset);

/* words.c: ncp_words_init once before any analyzer reads a block (builds
 * the G code table) */
void ncp_words_init(void);
int ncp_words_collect(struct ncp_analyzer *a, const struct ncp_block *b);
/* The G code table a's words read (a->g_group): the built-in one, or with
 * G remaps the remaps' copy with those codes marked, and each G remap of
 * one of rs274's own codes marked as never running. */
void ncp_words_use_remaps(struct ncp_analyzer *a);
int ncp_words_fault_before(struct ncp_analyzer *a, const struct ncp_block *b, uint16_t col);
/* v as rs274 reads an integer word, or 'Non integer value for integer' at col. */
int ncp_integer_word(struct ncp_analyzer *a, double v, uint16_t col, int *out);
/* Axis ax (enum ncp_axis)'s letter, and its slot in struct ncp_words: a table,
 * since NCP_LETTER of a variable is a chain of compares at run time. */
extern const char ncp_axis_letter[NCP_NAX];
extern const unsigned char ncp_axis_slot[NCP_NAX];
/* 1 and *v when the block has axis ax's word, else 0. */
int ncp_axis_word(const struct ncp_words *w, int ax, double *v);
int ncp_words_assign(struct ncp_analyzer *a, const struct ncp_block *b);

/* modal.c */
int ncp_modal_check(struct ncp_analyzer *a);
/* steps.c: read back what the canon did, then read and execute block b (the
 * whole block in rs274's order: ncp_an_steps) */
int ncp_an_execute(struct ncp_analyzer *a, const struct ncp_block *b);
int ncp_an_steps(struct ncp_analyzer *a);

/* motion.c: the motions; steps.c picks the one the block's motion mode names */
/* G0/G1 and G2/G3 to the block's words, in the current distance modes */
int ncp_motion_straight(struct ncp_analyzer *a, int motion);
int ncp_motion_arc(struct ncp_analyzer *a, int motion);
/* G5, G5.1 splines; G33, G33.1, G76 (spindle-synchronised); G38.2-G38.5 probes */
int ncp_motion_spline(struct ncp_analyzer *a, int motion);
int ncp_motion_synced(struct ncp_analyzer *a, int motion);
int ncp_motion_probe(struct ncp_analyzer *a, int motion);
/* call_text.c: a call rs274 makes in the block's place ("O<Q> call" for
 * G71, "o<sub> call" for a remap), run inline; col is where it points */
int ncp_an_call_text(struct ncp_analyzer *a, const char *text, size_t len, uint16_t col);
/* The next block of the sub such a call runs: NCP_OK, NCP_FLOW_RETURNED at
 * its return (*b the return's block), else an error, set in a->err */
int ncp_an_sub_next(struct ncp_analyzer *a, const struct ncp_block **b);
/* g7x.c: G70, G71, G71.1, G71.2, G72, G72.1, G72.2 (motion x10) */
int ncp_g7x_run(struct ncp_analyzer *a, int motion);
int ncp_arc_run(struct ncp_analyzer *a, int motion, const double *end);
int ncp_canned_run(struct ncp_analyzer *a, int motion);
/* g76.c: G76 from the current point to end (checked by motion.c) */
int ncp_g76_cycle(struct ncp_analyzer *a, const double *end);
/* m7x.c: M70-M73 (m is 70..73); the flow's frame hooks; a restore a return
 * left pending (before the next block, or a parameter read); teardown */
int ncp_m7x_run(struct ncp_analyzer *a, int m);
struct ncp_flow_frames ncp_m7x_hooks(struct ncp_analyzer *a);
int ncp_m7x_pending(struct ncp_analyzer *a);
void ncp_m7x_reset(struct ncp_analyzer *a);
void ncp_m7x_free(struct ncp_analyzer *a);
int ncp_motion_ends(struct ncp_analyzer *a, int absolute53, double *end);

/* nurbs.c: G5.2 (a control point, as the motion) and G5.3 (draw them) */
int ncp_g52_point(struct ncp_analyzer *a);
int ncp_g52_draw(struct ncp_analyzer *a);
void ncp_g52_free(struct ncp_analyzer *a);

/* offsets.c */
int ncp_offsets_units(struct ncp_analyzer *a, int inches);
int ncp_offsets_coord(struct ncp_analyzer *a, int origin);
int ncp_offsets_tlo(struct ncp_analyzer *a, int g);
int ncp_offsets_modal0(struct ncp_analyzer *a, int g);
void ncp_comp_reported_pos(const struct ncp_analyzer *a, double *pos);
/* what the canon did since the last block (a probe, a tool change), read back
 * into the state and the parameters before the next block reads them */
int ncp_offsets_resync(struct ncp_analyzer *a);

/* frames.c: rs274's conversions through the XY rotation, and between the
 * program's unit and the user unit (parameters, tool table) */
double ncp_user_len(const struct ncp_analyzer *a, double user);
double ncp_to_user_len(const struct ncp_analyzer *a, double prog);
double ncp_tool_len(const struct ncp_analyzer *a, double user);
void ncp_rotate(double *x, double *y, double deg);
double ncp_frame_param(const struct ncp_analyzer *a, int index);
void ncp_frame_absolute_of(const struct ncp_analyzer *a, const double *pos, double *out);
double ncp_frame_user(const struct ncp_analyzer *a, int ax, int index);
void ncp_frame_current_in(const struct ncp_analyzer *a, int sys, int with_tlo, double *out);
void ncp_frame_relative(const struct ncp_analyzer *a, const double *abs, double *out);
void ncp_frame_absolute(const struct ncp_analyzer *a, double *out);
void ncp_frame_g53(const struct ncp_analyzer *a, const double *word, uint32_t given, double *end);

/* analyzer.c: rs274's start-up from a parameter file */
void ncp_an_take_params(struct ncp_analyzer *a, const struct ncp_var_file *vf);

/* g10.c: G10 L1/L10/L11 (tool table) and L2/L20 (coordinate systems) */
int ncp_g10_run(struct ncp_analyzer *a);

/* tools.c */
int ncp_tools_load(struct ncp_analyzer *a, const char *path, struct ncp_diag *d);
/* A tool table file's whole text (malloc'd; NULL with d set: it cannot be read). */
char *ncp_tools_read_file(const char *path, size_t *len, struct ncp_diag *d);
/* One line of a tool table as the loader reads it (tools.c): 1 and the
 * entry (Y A B C U V W offsets in more[7]) for a tool line the loader
 * keeps, 0 for any other (blank, comment, skipped). */
int ncp_tools_read_line(const char *s, const char *end, struct ncp_tool_entry *t, double *more,
                        int *toolno);
int ncp_tools_find(const struct ncp_analyzer *a, int tool);
int ncp_tools_select(struct ncp_analyzer *a);
int ncp_tools_change(struct ncp_analyzer *a);
void ncp_tools_sync_params(struct ncp_analyzer *a, int when_empty);
double ncp_tool_offset(const struct ncp_analyzer *a, int idx, int ax);
void ncp_tool_set_offset(struct ncp_analyzer *a, int idx, int ax, double user);
void ncp_tools_copy(struct ncp_analyzer *a, int dst, int src);

/* comments.c */
int ncp_comment_run(struct ncp_analyzer *a);

/* predef.c */
int ncp_predef_lookup(void *ctx, const char *name, size_t len, double *out);
struct ncp_param_ops ncp_predef_ops(struct ncp_analyzer *a);

/* sai.c */
void ncp_sai_move(struct ncp_analyzer *a, const double *end);
void ncp_sai_g5x(struct ncp_analyzer *a, const double *v);
void ncp_sai_g92(struct ncp_analyzer *a, const double *v);
void ncp_sai_units(struct ncp_analyzer *a, int inches);
void ncp_sai_probe(struct ncp_analyzer *a, const double *end);
void ncp_sai_op(struct ncp_analyzer *a, const struct ncp_canon *op);

/* remap_run.c: the block's M code in slot `slot` (enum ncp_mgroup) when its
 * remap runs there (not in its own remap, for the codes rs274 then runs
 * built in): *ran = 1 and the remap's result. */
int ncp_remap_step(struct ncp_analyzer *a, int slot, int *ran);
/* T, S or F in its step: *ran = 1 when its remap ran (else the built-in step
 * is the caller's: no remap, or inside its own) */
int ncp_remap_letter_step(struct ncp_analyzer *a, char letter, int *ran);
/* The block's motion G code (x10) when it is remapped: *ran = 1 and the
 * remap's result for a code of its own; rs274's "Bug unknown motion code" for
 * one of rs274's other groups moved to the motion's by its REMAP line. */
int ncp_remap_g_step(struct ncp_analyzer *a, int motion, int *ran);
/* 1 when G code g (x10) runs a remap (a code of rs274's own never does). */
static inline int ncp_remapped_g(const struct ncp_analyzer *a, int g)
{
    const struct ncp_remap *r = ncp_remap_of_g(a->remaps, g);
    return r && r->remappable;
}
/* A built-in tool code ran: rs274 notes it on the line that controls the
 * innermost remap (what stdglue's epilogs test) */
static inline void ncp_remap_note_builtin(struct ncp_analyzer *a)
{
    a->remap_builtin[a->remap_level > 0 ? a->remap_level - 1 : 0] = 1;
}

/* user_m.c: which of M100..M199 the machine has a program for (made once,
 * from cfg.user_m_dirs) */
void ncp_user_m_scan(struct ncp_analyzer *a);
static inline int ncp_user_m_has(const struct ncp_analyzer *a, int m)
{
    unsigned k = (unsigned)(m - 100);
    return k < 100 && ((a->user_m[k / 64] >> (k % 64)) & 1u);
}

/* stop.c */
int ncp_stop_run(struct ncp_analyzer *a, int m);
void ncp_state_init(struct ncp_analyzer *a);

#endif
