/* ADCAI's stages one by one and chained: exact sums in integer nm, no drift,
 * the axis limits from the output's differences, exact stops that drain, and
 * what the filters do to a corner. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ncpar/adcai.h"
#include "seg_line.h"

/* Quantising positions to 1 nm lets a k-th difference be off by 2^(k-1) nm. */
#define NM 1e-6

static void machine(struct ncp_machine_cfg *c, enum ncp_profile prof, int ratio)
{
    ncp_machine_cfg_default(c);
    c->profile = prof;
    c->nck = NCP_NCK_ADCAI;
    c->axis[2].max_vel = 100;
    c->axis[2].max_acc = 1000;
    c->axis[2].max_jerk = 50000;
    c->planning_period = ratio * c->servo_period;
}

/* A circle's arc in XY about (cx, cy) of radius r from angle a0 through da. */
static struct ncp_seg arc_seg(double cx, double cy, double r, double a0, double da, double feed)
{
    struct ncp_seg s;
    memset(&s, 0, sizeof s);
    s.kind = NCP_SEG_ARC;
    s.term = NCP_TERM_CONTINUOUS;
    s.line = 2;
    s.center[0] = cx;
    s.center[1] = cy;
    s.normal[2] = 1;
    s.u[0] = cos(a0);
    s.u[1] = sin(a0);
    s.w[0] = -sin(a0);
    s.w[1] = cos(a0);
    s.r0 = s.r1 = r;
    s.angle = da;
    s.length = r * fabs(da);
    ncp_seg_eval(&s, 0, s.start, NULL);
    s.end[0] = cx + r * cos(a0 + da);
    s.end[1] = cy + r * sin(a0 + da);
    s.feed = feed;
    return s;
}

/* ---- rough interpolator ---------------------------------------------------- */

/* A slow program of lines and arcs over 1.2 million rough periods: every
 * block's records sum to its quantised end point, none exceeds the feed. */
static void test_rough_no_drift(void **state)
{
    (void)state;
    struct ncp_machine_cfg c;
    machine(&c, NCP_PROFILE_TRAPEZOID, 1);
    const double o[NCP_AXES] = { 0 };
    struct ncp_adcai_rough *r = ncp_adcai_rough_new(&c, c.servo_period, o);
    assert_non_null(r);
    double p[3] = { 0, 0, 0 };
    int64_t sum[NCP_AXES] = { 0 };
    long periods = 0;
    const double feed = 1.0 / 9.0;  /* mm/s: no period holds a whole number of nm */
    for (int k = 0; k < 24; k++) {
        struct ncp_seg s;
        if (k % 3 == 2) {
            s = arc_seg(p[0] - 3.3, p[1], 3.3, 0, M_PI / 3, feed);
        } else {
            double q[3] = { p[0] + 7.123456789 * (k % 2 ? -1 : 1), p[1] + 3.987654321, p[2] };
            s = line_seg(p, q, feed, NCP_TERM_STOP);
        }
        s.term = NCP_TERM_STOP;
        memcpy(s.start, (double[NCP_AXES]){ p[0], p[1], p[2] }, sizeof(double) * 3);
        ncp_adcai_rough_push(r, &s);
        struct ncp_adcai_rough_rec rec;
        int stopped = 0;
        while (!stopped) {
            assert_int_equal(ncp_adcai_rough_step(r, &rec), 1);
            periods++;
            double l = 0;
            for (int j = 0; j < NCP_AXES; j++) {
                sum[j] += rec.inc[j];
                l += (double)rec.inc[j] * rec.inc[j];
            }
            assert_true(sqrt(l) * NM <= feed * c.servo_period + 2 * NM);
            stopped = rec.stop;
        }
        for (int j = 0; j < NCP_AXES; j++)
            assert_int_equal(sum[j], ncp_adcai_quantise(s.end[j]));
        memcpy(p, s.end, sizeof p);
    }
    assert_true(periods > 1000000);
    assert_int_equal(ncp_adcai_rough_step(r, &(struct ncp_adcai_rough_rec){ 0 }), 0);
    ncp_adcai_rough_free(r);
}

/* The speed caps: each axis's MAX_VELOCITY on a fast line, the centripetal
 * acceleration on a small arc. */
static void test_rough_speed_caps(void **state)
{
    (void)state;
    struct ncp_machine_cfg c;
    machine(&c, NCP_PROFILE_TRAPEZOID, 1);
    const double a[3] = { 0, 0, 0 }, b[3] = { 10, 0, 10 };
    struct ncp_seg s = line_seg(a, b, 1000, NCP_TERM_STOP);
    /* Z at its 100 mm/s: the path at 100 sqrt 2 */
    assert_true(fabs(ncp_adcai_rough_speed(&c, &s) - 100 * sqrt(2)) < 1e-9);
    struct ncp_seg arc = arc_seg(0, 0, 1.0, 0, M_PI, 150);
    assert_true(fabs(ncp_adcai_rough_speed(&c, &arc) - sqrt(2000.0)) < 1e-9);
    struct ncp_seg big = arc_seg(0, 0, 100.0, 0, M_PI, 50);
    assert_true(fabs(ncp_adcai_rough_speed(&c, &big) - 50) < 1e-9);
}

/* ---- ACC/DEC --------------------------------------------------------------- */

/* Random increments within the velocity limit, reversals included: the output
 * sums to the input once drained, stays within MAX_ACCELERATION (and
 * MAX_JERK with two windows) and never exceeds the input's velocity. */
static void accdec_case(enum ncp_profile prof)
{
    struct ncp_machine_cfg c;
    machine(&c, prof, 1);
    const double T = c.servo_period;
    int n[2];
    assert_int_equal(ncp_adcai_windows(&c, T, n), 0);
    assert_true(prof == NCP_PROFILE_SCURVE ? n[1] > 1 : n[1] == 1);
    struct ncp_adcai_accdec *f = ncp_adcai_accdec_new(n[0], n[1]);
    assert_non_null(f);
    srand(7);
    int64_t in[NCP_AXES] = { 0 }, out[NCP_AXES] = { 0 };
    double v1[NCP_AXES] = { 0 }, a1[NCP_AXES] = { 0 };
    double wa = 0, wj = 0;
    int32_t x[NCP_AXES] = { 0 }, y[NCP_AXES];
    for (int k = 0; k < 200000; k++) {
        /* a new velocity every so often: a step, at most from +V to -V */
        if (k % 97 == 0 || k >= 190000)
            for (int j = 0; j < 3; j++) {
                double vmax = c.axis[j].max_vel * T / NM;
                x[j] = k >= 190000 ? 0 : (int32_t)((2.0 * rand() / RAND_MAX - 1) * vmax);
            }
        ncp_adcai_accdec_step(f, x, y);
        for (int j = 0; j < 3; j++) {
            in[j] += x[j];
            out[j] += y[j];
            double v = y[j] * NM / T, a = (v - v1[j]) / T, jk = (a - a1[j]) / T;
            assert_true(fabs(v) <= c.axis[j].max_vel + NM / T);
            wa = fmax(wa, (fabs(a) - 2 * NM / (T * T)) / c.axis[j].max_acc);
            if (prof == NCP_PROFILE_SCURVE)
                wj = fmax(wj, (fabs(jk) - 4 * NM / (T * T * T)) / c.axis[j].max_jerk);
            v1[j] = v;
            a1[j] = a;
        }
    }
    assert_true(ncp_adcai_accdec_drained(f));
    for (int j = 0; j < NCP_AXES; j++)
        assert_int_equal(in[j], out[j]);
    print_message("  %s windows %d+%d: worst acceleration %.3f, jerk %.3f of the limits\n",
                  prof == NCP_PROFILE_SCURVE ? "scurve" : "trapezoid", n[0], n[1], wa, wj);
    assert_true(wa <= 1.0);
    assert_true(wj <= 1.0);
    assert_true(wa > 0.5);   /* the windows are not needlessly long */
    ncp_adcai_accdec_free(f);
}

static void test_accdec_trapezoid(void **state)
{
    (void)state;
    accdec_case(NCP_PROFILE_TRAPEZOID);
}

static void test_accdec_scurve(void **state)
{
    (void)state;
    accdec_case(NCP_PROFILE_SCURVE);
}

/* Drained means the output stands exactly where the input went, and not
 * before: one step of input keeps it busy n1 + n2 - 2 more periods. */
static void test_accdec_drained_exactly(void **state)
{
    (void)state;
    struct ncp_adcai_accdec *f = ncp_adcai_accdec_new(5, 3);
    int32_t x[NCP_AXES] = { 1000, -7 }, y[NCP_AXES], z[NCP_AXES] = { 0 };
    int64_t out[2] = { 0 };
    ncp_adcai_accdec_step(f, x, y);
    out[0] += y[0];
    out[1] += y[1];
    int k = 0;
    while (!ncp_adcai_accdec_drained(f)) {
        assert_true(out[0] != 1000 || out[1] != -7);
        ncp_adcai_accdec_step(f, z, y);
        out[0] += y[0];
        out[1] += y[1];
        k++;
    }
    assert_int_equal(k, 5 + 3 - 2);
    assert_int_equal(out[0], 1000);
    assert_int_equal(out[1], -7);
    ncp_adcai_accdec_free(f);
}

/* ---- fine interpolator ----------------------------------------------------- */

/* ratio 4: the servo increments sum to the rough ones, and the velocity steps
 * between rough records become ramps no steeper than the rough stream's. */
static void test_fine_exact_and_smooth(void **state)
{
    (void)state;
    for (int windows = 1; windows <= 2; windows++) {
        const int ratio = 4;
        struct ncp_adcai_fine *f = ncp_adcai_fine_new(ratio, windows);
        assert_non_null(f);
        int64_t in = 0, out = 0, prev = 0;
        double worst = 0;
        int32_t x[NCP_AXES] = { 0 }, y[NCP_AXES];
        for (int k = 0; k < 5000; k++) {
            x[0] = k < 4900 ? (int32_t)(k % 50 < 25 ? 4001 : -3999) : 0;
            ncp_adcai_fine_load(f, x);
            in += x[0];
            for (int i = 0; i < ratio; i++) {
                ncp_adcai_fine_step(f, y);
                out += y[0];
                /* servo acceleration against the rough step over one rough period */
                worst = fmax(worst, fabs((double)(y[0] - prev)) - 2);
                prev = y[0];
            }
        }
        assert_true(ncp_adcai_fine_drained(f));
        assert_int_equal(in, out);
        /* a rough step of 8000 nm is 2000 nm per servo period, spread over 4 */
        assert_true(worst <= 8000.0 / ratio / ratio + 1e-9);
        ncp_adcai_fine_free(f);
    }
}

/* ---- the chain --------------------------------------------------------------- */

struct run {
    double (*pos)[NCP_AXES];
    size_t n, cap;
};

/* The chain's output appended to out: periods of it, or (periods < 0)
 * until it ends. */
static void run_more(struct ncp_adcai *a, struct run *out, long periods)
{
    struct ncp_setpoint sp;
    for (long k = 0; periods < 0 || k < periods; k++) {
        int more = ncp_adcai_step(a, &sp);
        if (out->n == out->cap) {
            out->cap = out->cap ? 2 * out->cap : 4096;
            out->pos = realloc(out->pos, out->cap * sizeof *out->pos);
        }
        memcpy(out->pos[out->n++], sp.pos, sizeof sp.pos);
        if (!more)
            break;
        assert_true(out->n < 50000000);
    }
}

static void run_driver(struct ncp_adcai *a, struct run *out)
{
    out->n = 0;
    run_more(a, out, -1);
}

/* Velocity, acceleration and jerk from the servo output against the limits. */
static void check_limits(const struct run *r, const struct ncp_machine_cfg *c, int jerk)
{
    const double T = c->servo_period;
    double w[3] = { 0, 0, 0 };
    for (size_t k = 3; k < r->n; k++)
        for (int j = 0; j < 3; j++) {
            const double *p0 = r->pos[k - 3], *p1 = r->pos[k - 2], *p2 = r->pos[k - 1],
                         *p3 = r->pos[k];
            double v = fabs(p3[j] - p2[j]) / T;
            double a = fabs(p3[j] - 2 * p2[j] + p1[j]) / (T * T);
            double jk = fabs(p3[j] - 3 * p2[j] + 3 * p1[j] - p0[j]) / (T * T * T);
            w[0] = fmax(w[0], (v - NM / T) / c->axis[j].max_vel);
            w[1] = fmax(w[1], (a - 2 * NM / (T * T)) / c->axis[j].max_acc);
            w[2] = fmax(w[2], (jk - 4 * NM / (T * T * T)) / c->axis[j].max_jerk);
        }
    print_message("  worst velocity %.3f, acceleration %.3f, jerk %.3f of the limits\n", w[0],
                  w[1], w[2]);
    assert_true(w[0] <= 1.0);
    assert_true(w[1] <= 1.0);
    if (jerk)
        assert_true(w[2] <= 1.0);
}

/* A zigzag of rapids and feeds with reversals in G64, an arc, on 1:1 and 4:1
 * rough to servo: limits kept, and the end exactly the program's end. */
static void chain_case(enum ncp_profile prof, int ratio)
{
    struct ncp_machine_cfg c;
    machine(&c, prof, ratio);
    const double o[NCP_AXES] = { 0 };
    struct ncp_adcai *a = ncp_adcai_new(&c, o);
    assert_non_null(a);
    double p[3] = { 0, 0, 0 };
    for (int k = 0; k < 12; k++) {
        double q[3] = { k % 2 ? 0 : 80, 3.0 * k, k % 4 == 1 ? -20 : 0 };
        struct ncp_seg s = line_seg(p, q, k % 3 ? 400 : 30, NCP_TERM_CONTINUOUS);
        s.traverse = k % 3 != 0;
        ncp_adcai_push(a, &s);
        memcpy(p, q, sizeof p);
    }
    struct ncp_seg arc = arc_seg(p[0] + 5, p[1], 5, M_PI, 2 * M_PI / 3, 200);
    ncp_adcai_push(a, &arc);
    ncp_adcai_finish(a);
    struct run r = { 0 };
    run_driver(a, &r);
    check_limits(&r, &c, prof == NCP_PROFILE_SCURVE);
    for (int j = 0; j < NCP_AXES; j++)
        assert_true(r.pos[r.n - 1][j] ==
                    (double)ncp_adcai_quantise(arc.end[j]) / NCP_ADCAI_UNITS_PER_MM);
    free(r.pos);
    ncp_adcai_free(a);
}

static void test_chain_trapezoid(void **state)
{
    (void)state;
    chain_case(NCP_PROFILE_TRAPEZOID, 1);
}

static void test_chain_scurve(void **state)
{
    (void)state;
    chain_case(NCP_PROFILE_SCURVE, 1);
}

static void test_chain_fine_ipo(void **state)
{
    (void)state;
    chain_case(NCP_PROFILE_TRAPEZOID, 4);
    chain_case(NCP_PROFILE_SCURVE, 4);
}

/* The smallest distance of the output from the corner point, and whether
 * the axes stood still there. */
static double corner_run_late(int term, double tolerance, long late, int *stopped);

static double corner_run(int term, double tolerance, int *stopped)
{
    return corner_run_late(term, tolerance, 0, stopped);
}

/* corner_run with the second move queued only `late` periods after the
 * chain started: the first has ended by then with nothing after it, as when
 * the interpreter is behind the machine. */
static double corner_run_late(int term, double tolerance, long late, int *stopped)
{
    struct ncp_machine_cfg c;
    machine(&c, NCP_PROFILE_TRAPEZOID, 1);
    const double o[NCP_AXES] = { 0 };
    struct ncp_adcai *a = ncp_adcai_new(&c, o);
    const double p0[3] = { 0, 0, 0 }, p1[3] = { 50, 0, 0 }, p2[3] = { 50, 50, 0 };
    struct ncp_seg s1 = line_seg(p0, p1, 40, term), s2 = line_seg(p1, p2, 40, term);
    s1.tolerance = s2.tolerance = tolerance;
    struct run r = { 0 };
    ncp_adcai_push(a, &s1);
    run_more(a, &r, late);
    ncp_adcai_push(a, &s2);
    ncp_adcai_finish(a);
    run_more(a, &r, -1);
    double best = INFINITY;
    size_t at = 0;
    for (size_t k = 0; k < r.n; k++) {
        double d = hypot(r.pos[k][0] - 50, r.pos[k][1]);
        if (d < best)
            best = d, at = k;
    }
    /* at rest: the filters' last and first steps around it are the
     * ramps' smallest, V T / n1 */
    const double T = c.servo_period;
    *stopped = at > 0 && at + 1 < r.n &&
               hypot(r.pos[at][0] - r.pos[at - 1][0], r.pos[at][1] - r.pos[at - 1][1]) / T < 0.5 &&
               hypot(r.pos[at + 1][0] - r.pos[at][0], r.pos[at + 1][1] - r.pos[at][1]) / T < 0.5;
    free(r.pos);
    ncp_adcai_free(a);
    return best;
}

/* G64: the filters round a 90-degree corner, by about |dv| Tw / 8 (Tw the
 * window's time), unless that is beyond G64 P; G61 passes through it
 * exactly, at rest, as G61.1 does. */
static void test_corner(void **state)
{
    (void)state;
    int stopped;
    double g64 = corner_run(NCP_TERM_CONTINUOUS, 0, &stopped);
    struct ncp_machine_cfg c;
    machine(&c, NCP_PROFILE_TRAPEZOID, 1);
    int n[2];
    ncp_adcai_windows(&c, c.servo_period, n);
    double expect = 40 * sqrt(2) * n[0] * c.servo_period / 8;
    print_message("  G64 corner cut %.4f mm (|dv| Tw / 8 = %.4f mm)\n", g64, expect);
    assert_false(stopped);
    assert_true(g64 > 0.8 * expect && g64 < 1.2 * expect);
    /* G64 P above the cut rounds it, below it stops at the corner */
    assert_true(corner_run(NCP_TERM_CONTINUOUS, 1.1 * expect, &stopped) == g64);
    assert_false(stopped);
    assert_true(corner_run(NCP_TERM_CONTINUOUS, 0.9 * expect, &stopped) == 0.0);
    assert_true(stopped);
    assert_true(corner_run(NCP_TERM_EXACT_PATH, 0, &stopped) == 0.0);
    assert_true(stopped);
    assert_true(corner_run(NCP_TERM_STOP, 0, &stopped) == 0.0);
    assert_true(stopped);
}

/* The corner a late second move makes with the first is the corner it
 * makes queued in time: a stop where G64 P or G61 wants one (the first
 * move's rough interpolation ended 40 periods before the second came,
 * while its filters still moved), the same rounding where P allows it. */
static void test_corner_late(void **state)
{
    (void)state;
    int stopped;
    struct ncp_machine_cfg c;
    machine(&c, NCP_PROFILE_TRAPEZOID, 1);
    int n[2];
    ncp_adcai_windows(&c, c.servo_period, n);
    long late = 1250 + 40;   /* 50 mm at 40 mm/s, and 40 periods more */
    assert_true(40 < n[0] + n[1]);
    double expect = 40 * sqrt(2) * n[0] * c.servo_period / 8;
    assert_true(corner_run_late(NCP_TERM_CONTINUOUS, 0.9 * expect, late, &stopped) == 0.0);
    assert_true(stopped);
    assert_true(corner_run_late(NCP_TERM_EXACT_PATH, 0, late, &stopped) == 0.0);
    assert_true(stopped);
    double cut = corner_run_late(NCP_TERM_CONTINUOUS, 2 * expect, late, &stopped);
    print_message("  late G64 corner cut %.4f mm (P %.4f mm)\n", cut, 2 * expect);
    assert_true(cut > 0 && cut <= 2 * expect);
}

/* A dwell comes after a stop and lasts its time in rough periods at rest. */
static void test_dwell(void **state)
{
    (void)state;
    struct ncp_machine_cfg c;
    machine(&c, NCP_PROFILE_TRAPEZOID, 1);
    const double o[NCP_AXES] = { 0 };
    struct ncp_adcai *a = ncp_adcai_new(&c, o);
    const double p0[3] = { 0, 0, 0 }, p1[3] = { 20, 0, 0 };
    struct ncp_seg s1 = line_seg(p0, p1, 100, NCP_TERM_CONTINUOUS), d;
    memset(&d, 0, sizeof d);
    d.kind = NCP_SEG_DWELL;
    d.term = NCP_TERM_STOP;
    d.dwell = 0.5;
    memcpy(d.start, s1.end, sizeof d.start);
    memcpy(d.end, s1.end, sizeof d.end);
    ncp_adcai_push(a, &s1);
    ncp_adcai_push(a, &d);
    ncp_adcai_finish(a);
    struct run r = { 0 };
    run_driver(a, &r);
    size_t still = 0, longest = 0;
    for (size_t k = 1; k < r.n; k++) {
        still = r.pos[k][0] == 20 && r.pos[k - 1][0] == 20 ? still + 1 : 0;
        longest = still > longest ? still : longest;
    }
    /* 500 periods of dwell at the end point; the end adds one */
    assert_true(longest >= 500 && longest <= 502);
    free(r.pos);
    ncp_adcai_free(a);
}

/* A move that starts where the chain did not lead (the machine was homed
 * or moved meanwhile) starts there, without a jump; a dwell likewise stays
 * where it is. */
static void test_start_elsewhere(void **state)
{
    (void)state;
    struct ncp_machine_cfg c;
    machine(&c, NCP_PROFILE_TRAPEZOID, 1);
    const double o[NCP_AXES] = { 0 };
    struct ncp_adcai *a = ncp_adcai_new(&c, o);
    struct ncp_seg d;
    memset(&d, 0, sizeof d);
    d.kind = NCP_SEG_DWELL;
    d.term = NCP_TERM_STOP;
    d.dwell = 0.01;
    d.end[0] = 44.5;
    const double p0[3] = { 44.5, 0, 0 }, p1[3] = { 44.5, 10, 0 };
    struct ncp_seg s = line_seg(p0, p1, 100, NCP_TERM_STOP);
    ncp_adcai_push(a, &d);
    ncp_adcai_push(a, &s);
    ncp_adcai_finish(a);
    struct run r = { 0 };
    run_driver(a, &r);
    for (size_t k = 1; k < r.n; k++)
        assert_true(fabs(r.pos[k][0] - 44.5) < 1e-12 && r.pos[k][1] - r.pos[k - 1][1] < 0.2);
    assert_true(r.pos[r.n - 1][1] == 10.0);
    free(r.pos);
    ncp_adcai_free(a);
}

/* [PLANNER] NCK from an INI: the two values, a bad one named with its line,
 * and a kinematics ADCAI cannot filter. */
static void test_ini(void **state)
{
    (void)state;
    const char *path = "/tmp/ncpar-test-adcai.ini";
    const char *good = "[TRAJ]\nCOORDINATES = X\nMAX_LINEAR_VELOCITY = 10\n[AXIS_X]\nMIN_LIMIT = -1\nMAX_LIMIT = 1\n"
                       "MAX_VELOCITY = 10\nMAX_ACCELERATION = 100\nFERROR = 1\n"
                       "[PLANNER]\nNCK = %s\n";
    const char *vals[] = { "adcbi", "ADCAI", "adcx" };
    for (int i = 0; i < 3; i++) {
        FILE *f = fopen(path, "w");
        assert_non_null(f);
        fprintf(f, good, vals[i]);
        fclose(f);
        struct ncp_machine_cfg c;
        struct ncp_diag d;
        ncp_machine_cfg_default(&c);
        int rc = ncp_machine_cfg_load(&c, path, &d);
        if (i < 2) {
            if (rc != NCP_OK)
                print_message("%s\n", d.msg);
            assert_int_equal(rc, NCP_OK);
            assert_int_equal(c.nck, i == 0 ? NCP_NCK_ADCBI : NCP_NCK_ADCAI);
        } else {
            assert_int_not_equal(rc, NCP_OK);
            assert_int_equal(d.line, 11);
            assert_non_null(strstr(d.msg, "adcbi or adcai"));
        }
    }
    remove(path);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rough_no_drift),
        cmocka_unit_test(test_rough_speed_caps),
        cmocka_unit_test(test_accdec_trapezoid),
        cmocka_unit_test(test_accdec_scurve),
        cmocka_unit_test(test_accdec_drained_exactly),
        cmocka_unit_test(test_fine_exact_and_smooth),
        cmocka_unit_test(test_chain_trapezoid),
        cmocka_unit_test(test_chain_scurve),
        cmocka_unit_test(test_chain_fine_ipo),
        cmocka_unit_test(test_corner),
        cmocka_unit_test(test_corner_late),
        cmocka_unit_test(test_dwell),
        cmocka_unit_test(test_start_elsewhere),
        cmocka_unit_test(test_ini),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
