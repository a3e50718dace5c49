/* Arcs in the planner, checked from whole virtual-clock runs: an arc that
 * moves below its cruise cap spends the acceleration its centripetal part
 * leaves free on the tangent; arcs joined with the small kinks of four-decimal
 * CAM output keep their cruise speed; a G64 blend where a line meets an arc
 * stays within P and does not stop; an arc queued in pieces brakes with what
 * each speed leaves. Every run also keeps every axis within its velocity and
 * acceleration limits. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "trace_rows.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ncpar/feeder.h"
#include "ncpar/motion.h"
#include "ncpar/nck.h"
#include "gcode_src.h"

#include "lcnc_limits.h"

/* Largest path speed (from positions) on the rows of one program line. */
static double peak_speed_on_line(const struct row *r, size_t n, unsigned line, double T)
{
    double v = 0;
    for (size_t k = 1; k < n; k++) {
        if (r[k].line != line || r[k - 1].line != line)
            continue;
        double d2 = 0;
        for (int j = 0; j < 3; j++)
            d2 += (r[k].cmd[j] - r[k - 1].cmd[j]) * (r[k].cmd[j] - r[k - 1].cmd[j]);
        v = fmax(v, sqrt(d2) / T);
    }
    return v;
}

/* A 30 degree arc of radius 1 mm from rest to rest, too short to reach its
 * cruise cap (29.4 mm/s): planned with the tangential acceleration left at
 * that cap (half the vector) it speeds up at 500 mm/s^2; with the share left
 * at the speed it really reaches, at about 880, the vector still within
 * limits. */
static void test_short_arc_accelerates_with_the_free_share(void **state)
{
    (void)state;
    struct ncp_machine_cfg cfg;
    lcnc_like_cfg(&cfg);
    struct ncp_nck_result res;
    size_t n;
    struct row *r =
        run_text("G21 G90 G17 G64 P0.01\nG1 X0 Y0 F3000\nG2 X0.1340 Y0.5 I1 J0\nM2\n", &cfg, &n, &res);
    const double T = cfg.servo_period;
    double at_max = 0;
    for (size_t k = 1; k < n; k++)
        if (r[k].line == 3 && r[k - 1].line == 3)
            at_max = fmax(at_max, (r[k].v - r[k - 1].v) / T);
    double w = worst_acc(r, n, T);
    if (at_max < 0.8 * AMAX || w > 1 + 1e-9)
        fail_msg("tangential acceleration %.1f mm/s^2 (want >= %.0f), axis acceleration %.4f of "
                 "the limit",
                 at_max, 0.8 * AMAX, w);
    free(r);
}

/* Tangent arcs as a CAM system writes them (four decimals, so each joint
 * turns by a few hundredths of a degree): such a kink must not cap the speed
 * at a quarter of the arc's centripetal bound. Each arc reaches (nearly) its
 * cruise cap sqrt(0.866 a r). */
static void test_near_tangent_arcs_keep_cruise_speed(void **state)
{
    (void)state;
    static const char prog[] = "G21 G90 G17 G64 P0.01 Q0\n"
                               "G1 X0 Y0 F3000\n"
                               "G2 X2.1395 Y-4.1349 I0.0000 J-2.6210\n"
                               "G3 X2.4639 Y-7.7699 I2.2990 J-1.6268\n"
                               "G2 X3.0692 Y-11.9463 I-2.4448 J-2.4864\n"
                               "G3 X5.8718 Y-21.6215 I6.2145 J-3.4434\n"
                               "G2 X8.3851 Y-24.7572 I-2.5122 J-4.5886\n"
                               "G3 X11.1382 Y-25.8073 I1.7722 J0.5123\n"
                               "G2 X12.0730 Y-25.5325 I0.9554 J-1.5219\n"
                               "G3 X14.1810 Y-24.3758 I-0.0291 J2.5523\n"
                               "M2\n";
    struct ncp_machine_cfg cfg;
    lcnc_like_cfg(&cfg);
    struct ncp_nck_result res;
    size_t n;
    struct row *r = run_text(prog, &cfg, &n, &res);
    const double T = cfg.servo_period;
    /* line 9: radius 1.797 mm, long enough (about 180 degrees) to reach its cap */
    double radius = hypot(0.9554, 1.5219), cap = sqrt(0.866 * AMAX * radius);
    double peak = peak_speed_on_line(r, n, 9, T);
    double w = worst_acc(r, n, T);
    if (peak < 0.95 * cap || w > 1 + 1e-9)
        fail_msg("peak %.2f mm/s on the r=%.3f arc (cap %.2f), axis acceleration %.4f of the "
                 "limit",
                 peak, radius, cap, w);
    free(r);
}

/* Distance from p to the path: the line (0,0)-(10,0), then the G3 arc from
 * (10,0) around (15,0) through the lower half to (20,0). */
static double dist_line_arc(const double p[3])
{
    double t = fmin(10, fmax(0, p[0]));
    double d_line = hypot(p[0] - t, p[1]);
    double dx = p[0] - 15, dy = p[1];
    double d_arc = dy <= 0 ? fabs(hypot(dx, dy) - 5)
                           : fmin(hypot(p[0] - 10, p[1]), hypot(p[0] - 20, p[1]));
    return fmin(d_line, d_arc);
}

/* A line meeting an arc at a right angle under G64 P0.05: the corner is
 * blended (it does not stop there), every sample stays within P of the
 * programmed path, and the axes stay within their limits. */
static void test_line_arc_blend_within_p(void **state)
{
    (void)state;
    struct ncp_machine_cfg cfg;
    lcnc_like_cfg(&cfg);
    struct ncp_nck_result res;
    size_t n;
    struct row *r = run_text("G21 G90 G17 G64 P0.05\nG1 X0 Y0 F3000\nG1 X10\nG3 X20 Y0 I5 J0\n"
                             "M2\n",
                             &cfg, &n, &res);
    const double T = cfg.servo_period;
    double dev = 0, v_corner = INFINITY;
    for (size_t k = 0; k < n; k++) {
        dev = fmax(dev, dist_line_arc(r[k].cmd));
        if (r[k].cmd[0] > 9 && r[k].cmd[0] < 11 && r[k].cmd[1] > -1)
            v_corner = fmin(v_corner, r[k].v);
    }
    double w = worst_acc(r, n, T);
    if (dev > 0.05 + 1e-6 || v_corner < 1.0 || w > 1 + 1e-9)
        fail_msg("deviation %.4f mm (P 0.05), slowest %.3f mm/s at the corner, axis acceleration "
                 "%.4f of the limit",
                 dev, v_corner, w);
    free(r);
}

/* A half circle of radius 2 mm from rest to rest at F3000. The fastest run
 * the planner's arc model allows (the acceleration vector within the disc
 * of the axes' 1000 mm/s^2, the turn at v^2 / r, the tangent with what is
 * left, sqrt(a^2 - (v^2 / r)^2), the speed at most sqrt(0.866 a r) =
 * 41.6 mm/s), integrated here over the length: 0.194 s. As one trapezoid
 * the arc speeds up and brakes at the single acceleration its top speed
 * leaves (500 mm/s^2): 0.235 s. Queued in pieces cut near its ends, each
 * piece takes its own: the run must come within 5 % of the integral, on
 * the radius and within every axis's limits. */
static void test_arc_brakes_with_what_each_speed_leaves(void **state)
{
    (void)state;
    struct ncp_machine_cfg cfg;
    lcnc_like_cfg(&cfg);
    struct ncp_nck_result res;
    size_t n;
    struct row *r = run_text("G21 G90 G17 G64 P0.01 Q0\nG3 X-4 Y0 I-2 J0 F3000\nM2\n", &cfg, &n, &res);
    const double T = cfg.servo_period, rad = 2, len = M_PI * rad;
    double cap = fmin(50, sqrt(0.866 * AMAX * rad)), t_opt = 0;
    enum { STEPS = 100000 };
    static double vf[STEPS + 1];
    vf[0] = 0;
    for (int i = 0; i < STEPS; i++) {
        double an = vf[i] * vf[i] / rad, at = sqrt(fmax(0, AMAX * AMAX - an * an));
        vf[i + 1] = fmin(cap, sqrt(vf[i] * vf[i] + 2 * at * len / STEPS));
    }
    /* rest to rest on a symmetric path: braking mirrors speeding up */
    for (int i = 0; i < STEPS; i++) {
        double v0 = fmin(vf[i], vf[STEPS - i]), v1 = fmin(vf[i + 1], vf[STEPS - i - 1]);
        t_opt += 2 * (len / STEPS) / (v0 + v1);
    }
    size_t first = 0, last = 0;
    double off = 0;
    for (size_t k = 0; k < n; k++) {
        if (hypot(r[k].cmd[0], r[k].cmd[1]) < 2e-6)
            first = k;
        if (!last && hypot(r[k].cmd[0] + 4, r[k].cmd[1]) < 2e-6)
            last = k;
        off = fmax(off, fabs(hypot(r[k].cmd[0] + 2, r[k].cmd[1]) - rad));
    }
    double t = (double)(last - first) * T, w = worst_acc(r, n, T);
    if (!last || t > 1.05 * t_opt || off > 2e-6 || w > 1 + 1e-9)
        fail_msg("half circle r 2: %.3f s from rest to rest (the arc model's fastest %.3f s, want "
                 "within 5 %%), %.6f mm off the radius, axis acceleration %.4f of the limit",
                 t, t_opt, off, w);
    print_message("half circle r 2: %.3f s, fastest %.3f s\n", t, t_opt);
    free(r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_short_arc_accelerates_with_the_free_share),
        cmocka_unit_test(test_near_tangent_arcs_keep_cruise_speed),
        cmocka_unit_test(test_line_arc_blend_within_p),
        cmocka_unit_test(test_arc_brakes_with_what_each_speed_leaves),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
