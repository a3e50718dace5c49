/* Canonical machining calls, in binary form, and the command slot that carries
 * them from the analyzer through the executor pool to the in-order consumer.
 *
 * The analyzer fills slots in program order, numbering them (cmd_id). An executor
 * completes a slot without looking at any other slot: it resolves geometry
 * (arc centres, arc validity, rotation counts, cutter-compensation offsets) and
 * formats the canonical text (rs274 -g format without counter and N column).
 * The consumer emits slots strictly in cmd_id order and stops at the first slot
 * whose diag.code != NCP_OK. */
#ifndef NCPAR_CANON_H
#define NCPAR_CANON_H

#include <stddef.h>
#include <stdint.h>
#include "ncpar/diag.h"

/* One enumerator per rs274 canonical call (printed name = text after NCP_C_),
 * plus a few requests the executor turns into a printed call. Fields used per
 * kind are documented here; unused fields are zero. d[] are doubles in the
 * current program length units, angles in degrees, exactly the numbers rs274
 * prints. */
enum ncp_canon_kind {
    NCP_C_NONE = 0,
    NCP_C_USE_LENGTH_UNITS,      /* i[0]: 0 inches, 1 mm */
    NCP_C_SET_G5X_OFFSET,        /* i[0]: 1..9 index; d[0..5] x y z a b c */
    NCP_C_SET_G92_OFFSET,        /* d[0..5] */
    NCP_C_SET_XY_ROTATION,       /* d[0] degrees */
    NCP_C_SET_FEED_REFERENCE,    /* i[0]: 0 CANON_WORKPIECE, 1 CANON_XYZ */
    NCP_C_ON_RESET,
    NCP_C_STRAIGHT_TRAVERSE,     /* d[0..5] x y z a b c (program coordinates) */
    NCP_C_STRAIGHT_FEED,         /* d[0..5] */
    NCP_C_STRAIGHT_PROBE,        /* d[0..5] */
    NCP_C_SET_FEED_RATE,         /* d[0]. With flags NCP_FEED_F_INVERSE_ARC and directly
                                    before an ARC_REQUEST (G93 arc): d[0] = the F word,
                                    d[1] = the arc's axis (helix) start; the executor
                                    replaces d[0] by rs274's max(0.1, arc length * F) and
                                    drops this op too if the arc fails. */
    NCP_C_SET_FEED_MODE,         /* i[0] spindle, i[1] mode (0 units/min, 1 inverse time, 2 units/rev)
                                    NB printed verbatim, and rs274 calls SET_FEED_MODE(0, 0)
                                    for G93 and G94 alike, SET_FEED_MODE(spindle, 1) for G95:
                                    put those numbers in i[0]/i[1] to match its text. */
    NCP_C_SET_TRAVERSE_RATE,     /* d[0] */
    NCP_C_ARC_FEED,              /* d[0] first_end d[1] second_end d[2] first_axis(centre)
                                    d[3] second_axis(centre) i[0] rotation d[4] axis_end
                                    d[5..7] a b c. Printed as rs274 prints it. */
    NCP_C_ARC_REQUEST,           /* analyzer -> executor, becomes ARC_FEED or an error.
                                    d[0] first_start d[1] second_start d[2] first_end
                                    d[3] second_end d[4] axis_end d[5..7] a b c
                                    d[8] IJK: first centre  | R form: radius (signed)
                                    d[9] IJK: second centre
                                    i[0] +1 ccw (G3) / -1 cw (G2)
                                    i[1] 0 = centre form (IJK, centre absolute), 1 = radius form
                                    i[2] P turns (>= 1)
                                    i[3] plane (0 XY, 1 YZ, 2 XZ) for error messages
                                    d[10] tolerance for radius difference (program units)
                                    d[11] relative tolerance used by rs274 (fraction)
                                    flags bit 0: inches (for messages)
                                    Tolerances, as rs274 (interp_internal.hh) uses them:
                                    d[10] = CENTER_ARC_RADIUS_TOLERANCE_INCH/_MM of the INI
                                      [RS274NGC] section, default 2*0.001*sqrt(2) in
                                      (0.0028284) and 2*0.01*sqrt(2) mm (0.028284);
                                    d[11] = SPIRAL_RELATIVE_TOLERANCE 0.001 (fixed);
                                    zero in either means that default. IJK arcs fail when
                                    |r2-r1| > 100*d[10], or when |r2-r1| > d[10] and
                                    |r2-r1|/max(r1,r2) > d[11]. RADIUS_TOLERANCE 0.00005 in /
                                    0.00127 mm (fixed, picked by flags bit 0) is the zero-
                                    radius limit (IJK) and the reach slack (R form).
                                    i[2] = 0 is taken as 1. Errors carry col 0. */
    NCP_C_DWELL,                 /* d[0] seconds */
    NCP_C_SELECT_PLANE,          /* i[0]: 0 XY, 1 YZ, 2 XZ (printed CANON_PLANE_XY|YZ|XZ) */
    NCP_C_SET_MOTION_CONTROL_MODE, /* i[0]: 0 EXACT_STOP, 1 EXACT_PATH, 2 CONTINUOUS; d[0] tolerance */
    NCP_C_SET_NAIVECAM_TOLERANCE,  /* d[0] */
    NCP_C_SET_SPINDLE_SPEED,     /* i[0] spindle, d[0] */
    NCP_C_SET_SPINDLE_MODE,      /* i[0] spindle, d[0] css max */
    NCP_C_START_SPINDLE_CLOCKWISE,        /* i[0] */
    NCP_C_START_SPINDLE_COUNTERCLOCKWISE, /* i[0] */
    NCP_C_STOP_SPINDLE_TURNING,  /* i[0] */
    NCP_C_ORIENT_SPINDLE,        /* i[0] spindle, d[0] angle, i[1] direction */
    NCP_C_SPINDLE_RETRACT_TRAVERSE,
    NCP_C_FLOOD_ON, NCP_C_FLOOD_OFF, NCP_C_MIST_ON, NCP_C_MIST_OFF,
    NCP_C_SELECT_TOOL,           /* i[0] */
    NCP_C_START_CHANGE,
    NCP_C_CHANGE_TOOL,           /* i[0] */
    NCP_C_CHANGE_TOOL_NUMBER,    /* i[0] */
    NCP_C_USE_TOOL_LENGTH_OFFSET,/* d[0..8] x y z a b c u v w (rs274's format, see executor) */
    NCP_C_SET_CUTTER_RADIUS_COMPENSATION, /* d[0] */
    NCP_C_START_CUTTER_RADIUS_COMPENSATION, /* i[0]: 1 LEFT, 2 RIGHT */
    NCP_C_STOP_CUTTER_RADIUS_COMPENSATION,
    NCP_C_COMMENT,               /* text */
    NCP_C_MESSAGE,               /* text */
    NCP_C_LOGOPEN, NCP_C_LOGAPPEND, NCP_C_LOGCLOSE, NCP_C_LOG, /* text */
    NCP_C_PRINT,                 /* text: a (PRINT,...) comment, expanded, and '\n'. rs274 writes it to
                                    its own stdout, not to the canonical stream: prints
                                    nothing there (ncp_exec_write_prints has it) */
    NCP_C_ENABLE_FEED_OVERRIDE, NCP_C_DISABLE_FEED_OVERRIDE,
    NCP_C_ENABLE_SPEED_OVERRIDE, NCP_C_DISABLE_SPEED_OVERRIDE, /* i[0] spindle */
    NCP_C_ENABLE_FEED_HOLD, NCP_C_DISABLE_FEED_HOLD,
    NCP_C_ENABLE_ADAPTIVE_FEED, NCP_C_DISABLE_ADAPTIVE_FEED,
    NCP_C_PROGRAM_STOP, NCP_C_OPTIONAL_PROGRAM_STOP, NCP_C_PALLET_SHUTTLE,
    NCP_C_PROGRAM_END,
    NCP_C_TURN_PROBE_ON, NCP_C_TURN_PROBE_OFF,
    NCP_C_SET_AUX_OUTPUT_BIT, NCP_C_CLEAR_AUX_OUTPUT_BIT,       /* i[0] */
    NCP_C_SET_MOTION_OUTPUT_BIT, NCP_C_CLEAR_MOTION_OUTPUT_BIT, /* i[0] */
    NCP_C_SET_AUX_OUTPUT_VALUE, NCP_C_SET_MOTION_OUTPUT_VALUE,  /* i[0], d[0] */
    NCP_C_START_SPEED_FEED_SYNCH,/* i[0] spindle, d[0] feed per rev, i[1] velocity mode */
    NCP_C_STOP_SPEED_FEED_SYNCH,
    NCP_C_NURBS_FEED,            /* i[0] control points (3 G5.1, 4 G5, n G5.3), d[0..2] the end
                                    x y z. G5/G5.1: d[3..4] the start, d[5..6] and (G5) d[7..8]
                                    the control points, x y. G5.3: i[1] the order, i[2]
                                    NCP_NURBS_POINTS_FOLLOW, the points in the NURBS_POINTS ops
                                    right after. For the NCK only: rs274 -g prints no point */
    NCP_C_NURBS_POINTS,          /* i[0] points (1..NCP_NURBS_POINTS_PER_OP), d[3k..3k+2] x y
                                    weight, program units; prints nothing */
    NCP_C_RIGID_TAP,             /* d[0..2] x y z of the hole's bottom (G33.1); back at the start after */
    NCP_C_RAW_TEXT,              /* text printed verbatim (for calls not modelled above) */
    NCP_C__COUNT
};

/* NURBS_FEED's i[2]: the control points follow in NURBS_POINTS ops */
#define NCP_NURBS_POINTS_FOLLOW 1
#define NCP_NURBS_POINTS_PER_OP 4

/* ncp_canon.flags of SET_FEED_RATE (see above) */
#define NCP_FEED_F_INVERSE_ARC 1u

#define NCP_CANON_NI 4
#define NCP_CANON_ND 12

struct ncp_canon {
    uint16_t kind;     /* enum ncp_canon_kind */
    uint16_t flags;
    uint16_t text_off, text_len; /* into the slot's text pool */
    int32_t i[NCP_CANON_NI];
    double d[NCP_CANON_ND];
};

#define NCP_CMD_MAX_OPS 8       /* more calls for one block continue in the next slot */
#define NCP_CMD_TEXT_POOL 600   /* comment / message text for this slot's ops */
#define NCP_CMD_OUT_MAX 2048    /* formatted canonical lines of this slot */

enum ncp_cmd_flags {
    NCP_CMD_F_END = 1u << 0,    /* program ended after this slot (M2/M30/%/EOF) */
    NCP_CMD_F_ERROR = 1u << 1,  /* diag holds the error; ops before it are valid */
    NCP_CMD_F_CONT = 1u << 2    /* continues the previous slot's block */
};
/* The bits above the flags: the block's subroutine file, as a tag of
 * ncp_diag_file_tag (0: the program itself), for errors found after the
 * analyzer (arc geometry, output) to name the file their line is in. */
#define NCP_CMD_FILE_SHIFT 3u
#define NCP_CMD_FILE(c) ((unsigned)(c)->flags >> NCP_CMD_FILE_SHIFT)
_Static_assert(NCP_DIAG_FILE_TAGS < (1u << (16 - NCP_CMD_FILE_SHIFT)), "a tag fits the flags");

/* Slots cross cores in the pipeline's rings: what every slot writes (the
 * header and its first op) is contiguous from the start; the error, which
 * only a failing block writes, and the pools follow. */
struct ncp_cmd {
    uint64_t cmd_id;            /* 0, 1, 2, ... in program order */
    uint32_t line;              /* source line of the block */
    uint16_t n_ops;
    uint16_t flags;             /* enum ncp_cmd_flags */
    uint16_t text_used;
    uint32_t out_len;           /* filled by the executor */
    struct ncp_canon ops[NCP_CMD_MAX_OPS];
    struct ncp_diag diag;       /* the error: valid only when flags has NCP_CMD_F_ERROR */
    char text[NCP_CMD_TEXT_POOL];
    char out[NCP_CMD_OUT_MAX];  /* filled by the executor */
};

/* Clear a slot's header (not its ops, not its diag) and number it: what
 * acquire() does. Whoever sets diag sets NCP_CMD_F_ERROR with it. */
void ncp_cmd_reset_header(struct ncp_cmd *cmd, uint64_t id);

#endif
