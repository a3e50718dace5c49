/* Canonical text, table-driven: each kind maps to one rs274 print template (or
 * a few, chosen by i[0], where rs274 prints an enum name). Templates are
 * compiled once into literal runs and fields, so a line costs a handful of
 * memcpy calls and number conversions and no format parsing.
 *
 * Template fields: %Dk = d[k] as "%.4f", %Fk = d[k] as "%f", %Ik = i[k] as
 * "%d", %T = the op's text. Templates mirror rs274 -g (LinuxCNC 2.9 saicanon)
 * byte for byte, odd spacing included. */
#include "fmt_num.h"
#include "format.h"
#include "ncpar/executor.h"

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <string.h>

#define NCP_TPL_VARIANTS 4

struct ncp_kind_fmt {
    const char *tpl[NCP_TPL_VARIANTS]; /* chosen by i[0] when more than one */
    const char *fallback;              /* i[0] out of range or tpl NULL */
};

static const struct ncp_kind_fmt ncp_kind_fmts[NCP_C__COUNT] = {
    [NCP_C_USE_LENGTH_UNITS] = {{"USE_LENGTH_UNITS(CANON_UNITS_INCHES)",
                                 "USE_LENGTH_UNITS(CANON_UNITS_MM)"},
                                "USE_LENGTH_UNITS(UNKNOWN)"},
    [NCP_C_SET_G5X_OFFSET] = {{"SET_G5X_OFFSET(%I0, %D0, %D1, %D2, %D3, %D4, %D5)"}, NULL},
    [NCP_C_SET_G92_OFFSET] = {{"SET_G92_OFFSET(%D0, %D1, %D2, %D3, %D4, %D5)"}, NULL},
    [NCP_C_SET_XY_ROTATION] = {{"SET_XY_ROTATION(%D0)"}, NULL},
    [NCP_C_SET_FEED_REFERENCE] = {{"SET_FEED_REFERENCE(CANON_WORKPIECE)",
                                   "SET_FEED_REFERENCE(CANON_XYZ)"},
                                  "SET_FEED_REFERENCE(CANON_XYZ)"},
    [NCP_C_ON_RESET] = {{"ON_RESET()"}, NULL},
    [NCP_C_STRAIGHT_TRAVERSE] = {{"STRAIGHT_TRAVERSE(%D0, %D1, %D2, %D3, %D4, %D5)"}, NULL},
    [NCP_C_STRAIGHT_FEED] = {{"STRAIGHT_FEED(%D0, %D1, %D2, %D3, %D4, %D5)"}, NULL},
    [NCP_C_STRAIGHT_PROBE] = {{"STRAIGHT_PROBE(%D0, %D1, %D2, %D3, %D4, %D5)"}, NULL},
    [NCP_C_SET_FEED_RATE] = {{"SET_FEED_RATE(%D0)"}, NULL},
    [NCP_C_SET_FEED_MODE] = {{"SET_FEED_MODE(%I0, %I1)"}, NULL},
    [NCP_C_SET_TRAVERSE_RATE] = {{"SET_TRAVERSE_RATE(%D0)"}, NULL},
    [NCP_C_ARC_FEED] = {{"ARC_FEED(%D0, %D1, %D2, %D3, %I0, %D4, %D5, %D6, %D7)"}, NULL},
    [NCP_C_DWELL] = {{"DWELL(%D0)"}, NULL},
    [NCP_C_SELECT_PLANE] = {{"SELECT_PLANE(CANON_PLANE_XY)", "SELECT_PLANE(CANON_PLANE_YZ)",
                             "SELECT_PLANE(CANON_PLANE_XZ)"},
                            "SELECT_PLANE(CANON_PLANE_UNKNOWN)"},
    [NCP_C_SET_MOTION_CONTROL_MODE] = {{"SET_MOTION_CONTROL_MODE(CANON_EXACT_STOP)",
                                        "SET_MOTION_CONTROL_MODE(CANON_EXACT_PATH)",
                                        "SET_MOTION_CONTROL_MODE(CANON_CONTINUOUS, %F0)"},
                                       "SET_MOTION_CONTROL_MODE(UNKNOWN)"},
    [NCP_C_SET_NAIVECAM_TOLERANCE] = {{"SET_NAIVECAM_TOLERANCE(%D0)"}, NULL},
    [NCP_C_SET_SPINDLE_SPEED] = {{"SET_SPINDLE_SPEED(%I0, %D0)"}, NULL},
    [NCP_C_SET_SPINDLE_MODE] = {{"SET_SPINDLE_MODE(%I0 %D0)"}, NULL},
    [NCP_C_START_SPINDLE_CLOCKWISE] = {{"START_SPINDLE_CLOCKWISE(%I0)"}, NULL},
    [NCP_C_START_SPINDLE_COUNTERCLOCKWISE] = {{"START_SPINDLE_COUNTERCLOCKWISE(%I0)"}, NULL},
    [NCP_C_STOP_SPINDLE_TURNING] = {{"STOP_SPINDLE_TURNING(%I0)"}, NULL},
    [NCP_C_ORIENT_SPINDLE] = {{"ORIENT_SPINDLE(%I0, %D0, %I1)"}, NULL},
    [NCP_C_SPINDLE_RETRACT_TRAVERSE] = {{"SPINDLE_RETRACT_TRAVERSE()"}, NULL},
    [NCP_C_FLOOD_ON] = {{"FLOOD_ON()"}, NULL},
    [NCP_C_FLOOD_OFF] = {{"FLOOD_OFF()"}, NULL},
    [NCP_C_MIST_ON] = {{"MIST_ON()"}, NULL},
    [NCP_C_MIST_OFF] = {{"MIST_OFF()"}, NULL},
    [NCP_C_SELECT_TOOL] = {{"SELECT_TOOL(%I0)"}, NULL},
    [NCP_C_START_CHANGE] = {{"START_CHANGE()"}, NULL},
    [NCP_C_CHANGE_TOOL] = {{"CHANGE_TOOL(%I0)"}, NULL},
    [NCP_C_CHANGE_TOOL_NUMBER] = {{"CHANGE_TOOL_NUMBER(%I0)"}, NULL},
    [NCP_C_USE_TOOL_LENGTH_OFFSET] =
        {{"USE_TOOL_LENGTH_OFFSET(%D0 %D1 %D2, %D3 %D4 %D5, %D6 %D7 %D8)"}, NULL},
    [NCP_C_SET_CUTTER_RADIUS_COMPENSATION] = {{"SET_CUTTER_RADIUS_COMPENSATION(%D0)"}, NULL},
    [NCP_C_START_CUTTER_RADIUS_COMPENSATION] =
        {{NULL, "START_CUTTER_RADIUS_COMPENSATION(LEFT)",
          "START_CUTTER_RADIUS_COMPENSATION(RIGHT)"},
         "START_CUTTER_RADIUS_COMPENSATION(UNKNOWN)"},
    [NCP_C_STOP_CUTTER_RADIUS_COMPENSATION] = {{"STOP_CUTTER_RADIUS_COMPENSATION()"}, NULL},
    [NCP_C_COMMENT] = {{"COMMENT(\"%T\")"}, NULL},
    [NCP_C_MESSAGE] = {{"MESSAGE(\"%T\")"}, NULL},
    [NCP_C_LOGOPEN] = {{"LOGOPEN(\"%T\")"}, NULL},
    [NCP_C_LOGAPPEND] = {{"LOGAPPEND(\"%T\")"}, NULL},
    [NCP_C_LOGCLOSE] = {{"LOGCLOSE()"}, NULL},
    [NCP_C_LOG] = {{"LOG(\"%T\")"}, NULL},
    [NCP_C_ENABLE_FEED_OVERRIDE] = {{"ENABLE_FEED_OVERRIDE()"}, NULL},
    [NCP_C_DISABLE_FEED_OVERRIDE] = {{"DISABLE_FEED_OVERRIDE()"}, NULL},
    [NCP_C_ENABLE_SPEED_OVERRIDE] = {{"ENABLE_SPEED_OVERRIDE(%I0)"}, NULL},
    [NCP_C_DISABLE_SPEED_OVERRIDE] = {{"DISABLE_SPEED_OVERRIDE(%I0)"}, NULL},
    [NCP_C_ENABLE_FEED_HOLD] = {{"ENABLE_FEED_HOLD()"}, NULL},
    [NCP_C_DISABLE_FEED_HOLD] = {{"DISABLE_FEED_HOLD()"}, NULL},
    [NCP_C_ENABLE_ADAPTIVE_FEED] = {{"ENABLE_ADAPTIVE_FEED()"}, NULL},
    [NCP_C_DISABLE_ADAPTIVE_FEED] = {{"DISABLE_ADAPTIVE_FEED()"}, NULL},
    [NCP_C_PROGRAM_STOP] = {{"PROGRAM_STOP()"}, NULL},
    [NCP_C_OPTIONAL_PROGRAM_STOP] = {{"OPTIONAL_PROGRAM_STOP()"}, NULL},
    [NCP_C_PALLET_SHUTTLE] = {{"PALLET_SHUTTLE()"}, NULL},
    [NCP_C_PROGRAM_END] = {{"PROGRAM_END()"}, NULL},
    [NCP_C_TURN_PROBE_ON] = {{"TURN_PROBE_ON()"}, NULL},
    [NCP_C_TURN_PROBE_OFF] = {{"TURN_PROBE_OFF()"}, NULL},
    [NCP_C_SET_AUX_OUTPUT_BIT] = {{"SET_AUX_OUTPUT_BIT(%I0)"}, NULL},
    [NCP_C_CLEAR_AUX_OUTPUT_BIT] = {{"CLEAR_AUX_OUTPUT_BIT(%I0)"}, NULL},
    [NCP_C_SET_MOTION_OUTPUT_BIT] = {{"SET_MOTION_OUTPUT_BIT(%I0)"}, NULL},
    [NCP_C_CLEAR_MOTION_OUTPUT_BIT] = {{"CLEAR_MOTION_OUTPUT_BIT(%I0)"}, NULL},
    [NCP_C_SET_AUX_OUTPUT_VALUE] = {{"SET_AUX_OUTPUT_VALUE(%I0,%F0)"}, NULL},
    [NCP_C_SET_MOTION_OUTPUT_VALUE] = {{"SET_MOTION_OUTPUT_VALUE(%I0,%F0)"}, NULL},
    /* rs274 spells this one without the H and prints the mode as %d of a bool */
    [NCP_C_START_SPEED_FEED_SYNCH] = {{"START_SPEED_FEED_SYNC(%F0,%I1)"}, NULL},
    [NCP_C_STOP_SPEED_FEED_SYNCH] = {{"STOP_SPEED_FEED_SYNCH()"}, NULL},
    [NCP_C_NURBS_FEED] = {{"NURBS_FEED(%I0, ...)"}, NULL},
    [NCP_C_RIGID_TAP] = {{"RIGID_TAP(%D0, %D1, %D2)"}, NULL},
    [NCP_C_RAW_TEXT] = {{"%T"}, NULL},
};

enum ncp_field { NCP_FLD_END, NCP_FLD_D4, NCP_FLD_F6, NCP_FLD_INT, NCP_FLD_TEXT };

struct ncp_seg {
    const char *lit;   /* literal text printed before the field */
    uint8_t lit_len;
    uint8_t field;     /* enum ncp_field */
    uint8_t idx;
    uint8_t pooled;    /* lit is in ncp_lit_pool: block copies may read past it */
};

#define NCP_TPL_SEGS 12 /* most fields in one template (9) + end, with room */

struct ncp_tpl {
    struct ncp_seg seg[NCP_TPL_SEGS];
};

/* Compiled form of ncp_kind_fmts; slot NCP_TPL_VARIANTS is the fallback. */
static struct ncp_tpl ncp_tpls[NCP_C__COUNT][NCP_TPL_VARIANTS + 1];
static pthread_once_t ncp_tpls_once = PTHREAD_ONCE_INIT;

/* Literals live in one pool with slack behind the last one, so a short literal
 * can be copied as a fixed-size block (one or two moves, no memcpy call). */
#define NCP_LIT_BLOCK 32
static char ncp_lit_pool[16384 + NCP_LIT_BLOCK];
static size_t ncp_lit_used;

static void ncp_lit_intern(struct ncp_seg *seg, const char *s, size_t n)
{
    seg->lit = s;
    seg->pooled = 0;
    if (ncp_lit_used + n > sizeof ncp_lit_pool - NCP_LIT_BLOCK)
        return; /* the table is far smaller; stay correct anyway */
    char *p = ncp_lit_pool + ncp_lit_used;
    memcpy(p, s, n);
    ncp_lit_used += n;
    seg->lit = p;
    seg->pooled = 1;
}

/* A field is '%' + one of D F I (+ index digit) or T; anything else is text. */
static int ncp_tpl_is_field(const char *p)
{
    if (p[0] != '%')
        return 0;
    if (p[1] == 'T')
        return 1;
    return (p[1] == 'D' || p[1] == 'F' || p[1] == 'I') && p[2] >= '0' && p[2] <= '9';
}

static void ncp_tpl_compile(struct ncp_tpl *t, const char *src)
{
    int n = 0;
    const char *lit = src;
    const char *p = src;
    for (;;) {
        struct ncp_seg *s = &t->seg[n];
        if (*p == '\0' || (n < NCP_TPL_SEGS - 1 && ncp_tpl_is_field(p))) {
            s->lit_len = (uint8_t)(p - lit);
            ncp_lit_intern(s, lit, s->lit_len);
            if (*p == '\0') {
                s->field = NCP_FLD_END;
                return;
            }
            char c = p[1];
            s->field = c == 'D' ? NCP_FLD_D4 : c == 'F' ? NCP_FLD_F6
                     : c == 'I' ? NCP_FLD_INT : NCP_FLD_TEXT;
            p += 2;
            s->idx = 0;
            if (s->field != NCP_FLD_TEXT)
                s->idx = (uint8_t)(*p++ - '0');
            lit = p;
            n++;
        } else {
            p++;
        }
    }
}

static void ncp_tpls_build(void)
{
    for (int k = 0; k < NCP_C__COUNT; k++) {
        const struct ncp_kind_fmt *f = &ncp_kind_fmts[k];
        for (int v = 0; v < NCP_TPL_VARIANTS; v++)
            ncp_tpl_compile(&ncp_tpls[k][v], f->tpl[v] ? f->tpl[v]
                                               : f->fallback ? f->fallback : "");
        ncp_tpl_compile(&ncp_tpls[k][NCP_TPL_VARIANTS], f->fallback ? f->fallback : "");
    }
}

static const struct ncp_tpl *ncp_tpl_for(const struct ncp_canon *op)
{
    const struct ncp_kind_fmt *f = &ncp_kind_fmts[op->kind];
    if (!f->fallback)
        return &ncp_tpls[op->kind][0];
    if (op->raw.i[0] >= 0 && op->raw.i[0] < NCP_TPL_VARIANTS)
        return &ncp_tpls[op->kind][op->raw.i[0]];
    return &ncp_tpls[op->kind][NCP_TPL_VARIANTS];
}

struct ncp_out {
    char *p, *end;
    int full;
};

static void ncp_out_put(struct ncp_out *o, const char *s, size_t n)
{
    if (o->full || (size_t)(o->end - o->p) < n) {
        o->full = 1;
        return;
    }
    memcpy(o->p, s, n);
    o->p += n;
}

/* Converters need NCP_FMT_NUM_MAX bytes of room; near the end of the buffer the
 * number goes through a scratch buffer so a short tail is still usable. */
static void ncp_out_num(struct ncp_out *o, size_t (*conv)(char *, double), double v)
{
    if (o->full)
        return;
    if (o->end - o->p >= NCP_FMT_NUM_MAX) {
        o->p += conv(o->p, v);
        return;
    }
    char tmp[NCP_FMT_NUM_MAX];
    size_t n = conv(tmp, v);
    ncp_out_put(o, tmp, n);
}

static void ncp_out_lit(struct ncp_out *o, const struct ncp_seg *s)
{
    if (s->pooled && s->lit_len <= NCP_LIT_BLOCK && o->end - o->p >= NCP_LIT_BLOCK) {
        memcpy(o->p, s->lit, NCP_LIT_BLOCK);
        o->p += s->lit_len;
        return;
    }
    ncp_out_put(o, s->lit, s->lit_len);
}

static void ncp_out_int(struct ncp_out *o, int32_t v)
{
    char tmp[12];
    size_t n = ncp_fmt_int(tmp, v);
    ncp_out_put(o, tmp, n);
}

/* The text of op, clamped to the pool so a bad offset cannot read outside it. */
static void ncp_op_text(const struct ncp_cmd *cmd, const struct ncp_canon *op,
                        const char **s, size_t *n)
{
    size_t off = op->text_off < NCP_CMD_TEXT_POOL ? op->text_off : NCP_CMD_TEXT_POOL;
    size_t len = op->text_len;
    if (len > NCP_CMD_TEXT_POOL - off)
        len = NCP_CMD_TEXT_POOL - off;
    *s = cmd->text + off;
    *n = len;
}

/* The calls a CAM program is made of, written as straight-line code instead
 * of a template walk (half the instructions per line): the same text as
 * their templates above, which tests/unit/test_executor.c holds them to. Only
 * when every number is below 1e14 (at most 32 bytes of text each) and the
 * line surely fits; otherwise the template walk with its checks. */
#define NCP_HOT_NUM 32
#define NCP_HOT_LINE (NCP_LIT_BLOCK + 9 * (NCP_HOT_NUM + NCP_LIT_BLOCK) + 12)

_Static_assert(NCP_HOT_LINE < NCP_CMD_OUT_MAX, "a motion line fits an empty slot");

static int ncp_hot_numbers(const double *d, int n)
{
    for (int k = 0; k < n; k++)
        if (!(fabs(d[k]) < 1e14))
            return 0;
    return 1;
}

/* ", " + number; +0, what most of a move's A, B, C are, as one eight-byte
 * move. Both without a NUL: these are pieces of a line (room is assured). */
static const char ncp_sep[2] = {',', ' '};
static const char ncp_sep_zero[8] = {',', ' ', '0', '.', '0', '0', '0', '0'};

static char *ncp_hot_next(char *p, double v)
{
    uint64_t bits;
    memcpy(&bits, &v, sizeof bits);
    if (bits == 0) {
        memcpy(p, ncp_sep_zero, sizeof ncp_sep_zero);
        return p + sizeof ncp_sep_zero;
    }
    memcpy(p, ncp_sep, sizeof ncp_sep);
    p += sizeof ncp_sep;
    return p + ncp_fmt_fixed4(p, v);
}

/* The call's name and '(' come from its compiled template (the literal before
 * its first field), copied as one fixed-size block like any pooled literal. */
static int ncp_format_hot(struct ncp_out *o, const struct ncp_canon *op)
{
    unsigned kind = op->kind;
    int straight = kind == NCP_C_STRAIGHT_TRAVERSE || kind == NCP_C_STRAIGHT_FEED ||
                   kind == NCP_C_STRAIGHT_PROBE;
    if (!straight && kind != NCP_C_ARC_FEED)
        return 0;
    /* The numbers in print order: move.end, or arc_feed's doubles and its
     * rotation, which stand in print order in raw (canon.h asserts their
     * places). */
    const struct ncp_seg *head = &ncp_tpls[kind][0].seg[0];
    if (o->full || o->end - o->p < NCP_HOT_LINE || !head->pooled ||
        !ncp_hot_numbers(op->raw.d, straight ? 6 : 8))
        return 0;
    char *p = o->p;
    memcpy(p, head->lit, NCP_LIT_BLOCK);
    p += head->lit_len;
    p += ncp_fmt_fixed4(p, op->raw.d[0]);
    if (straight) {
        for (int k = 1; k < 6; k++)
            p = ncp_hot_next(p, op->raw.d[k]);
    } else {
        for (int k = 1; k < 4; k++)
            p = ncp_hot_next(p, op->raw.d[k]);
        memcpy(p, ncp_sep, sizeof ncp_sep);
        p += sizeof ncp_sep;
        p += ncp_fmt_int(p, op->raw.i[0]);
        for (int k = 4; k < 8; k++)
            p = ncp_hot_next(p, op->raw.d[k]);
    }
    memcpy(p, ")\n", 2);
    o->p = p + 2;
    return 1;
}

static void ncp_format_op(struct ncp_out *o, const struct ncp_cmd *cmd,
                          const struct ncp_canon *op)
{
    if (ncp_format_hot(o, op))
        return;
    const struct ncp_seg *s = ncp_tpl_for(op)->seg;
    for (;; s++) {
        ncp_out_lit(o, s);
        switch (s->field) {
        case NCP_FLD_END:
            ncp_out_put(o, "\n", 1);
            return;
        case NCP_FLD_D4:
            ncp_out_num(o, ncp_fmt_fixed4, op->raw.d[s->idx]);
            break;
        case NCP_FLD_F6:
            ncp_out_num(o, ncp_fmt_fixed6, op->raw.d[s->idx]);
            break;
        case NCP_FLD_INT:
            ncp_out_int(o, op->raw.i[s->idx]);
            break;
        default: {
            const char *t;
            size_t n;
            ncp_op_text(cmd, op, &t, &n);
            ncp_out_put(o, t, n);
            break;
        }
        }
    }
}

/* Kinds with nothing to print: NONE, and requests that resolve() did not turn
 * into a call (it only leaves them when it stopped at an error before them). */
static int ncp_kind_prints(unsigned kind)
{
    return kind < NCP_C__COUNT && (ncp_kind_fmts[kind].tpl[0] || ncp_kind_fmts[kind].fallback);
}

void ncp_exec_format(struct ncp_cmd *cmd)
{
    ncp_exec_format_into(cmd, cmd->out);
}

void ncp_exec_format_into(struct ncp_cmd *cmd, char *dst)
{
    ncp_exec_format_diag(cmd, dst, &cmd->diag);
}

void ncp_exec_format_diag(struct ncp_cmd *cmd, char *dst, struct ncp_diag *g)
{
    pthread_once(&ncp_tpls_once, ncp_tpls_build);
    struct ncp_out o = {dst, dst + NCP_CMD_OUT_MAX, 0};
    unsigned n_ops = cmd->n_ops;
    if (n_ops > NCP_CMD_MAX_OPS)
        n_ops = NCP_CMD_MAX_OPS;
    for (unsigned k = 0; k < n_ops; k++) {
        const struct ncp_canon *op = &cmd->ops[k];
        if (!ncp_kind_prints(op->kind))
            continue;
        char *line = o.p;
        ncp_format_op(&o, cmd, op);
        if (o.full) {
            /* Only absurd magnitudes or a pool-sized comment get here; say so
             * rather than emit a cut line. */
            o.p = line;
            cmd->n_ops = (uint16_t)k;
            if (!(cmd->flags & NCP_CMD_F_ERROR)) {
                ncp_diag_set(g, NCP_ERR_LIMIT, cmd->line, 0,
                             "canonical output of this block exceeds %d bytes",
                             NCP_CMD_OUT_MAX);
                g->file = ncp_diag_file_of_tag(NCP_CMD_FILE(cmd));
            }
            cmd->flags |= NCP_CMD_F_ERROR;
            break;
        }
    }
    cmd->out_len = (uint32_t)(o.p - dst);
}
