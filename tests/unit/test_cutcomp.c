/* Cutter compensation against rs274. A tiny driver stands in for the analyzer
 * core (absolute XY/XZ moves, G40-G42, F, comments, M2) and feeds the module;
 * the expected lines are rs274 -g output of the same programs (counter, N
 * column, preamble and M2 epilogue removed). Built with -DNCP_COMP_DRIVER_MAIN
 * the same driver reads a program file and prints, for comparing random
 * programs with rs274. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>

#include <ctype.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ncpar/executor.h"
#include "../../src/analyzer/cutcomp.h"

#ifndef NCP_COMP_DRIVER_MAIN
#include <cmocka.h>
#endif

/* ---- the stand-in analyzer -------------------------------------------- */

struct drv {
    struct ncp_cutcomp comp;
    struct ncp_diag diag;
    double pos[3];            /* x y z */
    int motion, plane, inches;
    char out[65536];
    size_t len;
};

static int drv_emit(void *ctx, const struct ncp_canon *op, const char *text, size_t len)
{
    struct drv *d = ctx;
    static struct ncp_cmd cmd;
    memset(&cmd, 0, sizeof cmd);
    cmd.ops[0] = *op;
    cmd.n_ops = 1;
    if (len > sizeof cmd.text)
        len = sizeof cmd.text;
    if (len)
        memcpy(cmd.text, text, len);
    cmd.ops[0].text_off = 0;
    cmd.ops[0].text_len = (uint16_t)len;
    ncp_exec_format(&cmd);
    if (d->len + cmd.out_len < sizeof d->out) {
        memcpy(d->out + d->len, cmd.out, cmd.out_len);
        d->len += cmd.out_len;
        d->out[d->len] = 0;
    }
    return NCP_OK;
}

/* simpockets.tbl, diameters in inches: T4 D0.375, T1 D0.75, T11 D0.125 */
static int drv_tool(void *ctx, int toolno, double *dia, int *orient)
{
    const struct drv *d = ctx;
    static const struct { int no; double dia; } tab[] = {{4, 0.375}, {1, 0.75}, {11, 0.125}};
    if (toolno < 0)
        toolno = 4;
    *orient = 0;
    for (size_t k = 0; k < sizeof tab / sizeof tab[0]; k++)
        if (tab[k].no == toolno) {
            *dia = tab[k].dia * (d->inches ? 1.0 : 25.4);
            return 0;
        }
    return -1;
}

static void drv_plane(const struct drv *d, const double xyz[3], double p[3])
{
    if (d->plane == 2) {
        p[0] = xyz[2]; p[1] = xyz[0]; p[2] = xyz[1];
    } else {
        p[0] = xyz[0]; p[1] = xyz[1]; p[2] = xyz[2];
    }
}

static int drv_plain_move(struct drv *d, const double end[3], int motion, double ci, double cj,
                          double ck, uint32_t line)
{
    const struct ncp_comp_sink sink = {d, drv_emit};
    struct ncp_canon op = {0};
    if (motion <= 1) {
        op.kind = motion ? NCP_C_STRAIGHT_FEED : NCP_C_STRAIGHT_TRAVERSE;
        memcpy(op.move.end, end, 3 * sizeof(double));
        return ncp_cutcomp_other(&d->comp, &op, NULL, 0, &sink, &d->diag, line);
    }
    /* uncompensated arcs: centre form only, via the executor's resolver */
    static struct ncp_cmd cmd;
    memset(&cmd, 0, sizeof cmd);
    double s[3], e[3];
    drv_plane(d, d->pos, s);
    drv_plane(d, end, e);
    struct ncp_canon *a = &cmd.ops[0];
    a->kind = NCP_C_ARC_REQUEST;
    a->arc.first_start = s[0];
    a->arc.second_start = s[1];
    a->arc.first_end = e[0];
    a->arc.second_end = e[1];
    a->arc.axis_end = e[2];
    a->arc.first_centre = d->plane == 2 ? s[0] + ck : s[0] + ci;
    a->arc.second_centre = d->plane == 2 ? s[1] + ci : s[1] + cj;
    a->arc.dir = motion == 3 ? 1 : -1;
    a->arc.plane = d->plane;
    a->flags = (uint16_t)d->inches;
    cmd.n_ops = 1;
    cmd.line = line;
    if (ncp_exec_resolve(&cmd) != NCP_OK) {
        d->diag = cmd.diag;
        return d->diag.code;
    }
    return ncp_cutcomp_other(&d->comp, &cmd.ops[0], NULL, 0, &sink, &d->diag, line);
}

static int drv_comment(struct drv *d, const char *s, size_t n, uint32_t line)
{
    const struct ncp_comp_sink sink = {d, drv_emit};
    struct ncp_canon op = {.kind = NCP_C_COMMENT};
    return ncp_cutcomp_other(&d->comp, &op, s, n, &sink, &d->diag, line);
}

struct words {
    int g[8], ng, m;
    int has[26];
    double v[26];
};

static const char *drv_words(struct drv *d, const char *s, struct words *w, uint32_t line,
                             int *rc)
{
    memset(w, 0, sizeof *w);
    w->m = -1;
    while (*s && *s != '\n') {
        if (*s == '(') {
            const char *e = strchr(s, ')');
            if (!e)
                break;
            *rc = drv_comment(d, s + 1, (size_t)(e - s - 1), line);
            if (*rc)
                return s;
            s = e + 1;
            continue;
        }
        if (!isalpha((unsigned char)*s)) {
            s++;
            continue;
        }
        int L = toupper((unsigned char)*s) - 'A';
        char *end;
        double v = strtod(s + 1, &end);
        s = end;
        if (L == 'G' - 'A' && w->ng < 8)
            w->g[w->ng++] = (int)lround(v * 10);
        else if (L == 'M' - 'A')
            w->m = (int)lround(v);
        else {
            w->has[L] = 1;
            w->v[L] = v;
        }
    }
    return s;
}

static int drv_block(struct drv *d, const char *s, uint32_t line)
{
    const struct ncp_comp_sink sink = {d, drv_emit};
    struct words w;
    int rc = 0, comp = -1;
    drv_words(d, s, &w, line, &rc);
    if (rc)
        return rc;
    if (w.has['F' - 'A']) {
        struct ncp_canon op = {.kind = NCP_C_SET_FEED_RATE};
        op.feed_rate.rate = w.v['F' - 'A'];
        if ((rc = ncp_cutcomp_other(&d->comp, &op, NULL, 0, &sink, &d->diag, line)))
            return rc;
    }
    if (w.has['S' - 'A']) {
        struct ncp_canon op = {.kind = NCP_C_SET_SPINDLE_SPEED};
        op.spindle_speed.speed = w.v['S' - 'A'];
        if ((rc = ncp_cutcomp_other(&d->comp, &op, NULL, 0, &sink, &d->diag, line)))
            return rc;
    }
    if (w.m == 3 || w.m == 8) {
        struct ncp_canon op = {.kind = w.m == 3 ? NCP_C_START_SPINDLE_CLOCKWISE : NCP_C_FLOOD_ON};
        if ((rc = ncp_cutcomp_other(&d->comp, &op, NULL, 0, &sink, &d->diag, line)))
            return rc;
    }
    for (int k = 0; k < w.ng; k++) {
        if (w.g[k] != 40)
            continue;
        struct ncp_canon op = {.kind = NCP_C_DWELL};
        op.dwell.seconds = w.v['P' - 'A'];
        if ((rc = ncp_cutcomp_other(&d->comp, &op, NULL, 0, &sink, &d->diag, line)))
            return rc;
    }
    for (int k = 0; k < w.ng; k++) {
        int g = w.g[k];
        if (g == 170 || g == 180 || g == 190) {
            d->plane = g == 180 ? 2 : g == 190 ? 1 : 0;
            struct ncp_canon op = {.kind = NCP_C_SELECT_PLANE};
            op.plane.plane = d->plane;
            rc = ncp_cutcomp_other(&d->comp, &op, NULL, 0, &sink, &d->diag, line);
        } else if (g == 200 || g == 210) {
            if (d->inches != (g == 200)) {
                double f = g == 200 ? 1 / 25.4 : 25.4;
                for (int i = 0; i < 3; i++)
                    d->pos[i] *= f;
                ncp_cutcomp_scale(&d->comp, f, g == 200);
            }
            d->inches = g == 200;
            struct ncp_canon op = {.kind = NCP_C_USE_LENGTH_UNITS};
            op.units.mm = !d->inches;
            rc = ncp_cutcomp_other(&d->comp, &op, NULL, 0, &sink, &d->diag, line);
        } else if (g <= 30 && g % 10 == 0) {
            d->motion = g / 10;
        } else if (g >= 400 && g <= 421) {
            comp = g;
        }
        if (rc)
            return rc;
    }
    if (comp == 400) {
        if ((rc = ncp_cutcomp_off(&d->comp, &sink, &d->diag, line)))
            return rc;
    } else if (comp > 400) {
        struct ncp_comp_on_req req = {.gcode = comp, .plane = d->plane, .inches = d->inches,
                                      .has_d = w.has['D' - 'A'], .d = w.v['D' - 'A'],
                                      .has_l = w.has['L' - 'A'], .l = (int)w.v['L' - 'A'],
                                      .line = line, .tool = drv_tool, .tool_ctx = d};
        if ((rc = ncp_cutcomp_on(&d->comp, &req, &sink, &d->diag)))
            return rc;
    }
    int moves = w.has['X' - 'A'] || w.has['Y' - 'A'] || w.has['Z' - 'A'];
    if (moves) {
        double end[3];
        for (int k = 0; k < 3; k++)
            end[k] = w.has['X' - 'A' + k] ? w.v['X' - 'A' + k] : d->pos[k];
        int arc = d->motion >= 2;
        if ((rc = ncp_cutcomp_check_motion(&d->comp, arc, &d->diag, line)))
            return rc;
        if (ncp_cutcomp_engaged(&d->comp)) {
            struct ncp_comp_move m = {.motion = d->motion, .inches = d->inches, .line = line};
            drv_plane(d, d->pos, m.start);
            drv_plane(d, end, m.end);
            m.radius_form = w.has['R' - 'A'];
            m.r = w.v['R' - 'A'];
            m.turns = w.has['P' - 'A'] ? (int)w.v['P' - 'A'] : 1;
            double ci = w.v['I' - 'A'], cj = w.v['J' - 'A'], ck = w.v['K' - 'A'];
            m.centre[0] = m.start[0] + (d->plane == 2 ? ck : ci);
            m.centre[1] = m.start[1] + (d->plane == 2 ? ci : cj);
            rc = ncp_cutcomp_move(&d->comp, &m, &sink, &d->diag);
        } else {
            rc = drv_plain_move(d, end, d->motion, w.v['I' - 'A'], w.v['J' - 'A'],
                                w.v['K' - 'A'], line);
        }
        if (rc)
            return rc;
        memcpy(d->pos, end, sizeof end);
    }
    if (w.m == 2 || w.m == 30 || w.m == 0 || w.m == 1) {
        rc = ncp_cutcomp_flush(&d->comp, &sink, &d->diag, line);
        if (w.m >= 2)
            ncp_cutcomp_reset(&d->comp);
    }
    return rc;
}

/* Runs a program; returns 0 or the error code (message in d->diag). */
static int drv_run(struct drv *d, const char *prog)
{
    memset(d, 0, sizeof *d);
    ncp_cutcomp_init(&d->comp, NULL);
    d->motion = 0;
    uint32_t line = 1;
    for (const char *s = prog; *s; line++) {
        int rc = drv_block(d, s, line);
        if (rc)
            return rc;
        const char *nl = strchr(s, '\n');
        if (!nl)
            break;
        s = nl + 1;
    }
    return 0;
}

#ifdef NCP_COMP_DRIVER_MAIN
int main(int argc, char **argv)
{
    static struct drv d;
    static char prog[1 << 20];
    FILE *f = argc > 1 ? fopen(argv[1], "r") : stdin;
    if (!f)
        return 1;
    size_t n = fread(prog, 1, sizeof prog - 1, f);
    prog[n] = 0;
    int rc = drv_run(&d, prog);
    fputs(d.out, stdout);
    if (rc)
        printf("ERROR %u: %s\n", d.diag.line, d.diag.msg);
    return 0;
}
#else

/* ---- cases ------------------------------------------------------------ */

static struct drv drv;

static void expect(const char *prog, const char *want, const char *err)
{
    int rc = drv_run(&drv, prog);
    assert_string_equal(drv.out, want);
    if (err) {
        assert_int_not_equal(rc, 0);
        assert_string_equal(drv.diag.msg, err);
    } else {
        assert_int_equal(rc, 0);
    }
}

/* generated from rs274 runs of the same programs */
static void t_arc_after_g40(void **state)
{
    (void)state;
    expect("G20\n"
        "F10\n"
        "G41.1 D0.2\n"
        "G1 X1 Y0\n"
        "G1 X2 Y0\n"
        "G40\n"
        "G2 X3 Y1 I0 J1\n"
        "M2\n",
        "USE_LENGTH_UNITS(CANON_UNITS_INCHES)\n"
        "SET_FEED_RATE(10.0000)\n"
        "COMMENT(\"interpreter: cutter radius compensation on left\")\n"
        "STRAIGHT_FEED(1.0000, 0.1000, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "STRAIGHT_FEED(2.0000, 0.1000, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "COMMENT(\"interpreter: cutter radius compensation off\")\n",
        "The move just after exiting cutter compensation mode must be straight, not an arc");
}

static void t_arc_arc_gouge(void **state)
{
    (void)state;
    expect("G21\n"
        "F100\n"
        "G0 X0 Y0\n"
        "G41.1 D10\n"
        "G1 X20 Y0\n"
        "G3 X30 Y10 I0 J10\n"
        "G2 X40 Y20 I10 J0\n"
        "G3 X41 Y21 I0 J1\n"
        "M2\n",
        "USE_LENGTH_UNITS(CANON_UNITS_MM)\n"
        "SET_FEED_RATE(100.0000)\n"
        "STRAIGHT_TRAVERSE(0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "COMMENT(\"interpreter: cutter radius compensation on left\")\n"
        "STRAIGHT_FEED(20.0000, 5.0000, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "ARC_FEED(25.0000, 10.0000, 20.0000, 10.0000, 1, 0.0000, 0.0000, 0.0000, 0.0000)\n",
        "Tool radius not less than arc radius with comp");
}

static void t_arcs(void **state)
{
    (void)state;
    expect("G21\n"
        "F500\n"
        "G0 X-10 Y-10\n"
        "G41.1 D6\n"
        "G1 X0 Y0\n"
        "G2 X20 Y0 I10 J0\n"
        "G1 X20 Y-20\n"
        "G3 X40 Y-20 R10\n"
        "G1 X60 Y-20\n"
        "G3 X60 Y20 I0 J20\n"
        "G2 X40 Y40 R20\n"
        "G3 X20 Y40 I-10 J0\n"
        "G2 X0 Y20 I0 J-20\n"
        "G1 X0 Y0\n"
        "G40\n"
        "G0 X-10 Y-10\n"
        "G42.1 D4\n"
        "G1 X0 Y-20\n"
        "G1 X0 Y0\n"
        "G3 X10 Y10 I10 J0\n"
        "G1 X30 Y10\n"
        "G2 X30 Y-10 I0 J-10\n"
        "G1 X10 Y-10\n"
        "G3 X10 Y-30 R10\n"
        "G40\n"
        "G0 X0 Y0\n"
        "M2\n",
        "USE_LENGTH_UNITS(CANON_UNITS_MM)\n"
        "SET_FEED_RATE(500.0000)\n"
        "STRAIGHT_TRAVERSE(-10.0000, -10.0000, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "COMMENT(\"interpreter: cutter radius compensation on left\")\n"
        "STRAIGHT_FEED(-2.9340, 1.3087, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "ARC_FEED(23.0000, 0.0000, 10.0000, 0.0000, -1, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "STRAIGHT_FEED(23.0000, -20.0000, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "ARC_FEED(37.0000, -20.0000, 30.0000, -20.0000, 1, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "ARC_FEED(40.0000, -17.0000, 40.0000, -20.0000, -1, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "STRAIGHT_FEED(60.0000, -17.0000, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "ARC_FEED(60.0000, 17.0000, 60.0000, 0.0000, 1, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "ARC_FEED(37.0000, 40.0000, 60.0000, 40.0000, -1, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "ARC_FEED(23.5518, 42.7241, 30.0000, 40.0000, 1, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "ARC_FEED(3.0000, 4.5081, 20.0000, 20.0000, -1, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "STRAIGHT_FEED(3.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "COMMENT(\"interpreter: cutter radius compensation off\")\n"
        "STRAIGHT_TRAVERSE(-10.0000, -10.0000, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "COMMENT(\"interpreter: cutter radius compensation on right\")\n"
        "STRAIGHT_FEED(-1.4142, -21.4142, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "ARC_FEED(2.0000, -20.0000, 0.0000, -20.0000, 1, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "STRAIGHT_FEED(2.0000, -8.9443, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "ARC_FEED(18.9443, 8.0000, 10.0000, 0.0000, 1, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "STRAIGHT_FEED(30.0000, 8.0000, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "ARC_FEED(30.0000, -8.0000, 30.0000, 0.0000, -1, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "STRAIGHT_FEED(10.0000, -8.0000, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "ARC_FEED(10.0000, -32.0000, 10.0000, -20.0000, 1, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "COMMENT(\"interpreter: cutter radius compensation off\")\n"
        "STRAIGHT_TRAVERSE(0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)\n",
        NULL);
}

static void t_entry_arc_short(void **state)
{
    (void)state;
    expect("G20\n"
        "F10\n"
        "G0 X0 Y0\n"
        "G41.1 D1\n"
        "G2 X0.2 Y0.2 I0.1 J0.1\n"
        "M2\n",
        "USE_LENGTH_UNITS(CANON_UNITS_INCHES)\n"
        "SET_FEED_RATE(10.0000)\n"
        "STRAIGHT_TRAVERSE(0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "COMMENT(\"interpreter: cutter radius compensation on left\")\n",
        "Radius of cutter compensation entry arc is not greater than the tool radius");
}

static void t_entry_short(void **state)
{
    (void)state;
    expect("G20\n"
        "F10\n"
        "G0 X0 Y0\n"
        "G41.1 D1\n"
        "G1 X0.4 Y0\n"
        "M2\n",
        "USE_LENGTH_UNITS(CANON_UNITS_INCHES)\n"
        "SET_FEED_RATE(10.0000)\n"
        "STRAIGHT_TRAVERSE(0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "COMMENT(\"interpreter: cutter radius compensation on left\")\n",
        "Length of cutter compensation entry move is not greater than the tool radius");
}

static void t_feed_gouge(void **state)
{
    (void)state;
    expect("G20\n"
        "F10\n"
        "G0 X0 Y0\n"
        "G41.1 D1\n"
        "G1 X5 Y0\n"
        "G1 X5 Y0.5\n"
        "G1 X0 Y0.5\n"
        "M2\n",
        "USE_LENGTH_UNITS(CANON_UNITS_INCHES)\n"
        "SET_FEED_RATE(10.0000)\n"
        "STRAIGHT_TRAVERSE(0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "COMMENT(\"interpreter: cutter radius compensation on left\")\n"
        "STRAIGHT_FEED(4.5000, 0.5000, 0.0000, 0.0000, 0.0000, 0.0000)\n",
        "Straight feed in concave corner cannot be reached by the tool without gouging");
}

static void t_g0_corner(void **state)
{
    (void)state;
    expect("G20\n"
        "F10\n"
        "G0 X0 Y0\n"
        "G42.1 D0.5\n"
        "G0 X2 Y0\n"
        "G0 X2 Y-2\n"
        "G1 X0 Y-3\n"
        "G40\n"
        "G0 X0 Y0\n"
        "M2\n",
        "USE_LENGTH_UNITS(CANON_UNITS_INCHES)\n"
        "SET_FEED_RATE(10.0000)\n"
        "STRAIGHT_TRAVERSE(0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "COMMENT(\"interpreter: cutter radius compensation on right\")\n"
        "STRAIGHT_TRAVERSE(1.7500, -0.2500, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "STRAIGHT_TRAVERSE(1.7500, -1.8455, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "STRAIGHT_FEED(-0.1118, -2.7764, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "COMMENT(\"interpreter: cutter radius compensation off\")\n"
        "STRAIGHT_TRAVERSE(0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)\n",
        NULL);
}

static void t_h_shape(void **state)
{
    (void)state;
    expect("G20\n"
        "F10\n"
        "G0 X3 Y2\n"
        "G42.1 D0.25\n"
        "G1 X2 Y0\n"
        "G2 X0 Y0 I-1 J0\n"
        "G1 X0 Y3\n"
        "G40\n"
        "G0 X-1 Y4\n"
        "M2\n",
        "USE_LENGTH_UNITS(CANON_UNITS_INCHES)\n"
        "SET_FEED_RATE(10.0000)\n"
        "STRAIGHT_TRAVERSE(3.0000, 2.0000, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "COMMENT(\"interpreter: cutter radius compensation on right\")\n"
        "STRAIGHT_FEED(1.8882, 0.0559, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "ARC_FEED(1.8750, 0.0000, 2.0000, 0.0000, 1, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "ARC_FEED(0.1250, 0.0000, 1.0000, 0.0000, -1, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "STRAIGHT_FEED(0.1250, 3.0000, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "COMMENT(\"interpreter: cutter radius compensation off\")\n"
        "STRAIGHT_TRAVERSE(-1.0000, 4.0000, 0.0000, 0.0000, 0.0000, 0.0000)\n",
        NULL);
}

static void t_lines(void **state)
{
    (void)state;
    expect("G20\n"
        "F30\n"
        "G0 X-1 Y-1 Z0.1\n"
        "G41.1 D0.25\n"
        "G1 X0 Y0\n"
        "G1 X4\n"
        "G1 Y3\n"
        "G1 X2 Y1.5\n"
        "G1 X0 Y3\n"
        "G1 Y0\n"
        "G40\n"
        "G0 X-1 Y-1\n"
        "G42.1 D0.5\n"
        "G1 X0 Y0\n"
        "G1 X2 Y1\n"
        "G1 X4 Y0\n"
        "G1 Y-3\n"
        "G0 X0 Y-3\n"
        "G1 X0 Y0\n"
        "G40\n"
        "G1 X-1 Y-1\n"
        "M2\n",
        "USE_LENGTH_UNITS(CANON_UNITS_INCHES)\n"
        "SET_FEED_RATE(30.0000)\n"
        "STRAIGHT_TRAVERSE(-1.0000, -1.0000, 0.1000, 0.0000, 0.0000, 0.0000)\n"
        "COMMENT(\"interpreter: cutter radius compensation on left\")\n"
        "STRAIGHT_FEED(-0.0884, 0.0884, 0.1000, 0.0000, 0.0000, 0.0000)\n"
        "ARC_FEED(0.0000, 0.1250, 0.0000, 0.0000, -1, 0.1000, 0.0000, 0.0000, 0.0000)\n"
        "STRAIGHT_FEED(3.8750, 0.1250, 0.1000, 0.0000, 0.0000, 0.0000)\n"
        "STRAIGHT_FEED(3.8750, 2.7500, 0.1000, 0.0000, 0.0000, 0.0000)\n"
        "STRAIGHT_FEED(2.0750, 1.4000, 0.1000, 0.0000, 0.0000, 0.0000)\n"
        "ARC_FEED(1.9250, 1.4000, 2.0000, 1.5000, -1, 0.1000, 0.0000, 0.0000, 0.0000)\n"
        "STRAIGHT_FEED(0.1250, 2.7500, 0.1000, 0.0000, 0.0000, 0.0000)\n"
        "STRAIGHT_FEED(0.1250, 0.0000, 0.1000, 0.0000, 0.0000, 0.0000)\n"
        "COMMENT(\"interpreter: cutter radius compensation off\")\n"
        "STRAIGHT_TRAVERSE(-1.0000, -1.0000, 0.1000, 0.0000, 0.0000, 0.0000)\n"
        "COMMENT(\"interpreter: cutter radius compensation on right\")\n"
        "STRAIGHT_FEED(0.1481, -0.2055, 0.1000, 0.0000, 0.0000, 0.0000)\n"
        "STRAIGHT_FEED(2.0000, 0.7205, 0.1000, 0.0000, 0.0000, 0.0000)\n"
        "STRAIGHT_FEED(3.7500, -0.1545, 0.1000, 0.0000, 0.0000, 0.0000)\n"
        "STRAIGHT_FEED(3.7500, -2.7500, 0.1000, 0.0000, 0.0000, 0.0000)\n"
        "STRAIGHT_TRAVERSE(0.2500, -2.7500, 0.1000, 0.0000, 0.0000, 0.0000)\n"
        "STRAIGHT_FEED(0.2500, 0.0000, 0.1000, 0.0000, 0.0000, 0.0000)\n"
        "COMMENT(\"interpreter: cutter radius compensation off\")\n"
        "STRAIGHT_FEED(-1.0000, -1.0000, 0.1000, 0.0000, 0.0000, 0.0000)\n",
        NULL);
}

static void t_neg_dia(void **state)
{
    (void)state;
    expect("G20\n"
        "F10\n"
        "G0 X0 Y0\n"
        "G41.1 D-0.5\n"
        "G1 X2 Y0\n"
        "G1 X2 Y2\n"
        "G1 X0 Y2\n"
        "G40\n"
        "G1 X-1 Y-1\n"
        "M2\n",
        "USE_LENGTH_UNITS(CANON_UNITS_INCHES)\n"
        "SET_FEED_RATE(10.0000)\n"
        "STRAIGHT_TRAVERSE(0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "COMMENT(\"interpreter: cutter radius compensation on right\")\n"
        "STRAIGHT_FEED(2.0000, -0.2500, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "ARC_FEED(2.2500, 0.0000, 2.0000, 0.0000, 1, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "STRAIGHT_FEED(2.2500, 2.0000, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "ARC_FEED(2.0000, 2.2500, 2.0000, 2.0000, 1, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "STRAIGHT_FEED(0.0000, 2.2500, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "COMMENT(\"interpreter: cutter radius compensation off\")\n"
        "STRAIGHT_FEED(-1.0000, -1.0000, 0.0000, 0.0000, 0.0000, 0.0000)\n",
        NULL);
}

static void t_on_when_on(void **state)
{
    (void)state;
    expect("G20\n"
        "F10\n"
        "G41.1 D0.2\n"
        "G1 X1 Y0\n"
        "G42.1 D0.2\n"
        "M2\n",
        "USE_LENGTH_UNITS(CANON_UNITS_INCHES)\n"
        "SET_FEED_RATE(10.0000)\n"
        "COMMENT(\"interpreter: cutter radius compensation on left\")\n",
        "Cannot turn cutter radius comp on when on");
}

static void t_plane_yz(void **state)
{
    (void)state;
    expect("G19\n"
        "G41.1 D0.2\n"
        "M2\n",
        "SELECT_PLANE(CANON_PLANE_YZ)\n",
        "Cutter radius compensation allowed only in XY, XZ planes");
}

static void t_queue(void **state)
{
    (void)state;
    expect("G20\n"
        "F20\n"
        "G0 X0 Y0 Z1\n"
        "G41.1 D0.2 (comp on)\n"
        "G1 X1 Y0 (entry)\n"
        "S1000 M3\n"
        "G1 X1 Y1 F25\n"
        "M8 (coolant)\n"
        "G1 Z-0.5\n"
        "G4 P0.5\n"
        "G1 Z-0.25\n"
        "G1 X0.5 Y1.5\n"
        "(plain comment)\n"
        "G1 X0 Y1\n"
        "G1 X0 Y2\n"
        "G40 (off)\n"
        "G0 X-1 Y3\n"
        "M2\n",
        "USE_LENGTH_UNITS(CANON_UNITS_INCHES)\n"
        "SET_FEED_RATE(20.0000)\n"
        "STRAIGHT_TRAVERSE(0.0000, 0.0000, 1.0000, 0.0000, 0.0000, 0.0000)\n"
        "COMMENT(\"comp on\")\n"
        "COMMENT(\"interpreter: cutter radius compensation on left\")\n"
        "COMMENT(\"entry\")\n"
        "STRAIGHT_FEED(0.9000, 0.1000, 1.0000, 0.0000, 0.0000, 0.0000)\n"
        "SET_SPINDLE_SPEED(0, 1000.0000)\n"
        "START_SPINDLE_CLOCKWISE(0)\n"
        "SET_FEED_RATE(25.0000)\n"
        "STRAIGHT_FEED(0.9000, 0.9586, 1.0000, 0.0000, 0.0000, 0.0000)\n"
        "COMMENT(\"coolant\")\n"
        "FLOOD_ON()\n"
        "STRAIGHT_FEED(0.9000, 0.9586, -0.5000, 0.0000, 0.0000, 0.0000)\n"
        "DWELL(0.5000)\n"
        "STRAIGHT_FEED(0.9000, 0.9586, -0.2500, 0.0000, 0.0000, 0.0000)\n"
        "STRAIGHT_FEED(0.5000, 1.3586, -0.2500, 0.0000, 0.0000, 0.0000)\n"
        "COMMENT(\"plain comment\")\n"
        "STRAIGHT_FEED(0.0707, 0.9293, -0.2500, 0.0000, 0.0000, 0.0000)\n"
        "ARC_FEED(-0.1000, 1.0000, 0.0000, 1.0000, -1, -0.2500, 0.0000, 0.0000, 0.0000)\n"
        "STRAIGHT_FEED(-0.1000, 2.0000, -0.2500, 0.0000, 0.0000, 0.0000)\n"
        "COMMENT(\"off\")\n"
        "COMMENT(\"interpreter: cutter radius compensation off\")\n"
        "STRAIGHT_TRAVERSE(-1.0000, 3.0000, -0.2500, 0.0000, 0.0000, 0.0000)\n",
        NULL);
}

static void t_tool_too_big(void **state)
{
    (void)state;
    expect("G20\n"
        "F10\n"
        "G0 X0 Y0\n"
        "G41.1 D1\n"
        "G1 X2 Y0\n"
        "G3 X2.5 Y0.5 I0 J0.5\n"
        "M2\n",
        "USE_LENGTH_UNITS(CANON_UNITS_INCHES)\n"
        "SET_FEED_RATE(10.0000)\n"
        "STRAIGHT_TRAVERSE(0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "COMMENT(\"interpreter: cutter radius compensation on left\")\n",
        "Tool radius not less than arc radius with comp");
}

static void t_traverse_gouge(void **state)
{
    (void)state;
    expect("G20\n"
        "F10\n"
        "G0 X0 Y0\n"
        "G41.1 D1\n"
        "G1 X5 Y0\n"
        "G0 X5 Y0.5\n"
        "G0 X0 Y0.5\n"
        "M2\n",
        "USE_LENGTH_UNITS(CANON_UNITS_INCHES)\n"
        "SET_FEED_RATE(10.0000)\n"
        "STRAIGHT_TRAVERSE(0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "COMMENT(\"interpreter: cutter radius compensation on left\")\n"
        "STRAIGHT_FEED(4.5000, 0.5000, 0.0000, 0.0000, 0.0000, 0.0000)\n",
        "Straight traverse in concave corner cannot be reached by the tool without gouging");
}

static void t_units_switch(void **state)
{
    (void)state;
    expect("G21\n"
        "F100\n"
        "G0 X0 Y0\n"
        "G41.1 D5\n"
        "G1 X50 Y0\n"
        "G20\n"
        "G1 X2 Y1\n"
        "G1 X1 Y2\n"
        "G21\n"
        "G1 X0 Y25\n"
        "G1 X0 Y0\n"
        "G40\n"
        "G0 X-10 Y-10\n"
        "M2\n",
        "USE_LENGTH_UNITS(CANON_UNITS_MM)\n"
        "SET_FEED_RATE(100.0000)\n"
        "STRAIGHT_TRAVERSE(0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "COMMENT(\"interpreter: cutter radius compensation on left\")\n"
        "USE_LENGTH_UNITS(CANON_UNITS_INCHES)\n"
        "STRAIGHT_FEED(1.8731, 0.0984, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "STRAIGHT_FEED(1.9003, 0.9605, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "USE_LENGTH_UNITS(CANON_UNITS_MM)\n"
        "STRAIGHT_FEED(25.4139, 47.2506, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "STRAIGHT_FEED(2.5000, 23.9759, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "STRAIGHT_FEED(2.5000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "COMMENT(\"interpreter: cutter radius compensation off\")\n"
        "STRAIGHT_TRAVERSE(-10.0000, -10.0000, 0.0000, 0.0000, 0.0000, 0.0000)\n",
        NULL);
}

static void t_xz(void **state)
{
    (void)state;
    expect("(lathe-style profile in the XZ plane)\n"
        "G18\n"
        "G20\n"
        "F10\n"
        "G0 X1 Z0.5\n"
        "G42.1 D0.0625\n"
        "G1 X0.5 Z0\n"
        "G1 Z-0.5\n"
        "G2 X0.75 Z-0.75 I0.25 K0\n"
        "G1 Z-1.5\n"
        "G1 X1.0 Z-2\n"
        "G3 X1.25 Z-2.25 R0.25\n"
        "G1 Z-3\n"
        "G40\n"
        "G0 X1.5\n"
        "G41.1 D0.1\n"
        "G1 X0.4 Z0.2\n"
        "G1 X0.4 Z-1\n"
        "G1 X0.8 Z-1.2\n"
        "G40\n"
        "G0 X2\n"
        "M2\n",
        "COMMENT(\"lathe-style profile in the XZ plane\")\n"
        "SELECT_PLANE(CANON_PLANE_XZ)\n"
        "USE_LENGTH_UNITS(CANON_UNITS_INCHES)\n"
        "SET_FEED_RATE(10.0000)\n"
        "STRAIGHT_TRAVERSE(1.0000, 0.0000, 0.5000, 0.0000, 0.0000, 0.0000)\n"
        "COMMENT(\"interpreter: cutter radius compensation on right\")\n"
        "STRAIGHT_FEED(0.5312, 0.0000, -0.0129, 0.0000, 0.0000, 0.0000)\n"
        "STRAIGHT_FEED(0.5312, 0.0000, -0.5000, 0.0000, 0.0000, 0.0000)\n"
        "ARC_FEED(-0.7188, 0.7500, -0.5000, 0.7500, -1, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "ARC_FEED(-0.7500, 0.7812, -0.7500, 0.7500, 1, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "STRAIGHT_FEED(0.7812, 0.0000, -1.4926, 0.0000, 0.0000, 0.0000)\n"
        "STRAIGHT_FEED(1.0197, 0.0000, -1.9694, 0.0000, 0.0000, 0.0000)\n"
        "ARC_FEED(-2.2500, 1.2812, -2.2500, 1.0000, 1, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "STRAIGHT_FEED(1.2812, 0.0000, -3.0000, 0.0000, 0.0000, 0.0000)\n"
        "COMMENT(\"interpreter: cutter radius compensation off\")\n"
        "STRAIGHT_TRAVERSE(1.5000, 0.0000, -3.0000, 0.0000, 0.0000, 0.0000)\n"
        "COMMENT(\"interpreter: cutter radius compensation on left\")\n"
        "STRAIGHT_FEED(0.4473, 0.0000, 0.2163, 0.0000, 0.0000, 0.0000)\n"
        "ARC_FEED(0.2000, 0.3500, 0.2000, 0.4000, -1, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "STRAIGHT_FEED(0.3500, 0.0000, -1.0000, 0.0000, 0.0000, 0.0000)\n"
        "ARC_FEED(-1.0447, 0.3776, -1.0000, 0.4000, -1, 0.0000, 0.0000, 0.0000, 0.0000)\n"
        "STRAIGHT_FEED(0.7776, 0.0000, -1.2447, 0.0000, 0.0000, 0.0000)\n"
        "COMMENT(\"interpreter: cutter radius compensation off\")\n"
        "STRAIGHT_TRAVERSE(2.0000, 0.0000, -1.2000, 0.0000, 0.0000, 0.0000)\n",
        NULL);
}

static const struct CMUnitTest ncp_cutcomp_tests[] = {
    cmocka_unit_test(t_arc_after_g40),
    cmocka_unit_test(t_arc_arc_gouge),
    cmocka_unit_test(t_arcs),
    cmocka_unit_test(t_entry_arc_short),
    cmocka_unit_test(t_entry_short),
    cmocka_unit_test(t_feed_gouge),
    cmocka_unit_test(t_g0_corner),
    cmocka_unit_test(t_h_shape),
    cmocka_unit_test(t_lines),
    cmocka_unit_test(t_neg_dia),
    cmocka_unit_test(t_on_when_on),
    cmocka_unit_test(t_plane_yz),
    cmocka_unit_test(t_queue),
    cmocka_unit_test(t_tool_too_big),
    cmocka_unit_test(t_traverse_gouge),
    cmocka_unit_test(t_units_switch),
    cmocka_unit_test(t_xz),
};

int main(void)
{
    return cmocka_run_group_tests(ncp_cutcomp_tests, NULL, NULL);
}
#endif
