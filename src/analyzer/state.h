/* The analyzer core's own state (module-internal): modal state, positions and
 * offsets per axis, the tool table, the per-block word scratch and the slot
 * being filled. One struct owned by one ncp_analyzer, passed explicitly. */
#ifndef NCP_ANALYZER_STATE_H
#define NCP_ANALYZER_STATE_H

#include <stdint.h>
#include <string.h>
#include "ncpar/analyzer.h"
#include "codes.h"
#include "cutcomp.h"
#include "flow.h"
#include "params.h"
#include "remap.h"

enum ncp_axis { NCP_X, NCP_Y, NCP_Z, NCP_A, NCP_B, NCP_C, NCP_U, NCP_V, NCP_W, NCP_NAX };

/* rs274's standalone "user" length unit (parameters, tool table) is the inch. */
#define NCP_MM_PER_INCH 25.4

/* G73, G74 and G81-G89 (motion codes in tenths): the canned cycles, one
 * list for the word checks and the motion dispatch alike. */
static inline int ncp_is_canned_cycle(int motion)
{
    return motion == NCP_G73 || motion == NCP_G74 || (motion >= NCP_G81 && motion <= NCP_G89);
}

/* Modal group slots of the per-block G-code record. */
enum ncp_ggroup {
    NCP_GG_NONMODAL, NCP_GG_MOTION, NCP_GG_PLANE, NCP_GG_DIST, NCP_GG_ARCDIST,
    NCP_GG_FEEDMODE, NCP_GG_UNITS, NCP_GG_COMP, NCP_GG_TLO, NCP_GG_RETRACT,
    NCP_GG_COORD, NCP_GG_CONTROL, NCP_GG_SPINDLE, NCP_GG_LATHE, NCP_GG__N
};

enum ncp_mgroup {
    NCP_MG_STOP, NCP_MG_TOOL, NCP_MG_SPINDLE, NCP_MG_COOLANT, NCP_MG_OVERRIDE,
    NCP_MG_IO, NCP_MG_USER, NCP_MG__N
};

/* letters A..Z, then the polar radius '@', angle '^' and spindle '$' words */
#define NCP_LETTER(c) ((c) == '@' ? 26 : (c) == '^' ? 27 : (c) == '$' ? 28 : (c) - 'A')
#define NCP_WORD_SLOTS 29
#define NCP_POLAR_BITS ((1u << 26) | (1u << 27))
#define NCP_HAS(w, c) (((w)->has >> NCP_LETTER(c)) & 1u)
/* Where an error about the block's motion points: its motion G word, or the
 * line's start when the motion mode came from an earlier block. */
#define NCP_MOTION_COL(w) ((w)->gcol[NCP_GG_MOTION] ? (w)->gcol[NCP_GG_MOTION] : (w)->line_col)
#define NCP_AXIS_LETTERS ((1u << NCP_LETTER('X')) | (1u << NCP_LETTER('Y')) | \
    (1u << NCP_LETTER('Z')) | (1u << NCP_LETTER('A')) | (1u << NCP_LETTER('B')) | \
    (1u << NCP_LETTER('C')) | (1u << NCP_LETTER('U')) | (1u << NCP_LETTER('V')) | \
    (1u << NCP_LETTER('W')))

/* One block's words after evaluation. G codes are stored as code*10
 * (G38.2 -> 382), M codes whole, both named in codes.h; -1 = none in that
 * group. */
struct ncp_words {
    uint32_t has;                 /* bit per NCP_LETTER slot (not G, M) */
    double v[NCP_WORD_SLOTS];
    uint16_t col[NCP_WORD_SLOTS];
    int16_t g[NCP_GG__N];
    uint16_t gcol[NCP_GG__N];
    int16_t m[NCP_MG__N];
    uint16_t mcol[NCP_MG__N];
    int n_m;
    uint16_t line_col;            /* col of the first word, for block-level errors */
    int motion_to_be;             /* motion this block performs (x10), -1 none */
    int m98;                      /* 1 while an M98 line is checked: P and L are its */
    int remapped;                 /* an M code of the block runs a remap: rs274 then
                                     skips its word checks (the argspec's are the ones) */
};

struct ncp_modal {
    int motion;                   /* G code*10 of the active motion mode (NCP_G80 ...), -1 none
                                     (after G5.3) */
    int plane;                    /* 0 XY, 1 YZ, 2 XZ */
    int incremental, arc_incremental;
    int feed_mode;                /* 0 units/min, 1 inverse time, 2 units/rev */
    int inches;
    int retract_r;                /* G99 */
    int control;                  /* 0 exact stop, 1 exact path, 2 continuous */
    double p_tol, q_tol;
    int origin;                   /* 1..9 (G54..G59.3) */
    int comp_side;                /* 0 off, 1 left, 2 right */
    double comp_radius;
    int spindle_dir;              /* 0 stop, 1 cw, -1 ccw */
    int flood, mist;
    int feed_override, speed_override, adaptive, feed_hold;
    int g92_enabled;
    int lathe_diameter;           /* G7: X words are diameters (halved); G8: radii */
    int css;                      /* G96 (constant surface speed); G97 */
    double g64_p, g64_q;          /* rs274's own G64 tolerances (G61 leaves them): M72 */
};

struct ncp_state {
    double pos[NCP_NAX];          /* current point, program coordinates/units */
    double g5x[NCP_NAX];          /* active origin (program units) */
    double g92[NCP_NAX];          /* axis offsets (program units) */
    double tlo[NCP_NAX];          /* tool length offset (program units) */
    double rotation;
    double feed, speed;
    struct ncp_modal m;
    int selected_tool, selected_pocket, current_tool, current_pocket; /* pockets: entries */
    /* the table's P of those entries, which #<_selected_pocket> and
     * #<_current_pocket> read (the empty spindle's is -1) */
    int selected_pocket_no, current_pocket_no;
    int toolchange_flag;
    double g5_pq[2];              /* the last G5's P Q: where a G5 without I J starts off */
    /* canned cycle sticky values */
    double cycle_r, cycle_cc, cycle_p, cycle_q, cycle_il, cycle_ijk[3];
    int cycle_l, cycle_il_flag;
};

/* The canon side's view of the position (see sai.c). */
struct ncp_sai {
    double pos[6], g5x[6], g92[6];
    int inches;
    int probe_flag;               /* a G38.x ran: rs274 reads its results at the next block */
    double probed[6];             /* where the probe tripped: its programmed end */
    int input_flag;               /* an M66 ran on a machine: #5399 is read back too */
    int change_flag;              /* an M6 ran: on a machine the position is read back */
    ncp_machine_sync_fn sync;     /* the machine the busters wait for, or NULL */
    void *sync_ctx;
};

/* An op held back while cutter compensation has a move queued: it is handed
 * to the comp queue once the caller has filled it (see floor.c). */
struct ncp_staged {
    int pending;
    struct ncp_canon op;
    size_t len;
    char text[NCP_CMD_TEXT_POOL];
};

/* G5.2 control points until G5.3 draws them (nurbs.c): x y weight */
struct ncp_g52_points {
    double (*pt)[3];
    uint32_t n, cap;
    int order;
};

struct ncp_analyzer {
    struct ncp_analyzer_cfg cfg;
    struct ncp_sai sai;
    struct ncp_cutcomp comp;
    struct ncp_staged staged;
    struct ncp_params *params;
    struct ncp_flow *flow;
    struct ncp_state st;
    struct ncp_words w;
    const struct ncp_block *blk;
    const struct ncp_source *src;
    struct ncp_param_ops pops;
    double *par_pos;              /* #5420..#5428 (adjacent slots) */
    /* tool table: entry[i] for pocket-ordered tools as rs274 loads them */
    int n_tools;
    int tool_no[NCP_MAX_TOOLS];
    struct ncp_tool_entry tools[NCP_MAX_TOOLS];
    double tool_more[NCP_MAX_TOOLS][7]; /* Y A B C U V W offsets (user unit), see tools.c */
    /* output */
    const struct ncp_cmd_sink *sink;
    struct ncp_cmd *cmd;
    /* Ops go here once the sink has shut down, so callers need no NULL checks
     * on the hot path: this analyzer's own, as analyzers of other threads
     * write theirs at the same time. */
    struct ncp_canon scratch;
    uint64_t next_id;
    uint32_t line;
    unsigned file_tag;           /* the block's subroutine file (NCP_CMD_FILE), 0 */
    int stopped;
    struct ncp_diag err;
    /* M70-M73 (m7x.c) */
    struct ncp_m7x_frame *m7x;    /* saved modal state per call level */
    int m7x_cap;
    int m7x_restore_from;         /* a return left an M73 level: restore from it, else -1 */
    int block_consumed;           /* an M72 ran restore lines in this block's place */
    struct ncp_block *m7x_block;  /* the restore line being run */
    struct ncp_g52_points nurbs;
    /* REMAP (remap_run.c): NULL without REMAP lines; the remaps running,
     * innermost last (#<_remap_level> is their count) */
    struct ncp_remaps *remaps;
    int remap_level;
    struct ncp_remap_frame remap_frames[NCP_REMAP_DEPTH];
    /* rs274's builtin_used of the line running at each remap level: a code
     * ran built in (inside its own remap) for the remap that line started */
    int remap_builtin[NCP_REMAP_DEPTH + 1];
    /* How a handler runs a line of its own as a block (M72's restore lines):
     * ncp_an_execute, handed down by the run loop so that no handler calls
     * back up into the file that calls it. */
    int (*execute)(struct ncp_analyzer *a, const struct ncp_block *b);
    /* How the floor shows a machine the active codes with each slot it
     * publishes (floor.h): ncp_analyzer_active_codes (m7x.c, a handler),
     * handed down by the run loop for the same reason. */
    void (*active_codes)(const struct ncp_analyzer *a, struct ncp_active_codes *out);
};

/* comp.c: the analyzer side of cutter compensation */
int ncp_comp_gcode(struct ncp_analyzer *a, int g);
int ncp_comp_move_straight(struct ncp_analyzer *a, int motion, const double *end, int g53);
int ncp_comp_move_arc(struct ncp_analyzer *a, const struct ncp_canon *req, const double *end);
int ncp_comp_stop(struct ncp_analyzer *a, int reset);

/* words.c: ncp_words_init once before any analyzer reads a block (builds
 * the G code table) */
void ncp_words_init(void);
int ncp_words_collect(struct ncp_analyzer *a, const struct ncp_block *b);
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

/* g10.c: G10 L1/L10/L11 (tool table) and L2/L20 (coordinate systems) */
int ncp_g10_run(struct ncp_analyzer *a);

/* tools.c */
int ncp_tools_load(struct ncp_analyzer *a, const char *path, struct ncp_diag *d);
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
/* A built-in tool code ran: rs274 notes it on the line that controls the
 * innermost remap (what stdglue's epilogs test) */
static inline void ncp_remap_note_builtin(struct ncp_analyzer *a)
{
    a->remap_builtin[a->remap_level > 0 ? a->remap_level - 1 : 0] = 1;
}

/* stop.c */
int ncp_stop_run(struct ncp_analyzer *a, int m);
void ncp_state_init(struct ncp_analyzer *a);

#endif
