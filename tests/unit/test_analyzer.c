/* The analyzer core driven through its public contract: an in-memory program
 * lexed on demand, slots collected by a test sink, ops checked field by field.
 * Expected values come from LinuxCNC rs274 -g on the same programs. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "ncpar/analyzer.h"
#include "ncpar/feeder.h"
#include "ncpar/lex.h"

#include "mem_feed.h"

#define MAX_SLOTS 4096

/* Every published slot, plus a flat list of all ops in order. */
struct collect {
    unsigned n_slots;
    struct ncp_cmd *slots;
    struct ncp_cmd cur;
    unsigned n_ops;
    struct ncp_canon *ops;
    uint64_t next_id;
    int keep;                 /* 0: count only (benchmark) */
};

static struct ncp_cmd *c_acquire(void *ctx)
{
    struct collect *c = ctx;
    ncp_cmd_reset_header(&c->cur, c->next_id++);
    return &c->cur;
}

static void c_publish(void *ctx, struct ncp_cmd *cmd)
{
    struct collect *c = ctx;
    if (!c->keep) {
        c->n_slots++;
        return;
    }
    assert_true(c->n_slots < MAX_SLOTS);
    c->slots[c->n_slots++] = *cmd;
    for (unsigned k = 0; k < cmd->n_ops; k++)
        c->ops[c->n_ops++] = cmd->ops[k];
}

struct run {
    struct collect c;
    int rc;
    const struct ncp_cmd *last;
};

static void run_program(struct run *r, const char *text, int keep)
{
    static struct mem_feed feed;
    struct ncp_diag d;
    memset(r, 0, sizeof *r);
    r->c.keep = keep;
    if (keep) {
        r->c.slots = calloc(MAX_SLOTS, sizeof *r->c.slots);
        r->c.ops = calloc(MAX_SLOTS * NCP_CMD_MAX_OPS, sizeof *r->c.ops);
        assert_non_null(r->c.slots);
        assert_non_null(r->c.ops);
    }
    memset(&feed, 0, sizeof feed);
    assert_int_equal(ncp_source_from_memory(&feed.src, text, strlen(text), "t.ngc", &d), 0);
    feed.off = feed.src.begin;
    feed.line = feed.src.begin_line;
    struct ncp_analyzer_cfg cfg = {0};
    struct ncp_analyzer *a = ncp_analyzer_new(&cfg, &d);
    assert_non_null(a);
    struct ncp_block_feed bf = {&feed, mf_next, mf_release, &feed.src};
    struct ncp_cmd_sink sink = {&r->c, c_acquire, c_publish};
    r->rc = ncp_analyzer_run(a, &bf, &sink);
    ncp_analyzer_free(a);
    if (keep && r->c.n_slots)
        r->last = &r->c.slots[r->c.n_slots - 1];
}

static void run_free(struct run *r)
{
    free(r->c.slots);
    free(r->c.ops);
}

/* ops after the 6-call preamble */
static const struct ncp_canon *body_op(const struct run *r, unsigned k)
{
    assert_true(6 + k < r->c.n_ops);
    return &r->c.ops[6 + k];
}

static void test_preamble_and_end(void **state)
{
    (void)state;
    struct run r;
    run_program(&r, "M2\n", 1);
    assert_int_equal(r.rc, NCP_END);
    static const int want[] = {
        NCP_C_USE_LENGTH_UNITS, NCP_C_SET_G5X_OFFSET, NCP_C_SET_G92_OFFSET,
        NCP_C_SET_XY_ROTATION, NCP_C_SET_FEED_REFERENCE, NCP_C_ON_RESET,
        NCP_C_SET_G5X_OFFSET, NCP_C_SET_XY_ROTATION, NCP_C_SET_FEED_MODE,
        NCP_C_SET_FEED_RATE, NCP_C_STOP_SPINDLE_TURNING, NCP_C_SET_SPINDLE_MODE,
        NCP_C_PROGRAM_END, NCP_C_ON_RESET, NCP_C_ON_RESET,
    };
    assert_int_equal(r.c.n_ops, sizeof want / sizeof want[0]);
    for (unsigned k = 0; k < r.c.n_ops; k++)
        assert_int_equal(r.c.ops[k].kind, want[k]);
    assert_int_equal(r.c.ops[0].units.mm, 1); /* mm */
    assert_true(r.last->flags & NCP_CMD_F_END);
    for (unsigned k = 0; k < r.c.n_slots; k++)
        assert_int_equal(r.c.slots[k].cmd_id, k);
    run_free(&r);
}

/* (PRINT,...) is a call of its own with the expanded text and its line end
 * (rs274 writes it to its stdout), an empty one too; a DEBUG beside it stays
 * a MESSAGE. */
static void test_print_calls(void **state)
{
    (void)state;
    struct run r;
    run_program(&r, "#1 = 2.5\n(PRINT, v=#1 %d#1)\n(print,)\n(DEBUG, d=#1)\nM2\n", 1);
    assert_int_equal(r.rc, NCP_END);
    static const char *const want[] = {" v=2.500000 2\n", "\n"};
    unsigned prints = 0, messages = 0;
    for (unsigned s = 0; s < r.c.n_slots; s++) {
        const struct ncp_cmd *c = &r.c.slots[s];
        for (unsigned k = 0; k < c->n_ops; k++) {
            const struct ncp_canon *op = &c->ops[k];
            if (op->kind == NCP_C_MESSAGE)
                messages++;
            if (op->kind != NCP_C_PRINT)
                continue;
            assert_true(prints < 2);
            assert_int_equal(op->text_len, strlen(want[prints]));
            assert_memory_equal(c->text + op->text_off, want[prints], op->text_len);
            prints++;
        }
    }
    assert_int_equal(prints, 2);
    assert_int_equal(messages, 1);
    run_free(&r);
}

static void test_straight_feed(void **state)
{
    (void)state;
    struct run r;
    run_program(&r, "G1 X1.234 Y5.678 Z-1 F100\nG91 X1\nM2\n", 1);
    assert_int_equal(r.rc, NCP_END);
    const struct ncp_canon *f = body_op(&r, 0);
    assert_int_equal(f->kind, NCP_C_SET_FEED_RATE);
    assert_true(f->feed_rate.rate == 100.0);
    const struct ncp_canon *m = body_op(&r, 1);
    assert_int_equal(m->kind, NCP_C_STRAIGHT_FEED);
    assert_true(m->move.end[0] == 1.234 && m->move.end[1] == 5.678 && m->move.end[2] == -1.0);
    assert_int_equal(body_op(&r, 2)->kind, NCP_C_COMMENT); /* distance mode comment */
    m = body_op(&r, 3);
    assert_int_equal(m->kind, NCP_C_STRAIGHT_FEED);
    assert_true(fabs(m->move.end[0] - 2.234) < 1e-12);
    run_free(&r);
}

/* G7: X words are diameters, the mode after the line's own G7/G8 decides,
 * incremental X too; rs274 says when the mode changes, not when it stays. */
static void test_lathe_diameter_mode(void **state)
{
    (void)state;
    struct run r;
    run_program(&r, "G7 G0 X10 Z1\nG0 X3\nG91 G0 X-4\nG90 G8 G0 X3\n"
                    "G7\nG8 G0 X7\nG7 G0 X8\nM2\n", 1);
    assert_int_equal(r.rc, NCP_END);
    static const double want_x[] = {5.0, 1.5, -0.5, 3.0, 7.0, 4.0};
    unsigned moves = 0, comments = 0;
    for (unsigned k = 6; k < r.c.n_ops; k++) {
        const struct ncp_canon *op = &r.c.ops[k];
        if (op->kind == NCP_C_COMMENT)
            comments++;
        if (op->kind != NCP_C_STRAIGHT_TRAVERSE)
            continue;
        assert_true(moves < sizeof want_x / sizeof want_x[0]);
        if (op->move.end[0] != want_x[moves])
            fail_msg("move %u: X %a, want %a", moves, op->move.end[0], want_x[moves]);
        moves++;
    }
    assert_int_equal(moves, sizeof want_x / sizeof want_x[0]);
    /* diameter, radius, diameter, radius, diameter; the distance mode twice */
    assert_int_equal(comments, 7);
    run_free(&r);
}

static void test_error_slot(void **state)
{
    (void)state;
    struct run r;
    run_program(&r, "G0 X1\nS100 G1 X2\nM2\n", 1);
    assert_int_equal(r.rc, NCP_ERR_SEMANTIC);
    assert_true(r.last->flags & NCP_CMD_F_ERROR);
    assert_int_equal(r.last->diag.line, 2);
    assert_int_equal(r.last->diag.col, 6);
    assert_string_equal(r.last->diag.msg, "Cannot do g1 with zero feed rate");
    /* the spindle speed went out before the error, as rs274 printed it */
    assert_int_equal(r.last->ops[0].kind, NCP_C_SET_SPINDLE_SPEED);
    run_free(&r);
}

static void test_eof_without_end(void **state)
{
    (void)state;
    struct run r;
    run_program(&r, "G0 X1\n", 1);
    assert_int_equal(r.rc, NCP_ERR_SEMANTIC);
    assert_string_equal(r.last->diag.msg, "File ended with no percent sign or program end");
    run_free(&r);
}

static void test_arc_request(void **state)
{
    (void)state;
    struct run r;
    run_program(&r, "G0 X1 Y0\nG18 G3 X0 Z1 I-1 K0 F10\nM2\n", 1);
    assert_int_equal(r.rc, NCP_END);
    const struct ncp_canon *a = NULL;
    for (unsigned k = 0; k < r.c.n_ops; k++)
        if (r.c.ops[k].kind == NCP_C_ARC_REQUEST)
            a = &r.c.ops[k];
    assert_non_null(a);
    /* XZ plane: first axis Z, second X, helix Y; IJK incremental by default */
    assert_true(a->arc.first_start == 0.0 && a->arc.second_start == 1.0);
    assert_true(a->arc.first_end == 1.0 && a->arc.second_end == 0.0);
    assert_true(a->arc.first_centre == 0.0 && a->arc.second_centre == 0.0);
    assert_int_equal(a->arc.dir, 1);
    assert_int_equal(a->arc.radius_form, 0);
    assert_int_equal(a->arc.plane, 2);
    run_free(&r);
}

static void test_params_pre_block(void **state)
{
    (void)state;
    struct run r;
    run_program(&r, "#1=1\n#1=2 #2=#1\nG0 X#2 Y#1\nM2\n", 1);
    const struct ncp_canon *m = body_op(&r, 0);
    assert_int_equal(m->kind, NCP_C_STRAIGHT_TRAVERSE);
    assert_true(m->move.end[0] == 1.0 && m->move.end[1] == 2.0);
    run_free(&r);
}

static void test_slot_continuation(void **state)
{
    (void)state;
    struct run r;
    /* G91 L6 canned cycle: far more than one slot's worth of calls */
    run_program(&r, "G0 Z5\nG91 F10 G81 X1 Z-2 R-1 L6\nM2\n", 1);
    assert_int_equal(r.rc, NCP_END);
    unsigned cont = 0;
    for (unsigned k = 0; k < r.c.n_slots; k++) {
        if (r.c.slots[k].flags & NCP_CMD_F_CONT) {
            cont++;
            assert_int_equal(r.c.slots[k].line, r.c.slots[k - 1].line);
        }
        assert_int_equal(r.c.slots[k].cmd_id, k);
    }
    assert_true(cont >= 2);
    unsigned feeds = 0;
    for (unsigned k = 0; k < r.c.n_ops; k++)
        feeds += r.c.ops[k].kind == NCP_C_STRAIGHT_FEED;
    assert_int_equal(feeds, 6);
    run_free(&r);
}

static void test_g92_and_coords(void **state)
{
    (void)state;
    struct run r;
    run_program(&r, "G0 X5\nG92 X0\nG0 X1\nG10 L2 P2 X10\nG55 G0 X0\nM2\n", 1);
    assert_int_equal(r.rc, NCP_END);
    const struct ncp_canon *g92 = body_op(&r, 1);
    assert_int_equal(g92->kind, NCP_C_SET_G92_OFFSET);
    assert_true(g92->offset.v[0] == 5.0);
    const struct ncp_canon *g5x = NULL;
    for (unsigned k = 6; k < r.c.n_ops; k++)
        if (r.c.ops[k].kind == NCP_C_SET_G5X_OFFSET && r.c.ops[k].offset.index == 2)
            g5x = &r.c.ops[k];
    assert_non_null(g5x);
    assert_true(g5x->offset.v[0] == 10.0);
    run_free(&r);
}

/* The last op of `kind` in the run, NULL if none. */
static const struct ncp_canon *last_op(const struct run *r, int kind)
{
    for (unsigned k = r->c.n_ops; k-- > 6;)
        if ((int)r->c.ops[k].kind == kind)
            return &r->c.ops[k];
    return NULL;
}

/* G5.2/G5.3: the NURBS_FEED call carries count and order, and its points
 * follow it in order, up to four an op: the start with the weight of the
 * P-only first block, then each X Y P; under G91 every point counts from the
 * start (rs274 keeps its current point until G5.3). */
static void test_nurbs_points(void **state)
{
    (void)state;
    struct run r;
    run_program(&r,
                "G0 X1 Y2 F100\nG5.2 P2 L4\nX3 Y4 P0.5\nG91 X1 Y1 P1\nX2 Y0 P3\n"
                "X0 Y3 P1\nX5 Y5 P1\nX6 Y1 P1\nX7 Y2 P1\nX8 Y0 P1\nX9 Y4 P1\nG5.3\n"
                "G1 X1\nM2\n",
                1);
    assert_int_equal(r.rc, NCP_END);
    unsigned k = 0;
    while (k < r.c.n_ops && r.c.ops[k].kind != NCP_C_NURBS_FEED)
        k++;
    assert_true(k < r.c.n_ops);
    const struct ncp_canon *head = &r.c.ops[k];
    assert_int_equal(head->nurbs.n_points, 10);
    assert_int_equal(head->nurbs.order, 4);
    assert_int_equal(head->nurbs.follow, NCP_NURBS_POINTS_FOLLOW);
    assert_true(head->nurbs.end[0] == 10 && head->nurbs.end[1] == 6); /* the last point: start + (9, 4) */
    const double want[10][3] = {{1, 2, 2}, {3, 4, 0.5}, {2, 3, 1}, {3, 2, 3}, {1, 5, 1},
                                {6, 7, 1}, {7, 3, 1}, {8, 4, 1}, {9, 2, 1}, {10, 6, 1}};
    unsigned got = 0;
    for (k++; k < r.c.n_ops && r.c.ops[k].kind == NCP_C_NURBS_POINTS; k++) {
        const struct ncp_canon *op = &r.c.ops[k];
        assert_true(op->nurbs_points.n >= 1 && op->nurbs_points.n <= NCP_NURBS_POINTS_PER_OP);
        for (int j = 0; j < op->nurbs_points.n; j++, got++) {
            assert_true(got < 10);
            assert_true(op->nurbs_points.pt[j][0] == want[got][0] && op->nurbs_points.pt[j][1] == want[got][1] &&
                        op->nurbs_points.pt[j][2] == want[got][2]);
        }
    }
    assert_int_equal(got, 10);
    /* the next move starts from the curve's end: G91 X1 from (10, 6) */
    assert_int_equal(r.c.ops[k].kind, NCP_C_STRAIGHT_FEED);
    assert_true(r.c.ops[k].move.end[0] == 11 && r.c.ops[k].move.end[1] == 6);
    run_free(&r);

    /* 1 + 40 points from a loop: the call's points run on into continuation slots */
    run_program(&r,
                "G0 X0 Y0 F100\n#1=0\nG5.2 X0 Y1 P1\no1 while [#1 LT 40]\n"
                "#1=[#1+1]\nX#1 Y[#1 MOD 3] P1\no1 endwhile\nG5.3\nM2\n",
                1);
    assert_int_equal(r.rc, NCP_END);
    unsigned cont = 0, pts = 0, heads = 0;
    for (k = 0; k < r.c.n_slots; k++)
        cont += (r.c.slots[k].flags & NCP_CMD_F_CONT) != 0;
    for (k = 0; k < r.c.n_ops; k++) {
        heads += r.c.ops[k].kind == NCP_C_NURBS_FEED && r.c.ops[k].nurbs.n_points == 42;
        if (r.c.ops[k].kind == NCP_C_NURBS_POINTS)
            pts += (unsigned)r.c.ops[k].nurbs_points.n;
    }
    assert_int_equal(heads, 1);
    assert_int_equal(pts, 42);
    assert_true(cont >= 1);
    run_free(&r);
}

/* G53 goes through the XY rotation of the active system (rs274: -11.1603, 0.6699). */
static void test_rotation_g53(void **state)
{
    (void)state;
    struct run r;
    run_program(&r, "G21\nG10 L2 P1 X10 Y5 R30\nG0 X10 Y0\nG53 G0 X0 Y0\nM2\n", 1);
    assert_int_equal(r.rc, NCP_END);
    const struct ncp_canon *m = last_op(&r, NCP_C_STRAIGHT_TRAVERSE);
    assert_non_null(m);
    assert_true(fabs(m->move.end[0] - -11.160254037844387) < 1e-12);
    assert_true(fabs(m->move.end[1] - 0.6698729810778055) < 1e-12);
    run_free(&r);
}

/* Leaving a rotated system and coming back keeps the point; #<_abs_x> and
 * #<_abs_y> are machine coordinates through the rotation. */
static void test_rotation_switch_and_abs(void **state)
{
    (void)state;
    struct run r;
    run_program(&r, "G21\nG10 L2 P1 X10 Y5 R30\nG0 X3 Y4\nG55\nG54\n"
                    "#1=#<_abs_x> #2=#<_abs_y>\nG0 X#1 Y#2\nM2\n", 1);
    assert_int_equal(r.rc, NCP_END);
    const struct ncp_canon *m = last_op(&r, NCP_C_STRAIGHT_TRAVERSE);
    assert_non_null(m);
    double t = 30.0 * M_PI / 180.0;
    assert_true(fabs(m->move.end[0] - (3 * cos(t) - 4 * sin(t) + 10)) < 1e-9);
    assert_true(fabs(m->move.end[1] - (3 * sin(t) + 4 * cos(t) + 5)) < 1e-9);
    run_free(&r);
}

/* G10 L2 R on the active system turns the current point with it. */
static void test_rotation_change_while_active(void **state)
{
    (void)state;
    struct run r;
    run_program(&r, "G21\nG0 X10 Y0\nG10 L2 P1 R90\n#1=#5420 #2=#5421\nG0 X#1 Y#2\nM2\n", 1);
    assert_int_equal(r.rc, NCP_END);
    const struct ncp_canon *m = last_op(&r, NCP_C_STRAIGHT_TRAVERSE);
    assert_non_null(m);
    assert_true(fabs(m->move.end[0]) < 1e-12);
    assert_true(fabs(m->move.end[1] - -10.0) < 1e-12);
    run_free(&r);
}

/* The sequential bottleneck: a plain G1 block must stay well under 1 us. */
/* A REMAP line the interpreter cannot honour stops it before the program,
 * naming the INI and its line. */
static void expect_remap_refused_in(const char *text, const char *sub_path, const char *words)
{
    struct ncp_remap_line line = { text, "cfg.ini", 7 };
    struct ncp_analyzer_cfg cfg = { .remaps = &line, .n_remaps = 1, .subroutine_path = sub_path };
    struct ncp_diag d;
    memset(&d, 0, sizeof d);
    struct ncp_analyzer *a = ncp_analyzer_new(&cfg, &d);
    assert_null(a);
    assert_int_equal(d.line, 7);
    assert_non_null(d.file);
    assert_string_equal(d.file, "cfg.ini");
    if (!strstr(d.msg, words))
        fail_msg("'%s': message '%s' lacks '%s'", text, d.msg, words);
}

static void expect_remap_refused(const char *text, const char *words)
{
    expect_remap_refused_in(text, NULL, words);
}

static void test_remap_refused(void **state)
{
    (void)state;
    expect_remap_refused("M400 modalgroup=10 python=m400", "Python plugin");
    expect_remap_refused("M400 modalgroup=10 prolog=mine ngc=x", "Python plugin");
    expect_remap_refused("M400 modalgroup=10", "no remap function");
    expect_remap_refused("M400 modalgroup=10 ngc=surely_not_a_file", "NGC file not found");
    expect_remap_refused("M400 argspec=P% ngc=x", "illegal word '%'");
    expect_remap_refused("M400 colour=red", "unrecognized option 'colour'");
    expect_remap_refused("M400 modalgroup", "missing '=<value>'");
    expect_remap_refused("G88.1 modalgroup=1 argspec=xyz", "no remap function");
    expect_remap_refused("", "no code to remap");
}

/* A G code's REMAP line: rs274's modal group 1 only, G0 .. G99.9. */
static void test_remap_g_refused(void **state)
{
    (void)state;
    char dir[] = "/tmp/test_remap_g.XXXXXX";
    assert_non_null(mkdtemp(dir));
    char path[64];
    snprintf(path, sizeof path, "%s/g881.ngc", dir);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs("o<g881> sub\no<g881> endsub\nM2\n", f);
    fclose(f);
    expect_remap_refused_in("G88.1 modalgroup=2 ngc=g881", dir, "invalid modalgroup");
    expect_remap_refused_in("G88.1 modalgroup=10 argspec=x ngc=g881", dir, "invalid modalgroup");
    expect_remap_refused_in("Gx ngc=g881", dir, "can't parse G-code");
    expect_remap_refused_in("G100 ngc=g881", dir, "out of range");
    /* and taken in group 1 when it names none */
    struct ncp_remap_line line = { "G88.1 argspec=Xy ngc=g881", "cfg.ini", 7 };
    struct ncp_analyzer_cfg cfg = { .remaps = &line, .n_remaps = 1, .subroutine_path = dir };
    struct ncp_diag d;
    memset(&d, 0, sizeof d);
    struct ncp_analyzer *a = ncp_analyzer_new(&cfg, &d);
    assert_non_null(a);
    ncp_analyzer_free(a);
    remove(path);
    rmdir(dir);
}

static void test_speed(void **state)
{
    (void)state;
    enum { N = 200000 };
    size_t cap = (size_t)N * 32 + 64;
    char *text = malloc(cap);
    assert_non_null(text);
    size_t n = 0;
    n += (size_t)snprintf(text + n, cap - n, "F100\n");
    for (int k = 0; k < N; k++)
        n += (size_t)snprintf(text + n, cap - n, "G1 X%d.234 Y5.678 Z-1\n", k % 100);
    snprintf(text + n, cap - n, "M2\n");
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    struct run r;
    run_program(&r, text, 0);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    assert_int_equal(r.rc, NCP_END);
    double ns = ((double)(t1.tv_sec - t0.tv_sec) * 1e9 + (double)(t1.tv_nsec - t0.tv_nsec)) / N;
    print_message("analyzer incl. lexing: %.0f ns per block\n", ns);
    assert_true(ns < 5000.0); /* generous: shared CI machines */
    free(text);
}

/* Analyzer alone: the feed replays pre-lexed blocks, as the pipeline does. */
#define REPLAY 64
struct replay_feed {
    struct ncp_block *blocks;
    unsigned n, total;
};

static const struct ncp_block *rf_next(void *ctx)
{
    struct replay_feed *f = ctx;
    if (f->n >= f->total)
        return NULL;
    struct ncp_block *b = &f->blocks[f->n % REPLAY];
    b->line = f->n + 1;
    f->n++;
    return b;
}

static void test_speed_analyzer_only(void **state)
{
    (void)state;
    enum { N = 1000000 };
    struct replay_feed f = {calloc(REPLAY + 2, sizeof(struct ncp_block)), 0, N};
    assert_non_null(f.blocks);
    char line[64];
    for (int k = 0; k < REPLAY; k++) {
        int len = snprintf(line, sizeof line, k == 0 ? "G1 X1 F100" : "G1 X%d.234 Y5.678 Z-1", k);
        ncp_lex_block(line, (size_t)len, 1, 0, &f.blocks[k]);
    }
    static const char text[] = "M2\n";
    struct ncp_source src;
    struct ncp_diag d;
    assert_int_equal(ncp_source_from_memory(&src, text, sizeof text - 1, "t", &d), 0);
    struct collect c = {0};
    struct ncp_analyzer_cfg cfg = {0};
    struct ncp_analyzer *a = ncp_analyzer_new(&cfg, &d);
    assert_non_null(a);
    struct ncp_block_feed bf = {&f, rf_next, mf_release, &src};
    struct ncp_cmd_sink sink = {&c, c_acquire, c_publish};
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    int rc = ncp_analyzer_run(a, &bf, &sink);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    ncp_analyzer_free(a);
    /* the replayed body has no M2: rs274's end-of-file error closes it */
    assert_int_equal(rc, NCP_ERR_SEMANTIC);
    double ns = ((double)(t1.tv_sec - t0.tv_sec) * 1e9 + (double)(t1.tv_nsec - t0.tv_nsec)) / N;
    print_message("analyzer alone: %.0f ns per G1 block\n", ns);
    assert_true(ns < 2000.0);
    free(f.blocks);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_preamble_and_end),
        cmocka_unit_test(test_remap_refused),
        cmocka_unit_test(test_remap_g_refused),
        cmocka_unit_test(test_print_calls),
        cmocka_unit_test(test_straight_feed),
        cmocka_unit_test(test_lathe_diameter_mode),
        cmocka_unit_test(test_error_slot),
        cmocka_unit_test(test_eof_without_end),
        cmocka_unit_test(test_arc_request),
        cmocka_unit_test(test_params_pre_block),
        cmocka_unit_test(test_slot_continuation),
        cmocka_unit_test(test_g92_and_coords),
        cmocka_unit_test(test_nurbs_points),
        cmocka_unit_test(test_rotation_g53),
        cmocka_unit_test(test_rotation_switch_and_abs),
        cmocka_unit_test(test_rotation_change_while_active),
        cmocka_unit_test(test_speed),
        cmocka_unit_test(test_speed_analyzer_only),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
