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
    /* G code (x10) -> modal group, -1 unknown: words.c's table, or the
     * remaps' copy where a remapped code is NCP_G_REMAPPED (so that a
     * program without G remaps pays nothing for them) */
    const int8_t *g_group;
    /* M100+k has an executable on the machine (cfg.user_m_dirs): bit k */
    uint64_t user_m[2];
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

#endif
