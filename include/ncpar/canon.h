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
 * plus a few requests the executor turns into a printed call. Each kind's
 * fields are the member of struct ncp_canon's union named after the kind;
 * unused fields are zero. Doubles are in the current program length units,
 * angles in degrees, exactly the numbers rs274 prints. */
enum ncp_canon_kind {
    NCP_C_NONE = 0,
    NCP_C_USE_LENGTH_UNITS,      /* units */
    NCP_C_SET_G5X_OFFSET,        /* offset (index 1..9) */
    NCP_C_SET_G92_OFFSET,        /* offset (no index) */
    NCP_C_SET_XY_ROTATION,       /* rotation */
    NCP_C_SET_FEED_REFERENCE,    /* feed_reference */
    NCP_C_ON_RESET,
    NCP_C_STRAIGHT_TRAVERSE,     /* move (program coordinates) */
    NCP_C_STRAIGHT_FEED,         /* move */
    NCP_C_STRAIGHT_PROBE,        /* move; flags: NCP_PROBE_F_* */
    NCP_C_SET_FEED_RATE,         /* feed_rate */
    NCP_C_SET_FEED_MODE,         /* feed_mode */
    NCP_C_SET_TRAVERSE_RATE,     /* feed_rate (rate only) */
    NCP_C_ARC_FEED,              /* arc_feed */
    NCP_C_ARC_REQUEST,           /* arc: analyzer -> executor, becomes ARC_FEED or an error */
    NCP_C_DWELL,                 /* dwell */
    NCP_C_SELECT_PLANE,          /* plane */
    NCP_C_SET_MOTION_CONTROL_MODE, /* motion_control */
    NCP_C_SET_NAIVECAM_TOLERANCE,  /* naivecam */
    NCP_C_SET_SPINDLE_SPEED,     /* spindle_speed */
    NCP_C_SET_SPINDLE_MODE,      /* spindle_mode */
    NCP_C_START_SPINDLE_CLOCKWISE,        /* spindle */
    NCP_C_START_SPINDLE_COUNTERCLOCKWISE, /* spindle */
    NCP_C_STOP_SPINDLE_TURNING,  /* spindle */
    NCP_C_ORIENT_SPINDLE,        /* orient */
    NCP_C_SPINDLE_RETRACT_TRAVERSE,
    NCP_C_FLOOD_ON, NCP_C_FLOOD_OFF, NCP_C_MIST_ON, NCP_C_MIST_OFF,
    NCP_C_SELECT_TOOL,           /* tool */
    NCP_C_START_CHANGE,
    NCP_C_CHANGE_TOOL,           /* tool (the pocket) */
    NCP_C_CHANGE_TOOL_NUMBER,    /* tool (the table index) */
    NCP_C_USE_TOOL_LENGTH_OFFSET,/* tool_length (rs274's format, see executor) */
    NCP_C_SET_CUTTER_RADIUS_COMPENSATION, /* comp_radius */
    NCP_C_START_CUTTER_RADIUS_COMPENSATION, /* comp_start */
    NCP_C_STOP_CUTTER_RADIUS_COMPENSATION,
    NCP_C_COMMENT,               /* text */
    NCP_C_MESSAGE,               /* text */
    NCP_C_LOGOPEN, NCP_C_LOGAPPEND, NCP_C_LOGCLOSE, NCP_C_LOG, /* text */
    NCP_C_PRINT,                 /* text: a (PRINT,...) comment, expanded, and '\n'. rs274 writes it to
                                    its own stdout, not to the canonical stream: prints
                                    nothing there (ncp_exec_write_prints has it) */
    NCP_C_ENABLE_FEED_OVERRIDE, NCP_C_DISABLE_FEED_OVERRIDE,
    NCP_C_ENABLE_SPEED_OVERRIDE, NCP_C_DISABLE_SPEED_OVERRIDE, /* spindle */
    NCP_C_ENABLE_FEED_HOLD, NCP_C_DISABLE_FEED_HOLD,
    NCP_C_ENABLE_ADAPTIVE_FEED, NCP_C_DISABLE_ADAPTIVE_FEED,
    NCP_C_PROGRAM_STOP, NCP_C_OPTIONAL_PROGRAM_STOP, NCP_C_PALLET_SHUTTLE,
    NCP_C_PROGRAM_END,
    NCP_C_TURN_PROBE_ON, NCP_C_TURN_PROBE_OFF,
    NCP_C_SET_AUX_OUTPUT_BIT, NCP_C_CLEAR_AUX_OUTPUT_BIT,       /* output (index) */
    NCP_C_SET_MOTION_OUTPUT_BIT, NCP_C_CLEAR_MOTION_OUTPUT_BIT, /* output (index) */
    NCP_C_SET_AUX_OUTPUT_VALUE, NCP_C_SET_MOTION_OUTPUT_VALUE,  /* output (index, value) */
    NCP_C_START_SPEED_FEED_SYNCH,/* synch */
    NCP_C_STOP_SPEED_FEED_SYNCH,
    NCP_C_NURBS_FEED,            /* nurbs: for the NCK only, rs274 -g prints no point */
    NCP_C_NURBS_POINTS,          /* nurbs_points: prints nothing */
    NCP_C_RIGID_TAP,             /* rigid_tap (G33.1): back at the start after */
    NCP_C_RAW_TEXT,              /* text printed verbatim (for calls not modelled above) */
    NCP_C_WAIT_INPUT,            /* wait_input: M66 for the NCK only, rs274 -g prints nothing */
    NCP_C_USER_M,                /* user_m: M100..M199 for the NCK only (rs274 -g has none) */
    NCP_C__COUNT
};

/* nurbs.follow: the control points follow in NURBS_POINTS ops */
#define NCP_NURBS_POINTS_FOLLOW 1
#define NCP_NURBS_POINTS_PER_OP 4

/* ncp_canon.flags of SET_FEED_RATE (see feed_rate) */
#define NCP_FEED_F_INVERSE_ARC 1u

#define NCP_CANON_NI 4
#define NCP_CANON_ND 12

/* Every kind's ints stand in the first NCP_CANON_NI int32 slots and its
 * doubles after them, so all kinds share one layout (raw) and an op is the
 * same 120 bytes whatever its kind: a kind with fewer ints pads up to the
 * doubles with NCP_CANON_IPAD. */
/* STRAIGHT_PROBE's flags (rs274 -g prints neither): G38.4/G38.5 wait for
 * the contact to open; G38.2/G38.4 make a move that ends without it an error */
enum { NCP_PROBE_F_AWAY = 1, NCP_PROBE_F_ERROR = 2 };

#define NCP_CANON_IPAD(n) int32_t ipad_[NCP_CANON_NI - (n)]

struct ncp_canon {
    uint16_t kind;     /* enum ncp_canon_kind */
    uint16_t flags;
    uint16_t text_off, text_len; /* into the slot's text pool */
    union {
        /* Every kind's fields by position: for code that treats all kinds
         * alike (the executor's print templates index it). */
        struct { int32_t i[NCP_CANON_NI]; double d[NCP_CANON_ND]; } raw;
        struct { int32_t mm; } units;                       /* 0 inches, 1 mm */
        struct { int32_t index; NCP_CANON_IPAD(1); double v[6]; } offset; /* x y z a b c */
        struct { NCP_CANON_IPAD(0); double degrees; } rotation;
        struct { int32_t xyz; } feed_reference;             /* 0 CANON_WORKPIECE, 1 CANON_XYZ */
        struct { NCP_CANON_IPAD(0); double end[6]; } move;  /* x y z a b c */
        /* With flags NCP_FEED_F_INVERSE_ARC and directly before an ARC_REQUEST
         * (G93 arc): rate = the F word, arc_axis_start = the arc's axis (helix)
         * start; the executor replaces rate by rs274's max(0.1, arc length * F)
         * and drops this op too if the arc fails. */
        struct { NCP_CANON_IPAD(0); double rate, arc_axis_start; } feed_rate;
        /* Printed verbatim: rs274 calls SET_FEED_MODE(0, 0) for G93 and G94
         * alike, SET_FEED_MODE(spindle, 1) for G95; these numbers match its text. */
        struct { int32_t spindle, per_rev; } feed_mode;
        /* In print order (the executor prints ends, centre, rotation, axis end, a b c). */
        struct {
            int32_t rotation; NCP_CANON_IPAD(1);
            double first_end, second_end, first_axis, second_axis, axis_end, abc[3];
        } arc_feed;
        /* ARC_REQUEST. Tolerances, as rs274 (interp_internal.hh) uses them:
         * tol_abs = CENTER_ARC_RADIUS_TOLERANCE_INCH/_MM of the INI [RS274NGC]
         * section, default 2*0.001*sqrt(2) in (0.0028284) and 2*0.01*sqrt(2) mm
         * (0.028284); tol_rel = SPIRAL_RELATIVE_TOLERANCE 0.001 (fixed); zero in
         * either means that default. IJK arcs fail when |r2-r1| > 100*tol_abs,
         * or when |r2-r1| > tol_abs and |r2-r1|/max(r1,r2) > tol_rel.
         * RADIUS_TOLERANCE 0.00005 in / 0.00127 mm (fixed, picked by flags bit
         * 0: inches, for messages too) is the zero-radius limit (IJK) and the
         * reach slack (R form). turns = 0 is taken as 1. Errors carry col 0. */
        struct ncp_canon_arc {
            int32_t dir;          /* +1 ccw (G3) / -1 cw (G2) */
            int32_t radius_form;  /* 0 centre form (IJK, centre absolute), 1 radius form */
            int32_t turns;        /* P (>= 1) */
            int32_t plane;        /* 0 XY, 1 YZ, 2 XZ, for error messages */
            double first_start, second_start, first_end, second_end, axis_end, abc[3];
            union {
                struct { double first_centre, second_centre; };
                double radius;    /* R form, signed */
            };
            double tol_abs, tol_rel;
        } arc;
        struct { NCP_CANON_IPAD(0); double seconds; } dwell;
        struct { int32_t plane; } plane;                    /* 0 XY, 1 YZ, 2 XZ */
        struct {
            int32_t mode; NCP_CANON_IPAD(1);                /* 0 EXACT_STOP, 1 EXACT_PATH, 2 CONTINUOUS */
            double tolerance;
        } motion_control;
        struct { NCP_CANON_IPAD(0); double tolerance; } naivecam;
        struct { int32_t spindle; NCP_CANON_IPAD(1); double speed; } spindle_speed;
        struct { int32_t spindle; NCP_CANON_IPAD(1); double css_max; } spindle_mode;
        struct { int32_t spindle; } spindle;
        struct { int32_t spindle, direction; NCP_CANON_IPAD(2); double angle; } orient;
        /* tool: what rs274 prints (SELECT_TOOL's number, CHANGE_TOOL's table
         * entry); number: the tool's number, what the machine shows */
        struct { int32_t tool, number; } tool;
        struct { NCP_CANON_IPAD(0); double v[9]; } tool_length; /* x y z a b c u v w */
        struct { NCP_CANON_IPAD(0); double radius; } comp_radius;
        struct { int32_t side; } comp_start;                /* 1 LEFT, 2 RIGHT */
        struct { int32_t index; NCP_CANON_IPAD(1); double value; } output;
        struct {
            int32_t spindle, velocity_mode; NCP_CANON_IPAD(2);
            double per_rev;                                 /* feed per revolution */
        } synch;
        /* G5/G5.1: n_points 4 (G5) or 3 (G5.1), end x y z, start x y, ctrl the
         * control points x y (the second only for G5). G5.3: n_points the
         * control points, order, follow NCP_NURBS_POINTS_FOLLOW, the points in
         * the NURBS_POINTS ops right after. */
        struct ncp_canon_nurbs {
            int32_t n_points, order, follow; NCP_CANON_IPAD(3);
            double end[3], start[2], ctrl[2][2];
        } nurbs;
        struct {
            int32_t n; NCP_CANON_IPAD(1);                   /* 1..NCP_NURBS_POINTS_PER_OP */
            double pt[NCP_NURBS_POINTS_PER_OP][3];          /* x y weight, program units */
        } nurbs_points;
        struct { NCP_CANON_IPAD(0); double bottom[3]; } rigid_tap; /* x y z of the hole's bottom */
        /* M66: P (digital, analog 0) or E (analog 1), L the wait mode, Q the timeout */
        struct { int32_t index, mode, analog; NCP_CANON_IPAD(3); double timeout; } wait_input;
        /* M100..M199: the machine's program M<code> runs with P and Q as its
         * arguments (-1 when the block has none, as LinuxCNC passes them);
         * col: the M word's, for the error of a program that fails */
        struct { int32_t code, col; NCP_CANON_IPAD(2); double p, q; } user_m;
    };
};

/* The layout every kind shares: an op's size is what the rings and the
 * packed records count on, and each kind's ints and doubles stand where raw's
 * do. */
#define NCP_CANON_I0 offsetof(struct ncp_canon, raw.i)
#define NCP_CANON_D0 offsetof(struct ncp_canon, raw.d)
_Static_assert(sizeof(struct ncp_canon) == 8 + 4 * NCP_CANON_NI + 8 * NCP_CANON_ND,
               "an op is 120 bytes");
_Static_assert(NCP_CANON_I0 == 8 && NCP_CANON_D0 == 24, "ints after the header, doubles after them");
_Static_assert(offsetof(struct ncp_canon, offset.v) == NCP_CANON_D0 &&
               offsetof(struct ncp_canon, rotation.degrees) == NCP_CANON_D0 &&
               offsetof(struct ncp_canon, move.end) == NCP_CANON_D0 &&
               offsetof(struct ncp_canon, feed_rate.rate) == NCP_CANON_D0 &&
               offsetof(struct ncp_canon, arc_feed.first_end) == NCP_CANON_D0 &&
               offsetof(struct ncp_canon, arc_feed.abc) == NCP_CANON_D0 + 5 * 8 &&
               offsetof(struct ncp_canon, arc.first_start) == NCP_CANON_D0 &&
               offsetof(struct ncp_canon, arc.radius) == NCP_CANON_D0 + 8 * 8 &&
               offsetof(struct ncp_canon, arc.second_centre) == NCP_CANON_D0 + 9 * 8 &&
               offsetof(struct ncp_canon, arc.tol_rel) == NCP_CANON_D0 + 11 * 8 &&
               offsetof(struct ncp_canon, arc.plane) == NCP_CANON_I0 + 3 * 4 &&
               offsetof(struct ncp_canon, dwell.seconds) == NCP_CANON_D0 &&
               offsetof(struct ncp_canon, motion_control.tolerance) == NCP_CANON_D0 &&
               offsetof(struct ncp_canon, naivecam.tolerance) == NCP_CANON_D0 &&
               offsetof(struct ncp_canon, spindle_speed.speed) == NCP_CANON_D0 &&
               offsetof(struct ncp_canon, spindle_mode.css_max) == NCP_CANON_D0 &&
               offsetof(struct ncp_canon, orient.angle) == NCP_CANON_D0 &&
               offsetof(struct ncp_canon, orient.direction) == NCP_CANON_I0 + 4 &&
               offsetof(struct ncp_canon, tool_length.v) == NCP_CANON_D0 &&
               offsetof(struct ncp_canon, comp_radius.radius) == NCP_CANON_D0 &&
               offsetof(struct ncp_canon, output.value) == NCP_CANON_D0 &&
               offsetof(struct ncp_canon, synch.per_rev) == NCP_CANON_D0 &&
               offsetof(struct ncp_canon, synch.velocity_mode) == NCP_CANON_I0 + 4 &&
               offsetof(struct ncp_canon, nurbs.end) == NCP_CANON_D0 &&
               offsetof(struct ncp_canon, nurbs.ctrl) == NCP_CANON_D0 + 5 * 8 &&
               offsetof(struct ncp_canon, nurbs.follow) == NCP_CANON_I0 + 2 * 4 &&
               offsetof(struct ncp_canon, nurbs_points.pt) == NCP_CANON_D0 &&
               offsetof(struct ncp_canon, rigid_tap.bottom) == NCP_CANON_D0 &&
               offsetof(struct ncp_canon, user_m.p) == NCP_CANON_D0,
               "every kind's fields stand where raw's do");

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

/* The modal codes in force after a slot's block, as rs274's active G and M
 * codes (code*10, G64 = 640, G61.1 = 611; -1 = none in that group), for a
 * controller's display. The interpreter stamps every slot it hands on, so a
 * block that makes no call (G91 alone) shows in the next slot, at the latest
 * in the run's closing one. */
enum ncp_active_g {
    NCP_AG_MOTION, NCP_AG_PLANE, NCP_AG_DIST, NCP_AG_ARCDIST, NCP_AG_FEEDMODE,
    NCP_AG_UNITS, NCP_AG_COMP, NCP_AG_TLO, NCP_AG_RETRACT, NCP_AG_COORD, NCP_AG_CONTROL,
    NCP_AG_SPINDLE, NCP_AG_LATHE, NCP_AG__N
};
enum ncp_active_m { NCP_AM_SPINDLE, NCP_AM_MIST, NCP_AM_FLOOD, NCP_AM_OVERRIDE, NCP_AM__N };
struct ncp_active_codes {
    int16_t g[NCP_AG__N];
    int16_t m[NCP_AM__N];       /* M7 and M8 each in its slot; both off: M9 in MIST's */
    double g64_p, g64_q;        /* G64's tolerances (program units) */
};

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
    struct ncp_active_codes active; /* stamped when the slot is handed on */
    char text[NCP_CMD_TEXT_POOL];
    char out[NCP_CMD_OUT_MAX];  /* filled by the executor */
};

/* Clear a slot's header (not its ops, not its diag) and number it: what
 * acquire() does. Whoever sets diag sets NCP_CMD_F_ERROR with it. */
void ncp_cmd_reset_header(struct ncp_cmd *cmd, uint64_t id);

#endif
