/* Motion: config, canonical calls -> segments, planner and interpolator, checked
 * on the sampled trajectory with tolerances derived from the servo period. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "ncpar/motion.h"
#include "canon_ops.h"

/* ---- helpers ------------------------------------------------------------- */

struct trace {
    size_t n, cap;
    struct ncp_setpoint *sp;
};

static void trace_add(struct trace *t, const struct ncp_setpoint *s)
{
    if (t->n == t->cap) {
        t->cap = t->cap ? 2 * t->cap : 4096;
        t->sp = realloc(t->sp, t->cap * sizeof *t->sp);
        assert_non_null(t->sp);
    }
    t->sp[t->n++] = *s;
}

/* Runs ops through canon map + planner like the runtime does (window filled
 * before each start), collecting every setpoint. Segment ends go to ends[]. */
static struct trace run_ops_at(const struct ncp_machine_cfg *cfg, const struct ncp_canon *ops,
                               size_t n, double ends[][NCP_AXES], size_t *n_ends,
                               double feed_override, struct ncp_planner_stats *st)
{
    struct ncp_canon_map m;
    double zero[NCP_AXES] = { 0 };
    ncp_canon_map_init(&m, cfg, zero, feed_override);
    struct ncp_planner *p = ncp_planner_new(cfg, zero);
    assert_non_null(p);
    struct trace t = { 0 };
    size_t i = 0, ne = 0;
    for (;;) {
        while (i < n && !ncp_planner_full(p)) {
            struct ncp_seg s;
            struct ncp_diag d;
            int r = ncp_canon_map_op(&m, &ops[i], (uint32_t)(i + 1), &s, &d);
            assert_true(r == 0 || r == 1);
            if (r == 1) {
                ncp_planner_push(p, &s);
                if (ends)
                    memcpy(ends[ne], s.end, sizeof ends[ne]);
                ne++;
            }
            i++;
        }
        if (i == n)
            ncp_planner_finish(p);
        struct ncp_setpoint sp;
        if (!ncp_planner_step(p, &sp))
            break;
        trace_add(&t, &sp);
        assert_true(t.n < 50000000);
    }
    if (n_ends)
        *n_ends = ne;
    if (st)
        ncp_planner_get_stats(p, st);
    ncp_planner_free(p);
    return t;
}

static struct trace run_ops(const struct ncp_machine_cfg *cfg, const struct ncp_canon *ops,
                            size_t n, double ends[][NCP_AXES], size_t *n_ends)
{
    return run_ops_at(cfg, ops, n, ends, n_ends, 1.0, NULL);
}

/* Velocity and acceleration of every axis from first and second differences.
 * A difference of samples is a weighted mean of the continuous quantity, so
 * the limits hold for it exactly; 1e-6 relative slack covers rounding. */
static void check_limits(const struct ncp_machine_cfg *cfg, const struct trace *t)
{
    double T = cfg->servo_period;
    for (size_t k = 1; k < t->n; k++) {
        for (int j = 0; j < NCP_AXES; j++) {
            double v = (t->sp[k].pos[j] - t->sp[k - 1].pos[j]) / T;
            if (fabs(v) > cfg->axis[j].max_vel * (1 + 1e-6) + 1e-9) {
                fail_msg("axis %d velocity %.6f > %.6f at sample %zu", j, v,
                         cfg->axis[j].max_vel, k);
            }
            if (k < 2)
                continue;
            double a = (t->sp[k].pos[j] - 2 * t->sp[k - 1].pos[j] + t->sp[k - 2].pos[j]) / (T * T);
            if (fabs(a) > cfg->axis[j].max_acc * (1 + 1e-6) + 1e-6) {
                fail_msg("axis %d acceleration %.3f > %.3f at sample %zu (line %u)", j, a,
                         cfg->axis[j].max_acc, k, t->sp[k].line);
            }
        }
    }
}

static struct ncp_machine_cfg test_cfg(void)
{
    struct ncp_machine_cfg c;
    ncp_machine_cfg_default(&c);
    return c;
}

/* ---- config -------------------------------------------------------------- */

static char *write_tmp(const char *text)
{
    static char path[64];
    snprintf(path, sizeof path, "/tmp/ncp_test_motion_%d.ini", (int)getpid());
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
    return path;
}

/* what every machine INI states for each axis */
#define LIMITS "MIN_LIMIT = -500\nMAX_LIMIT = 500\nMAX_VELOCITY = 200\nMAX_ACCELERATION = 2000\nFERROR = 1\n"
#define AXES "[AXIS_X]\n" LIMITS "[AXIS_Y]\n" LIMITS "[AXIS_Z]\n" LIMITS

static void test_config_shipped(void **state)
{
    (void)state;
    struct ncp_machine_cfg c;
    struct ncp_diag d;
    ncp_machine_cfg_default(&c);
    assert_int_equal(ncp_machine_cfg_load(&c, "rt-config/sim-3axis.ini", &d), NCP_OK);
    assert_true(fabs(c.servo_period - 1e-3) < 1e-12);
    assert_true(c.axis[2].min_limit == -250 && c.axis[2].max_limit == 50);
    assert_true(c.axis[0].min_limit == -500 && c.axis[1].max_limit == 500);
    assert_int_equal(c.lookahead, 200);
    assert_int_equal(c.position.priority, 90);
}

static void test_config_errors(void **state)
{
    (void)state;
    struct ncp_machine_cfg c;
    struct ncp_diag d;
    ncp_machine_cfg_default(&c);
    char *p = write_tmp("[AXIS_X]\nMAX_VELOCITY = 10\nMAX_VELOCTY = 3\n");
    assert_int_not_equal(ncp_machine_cfg_load(&c, p, &d), NCP_OK);
    assert_int_equal(d.line, 3);
    assert_non_null(strstr(d.msg, "AXIS_X"));
    assert_non_null(strstr(d.msg, "MAX_VELOCTY"));
    assert_non_null(strstr(d.msg, p));

    p = write_tmp("[EMCMOT]\nSERVO_PERIOD = fast\n");
    assert_int_not_equal(ncp_machine_cfg_load(&c, p, &d), NCP_OK);
    assert_non_null(strstr(d.msg, "SERVO_PERIOD"));
    assert_non_null(strstr(d.msg, "EMCMOT"));

    p = write_tmp("[AXIS_Q]\nMAX_VELOCITY = 1\n");
    assert_int_not_equal(ncp_machine_cfg_load(&c, p, &d), NCP_OK);
    assert_non_null(strstr(d.msg, "AXIS_Q"));

    ncp_machine_cfg_default(&c);
    p = write_tmp("[PLANNER]\nSETPOINT_RING = 16\n" AXES);
    assert_int_not_equal(ncp_machine_cfg_load(&c, p, &d), NCP_OK);
    assert_non_null(strstr(d.msg, "SETPOINT_RING"));

    p = write_tmp("[PLANNER]\nPROFILE = wobbly\n");
    assert_int_not_equal(ncp_machine_cfg_load(&c, p, &d), NCP_OK);
    assert_non_null(strstr(d.msg, "PROFILE"));

    /* never a silent default for a machine: */
    static const struct { const char *text, *want; unsigned line; } strict[] = {
        { "", "empty file", 0 },
        { "[AXIS_X]\nMIN_LIMIT = -1\n", "[AXIS_X] MAX_LIMIT missing", 1 },
        { AXES "[AXIS_Q]\n", "unknown section [AXIS_Q]", 19 },
        { "[TRAJ]\nMAX_LINEAR_VELOCITY = 100\n", "[AXIS_X] missing", 0 },
        { "[AXIS_X]\n" LIMITS "MAX_VELOCITY = 20\n", "MAX_VELOCITY given twice (first on line 4)", 7 },
        { "[AXIS_X]\nMAX_VELOCITY = 0x10\n", "bad value '0x10' (mm/s from 0.000001 to 1000000)", 2 },
        { "[AXIS_X]\nFERROR = nan\n", "bad value 'nan'", 2 },
        { "[AXIS_X]\nFERROR = 1mm\n", "bad value '1mm'", 2 },
        { AXES "[AXIS_Y]\n", "[AXIS_Y] given twice (first on line 7)", 19 },
        { AXES "[PLANNER]\nPROFILE = scurve\n", "[AXIS_X] MAX_JERK missing: PROFILE = scurve (line 20)", 1 },
        { "[PLANNER]\nSETPOINT_RING = 2\n", "(planning periods, a whole number from 4 to 1048576)", 2 },
    };
    for (size_t i = 0; i < sizeof strict / sizeof strict[0]; i++) {
        ncp_machine_cfg_default(&c);
        p = write_tmp(strict[i].text);
        assert_int_not_equal(ncp_machine_cfg_load(&c, p, &d), NCP_OK);
        if (!strstr(d.msg, strict[i].want) || d.line != strict[i].line)
            fail_msg("case %zu: line %u '%s', wanted line %u '%s'", i, d.line, d.msg,
                     strict[i].line, strict[i].want);
    }
    ncp_machine_cfg_default(&c);
    assert_int_not_equal(ncp_machine_cfg_load(&c, "rt-config", &d), NCP_OK);
    assert_non_null(strstr(d.msg, "not a regular file (a directory)"));
    p = write_tmp(AXES "[AXIS_Z]\n");
    ncp_machine_cfg_default(&c);
    assert_int_not_equal(ncp_machine_cfg_load(&c, p, &d), NCP_OK);
    p = write_tmp("; a comment\n" AXES);
    ncp_machine_cfg_default(&c);
    assert_int_equal(ncp_machine_cfg_load(&c, p, &d), NCP_OK);
    unlink(p);
}

/* [EMCMOT] BACKEND: what run and serve drive without --backend */
static void test_config_backend(void **state)
{
    (void)state;
    struct ncp_machine_cfg c;
    struct ncp_diag d;
    ncp_machine_cfg_default(&c);
    assert_int_equal(c.backend, NCP_BACKEND_SIM);
    char *p = write_tmp("[EMCMOT]\nBACKEND = lcm\n" AXES);
    assert_int_equal(ncp_machine_cfg_load(&c, p, &d), NCP_OK);
    assert_int_equal(c.backend, NCP_BACKEND_LCM);
    ncp_machine_cfg_default(&c);
    p = write_tmp("[EMCMOT]\nBACKEND = SocketCAN\n" AXES);
    assert_int_equal(ncp_machine_cfg_load(&c, p, &d), NCP_OK);
    assert_int_equal(c.backend, NCP_BACKEND_SOCKETCAN);
    ncp_machine_cfg_default(&c);
    p = write_tmp("[EMCMOT]\nBACKEND = ethercat\n" AXES);
    assert_int_not_equal(ncp_machine_cfg_load(&c, p, &d), NCP_OK);
    assert_int_equal(d.line, 2);
    assert_non_null(strstr(d.msg, "sim, socketcan or lcm"));
    unlink(p);
}

/* ---- trapezoid ------------------------------------------------------------ */

static void test_trap_long_line_time(void **state)
{
    (void)state;
    struct ncp_machine_cfg c = test_cfg();
    /* 400 mm along X at F6000 (100 mm/s), a = 2000: T = L/v + v/a */
    struct ncp_canon ops[] = { op_feed(6000), op6(NCP_C_STRAIGHT_FEED, 400, 0, 0) };
    struct trace t = run_ops(&c, ops, 2, NULL, NULL);
    double expect = 400.0 / 100.0 + 100.0 / 2000.0;
    double got = (double)t.n * c.servo_period;
    assert_true(fabs(got - expect) / expect < 0.01);
    assert_true(fabs(got - expect) <= 2 * c.servo_period);
    assert_true(t.sp[t.n - 1].pos[0] == 400.0);
    check_limits(&c, &t);
    free(t.sp);
}

static void test_trap_short_triangle(void **state)
{
    (void)state;
    struct ncp_trap tp;
    ncp_trap_plan(&tp, 1.0, 0, 0, 100, 1000);
    /* never reaches 100: peak sqrt(a L) */
    assert_true(fabs(tp.vp - sqrt(1000.0)) < 1e-9);
    double v;
    assert_true(fabs(ncp_trap_eval(&tp, ncp_trap_duration(&tp), &v) - 1.0) < 1e-12);
    assert_true(fabs(ncp_trap_eval(&tp, tp.t1, &v) - 0.5) < 1e-9);
}

/* ---- corners, exact stop, arcs ------------------------------------------- */

static const double square[][2] = { { 50, 0 }, { 50, 30 }, { 0, 30 }, { 0, 0 }, { 20, 5 } };

static void test_g61_exact_stop_ends(void **state)
{
    (void)state;
    struct ncp_machine_cfg c = test_cfg();
    struct ncp_canon ops[16];
    size_t n = 0;
    ops[n++] = op_mode(0, 0);
    ops[n++] = op_feed(3000);
    for (size_t i = 0; i < sizeof square / sizeof square[0]; i++)
        ops[n++] = op6(NCP_C_STRAIGHT_FEED, square[i][0], square[i][1], 0);
    double ends[16][NCP_AXES];
    size_t ne;
    struct trace t = run_ops(&c, ops, n, ends, &ne);
    assert_int_equal(ne, 5);
    for (size_t e = 0; e < ne; e++) {
        int hit = 0;
        for (size_t k = 0; k < t.n && !hit; k++)
            hit = !memcmp(t.sp[k].pos, ends[e], sizeof ends[e]) && t.sp[k].v == 0;
        if (!hit)
            fail_msg("segment end %zu (%.3f, %.3f) never reached at rest", e, ends[e][0],
                     ends[e][1]);
    }
    check_limits(&c, &t);
    free(t.sp);
}

static void test_g64_corners_within_limits(void **state)
{
    (void)state;
    struct ncp_machine_cfg c = test_cfg();
    struct ncp_canon ops[64];
    size_t n = 0;
    ops[n++] = op_mode(2, 0);
    ops[n++] = op_feed(9000);
    for (size_t i = 0; i < sizeof square / sizeof square[0]; i++)
        ops[n++] = op6(NCP_C_STRAIGHT_FEED, square[i][0], square[i][1], -1.0 * (double)i);
    /* a polyline with small turns: the corners must not force stops */
    for (int i = 1; i <= 40; i++)
        ops[n++] = op6(NCP_C_STRAIGHT_FEED, 20 + 20 * sin(i * 0.05), 5 + 20 * (1 - cos(i * 0.05)), -4);
    ops[n++] = op_arc(60, 25, 40, 25, 1, -4);  /* tangent-ish arc after the polyline */
    ops[n++] = op6(NCP_C_STRAIGHT_TRAVERSE, 0, 0, 10);
    struct trace t = run_ops(&c, ops, n, NULL, NULL);
    check_limits(&c, &t);
    size_t stops = 0;
    for (size_t k = 1; k + 1 < t.n; k++)
        stops += t.sp[k].v == 0;
    /* only the polyline start, the arc corner and the traverse may stop */
    assert_true(stops < 10);
    free(t.sp);
}

static double dist_point_seg(const double p[2], const double a[2], const double b[2])
{
    const double ab[2] = { b[0] - a[0], b[1] - a[1] }, ap[2] = { p[0] - a[0], p[1] - a[1] };
    double f = (ap[0] * ab[0] + ap[1] * ab[1]) / (ab[0] * ab[0] + ab[1] * ab[1]);
    f = f < 0 ? 0 : f > 1 ? 1 : f;
    return hypot(a[0] + f * ab[0] - p[0], a[1] + f * ab[1] - p[1]);
}

/* G64 P: corners are rounded, at speed, never further than P from the
 * programmed path. */
static void test_g64_p_tolerance(void **state)
{
    (void)state;
    struct ncp_machine_cfg c = test_cfg();
    static const double pts[][2] = { { 0, 0 }, { 50, 0 }, { 50, 30 }, { 0, 30 }, { 20, 5 }, { 25, 60 } };
    const size_t np = sizeof pts / sizeof pts[0];
    const double tol = 0.05;
    struct ncp_canon ops[16];
    size_t n = 0;
    ops[n] = op_mode(2, 0);
    ops[n++].motion_control.tolerance = tol;
    ops[n++] = op_feed(9000);
    for (size_t i = 1; i < np; i++)
        ops[n++] = op6(NCP_C_STRAIGHT_FEED, pts[i][0], pts[i][1], 0);
    struct trace t = run_ops(&c, ops, n, NULL, NULL);
    check_limits(&c, &t);
    double worst = 0;
    for (size_t k = 0; k < t.n; k++) {
        double best = INFINITY;
        for (size_t i = 1; i < np; i++)
            best = fmin(best, dist_point_seg(t.sp[k].pos, pts[i - 1], pts[i]));
        worst = fmax(worst, best);
    }
    assert_true(worst <= tol * (1 + 1e-9));
    assert_true(worst > 0.5 * tol);  /* the corners really were rounded */
    for (size_t k = 1; k + 1 < t.n; k++)
        assert_true(t.sp[k].v > 0);   /* and taken without stopping */
    free(t.sp);
}

static double dist_point_seg3(const double p[3], const double a[3], const double b[3])
{
    double ab[3], ap[3], l2 = 0, f = 0, d2 = 0;
    for (int i = 0; i < 3; i++) {
        ab[i] = b[i] - a[i];
        ap[i] = p[i] - a[i];
        l2 += ab[i] * ab[i];
        f += ap[i] * ab[i];
    }
    f = l2 > 0 ? f / l2 : 0;
    f = f < 0 ? 0 : f > 1 ? 1 : f;
    for (int i = 0; i < 3; i++)
        d2 += (a[i] + f * ab[i] - p[i]) * (a[i] + f * ab[i] - p[i]);
    return sqrt(d2);
}

/* Farthest any sample of a lies from the polyline through b's samples. Both
 * run along the same path in the same direction, so the nearest piece of b is
 * searched near where the last one was. */
static double path_distance(const struct trace *a, const struct trace *b)
{
    double worst = 0;
    size_t at = 1;
    for (size_t k = 0; k < a->n; k++) {
        double best = INFINITY;
        size_t best_at = at;
        for (size_t i = at > 64 ? at - 64 : 1; i < b->n && i < at + 4096; i++) {
            double d = dist_point_seg3(a->sp[k].pos, b->sp[i - 1].pos, b->sp[i].pos);
            if (d < best) {
                best = d;
                best_at = i;
            }
        }
        at = best_at;
        worst = fmax(worst, best);
    }
    return worst;
}

/* Corners of every sharpness, with and without G64 P, at a slow and a fast
 * feed: the path cut at 1 %, 50 % and 200 % override is the one cut at 100 %
 * (the blends are sized for the largest override, not the one in force). */
static void test_g64_path_independent_of_override(void **state)
{
    (void)state;
    struct ncp_machine_cfg c = test_cfg();
    static const double pts[][2] = { { 10, 10 }, { 0, 10 }, { 5, 0 }, { 15, 2 }, { 30, 0 },
                                     { 30, 12 }, { 18, 14 } };
    const size_t np = sizeof pts / sizeof pts[0];
    struct ncp_canon ops[64];
    size_t n = 0;
    for (int pass = 0; pass < 2; pass++) {
        ops[n] = op_mode(2, 0);
        ops[n++].motion_control.tolerance = pass ? 0.05 : 0;
        ops[n++] = op_feed(pass ? 1000 : 6000);
        ops[n++] = op6(NCP_C_STRAIGHT_FEED, 0, 0, pass ? -1.0 : 0);
        for (size_t i = 0; i < np; i++)
            ops[n++] = op6(NCP_C_STRAIGHT_FEED, pts[i][0], pts[i][1], pass ? -1.0 : 0);
    }
    struct trace ref = run_ops_at(&c, ops, n, NULL, NULL, 1.0, NULL);
    static const double overrides[] = { 0.01, 0.5, 2.0 };
    for (size_t i = 0; i < sizeof overrides / sizeof overrides[0]; i++) {
        struct trace t = run_ops_at(&c, ops, n, NULL, NULL, overrides[i], NULL);
        double ab = path_distance(&t, &ref), ba = path_distance(&ref, &t);
        if (ab > 1e-3 || ba > 1e-3) /* 1 um */
            fail_msg("override %.0f %%: paths %.6f / %.6f mm apart", 100 * overrides[i], ab, ba);
        free(t.sp);
    }
    free(ref.sp);
}

/* A blend leaves the programmed corner only as far as its speed needs: at
 * F120 (4 mm/s at the largest override) a square's corners are cut by
 * microns, though the lines would allow a blend of millimetres. */
static void test_g64_blend_only_as_needed(void **state)
{
    (void)state;
    struct ncp_machine_cfg c = test_cfg();
    struct ncp_canon ops[8];
    size_t n = 0;
    ops[n++] = op_mode(2, 0);
    ops[n++] = op_feed(120);
    ops[n++] = op6(NCP_C_STRAIGHT_FEED, 4, 0, 0);
    ops[n++] = op6(NCP_C_STRAIGHT_FEED, 4, 4, 0);
    ops[n++] = op6(NCP_C_STRAIGHT_FEED, 0, 4, 0);
    struct trace t = run_ops(&c, ops, n, NULL, NULL);
    static const double corner[2][2] = { { 4, 0 }, { 4, 4 } };
    for (int i = 0; i < 2; i++) {
        double miss = INFINITY;
        for (size_t k = 0; k < t.n; k++)
            miss = fmin(miss, hypot(t.sp[k].pos[0] - corner[i][0], t.sp[k].pos[1] - corner[i][1]));
        /* 4 mm/s with half of 2000 mm/s^2 for the turn: a radius of 16 um,
         * which misses the corner by (sqrt 2 - 1) 16 = 6.6 um */
        if (miss > 0.008)
            fail_msg("corner %d cut by %.4f mm at 2 mm/s", i, miss);
    }
    for (size_t k = 1; k + 1 < t.n; k++)
        assert_true(t.sp[k].v > 0);  /* still blended: no stop at the corners */
    free(t.sp);
}

/* G64 Q: CAM output's tiny, nearly collinear lines reach the interpolator
 * as a few long ones, and the path still passes within Q (plus P at the
 * corners) of every programmed point. Q0 merges nothing. */
static void run_naivecam(double q, struct ncp_planner_stats *st, double *worst_prog,
                         double *worst_path)
{
    struct ncp_machine_cfg c = test_cfg();
    enum { N = 400 };
    static struct ncp_canon ops[N + 8];
    static double pts[N + 1][3];
    size_t n = 0, np = 0;
    const double p_tol = 0.01;
    ops[n] = op_mode(2, 0);
    ops[n++].motion_control.tolerance = p_tol;
    ops[n].kind = NCP_C_SET_NAIVECAM_TOLERANCE;
    ops[n++].naivecam.tolerance = q;
    ops[n++] = op_feed(3000);
    pts[np][0] = pts[np][1] = pts[np][2] = 0;
    np++;
    for (int i = 1; i <= N; i++) {
        /* 0.25 mm steps along X, then along Y, wobbling by +-0.01 mm */
        double wob = 0.01 * sin(i * 2.3);
        double x = i <= N / 2 ? 0.25 * i : 0.25 * (N / 2) + wob;
        double y = i <= N / 2 ? wob : 0.25 * (i - N / 2);
        ops[n++] = op6(NCP_C_STRAIGHT_FEED, x, y, 0);
        pts[np][0] = x;
        pts[np][1] = y;
        pts[np][2] = 0;
        np++;
    }
    struct trace t = run_ops_at(&c, ops, n, NULL, NULL, 1.0, st);
    check_limits(&c, &t);
    *worst_prog = *worst_path = 0;
    for (size_t k = 0; k < t.n; k++) {
        double best = INFINITY;
        for (size_t i = 1; i < np; i++)
            best = fmin(best, dist_point_seg3(t.sp[k].pos, pts[i - 1], pts[i]));
        *worst_path = fmax(*worst_path, best);
    }
    for (size_t i = 0; i < np; i++) {
        double best = INFINITY;
        for (size_t k = 1; k < t.n; k++)
            best = fmin(best, dist_point_seg3(pts[i], t.sp[k - 1].pos, t.sp[k].pos));
        *worst_prog = fmax(*worst_prog, best);
    }
    free(t.sp);
}

static void test_g64_q_merges_collinear_lines(void **state)
{
    (void)state;
    struct ncp_planner_stats st;
    double worst_prog, worst_path;
    run_naivecam(0.02, &st, &worst_prog, &worst_path);
    /* 400 lines, two straight runs of them: a handful of segments */
    if (st.segments > 20 || st.merged < 380)
        fail_msg("G64 Q0.02: %llu segments planned, %llu lines merged", (unsigned long long)st.segments,
                 (unsigned long long)st.merged);
    /* every programmed point within Q of the path, the path within Q of the
     * programmed lines, plus P at the one corner */
    if (worst_prog > 0.02 + 0.01 || worst_path > 0.02 + 0.01)
        fail_msg("G64 Q0.02: program %.4f / path %.4f mm apart", worst_prog, worst_path);
    run_naivecam(0, &st, &worst_prog, &worst_path);
    if (st.merged != 0 || st.segments < 400)
        fail_msg("G64 Q0: %llu lines merged", (unsigned long long)st.merged);
}

static void test_arc_radius_and_helix(void **state)
{
    (void)state;
    struct ncp_machine_cfg c = test_cfg();
    struct ncp_canon ops[] = {
        op_feed(12000),
        op6(NCP_C_STRAIGHT_FEED, 30, 0, 0),
        op_arc(30, 0, 0, 0, 2, -5),   /* two full turns of helix, r = 30, 5 mm down */
        op_arc(-30, 0, 0, 0, -1, -5), /* half circle clockwise */
    };
    struct trace t = run_ops(&c, ops, 4, NULL, NULL);
    check_limits(&c, &t);
    size_t on_arc = 0;
    double zmin = 0;
    for (size_t k = 0; k < t.n; k++) {
        if (t.sp[k].line < 3)
            continue;
        double r = hypot(t.sp[k].pos[0], t.sp[k].pos[1]);
        if (fabs(r - 30) > 1e-6)
            fail_msg("radius %.9f at sample %zu", r, k);
        on_arc++;
        zmin = fmin(zmin, t.sp[k].pos[2]);
    }
    assert_true(on_arc > 100);
    assert_true(fabs(zmin + 5) < 1e-9);
    assert_true(fabs(t.sp[t.n - 1].pos[0] + 30) < 1e-9);
    free(t.sp);
}

static void test_arc_centripetal_cap(void **state)
{
    (void)state;
    struct ncp_machine_cfg c = test_cfg();
    /* r = 2 mm at F12000: v^2/r must stay below the acceleration limit, at
     * most 0.866 of it (the rest is the tangential acceleration's, at right
     * angles: LinuxCNC's split) */
    struct ncp_canon ops[] = { op_feed(12000), op6(NCP_C_STRAIGHT_FEED, 2, 0, 0),
                               op_arc(2, 0, 0, 0, 3, 0) };
    struct trace t = run_ops(&c, ops, 3, NULL, NULL);
    check_limits(&c, &t);
    double vmax = 0;
    for (size_t k = 0; k < t.n; k++)
        vmax = fmax(vmax, t.sp[k].v);
    assert_true(vmax * vmax / 2.0 <= 0.866 * c.axis[0].max_acc * 1.000001);
    assert_true(vmax * vmax / 2.0 >= 0.85 * c.axis[0].max_acc);
    free(t.sp);
}

/* ---- canon mapping -------------------------------------------------------- */

static void test_canon_units_offsets(void **state)
{
    (void)state;
    struct ncp_machine_cfg c = test_cfg();
    struct ncp_canon_map m;
    ncp_canon_map_init(&m, &c, NULL, 1.0);
    struct ncp_seg s;
    struct ncp_diag d;
    struct ncp_canon u = op6(NCP_C_USE_LENGTH_UNITS, 0, 0, 0);
    u.units.mm = 0; /* inches */
    assert_int_equal(ncp_canon_map_op(&m, &u, 1, &s, &d), 0);
    struct ncp_canon g5x = op6(NCP_C_SET_G5X_OFFSET, 1, 0, 0);
    assert_int_equal(ncp_canon_map_op(&m, &g5x, 2, &s, &d), 0);
    struct ncp_canon mm = u;
    mm.units.mm = 1;
    assert_int_equal(ncp_canon_map_op(&m, &mm, 3, &s, &d), 0);
    struct ncp_canon g92 = op6(NCP_C_SET_G92_OFFSET, 0, 2, 0);
    assert_int_equal(ncp_canon_map_op(&m, &g92, 4, &s, &d), 0);
    struct ncp_canon tlo = op6(NCP_C_USE_TOOL_LENGTH_OFFSET, 0, 0, 3);
    assert_int_equal(ncp_canon_map_op(&m, &tlo, 5, &s, &d), 0);
    struct ncp_canon tr = op6(NCP_C_STRAIGHT_TRAVERSE, 10, 10, 10);
    assert_int_equal(ncp_canon_map_op(&m, &tr, 6, &s, &d), 1);
    /* G5X offset given in inches stays 25.4 mm after the switch to mm */
    assert_true(fabs(s.end[0] - 35.4) < 1e-12);
    assert_true(fabs(s.end[1] - 12.0) < 1e-12);
    assert_true(fabs(s.end[2] - 13.0) < 1e-12);
    assert_int_equal(s.line, 6);
}

/* A canon map on the test machine, and what its calls fill. */
struct map_fixture {
    struct ncp_machine_cfg cfg;
    struct ncp_canon_map m;
    struct ncp_seg s;
    struct ncp_diag d;
};

static void map_fixture_init(struct map_fixture *f, double feed_override)
{
    f->cfg = test_cfg();
    ncp_canon_map_init(&f->m, &f->cfg, NULL, feed_override);
}

/* Feeds op to the map: what ncp_canon_map_op returns. */
static int map_op(struct map_fixture *f, struct ncp_canon op, uint32_t line)
{
    return ncp_canon_map_op(&f->m, &op, line, &f->s, &f->d);
}

static int map_more(struct map_fixture *f)
{
    return ncp_canon_map_more(&f->m, &f->s, &f->d);
}

/* G95 feeds per turn, G96 at the end point's radius capped at D, and the
 * synchronised moves of G33/G76 at their pitch, whatever the override. */
static void test_canon_spindle_feeds(void **state)
{
    (void)state;
    struct map_fixture f;
    map_fixture_init(&f, 0.5); /* 50 % override */
    struct ncp_canon mode = op6(NCP_C_SET_FEED_MODE, 0, 0, 0);
    mode.feed_mode.per_rev = 1; /* units per revolution */
    assert_int_equal(map_op(&f, mode, 1), 0);
    assert_int_equal(map_op(&f, op6(NCP_C_SET_SPINDLE_SPEED, 600, 0, 0), 2), 0);
    assert_int_equal(map_op(&f, op_feed(0.2), 3), 0);
    /* per turn of a stopped spindle: refused (it would never move) */
    assert_true(map_op(&f, op6(NCP_C_STRAIGHT_FEED, 10, 0, -5), 4) < 0);
    assert_non_null(strstr(f.d.msg, "spindle stopped"));
    assert_int_equal(map_op(&f, op6(NCP_C_START_SPINDLE_CLOCKWISE, 0, 0, 0), 4), 0);
    assert_int_equal(map_op(&f, op6(NCP_C_STRAIGHT_FEED, 10, 0, -5), 4), 1);
    assert_true(fabs(f.s.feed - 0.2 * 600 / 60.0 * 0.5) < 1e-12);
    /* G96 S180 (m/min) D2500: at X 10 mm 180000 / (2 pi 10) = 2864.8 rpm, capped */
    assert_int_equal(map_op(&f, op6(NCP_C_SET_SPINDLE_MODE, 2500, 0, 0), 5), 0);
    assert_int_equal(map_op(&f, op6(NCP_C_SET_SPINDLE_SPEED, 180, 0, 0), 6), 0);
    assert_int_equal(map_op(&f, op6(NCP_C_STRAIGHT_FEED, 10, 0, -10), 7), 1);
    assert_true(fabs(f.s.feed - 0.2 * 2500 / 60.0 * 0.5) < 1e-12);
    assert_int_equal(map_op(&f, op6(NCP_C_STRAIGHT_FEED, 20, 0, -10), 8), 1);
    assert_true(fabs(f.s.feed - 0.2 * (180000 / (2 * M_PI * 20)) / 60.0 * 0.5) < 1e-9);
    /* synchronised at pitch 1.5 under G97 S400: 10 mm/s, no override */
    assert_int_equal(map_op(&f, op6(NCP_C_SET_SPINDLE_MODE, 0, 0, 0), 9), 0);
    assert_int_equal(map_op(&f, op6(NCP_C_SET_SPINDLE_SPEED, 400, 0, 0), 10), 0);
    assert_int_equal(map_op(&f, op6(NCP_C_START_SPEED_FEED_SYNCH, 1.5, 0, 0), 11), 0);
    assert_int_equal(map_op(&f, op6(NCP_C_STRAIGHT_FEED, 20, 0, -30), 12), 1);
    assert_true(fabs(f.s.feed - 10.0) < 1e-12);
    assert_int_equal(map_op(&f, op6(NCP_C_STOP_SPEED_FEED_SYNCH, 0, 0, 0), 13), 0);
    assert_int_equal(map_op(&f, op6(NCP_C_STRAIGHT_FEED, 20, 0, -20), 14), 1);
    assert_true(fabs(f.s.feed - 0.2 * 400 / 60.0 * 0.5) < 1e-12);
}

/* A NURBS_FEED op: order 3 (G5.1) or 4 (G5), end, start and control points. */
static struct ncp_canon op_spline(int order, const double end[2], const double pts[6])
{
    struct ncp_canon c = op6(NCP_C_NURBS_FEED, end[0], end[1], 2);
    c.nurbs.n_points = order;
    c.nurbs.start[0] = pts[0];
    c.nurbs.start[1] = pts[1];
    for (int k = 0; k < 4; k++)
        c.nurbs.ctrl[k / 2][k % 2] = pts[2 + k];
    return c;
}

/* A rigid tap goes down and comes back; a spline comes out as lines on the
 * Bezier curve of its control points. */
static void test_canon_tap_and_spline(void **state)
{
    (void)state;
    struct map_fixture f;
    map_fixture_init(&f, 1.0);
    assert_int_equal(map_op(&f, op_feed(600), 1), 0);
    assert_int_equal(map_op(&f, op6(NCP_C_STRAIGHT_TRAVERSE, 5, 5, 2), 2), 1);
    assert_int_equal(map_op(&f, op6(NCP_C_RIGID_TAP, 5, 5, -8), 3), 1);
    assert_true(fabs(f.s.end[2] + 8.0) < 1e-12 && fabs(f.s.start[2] - 2.0) < 1e-12);
    assert_int_equal(map_more(&f), 1);
    assert_true(fabs(f.s.end[2] - 2.0) < 1e-12 && fabs(f.s.end[0] - 5.0) < 1e-12);
    assert_int_equal(f.s.line, 3);
    assert_int_equal(map_more(&f), 0);
    /* G5.1 from (5,5) with control point (15,5) to (15,15): at t = 1/2 the
     * curve is at (12.5, 7.5) */
    const double qend[2] = {15, 15}, qpts[6] = {5, 5, 15, 5, 0, 0};
    int n = map_op(&f, op_spline(3, qend, qpts), 4);
    for (int k = 1; n == 1; k++) {
        if (k == NCP_SPLINE_STEPS / 2)
            assert_true(fabs(f.s.end[0] - 12.5) < 1e-12 && fabs(f.s.end[1] - 7.5) < 1e-12);
        assert_true(k <= NCP_SPLINE_STEPS);
        n = map_more(&f);
    }
    assert_int_equal(n, 0);
    assert_true(fabs(f.m.pos[0] - 15) < 1e-12 && fabs(f.m.pos[1] - 15) < 1e-12);
    /* G5 back to (5,5) through (15,10) and (10,5): at t = 1/2,
     * (15 + 3*15 + 3*10 + 5) / 8 = 11.875 and (15 + 3*10 + 3*5 + 5) / 8 = 8.125 */
    const double cend[2] = {5, 5}, cpts[6] = {15, 15, 15, 10, 10, 5};
    int segs = 0;
    for (n = map_op(&f, op_spline(4, cend, cpts), 5); n == 1; n = map_more(&f)) {
        if (++segs == NCP_SPLINE_STEPS / 2)
            assert_true(fabs(f.s.end[0] - 11.875) < 1e-12 && fabs(f.s.end[1] - 8.125) < 1e-12);
    }
    assert_int_equal(segs, NCP_SPLINE_STEPS);
}

/* Reference for G5.3 curves, independent of de Boor: the Cox-de Boor basis
 * on LinuxCNC's knots (order zeros, 1 .. n - order + 1, then order times
 * n - order + 2, for points 0..n), the rational sum written out. */
static double ref_knot(int j, int n, int k)
{
    return j < k ? 0 : j <= n ? j - k + 1 : n - k + 2;
}

static double ref_basis(int i, int k, double t, int n, int order)
{
    if (k == 1) {
        double lo = ref_knot(i, n, order), hi = ref_knot(i + 1, n, order);
        double top = ref_knot(n + 1, n, order);
        return (t >= lo && t < hi) || (t == top && hi == top && lo < hi) ? 1 : 0;
    }
    double v = 0, a = ref_knot(i, n, order), b = ref_knot(i + k - 1, n, order);
    double c = ref_knot(i + 1, n, order), e = ref_knot(i + k, n, order);
    if (b > a)
        v += (t - a) / (b - a) * ref_basis(i, k - 1, t, n, order);
    if (e > c)
        v += (e - t) / (e - c) * ref_basis(i + 1, k - 1, t, n, order);
    return v;
}

static void ref_nurbs(const double (*p)[3], int count, int order, double t, double xy[2])
{
    double sx = 0, sy = 0, sw = 0;
    for (int i = 0; i < count; i++) {
        double b = ref_basis(i, order, t, count - 1, order) * p[i][2];
        sx += b * p[i][0];
        sy += b * p[i][1];
        sw += b;
    }
    xy[0] = sx / sw;
    xy[1] = sy / sw;
}

static struct ncp_canon op_nurbs_head(int count, int order, double x, double y, double z)
{
    struct ncp_canon c = op6(NCP_C_NURBS_FEED, x, y, z);
    c.nurbs.n_points = count;
    c.nurbs.order = order;
    c.nurbs.follow = NCP_NURBS_POINTS_FOLLOW;
    return c;
}

static struct ncp_canon op_nurbs_points(const double (*p)[3], int n)
{
    struct ncp_canon c = op6(NCP_C_NURBS_POINTS, 0, 0, 0);
    c.nurbs_points.n = n;
    memcpy(c.nurbs_points.pt, p, (size_t)n * sizeof p[0]);
    return c;
}

/* G5.3: a rational quadratic that is exactly a quarter circle, then an order
 * 4 curve of 9 points drawn span by span as its points come in, four at a
 * time, every line ending on the reference curve; bad weights and orders
 * stop with a message. */
static void test_canon_nurbs(void **state)
{
    (void)state;
    struct map_fixture f;
    map_fixture_init(&f, 1.0);
    assert_int_equal(map_op(&f, op_feed(600), 1), 0);
    assert_int_equal(map_op(&f, op6(NCP_C_STRAIGHT_TRAVERSE, 50, 0, 0), 2), 1);
    const double arc[3][3] = {{50, 0, 1}, {50, 50, M_SQRT1_2}, {0, 50, 1}};
    assert_int_equal(map_op(&f, op_nurbs_head(3, 3, 0, 50, 0), 3), 0);
    int segs = 0, n;
    for (n = map_op(&f, op_nurbs_points(arc, 3), 3); n == 1; n = map_more(&f)) {
        segs++;
        assert_true(fabs(hypot(f.s.end[0], f.s.end[1]) - 50) < 1e-9);
        assert_int_equal(f.s.line, 3);
    }
    assert_int_equal(n, 0);
    assert_int_equal(segs, NCP_SPLINE_STEPS);
    assert_true(fabs(f.m.pos[0]) < 1e-12 && fabs(f.m.pos[1] - 50) < 1e-12);

    const double pts[9][3] = {{0, 50, 1}, {-20, 60, 1}, {-40, 30, 2}, {-60, 10, 1},
                              {-50, -10, 0.5}, {-30, -20, 1}, {0, -30, 3}, {10, -5, 1},
                              {20, 0, 1}};
    assert_int_equal(map_op(&f, op_nurbs_head(9, 4, 20, 0, 0), 4), 0);
    int spans_done = 0, step = 0;
    for (int first = 0; first < 9; first += 4) {
        int m = 9 - first < 4 ? 9 - first : 4;
        for (n = map_op(&f, op_nurbs_points(pts + first, m), 4); n == 1; n = map_more(&f)) {
            step++;
            double t = (double)step / NCP_SPLINE_STEPS, want[2];
            ref_nurbs(pts, 9, 4, t, want);
            assert_true(fabs(f.s.end[0] - want[0]) < 1e-9 && fabs(f.s.end[1] - want[1]) < 1e-9);
        }
        assert_int_equal(n, 0);
        /* a span is drawn once its 4 points are in: 1 after 4 points, 5 after 8, 6 */
        spans_done = first + m >= 4 ? first + m - 3 : 0;
        assert_int_equal(step, spans_done * NCP_SPLINE_STEPS);
    }
    assert_int_equal(spans_done, 6);
    assert_true(fabs(f.m.pos[0] - 20) < 1e-9 && fabs(f.m.pos[1]) < 1e-9);

    const double zero_w[3][3] = {{20, 0, 1}, {30, 0, 0}, {30, 10, 1}};
    assert_int_equal(map_op(&f, op_nurbs_head(3, 3, 30, 10, 0), 5), 0);
    assert_true(map_op(&f, op_nurbs_points(zero_w, 3), 5) < 0);
    assert_non_null(strstr(f.d.msg, "weight"));
    assert_int_equal(f.d.line, 5);
    assert_true(map_op(&f, op_nurbs_head(40, NCP_NURBS_MAX_ORDER + 1, 0, 0, 0), 6) < 0);
    assert_non_null(strstr(f.d.msg, "order"));
}

/* A helix of zero radius (rs274 sends one for a bore the tool fills) is
 * the straight move along its axis; an arc whose centre is only one of its
 * ends stays refused. */
static void test_canon_zero_radius_helix(void **state)
{
    (void)state;
    struct map_fixture f;
    map_fixture_init(&f, 1.0);
    assert_int_equal(map_op(&f, op_feed(600), 1), 0);
    assert_int_equal(map_op(&f, op_arc(0, 0, 0, 0, 1, -2.5), 2), 1);
    assert_int_equal(f.s.kind, NCP_SEG_LINE);
    assert_true(fabs(f.s.end[2] + 2.5) < 1e-12 && fabs(f.s.length - 2.5) < 1e-12);
    assert_true(map_op(&f, op_arc(5, 0, 0, 0, 1, -2.5), 3) < 0);
    assert_non_null(strstr(f.d.msg, "zero radius at one end"));
}

static void test_soft_limit(void **state)
{
    (void)state;
    struct ncp_machine_cfg c = test_cfg();
    struct ncp_canon_map m;
    ncp_canon_map_init(&m, &c, NULL, 1.0);
    struct ncp_seg s;
    struct ncp_diag d;
    struct ncp_canon f = op_feed(100);
    ncp_canon_map_op(&m, &f, 1, &s, &d);
    struct ncp_canon z = op6(NCP_C_STRAIGHT_FEED, 0, 0, 60);
    assert_int_equal(ncp_canon_map_op(&m, &z, 7, &s, &d), -NCP_ERR_LIMIT);
    assert_int_equal(d.line, 7);
    assert_non_null(strstr(d.msg, "Z"));
    /* an arc whose end is inside but whose bulge leaves the travel */
    struct ncp_canon l = op6(NCP_C_STRAIGHT_FEED, 480, 0, 0);
    assert_int_equal(ncp_canon_map_op(&m, &l, 8, &s, &d), 1);
    struct ncp_canon a = op_arc(480, 10, 480, 5, 1, 0);
    assert_int_equal(ncp_canon_map_op(&m, &a, 9, &s, &d), 1);
    /* from (480,10): clockwise r 20 about (480,-10) bulges to x = 500 exactly */
    struct ncp_canon b = op_arc(480, -30, 480, -10, -1, 0);
    assert_int_equal(ncp_canon_map_op(&m, &b, 10, &s, &d), 1);
    /* counter-clockwise r 25 bulges to x = 455 */
    struct ncp_canon e = op_arc(480, -80, 480, -55, 1, 0);
    assert_int_equal(ncp_canon_map_op(&m, &e, 11, &s, &d), 1);
    /* clockwise r 25 bulges to x = 505: beyond +500 */
    struct ncp_canon h = op_arc(480, -130, 480, -105, -1, 0);
    assert_int_equal(ncp_canon_map_op(&m, &h, 13, &s, &d), -NCP_ERR_LIMIT);
    assert_int_equal(d.line, 13);
}

/* ---- amortised cost --------------------------------------------------------- */

static void test_replan_cost_bounded(void **state)
{
    (void)state;
    struct ncp_machine_cfg c = test_cfg();
    double zero[NCP_AXES] = { 0 };
    struct ncp_planner *p = ncp_planner_new(&c, zero);
    struct ncp_seg s;
    memset(&s, 0, sizeof s);
    s.kind = NCP_SEG_LINE;
    s.term = NCP_TERM_CONTINUOUS;
    s.feed = 100;
    s.length = 0.05;
    struct ncp_setpoint sp;
    size_t pushed = 0;
    for (int i = 0; i < 20000; i++) {
        s.start[0] = 0.05 * i;
        s.end[0] = 0.05 * (i + 1);
        if (ncp_planner_full(p))
            ncp_planner_step(p, &sp);
        if (!ncp_planner_full(p)) {
            ncp_planner_push(p, &s);
            pushed++;
        }
    }
    struct ncp_planner_stats st;
    ncp_planner_get_stats(p, &st);
    /* stopping distance v^2/2a = 2.5 mm = 50 segments: the pass is bounded by it,
     * not by the window (200) or the program length */
    assert_true(st.replans <= pushed * 60);
    ncp_planner_free(p);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_config_shipped),
        cmocka_unit_test(test_config_errors),
        cmocka_unit_test(test_config_backend),
        cmocka_unit_test(test_trap_long_line_time),
        cmocka_unit_test(test_trap_short_triangle),
        cmocka_unit_test(test_g61_exact_stop_ends),
        cmocka_unit_test(test_g64_corners_within_limits),
        cmocka_unit_test(test_g64_p_tolerance),
        cmocka_unit_test(test_g64_path_independent_of_override),
        cmocka_unit_test(test_g64_blend_only_as_needed),
        cmocka_unit_test(test_g64_q_merges_collinear_lines),
        cmocka_unit_test(test_arc_radius_and_helix),
        cmocka_unit_test(test_arc_centripetal_cap),
        cmocka_unit_test(test_canon_units_offsets),
        cmocka_unit_test(test_canon_spindle_feeds),
        cmocka_unit_test(test_canon_tap_and_spline),
        cmocka_unit_test(test_canon_nurbs),
        cmocka_unit_test(test_soft_limit),
        cmocka_unit_test(test_canon_zero_radius_helix),
        cmocka_unit_test(test_replan_cost_bounded),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
