/* Executor: number formatting against printf, every canonical kind's text
 * against what rs274 -g prints, and arc resolution against rs274 (expected
 * lines captured from rs274 runs of the same moves). */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "ncpar/executor.h"

static struct ncp_cmd cmd;

static void cmd_clear(void)
{
    memset(&cmd, 0, sizeof cmd);
    cmd.line = 7;
}

static struct ncp_canon *add_op(int kind)
{
    struct ncp_canon *op = &cmd.ops[cmd.n_ops++];
    memset(op, 0, sizeof *op);
    op->kind = (uint16_t)kind;
    return op;
}

static void add_text(struct ncp_canon *op, const char *s)
{
    size_t n = strlen(s);
    op->text_off = cmd.text_used;
    op->text_len = (uint16_t)n;
    memcpy(cmd.text + cmd.text_used, s, n);
    cmd.text_used = (uint16_t)(cmd.text_used + n);
}

/* ---- ncp_fmt_fixed4 vs printf ------------------------------------------- */

static uint64_t rng_state = 0x9E3779B97F4A7C15ull;
static uint64_t rng(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return rng_state;
}

static void check_fixed4(double v)
{
    char want[400], got[400];
    int n = snprintf(want, sizeof want, "%.4f", v);
    size_t len = ncp_fmt_fixed4(got, v);
    if (strcmp(want, got) != 0 || len != (size_t)n)
        fail_msg("%a: printf \"%s\", ncp_fmt_fixed4 \"%s\"", v, want, got);
}

static void test_fixed4_special(void **state)
{
    (void)state;
    static const double vals[] = {
        0.0, -0.0, -0.00004, 0.00004, -0.00005, 0.00005, 0.00015, 0.00025, 1.00005,
        0.5, -0.5, 9.99995, 9.999949999, 99999.99995, 123.45675, -123.45665,
        0.03125, 0.09375, 1.03125, -2.96875, 0.00003125, /* exact binary ties */
        1e13, 99999999999999.99, 1e14, -1e14, 1e15 + 0.5, 4503599627370495.5,
        9007199254740993.0, 1.8446744073709552e19, 1e22, 1e300, -1e300, DBL_MAX,
        -DBL_MAX, DBL_MIN, DBL_TRUE_MIN, -DBL_TRUE_MIN, 1.0 / 3, -2.0 / 3,
    };
    for (size_t k = 0; k < sizeof vals / sizeof vals[0]; k++)
        check_fixed4(vals[k]);
    check_fixed4(NAN);
    check_fixed4(-NAN);
    check_fixed4(INFINITY);
    check_fixed4(-INFINITY);
    /* Every decimal tie at the fifth place over a range, both signs. */
    for (int64_t k = -2000000; k <= 2000000; k += 7)
        check_fixed4((double)k / 100000.0 + 0.00005);
}

static void test_fixed4_random(void **state)
{
    (void)state;
    for (int k = 0; k < 3000000; k++) {
        uint64_t r = rng();
        double v;
        switch (k % 5) {
        case 0: /* any bit pattern */
            memcpy(&v, &r, sizeof v);
            if (!isfinite(v))
                continue;
            break;
        case 1: /* machining magnitudes */
            v = ((double)(r >> 11) / 9007199254740992.0 - 0.5) * pow(10, (int)(rng() % 20) - 6);
            break;
        case 2: /* five-decimal program values: decimal near-ties */
            v = (double)((int64_t)(r % 2000000001u) - 1000000000) / 100000.0;
            break;
        case 3: /* dyadic values: exact binary ties */
            v = ldexp((double)((int64_t)(r % (1u << 20)) - (1 << 19)), -(int)(rng() % 30));
            break;
        default:
            v = (double)(int64_t)r * 1e-6 * pow(10, -(int)(rng() % 12));
            break;
        }
        check_fixed4(v);
    }
}

/* ---- every kind's text ------------------------------------------------- */

struct kind_case {
    int kind;
    int32_t i0, i1;
    double d[9];
    const char *text;
    const char *want;
};

/* Expected lines are rs274 -g output (LinuxCNC 2.9) for the same values. */
static const struct kind_case kind_cases[] = {
    {NCP_C_USE_LENGTH_UNITS, 0, 0, {0}, NULL, "USE_LENGTH_UNITS(CANON_UNITS_INCHES)"},
    {NCP_C_USE_LENGTH_UNITS, 1, 0, {0}, NULL, "USE_LENGTH_UNITS(CANON_UNITS_MM)"},
    {NCP_C_USE_LENGTH_UNITS, 5, 0, {0}, NULL, "USE_LENGTH_UNITS(UNKNOWN)"},
    {NCP_C_SET_G5X_OFFSET, 2, 0, {1.5, -2.25, 3, 4, 5, 6}, NULL,
     "SET_G5X_OFFSET(2, 1.5000, -2.2500, 3.0000, 4.0000, 5.0000, 6.0000)"},
    {NCP_C_SET_G92_OFFSET, 0, 0, {-2.5, 0.25, 0, 0, 0, 0}, NULL,
     "SET_G92_OFFSET(-2.5000, 0.2500, 0.0000, 0.0000, 0.0000, 0.0000)"},
    {NCP_C_SET_XY_ROTATION, 0, 0, {0}, NULL, "SET_XY_ROTATION(0.0000)"},
    {NCP_C_SET_FEED_REFERENCE, 0, 0, {0}, NULL, "SET_FEED_REFERENCE(CANON_WORKPIECE)"},
    {NCP_C_SET_FEED_REFERENCE, 1, 0, {0}, NULL, "SET_FEED_REFERENCE(CANON_XYZ)"},
    {NCP_C_ON_RESET, 0, 0, {0}, NULL, "ON_RESET()"},
    {NCP_C_STRAIGHT_TRAVERSE, 0, 0, {1, 2, 3, 4, 5, 6}, NULL,
     "STRAIGHT_TRAVERSE(1.0000, 2.0000, 3.0000, 4.0000, 5.0000, 6.0000)"},
    {NCP_C_STRAIGHT_FEED, 0, 0, {-1.23456, 0.00004, -0.00004, 4, 5, 6}, NULL,
     "STRAIGHT_FEED(-1.2346, 0.0000, -0.0000, 4.0000, 5.0000, 6.0000)"},
    {NCP_C_STRAIGHT_PROBE, 0, 0, {5, 0, -1, 0, 0, 0}, NULL,
     "STRAIGHT_PROBE(5.0000, 0.0000, -1.0000, 0.0000, 0.0000, 0.0000)"},
    {NCP_C_SET_FEED_RATE, 0, 0, {250.5}, NULL, "SET_FEED_RATE(250.5000)"},
    {NCP_C_SET_FEED_MODE, 0, 1, {0}, NULL, "SET_FEED_MODE(0, 1)"},
    {NCP_C_SET_TRAVERSE_RATE, 0, 0, {1000}, NULL, "SET_TRAVERSE_RATE(1000.0000)"},
    {NCP_C_ARC_FEED, -3, 0, {0, 0, 5, 0, 0, 0, 0, 0}, NULL,
     "ARC_FEED(0.0000, 0.0000, 5.0000, 0.0000, -3, 0.0000, 0.0000, 0.0000, 0.0000)"},
    {NCP_C_DWELL, 0, 0, {2.5}, NULL, "DWELL(2.5000)"},
    {NCP_C_SELECT_PLANE, 0, 0, {0}, NULL, "SELECT_PLANE(CANON_PLANE_XY)"},
    {NCP_C_SELECT_PLANE, 1, 0, {0}, NULL, "SELECT_PLANE(CANON_PLANE_YZ)"},
    {NCP_C_SELECT_PLANE, 2, 0, {0}, NULL, "SELECT_PLANE(CANON_PLANE_XZ)"},
    {NCP_C_SET_MOTION_CONTROL_MODE, 0, 0, {0}, NULL, "SET_MOTION_CONTROL_MODE(CANON_EXACT_STOP)"},
    {NCP_C_SET_MOTION_CONTROL_MODE, 1, 0, {0}, NULL, "SET_MOTION_CONTROL_MODE(CANON_EXACT_PATH)"},
    {NCP_C_SET_MOTION_CONTROL_MODE, 2, 0, {0.01}, NULL,
     "SET_MOTION_CONTROL_MODE(CANON_CONTINUOUS, 0.010000)"},
    {NCP_C_SET_NAIVECAM_TOLERANCE, 0, 0, {0.005}, NULL, "SET_NAIVECAM_TOLERANCE(0.0050)"},
    {NCP_C_SET_SPINDLE_SPEED, 0, 0, {1200}, NULL, "SET_SPINDLE_SPEED(0, 1200.0000)"},
    {NCP_C_SET_SPINDLE_MODE, 0, 0, {2000}, NULL, "SET_SPINDLE_MODE(0 2000.0000)"},
    {NCP_C_START_SPINDLE_CLOCKWISE, 0, 0, {0}, NULL, "START_SPINDLE_CLOCKWISE(0)"},
    {NCP_C_START_SPINDLE_COUNTERCLOCKWISE, 0, 0, {0}, NULL, "START_SPINDLE_COUNTERCLOCKWISE(0)"},
    {NCP_C_STOP_SPINDLE_TURNING, 0, 0, {0}, NULL, "STOP_SPINDLE_TURNING(0)"},
    {NCP_C_ORIENT_SPINDLE, 0, 1, {45}, NULL, "ORIENT_SPINDLE(0, 45.0000, 1)"},
    {NCP_C_SPINDLE_RETRACT_TRAVERSE, 0, 0, {0}, NULL, "SPINDLE_RETRACT_TRAVERSE()"},
    {NCP_C_FLOOD_ON, 0, 0, {0}, NULL, "FLOOD_ON()"},
    {NCP_C_FLOOD_OFF, 0, 0, {0}, NULL, "FLOOD_OFF()"},
    {NCP_C_MIST_ON, 0, 0, {0}, NULL, "MIST_ON()"},
    {NCP_C_MIST_OFF, 0, 0, {0}, NULL, "MIST_OFF()"},
    {NCP_C_SELECT_TOOL, 2, 0, {0}, NULL, "SELECT_TOOL(2)"},
    {NCP_C_START_CHANGE, 0, 0, {0}, NULL, "START_CHANGE()"},
    {NCP_C_CHANGE_TOOL, 11, 0, {0}, NULL, "CHANGE_TOOL(11)"},
    {NCP_C_CHANGE_TOOL_NUMBER, 6, 0, {0}, NULL, "CHANGE_TOOL_NUMBER(6)"},
    {NCP_C_USE_TOOL_LENGTH_OFFSET, 0, 0, {0, 0, -161.7064, 0, 0, 0, 0, 0, 0}, NULL,
     "USE_TOOL_LENGTH_OFFSET(0.0000 0.0000 -161.7064, 0.0000 0.0000 0.0000, "
     "0.0000 0.0000 0.0000)"},
    {NCP_C_SET_CUTTER_RADIUS_COMPENSATION, 0, 0, {0.25}, NULL,
     "SET_CUTTER_RADIUS_COMPENSATION(0.2500)"},
    {NCP_C_START_CUTTER_RADIUS_COMPENSATION, 1, 0, {0}, NULL,
     "START_CUTTER_RADIUS_COMPENSATION(LEFT)"},
    {NCP_C_START_CUTTER_RADIUS_COMPENSATION, 2, 0, {0}, NULL,
     "START_CUTTER_RADIUS_COMPENSATION(RIGHT)"},
    {NCP_C_START_CUTTER_RADIUS_COMPENSATION, 0, 0, {0}, NULL,
     "START_CUTTER_RADIUS_COMPENSATION(UNKNOWN)"},
    {NCP_C_STOP_CUTTER_RADIUS_COMPENSATION, 0, 0, {0}, NULL, "STOP_CUTTER_RADIUS_COMPENSATION()"},
    {NCP_C_COMMENT, 0, 0, {0}, "a comment", "COMMENT(\"a comment\")"},
    {NCP_C_MESSAGE, 0, 0, {0}, " hello world", "MESSAGE(\" hello world\")"},
    {NCP_C_LOGOPEN, 0, 0, {0}, "/tmp/log.txt", "LOGOPEN(\"/tmp/log.txt\")"},
    {NCP_C_LOGAPPEND, 0, 0, {0}, "/tmp/log.txt", "LOGAPPEND(\"/tmp/log.txt\")"},
    {NCP_C_LOGCLOSE, 0, 0, {0}, NULL, "LOGCLOSE()"},
    {NCP_C_LOG, 0, 0, {0}, "text here", "LOG(\"text here\")"},
    {NCP_C_ENABLE_FEED_OVERRIDE, 0, 0, {0}, NULL, "ENABLE_FEED_OVERRIDE()"},
    {NCP_C_DISABLE_FEED_OVERRIDE, 0, 0, {0}, NULL, "DISABLE_FEED_OVERRIDE()"},
    {NCP_C_ENABLE_SPEED_OVERRIDE, 0, 0, {0}, NULL, "ENABLE_SPEED_OVERRIDE(0)"},
    {NCP_C_DISABLE_SPEED_OVERRIDE, 0, 0, {0}, NULL, "DISABLE_SPEED_OVERRIDE(0)"},
    {NCP_C_ENABLE_FEED_HOLD, 0, 0, {0}, NULL, "ENABLE_FEED_HOLD()"},
    {NCP_C_DISABLE_FEED_HOLD, 0, 0, {0}, NULL, "DISABLE_FEED_HOLD()"},
    {NCP_C_ENABLE_ADAPTIVE_FEED, 0, 0, {0}, NULL, "ENABLE_ADAPTIVE_FEED()"},
    {NCP_C_DISABLE_ADAPTIVE_FEED, 0, 0, {0}, NULL, "DISABLE_ADAPTIVE_FEED()"},
    {NCP_C_PROGRAM_STOP, 0, 0, {0}, NULL, "PROGRAM_STOP()"},
    {NCP_C_OPTIONAL_PROGRAM_STOP, 0, 0, {0}, NULL, "OPTIONAL_PROGRAM_STOP()"},
    {NCP_C_PALLET_SHUTTLE, 0, 0, {0}, NULL, "PALLET_SHUTTLE()"},
    {NCP_C_PROGRAM_END, 0, 0, {0}, NULL, "PROGRAM_END()"},
    {NCP_C_TURN_PROBE_ON, 0, 0, {0}, NULL, "TURN_PROBE_ON()"},
    {NCP_C_TURN_PROBE_OFF, 0, 0, {0}, NULL, "TURN_PROBE_OFF()"},
    {NCP_C_SET_AUX_OUTPUT_BIT, 2, 0, {0}, NULL, "SET_AUX_OUTPUT_BIT(2)"},
    {NCP_C_CLEAR_AUX_OUTPUT_BIT, 2, 0, {0}, NULL, "CLEAR_AUX_OUTPUT_BIT(2)"},
    {NCP_C_SET_MOTION_OUTPUT_BIT, 1, 0, {0}, NULL, "SET_MOTION_OUTPUT_BIT(1)"},
    {NCP_C_CLEAR_MOTION_OUTPUT_BIT, 1, 0, {0}, NULL, "CLEAR_MOTION_OUTPUT_BIT(1)"},
    {NCP_C_SET_AUX_OUTPUT_VALUE, 2, 0, {3.25}, NULL, "SET_AUX_OUTPUT_VALUE(2,3.250000)"},
    {NCP_C_SET_MOTION_OUTPUT_VALUE, 1, 0, {2.5}, NULL, "SET_MOTION_OUTPUT_VALUE(1,2.500000)"},
    {NCP_C_START_SPEED_FEED_SYNCH, 0, 0, {0.1}, NULL, "START_SPEED_FEED_SYNC(0.100000,0)"},
    {NCP_C_STOP_SPEED_FEED_SYNCH, 0, 0, {0}, NULL, "STOP_SPEED_FEED_SYNCH()"},
    /* the end point rides along for the motion module; rs274 -g prints the order only */
    {NCP_C_NURBS_FEED, 3, 0, {10.0, 5.0, -1.0}, NULL, "NURBS_FEED(3, ...)"},
    {NCP_C_NURBS_FEED, 1234, 0, {10.0, 5.0, -1.0}, NULL, "NURBS_FEED(1234, ...)"},
    {NCP_C_RIGID_TAP, 0, 0, {1.5, -2.0, -8.25}, NULL, "RIGID_TAP(1.5000, -2.0000, -8.2500)"},
    {NCP_C_RAW_TEXT, 0, 0, {0}, "SPINDLE.0.WAIT_ORIENT_COMPLETE(2.0000)",
     "SPINDLE.0.WAIT_ORIENT_COMPLETE(2.0000)"},
};

static void format_one(const struct kind_case *c, char *line, size_t cap)
{
    cmd_clear();
    struct ncp_canon *op = add_op(c->kind);
    op->raw.i[0] = c->i0;
    op->raw.i[1] = c->i1;
    memcpy(op->raw.d, c->d, sizeof c->d);
    if (c->text)
        add_text(op, c->text);
    assert_int_equal(ncp_exec_cmd(&cmd), NCP_OK);
    assert_true(cmd.out_len > 0 && cmd.out_len < cap);
    assert_int_equal(cmd.out[cmd.out_len - 1], '\n');
    memcpy(line, cmd.out, cmd.out_len - 1);
    line[cmd.out_len - 1] = '\0';
}

static void test_every_kind(void **state)
{
    (void)state;
    int seen[NCP_C__COUNT] = {0};
    char line[NCP_CMD_OUT_MAX];
    for (size_t k = 0; k < sizeof kind_cases / sizeof kind_cases[0]; k++) {
        format_one(&kind_cases[k], line, sizeof line);
        assert_string_equal(line, kind_cases[k].want);
        seen[kind_cases[k].kind] = 1;
    }
    /* Every printable kind has a case; only NONE, the arc request, the
     * NURBS points (rs274 -g prints none) and PRINT (rs274's stdout, not its
     * canonical stream: test_print_text) are silent. */
    for (int kind = 1; kind < NCP_C__COUNT; kind++)
        if (kind != NCP_C_ARC_REQUEST && kind != NCP_C_NURBS_POINTS && kind != NCP_C_PRINT &&
            kind != NCP_C_WAIT_INPUT && kind != NCP_C_USER_M && !seen[kind])
            fail_msg("canonical kind %d has no text case", kind);
}

/* A coordinate for the motion lines: mostly machining sizes, some long enough
 * to crowd the slot, some beyond the fast formatter's reach. */
static double hot_value(void)
{
    uint64_t r = rng();
    switch (r % 16) {
    case 0: return 0.0;
    case 1: return -0.0;
    case 2: return 1e14 * (double)(r % 5 + 1); /* the templates' slow path */
    case 3: return -9.99999999999e13;
    case 4: return ((double)(r >> 12) / 4503599627370496.0 - 0.5) * 2e13;
    default: return (double)((int64_t)(r >> 20) % 20000001 - 10000000) / 1000.0;
    }
}

static size_t hot_expect(char *w, size_t cap, const struct ncp_canon *op)
{
    static const char *const head[] = {"STRAIGHT_TRAVERSE", "STRAIGHT_FEED",
                                       "STRAIGHT_PROBE"};
    if (op->kind == NCP_C_ARC_FEED) {
        const struct ncp_canon *q = op;
        return (size_t)snprintf(w, cap, "ARC_FEED(%.4f, %.4f, %.4f, %.4f, %d, %.4f, %.4f, "
                                "%.4f, %.4f)\n", q->arc_feed.first_end, q->arc_feed.second_end,
                                q->arc_feed.first_axis, q->arc_feed.second_axis,
                                q->arc_feed.rotation, q->arc_feed.axis_end,
                                q->arc_feed.abc[0], q->arc_feed.abc[1], q->arc_feed.abc[2]);
    }
    const double *d = op->move.end;
    return (size_t)snprintf(w, cap, "%s(%.4f, %.4f, %.4f, %.4f, %.4f, %.4f)\n",
                            head[op->kind - NCP_C_STRAIGHT_TRAVERSE], d[0], d[1], d[2],
                            d[3], d[4], d[5]);
}

/* Motion lines have a formatter of their own beside the template walk: it must
 * print exactly what printf would, wherever in the slot the line starts (near
 * its end the walk takes over) and whatever the magnitudes. */
static void test_motion_lines_random(void **state)
{
    (void)state;
    static const int kinds[] = {NCP_C_STRAIGHT_TRAVERSE, NCP_C_STRAIGHT_FEED,
                                NCP_C_STRAIGHT_PROBE, NCP_C_ARC_FEED};
    char want[NCP_CMD_MAX_OPS * 3200];
    for (int round = 0; round < 20000; round++) {
        cmd_clear();
        size_t len = 0;
        int n_ops = (int)(rng() % NCP_CMD_MAX_OPS) + 1;
        for (int k = 0; k < n_ops; k++) {
            struct ncp_canon *op = add_op(kinds[rng() % 4]);
            for (int j = 0; j < 8; j++) /* move.end and arc_feed's doubles alike */
                op->raw.d[j] = hot_value();
            op->raw.i[0] = (int)(rng() % 7) - 3;
            len += hot_expect(want + len, sizeof want - len, op);
        }
        assert_int_equal(ncp_exec_cmd(&cmd), NCP_OK);
        if (len <= NCP_CMD_OUT_MAX) {
            assert_int_equal(cmd.out_len, len);
            assert_memory_equal(cmd.out, want, len);
        } else {
            /* refused whole lines only: what was printed is a prefix of the truth */
            assert_true(cmd.out_len < len);
            assert_memory_equal(cmd.out, want, cmd.out_len);
        }
    }
}

static void test_int_extremes(void **state)
{
    (void)state;
    static const struct kind_case c[] = {
        {NCP_C_SELECT_TOOL, INT32_MIN, 0, {0}, NULL, "SELECT_TOOL(-2147483648)"},
        {NCP_C_SELECT_TOOL, INT32_MAX, 0, {0}, NULL, "SELECT_TOOL(2147483647)"},
        {NCP_C_SELECT_TOOL, -7, 0, {0}, NULL, "SELECT_TOOL(-7)"},
    };
    char line[NCP_CMD_OUT_MAX];
    for (size_t k = 0; k < 3; k++) {
        format_one(&c[k], line, sizeof line);
        assert_string_equal(line, c[k].want);
    }
}

static void test_several_ops_and_silent_kinds(void **state)
{
    (void)state;
    cmd_clear();
    add_op(NCP_C_NONE);
    add_op(NCP_C_FLOOD_ON);
    struct ncp_canon *op = add_op(NCP_C_SET_FEED_RATE);
    op->feed_rate.rate = 12.5;
    add_op(NCP_C_NURBS_POINTS)->nurbs_points.n = 2;
    add_op(9999); /* corrupt kind: skipped, never indexes past the table */
    add_op(NCP_C_PROGRAM_END);
    assert_int_equal(ncp_exec_cmd(&cmd), NCP_OK);
    const char want[] = "FLOOD_ON()\nSET_FEED_RATE(12.5000)\nPROGRAM_END()\n";
    assert_int_equal(cmd.out_len, strlen(want));
    assert_memory_equal(cmd.out, want, cmd.out_len);
}

static void test_text_clamped_to_pool(void **state)
{
    (void)state;
    cmd_clear();
    struct ncp_canon *op = add_op(NCP_C_COMMENT);
    op->text_off = NCP_CMD_TEXT_POOL - 3;
    op->text_len = 500;
    memcpy(cmd.text + NCP_CMD_TEXT_POOL - 3, "xyz", 3);
    assert_int_equal(ncp_exec_cmd(&cmd), NCP_OK);
    assert_int_equal(cmd.out_len, strlen("COMMENT(\"xyz\")\n"));
    assert_memory_equal(cmd.out, "COMMENT(\"xyz\")\n", cmd.out_len);
}

/* Lines that cannot fit are refused whole, with an error, never cut. */
static void test_output_overflow(void **state)
{
    (void)state;
    cmd_clear();
    char big[NCP_CMD_TEXT_POOL];
    memset(big, 'c', sizeof big - 1);
    big[sizeof big - 1] = '\0';
    struct ncp_canon *first = add_op(NCP_C_COMMENT);
    add_text(first, big);
    for (int k = 1; k < NCP_CMD_MAX_OPS; k++)
        cmd.ops[cmd.n_ops++] = *first;
    assert_int_equal(ncp_exec_cmd(&cmd), NCP_ERR_LIMIT);
    assert_true(cmd.flags & NCP_CMD_F_ERROR);
    size_t line_len = strlen(big) + strlen("COMMENT(\"\")\n");
    assert_int_equal(cmd.n_ops, NCP_CMD_OUT_MAX / line_len);
    assert_int_equal(cmd.out_len, cmd.n_ops * line_len);

    cmd_clear();
    struct ncp_canon *op = add_op(NCP_C_ARC_FEED);
    for (int k = 0; k < 8; k++) /* every double of arc_feed */
        op->raw.d[k] = -DBL_MAX;
    for (int k = 1; k < 3; k++)
        cmd.ops[cmd.n_ops++] = *op;
    assert_int_equal(ncp_exec_cmd(&cmd), NCP_ERR_LIMIT);
    assert_int_equal(cmd.n_ops, 0);
    assert_int_equal(cmd.out_len, 0);
}

/* ---- arcs ------------------------------------------------------------- */

struct arc_case {
    const char *name;
    int plane, dir, rform;
    double s1, s2, e1, e2, c1, c2; /* c: incremental centre (IJK) or R */
    int p;
    double e3;
    int inch, err;
    const char *want; /* rs274's ARC_FEED line or error message */
};

static const struct arc_case arc_cases[] = {
    {"ijk_xy_cw", 0, -1, 0, 0.0, 0.0, 10.0, 0.0, 5.0, 0.0, 1, 0.0, 0, 0,
     "ARC_FEED(10.0000, 0.0000, 5.0000, 0.0000, -1, 0.0000, 0.0000, 0.0000, 0.0000)"},
    {"ijk_xy_ccw_quarter", 0, 1, 0, 1.5, 2.5, 3.5, 4.5, 2.0, 0.0, 1, 0.0, 0, 0,
     "ARC_FEED(3.5000, 4.5000, 3.5000, 2.5000, 1, 0.0000, 0.0000, 0.0000, 0.0000)"},
    {"ijk_full_circle_p3", 0, -1, 0, 0.0, 0.0, 0.0, 0.0, 5.0, 0.0, 3, 0.0, 0, 0,
     "ARC_FEED(0.0000, 0.0000, 5.0000, 0.0000, -3, 0.0000, 0.0000, 0.0000, 0.0000)"},
    {"ijk_helix", 0, 1, 0, 10.0, 0.0, 0.0, 10.0, -10.0, 0.0, 2, -5.5, 0, 0,
     "ARC_FEED(0.0000, 10.0000, 0.0000, 0.0000, 2, -5.5000, 0.0000, 0.0000, 0.0000)"},
    {"ijk_yz", 1, 1, 0, 0.0, 0.0, 0.0, 6.0, 0.0, 3.0, 1, 2.0, 0, 0,
     "ARC_FEED(0.0000, 6.0000, 0.0000, 3.0000, 1, 2.0000, 0.0000, 0.0000, 0.0000)"},
    {"ijk_xz", 2, -1, 0, 0.0, 0.0, 2.0, 2.0, 2.0, 0.0, 1, 1.25, 1, 0,
     "ARC_FEED(2.0000, 2.0000, 2.0000, 0.0000, -1, 1.2500, 0.0000, 0.0000, 0.0000)"},
    {"r_pos_cw", 0, -1, 1, 0.0, 0.0, 10.0, 0.0, 5.0, 0.0, 1, 0.0, 0, 0,
     "ARC_FEED(10.0000, 0.0000, 5.0000, -0.0000, -1, 0.0000, 0.0000, 0.0000, 0.0000)"},
    {"r_neg_cw_long", 0, -1, 1, 0.0, 0.0, 3.0, 4.0, -5.0, 0.0, 1, 0.0, 0, 0,
     "ARC_FEED(3.0000, 4.0000, -1.9641, 4.5981, -1, 0.0000, 0.0000, 0.0000, 0.0000)"},
    {"r_pos_ccw", 0, 1, 1, 0.0, 0.0, 3.0, 4.0, 5.0, 0.0, 1, 0.0, 0, 0,
     "ARC_FEED(3.0000, 4.0000, -1.9641, 4.5981, 1, 0.0000, 0.0000, 0.0000, 0.0000)"},
    {"r_neg_ccw_long", 0, 1, 1, 0.0, 0.0, 3.0, 4.0, -5.0, 0.0, 1, 0.0, 0, 0,
     "ARC_FEED(3.0000, 4.0000, 4.9641, -0.5981, 1, 0.0000, 0.0000, 0.0000, 0.0000)"},
    {"r_yz_helix", 1, -1, 1, 1.0, 1.0, 4.0, 5.0, 2.5, 0.0, 2, -3.0, 0, 0,
     "ARC_FEED(4.0000, 5.0000, 2.5000, 3.0000, -2, -3.0000, 0.0000, 0.0000, 0.0000)"},
    {"r_xz_inch", 2, 1, 1, 0.1, 0.2, 0.7, -0.3, 0.5, 0.0, 1, 0.125, 1, 0,
     "ARC_FEED(0.7000, -0.3000, 0.5999, 0.1899, 1, 0.1250, 0.0000, 0.0000, 0.0000)"},
    {"r_semicircle_slack", 0, 1, 1, 0.0, 0.0, 10.0, 0.0, 4.999, 0.0, 1, 0.0, 0, 0,
     "ARC_FEED(10.0000, 0.0000, 5.0000, 0.0000, 1, 0.0000, 0.0000, 0.0000, 0.0000)"},
    {"ijk_within_abs_tol", 0, 1, 0, 0.0, 0.0, 10.0, 0.02, 5.0, 0.0, 1, 0.0, 0, 0,
     "ARC_FEED(10.0000, 0.0200, 5.0000, 0.0000, 1, 0.0000, 0.0000, 0.0000, 0.0000)"},
    {"ijk_within_rel_tol", 0, 1, 0, 0.0, 0.0, 100.0, 2.0, 50.0, 0.0, 1, 0.0, 0, 0,
     "ARC_FEED(100.0000, 2.0000, 50.0000, 0.0000, 1, 0.0000, 0.0000, 0.0000, 0.0000)"},
    {"err_r_same_point", 0, -1, 1, 1.0, 2.0, 1.0, 2.0, 5.0, 0.0, 1, 0.0, 0, 1,
     "Current point same as end point of arc"},
    {"err_r_too_small", 0, 1, 1, 0.0, 0.0, 10.0, 0.0, 4.99, 0.0, 1, 0.0, 0, 1,
     "Arc radius too small to reach end point"},
    {"err_r_too_small_inch", 0, 1, 1, 0.0, 0.0, 1.0, 0.0, 0.4999, 0.0, 1, 0.0, 1, 1,
     "Arc radius too small to reach end point"},
    {"err_r_zero", 0, 1, 1, 0.0, 0.0, 10.0, 0.0, 0.0, 0.0, 1, 0.0, 0, 1,
     "Arc radius too small to reach end point"},
    {"err_zero_radius", 0, -1, 0, 0.0, 0.0, 10.0, 0.0, 0.0, 0.0, 1, 0.0, 0, 1,
     "Zero-radius arc: start=(X0.0000,Y0.0000) center=(X0.0000,Y0.0000) end=(X10.0000,Y0.0000) r1=0.0000 r2=10.0000"},
    {"err_zero_radius_full", 0, -1, 0, 1.0, 1.0, 1.0, 1.0, 0.00001, 0.0, 1, 0.0, 1, 1,
     "Zero-radius arc: start=(X1.0000,Y1.0000) center=(X1.0000,Y1.0000) end=(X1.0000,Y1.0000) r1=0.0000 r2=0.0000"},
    {"err_abs_tol", 0, 1, 0, 0.0, 0.0, 10.0, 0.6, 5.0, 0.0, 1, 0.0, 0, 1,
     "Radius to end of arc differs from radius to start: start=(X0.0000,Y0.0000) center=(X5.0000,Y0.0000) end=(X10.0000,Y0.6000) r1=5.0000 r2=5.0359 abs_err=0.03587 rel_err=0.7123%"},
    {"err_rel_tol_inch", 0, 1, 0, 0.0, 0.0, 1.0, 0.1, 0.5, 0.0, 1, 0.0, 1, 1,
     "Radius to end of arc differs from radius to start: start=(X0.0000,Y0.0000) center=(X0.5000,Y0.0000) end=(X1.0000,Y0.1000) r1=0.5000 r2=0.5099 abs_err=0.009902 rel_err=1.9419%"},
    {"err_yz_letters", 1, 1, 0, 10.0, 5.0, 3.0, 1.0, 1.0, 1.0, 1, 0.0, 0, 1,
     "Radius to end of arc differs from radius to start: start=(Y10.0000,Z5.0000) center=(Y11.0000,Z6.0000) end=(Y3.0000,Z1.0000) r1=1.4142 r2=9.4340 abs_err=8.02 rel_err=85.0094%"},
    {"err_xz_letters", 2, 1, 0, 10.0, 5.0, 3.0, 1.0, 1.0, 1.0, 1, 0.0, 1, 1,
     "Radius to end of arc differs from radius to start: start=(Z10.0000,X5.0000) center=(Z11.0000,X6.0000) end=(Z3.0000,X1.0000) r1=1.4142 r2=9.4340 abs_err=8.02 rel_err=85.0094%"},

};

static void arc_request(const struct arc_case *c)
{
    cmd_clear();
    add_op(NCP_C_SELECT_PLANE)->plane.plane = c->plane;
    struct ncp_canon *op = add_op(NCP_C_ARC_REQUEST);
    op->arc.first_start = c->s1;
    op->arc.second_start = c->s2;
    op->arc.first_end = c->e1;
    op->arc.second_end = c->e2;
    op->arc.axis_end = c->e3;
    /* The analyzer adds incremental IJK to the start, as rs274 does. */
    if (c->rform) {
        op->arc.radius = c->c1;
    } else {
        op->arc.first_centre = c->s1 + c->c1;
        op->arc.second_centre = c->s2 + c->c2;
    }
    op->arc.dir = c->dir;
    op->arc.radius_form = c->rform;
    op->arc.turns = c->p;
    op->arc.plane = c->plane;
    op->flags = (uint16_t)c->inch;
    add_op(NCP_C_FLOOD_ON);
}

static void test_arcs(void **state)
{
    (void)state;
    static const char *plane_line[] = {"SELECT_PLANE(CANON_PLANE_XY)\n",
                                       "SELECT_PLANE(CANON_PLANE_YZ)\n",
                                       "SELECT_PLANE(CANON_PLANE_XZ)\n"};
    for (size_t k = 0; k < sizeof arc_cases / sizeof arc_cases[0]; k++) {
        const struct arc_case *c = &arc_cases[k];
        char want[NCP_CMD_OUT_MAX];
        arc_request(c);
        int rc = ncp_exec_cmd(&cmd);
        if (c->err) {
            if (rc != NCP_ERR_GEOMETRY)
                fail_msg("%s: expected an error, got %.*s", c->name, (int)cmd.out_len, cmd.out);
            assert_true(cmd.flags & NCP_CMD_F_ERROR);
            assert_int_equal(cmd.n_ops, 1);
            assert_int_equal(cmd.diag.line, 7);
            assert_int_equal(cmd.diag.col, 0);
            /* rs274's longest messages exceed the diag buffer: a prefix match. */
            size_t n = strlen(c->want);
            if (n > NCP_DIAG_MSG_MAX - 1)
                n = NCP_DIAG_MSG_MAX - 1;
            if (strlen(cmd.diag.msg) != n || strncmp(cmd.diag.msg, c->want, n) != 0)
                fail_msg("%s:\n want %s\n got  %s", c->name, c->want, cmd.diag.msg);
            /* the run ends at the failing arc: rs274's driver resets twice */
            snprintf(want, sizeof want, "%sON_RESET()\nON_RESET()\n", plane_line[c->plane]);
        } else {
            if (rc != NCP_OK)
                fail_msg("%s: unexpected error %s", c->name, cmd.diag.msg);
            snprintf(want, sizeof want, "%s%s\nFLOOD_ON()\n", plane_line[c->plane], c->want);
        }
        if (cmd.out_len != strlen(want) || memcmp(cmd.out, want, cmd.out_len) != 0)
            fail_msg("%s:\n want %s\n got  %.*s", c->name, want, (int)cmd.out_len, cmd.out);
    }
}

/* Tolerances from the op override rs274's defaults (INI settings). */
static void test_arc_tolerance_from_op(void **state)
{
    (void)state;
    /* r1 = 5, r2 = 5.0359: 0.0359 apart, 0.71 % of the radius */
    const struct arc_case c = {"tol", 0, 1, 0, 0, 0, 10, 0.6, 5, 0, 1, 0, 0, 0, ""};
    arc_request(&c);
    assert_int_equal(ncp_exec_cmd(&cmd), NCP_ERR_GEOMETRY); /* default 0.0283 mm */
    arc_request(&c);
    cmd.ops[1].arc.tol_abs = 0.05;
    assert_int_equal(ncp_exec_cmd(&cmd), NCP_OK);
    arc_request(&c);
    cmd.ops[1].arc.tol_abs = 0.01;
    assert_int_equal(ncp_exec_cmd(&cmd), NCP_ERR_GEOMETRY);
    arc_request(&c);
    cmd.ops[1].arc.tol_abs = 0.01;
    cmd.ops[1].arc.tol_rel = 0.01;
    assert_int_equal(ncp_exec_cmd(&cmd), NCP_OK);
    arc_request(&c);
    cmd.ops[1].arc.tol_abs = 0.0003; /* beyond 100x the absolute tolerance fails outright */
    cmd.ops[1].arc.tol_rel = 0.01;
    assert_int_equal(ncp_exec_cmd(&cmd), NCP_ERR_GEOMETRY);
}

/* Rotary end values pass through; a helix axis end too. */
static void test_arc_rotary_passthrough(void **state)
{
    (void)state;
    const struct arc_case c = {"abc", 0, 1, 1, 0, 0, 3, 4, 5, 0, 1, -1.5, 0, 0, ""};
    arc_request(&c);
    cmd.ops[1].arc.abc[0] = 10;
    cmd.ops[1].arc.abc[1] = -20.00005;
    cmd.ops[1].arc.abc[2] = 0.12344;
    assert_int_equal(ncp_exec_cmd(&cmd), NCP_OK);
    const char want[] = "SELECT_PLANE(CANON_PLANE_XY)\n"
                        "ARC_FEED(3.0000, 4.0000, -1.9641, 4.5981, 1, -1.5000, "
                        "10.0000, -20.0001, 0.1234)\nFLOOD_ON()\n";
    assert_int_equal(cmd.out_len, strlen(want));
    assert_memory_equal(cmd.out, want, cmd.out_len);
}

/* G93 arcs: rs274 prints SET_FEED_RATE(max(0.1, length * F)) before the arc
 * (lines from rs274 -g on the same moves). */
static void inverse_arc(const struct arc_case *c, double f, double axis_start)
{
    arc_request(c);
    struct ncp_canon arc = cmd.ops[1];
    struct ncp_canon *feed = &cmd.ops[1];
    memset(feed, 0, sizeof *feed);
    feed->kind = NCP_C_SET_FEED_RATE;
    feed->flags = NCP_FEED_F_INVERSE_ARC;
    feed->feed_rate.rate = f;
    feed->feed_rate.arc_axis_start = axis_start;
    cmd.ops[2] = arc;
    cmd.n_ops = 3;
}

static void test_arc_inverse_time(void **state)
{
    (void)state;
    const struct arc_case half = {"g93", 0, -1, 0, 0, 0, 10, 0, 5, 0, 1, 1, 0, 0, ""};
    inverse_arc(&half, 2, 1);
    assert_int_equal(ncp_exec_cmd(&cmd), NCP_OK);
    const char want1[] = "SELECT_PLANE(CANON_PLANE_XY)\nSET_FEED_RATE(31.4159)\n"
                         "ARC_FEED(10.0000, 0.0000, 5.0000, 0.0000, -1, 1.0000, 0.0000, "
                         "0.0000, 0.0000)\n";
    assert_int_equal(cmd.out_len, strlen(want1));
    assert_memory_equal(cmd.out, want1, cmd.out_len);

    const struct arc_case helix = {"g93h", 0, 1, 1, 10, 0, 0, 0, 5, 0, 2, 3, 0, 0, ""};
    inverse_arc(&helix, 0.5, 1);
    assert_int_equal(ncp_exec_cmd(&cmd), NCP_OK);
    const char want2[] = "SELECT_PLANE(CANON_PLANE_XY)\nSET_FEED_RATE(23.5832)\n"
                         "ARC_FEED(0.0000, 0.0000, 5.0000, -0.0000, 2, 3.0000, 0.0000, "
                         "0.0000, 0.0000)\n";
    assert_int_equal(cmd.out_len, strlen(want2));
    assert_memory_equal(cmd.out, want2, cmd.out_len);

    inverse_arc(&half, 0.0001, 1); /* rs274 never goes below 0.1 */
    assert_int_equal(ncp_exec_cmd(&cmd), NCP_OK);
    assert_non_null(strstr(cmd.out, "SET_FEED_RATE(0.1000)\n"));

    const struct arc_case bad = {"g93e", 2, -1, 0, 3, 0, 4, 3, 1, 1, 1, 0, 0, 1, ""};
    inverse_arc(&bad, 3, 0); /* the rate is not set when the arc fails */
    assert_int_equal(ncp_exec_cmd(&cmd), NCP_ERR_GEOMETRY);
    assert_int_equal(cmd.n_ops, 1);
    /* the failing arc ends the program: rs274's driver resets twice */
    const char want3[] = "SELECT_PLANE(CANON_PLANE_XZ)\nON_RESET()\nON_RESET()\n";
    assert_int_equal(cmd.out_len, strlen(want3));
    assert_memory_equal(cmd.out, want3, cmd.out_len);
}

/* PRINT calls print nothing in the canonical text; ncp_exec_write_prints
 * writes theirs, in order, and nothing else. */
static void test_print_text(void **state)
{
    (void)state;
    cmd_clear();
    add_text(add_op(NCP_C_PRINT), "first 1.000000\n");
    add_text(add_op(NCP_C_COMMENT), "not printed");
    add_op(NCP_C_FLOOD_ON);
    add_text(add_op(NCP_C_PRINT), "\n");
    add_text(add_op(NCP_C_PRINT), " last\n");
    assert_int_equal(ncp_exec_cmd(&cmd), NCP_OK);
    const char canon[] = "COMMENT(\"not printed\")\nFLOOD_ON()\n";
    assert_int_equal(cmd.out_len, strlen(canon));
    assert_memory_equal(cmd.out, canon, cmd.out_len);
    FILE *f = tmpfile();
    assert_non_null(f);
    assert_int_equal(ncp_exec_write_prints(&cmd, f), 0);
    char buf[64] = {0};
    rewind(f);
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    const char want[] = "first 1.000000\n\n last\n";
    assert_int_equal(n, strlen(want));
    assert_string_equal(buf, want);
}

/* An earlier analyzer error in the slot stays; resolve reports its code. */
static void test_resolve_keeps_analyzer_error(void **state)
{
    (void)state;
    cmd_clear();
    add_op(NCP_C_FLOOD_ON);
    cmd.flags = NCP_CMD_F_ERROR;
    ncp_diag_set(&cmd.diag, NCP_ERR_SEMANTIC, 7, 3, "bad word");
    assert_int_equal(ncp_exec_cmd(&cmd), NCP_ERR_SEMANTIC);
    assert_string_equal(cmd.diag.msg, "bad word");
    assert_int_equal(cmd.out_len, strlen("FLOOD_ON()\n"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_fixed4_special),
        cmocka_unit_test(test_fixed4_random),
        cmocka_unit_test(test_every_kind),
        cmocka_unit_test(test_motion_lines_random),
        cmocka_unit_test(test_int_extremes),
        cmocka_unit_test(test_several_ops_and_silent_kinds),
        cmocka_unit_test(test_text_clamped_to_pool),
        cmocka_unit_test(test_output_overflow),
        cmocka_unit_test(test_arcs),
        cmocka_unit_test(test_arc_tolerance_from_op),
        cmocka_unit_test(test_arc_rotary_passthrough),
        cmocka_unit_test(test_arc_inverse_time),
        cmocka_unit_test(test_print_text),
        cmocka_unit_test(test_resolve_keeps_analyzer_error),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
