/* Rough/fine interpolation ([TRAJ] PLANNING_PERIOD = 4 servo periods): the
 * planner samples its profile every planning period and the position loop
 * fills in the servo cycles with a cubic Hermite curve. Checked from the
 * per-servo-cycle --trace of virtual-clock runs, like test_motion_limits. */
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
#include <unistd.h>

#include "ncpar/feeder.h"
#include "ncpar/motion.h"
#include "ncpar/pipeline.h"
#include "ncpar/nck.h"
#include "gcode_src.h"

/* the trace prints 6 decimals: half a unit of the last digit */
#define PRINT_Q 0.5e-6
#define RATIO 4

static void ipo_cfg(struct ncp_machine_cfg *c, enum ncp_profile prof)
{
    ncp_machine_cfg_default(c);
    c->profile = prof;
    c->axis[2].max_vel = 100;
    c->axis[2].max_acc = 1000;
    c->axis[2].max_jerk = 50000;
    c->planning_period = RATIO * c->servo_period;
}

/* Worst |k-th difference| / limit over all axes, k = 1, 2 (1 = at the limit),
 * less what the trace's print rounding can add. Also checks that there is
 * one row per servo period. */
static void worst_ratios(const struct row *r, size_t n, const struct ncp_machine_cfg *c,
                         double *vel, double *acc)
{
    const double T = c->servo_period;
    *vel = *acc = 0;
    for (size_t k = 2; k < n; k++) {
        assert_true(fabs(r[k].t - r[k - 1].t - T) < 1e-7);
        for (int j = 0; j < 3; j++) {
            double p1 = r[k - 2].cmd[j], p2 = r[k - 1].cmd[j], p3 = r[k].cmd[j];
            double v = fabs(p3 - p2) / T, a = fabs(p3 - 2 * p2 + p1) / (T * T);
            *vel = fmax(*vel, (v - 2 * PRINT_Q / T) / c->axis[j].max_vel);
            *acc = fmax(*acc, (a - 4 * PRINT_Q / (T * T)) / c->axis[j].max_acc);
        }
    }
}

/* Worst third difference / MAX_JERK over all axes (1 = at the limit). */
static double worst_jerk(const struct row *r, size_t n, const struct ncp_machine_cfg *c,
                         unsigned *line, double *t)
{
    double vmax[3], amax[3], jmax[3];
    for (int j = 0; j < 3; j++) {
        vmax[j] = c->axis[j].max_vel;
        amax[j] = c->axis[j].max_acc;
        jmax[j] = c->axis[j].max_jerk;
    }
    struct trace_worst w = trace_limits(r, n, c->servo_period, vmax, amax, jmax);
    *line = w.jerk_line;
    *t = w.jerk_t;
    return w.jerk;
}

static char *write_tmp(const char *text)
{
    static char path[] = "/tmp/ncp_ipo_XXXXXX";
    strcpy(path, "/tmp/ncp_ipo_XXXXXX");
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    assert_int_equal(write(fd, text, strlen(text)), (ssize_t)strlen(text));
    close(fd);
    return path;
}

/* what every machine INI states for each axis */
#define LIMITS "MIN_LIMIT = -500\nMAX_LIMIT = 500\nMAX_VELOCITY = 200\nMAX_ACCELERATION = 2000\nFERROR = 1\n"
#define AXES "[AXIS_X]\n" LIMITS "[AXIS_Y]\n" LIMITS "[AXIS_Z]\n" LIMITS

static void test_ini_planning_period(void **state)
{
    (void)state;
    struct ncp_machine_cfg c;
    struct ncp_diag d;
    ncp_machine_cfg_default(&c);
    assert_int_equal(ncp_machine_cfg_ipo_ratio(&c), 1);
    char *p = write_tmp("[EMCMOT]\nSERVO_PERIOD = 250000\n[TRAJ]\nPLANNING_PERIOD = 1000000\n" AXES);
    assert_int_equal(ncp_machine_cfg_load(&c, p, &d), NCP_OK);
    assert_int_equal(ncp_machine_cfg_ipo_ratio(&c), 4);

    ncp_machine_cfg_default(&c);
    p = write_tmp("[EMCMOT]\nSERVO_PERIOD = 1000000\n[TRAJ]\nPLANNING_PERIOD = 2500000\n" AXES);
    assert_int_not_equal(ncp_machine_cfg_load(&c, p, &d), NCP_OK);
    assert_non_null(strstr(d.msg, "PLANNING_PERIOD"));
    assert_non_null(strstr(d.msg, "multiple"));

    ncp_machine_cfg_default(&c);
    p = write_tmp("[TRAJ]\nPLANNING_PERIOD = 500000\n" AXES);  /* shorter than the servo period */
    assert_int_not_equal(ncp_machine_cfg_load(&c, p, &d), NCP_OK);
    assert_non_null(strstr(d.msg, "PLANNING_PERIOD"));

    ncp_machine_cfg_default(&c);
    p = write_tmp("[TRAJ]\nPLANNING_PERIOD = soon\n");
    assert_int_not_equal(ncp_machine_cfg_load(&c, p, &d), NCP_OK);
    assert_non_null(strstr(d.msg, "TRAJ"));
    unlink(p);
}

static void check_corners(enum ncp_profile prof)
{
    struct ncp_machine_cfg cfg;
    ipo_cfg(&cfg, prof);
    struct ncp_nck_result res;
    size_t n;
    struct row *r = run_text(corners_prog, &cfg, &n, &res);
    double vel, acc;
    worst_ratios(r, n, &cfg, &vel, &acc);
    if (vel > 1 + 1e-9 || acc > 1 + 1e-9)
        fail_msg("profile %d: vel %.4f acc %.4f of the limits", prof, vel, acc);
    assert_true(acc > 0.3);  /* the machine is really used */
    if (prof == NCP_PROFILE_SCURVE) {
        unsigned line;
        double t, jerk = worst_jerk(r, n, &cfg, &line, &t);
        print_message("fine interpolation, S-curve: jerk %.4f of the limit (line %u, t %.3f)\n",
                      jerk, line, t);
        if (jerk > 1 + 1e-9)
            fail_msg("jerk %.4f of the limit (line %u, t %.3f)", jerk, line, t);
    }
    assert_true(r[n - 1].cmd[2] == 5 && r[n - 1].v == 0);
    /* the rough stream takes about as long as the servo-rate one */
    struct ncp_machine_cfg fine = cfg;
    fine.planning_period = 0;
    struct ncp_nck_result res1;
    size_t n1;
    free(run_text(corners_prog, &fine, &n1, &res1));
    if (!(res.program_time < 1.3 * res1.program_time && res.program_time > res1.program_time))
        fail_msg("program time %.4f s with fine interpolation, %.4f s without",
                 res.program_time, res1.program_time);
    free(r);
}

static void test_corners_keep_limits_trapezoid(void **state)
{
    (void)state;
    check_corners(NCP_PROFILE_TRAPEZOID);
}

static void test_corners_keep_limits_scurve(void **state)
{
    (void)state;
    check_corners(NCP_PROFILE_SCURVE);
}

/* G61 segment ends are reached exactly (at rest), and the arc keeps its
 * radius within the fine interpolation's chord error (src/rt/scaler.c):
 * R theta^4 / 384 at constant speed (theta = v Tp / R), plus 0.0162 da Tp^2
 * theta where the tangential acceleration changes by da inside a planning
 * period (da <= 2 MAX_ACCELERATION), plus the trace's print rounding. */
static void test_g61_ends_and_arc_radius(void **state)
{
    (void)state;
    static const char prog[] = "G21 G90 G17 G61\n"
                               "G0 X10 Y5 Z2\n"
                               "G1 Z-1 F600\n"
                               "G1 X50 F3000\n"
                               "G2 X60 Y15 I0 J10\n"
                               "G1 Y40\n"
                               "G20 G1 X1\n"
                               "M2\n";
    struct ncp_machine_cfg cfg;
    ipo_cfg(&cfg, NCP_PROFILE_TRAPEZOID);
    struct ncp_nck_result res;
    size_t n;
    struct row *r = run_text(prog, &cfg, &n, &res);
    static const double ends[][3] = { { 10, 5, 2 }, { 10, 5, -1 }, { 50, 5, -1 },
                                      { 60, 15, -1 }, { 60, 40, -1 }, { 25.4, 40, -1 } };
    for (size_t e = 0; e < sizeof ends / sizeof ends[0]; e++) {
        int hit = 0;
        for (size_t k = 0; k < n && !hit; k++)
            hit = fabs(r[k].cmd[0] - ends[e][0]) < 1e-6 && fabs(r[k].cmd[1] - ends[e][1]) < 1e-6 &&
                  fabs(r[k].cmd[2] - ends[e][2]) < 1e-6 && r[k].v == 0;
        if (!hit)
            fail_msg("end %zu (%g %g %g) not reached at rest", e, ends[e][0], ends[e][1], ends[e][2]);
    }
    const double R = 10, v = 3000 / 60.0, theta = v * cfg.planning_period / R;
    const double Tp = cfg.planning_period, da = 2 * cfg.axis[0].max_acc;
    const double bound = R * pow(theta, 4) / 384 + 0.0162 * da * Tp * Tp * theta + 2 * PRINT_Q;
    assert_true(bound < 1e-3 * 0.05);  /* well inside the 1 um the arcs must keep */
    size_t on = 0;
    double worst = 0;
    for (size_t k = 0; k < n; k++) {
        if (r[k].line != 5)
            continue;
        on++;
        worst = fmax(worst, fabs(hypot(r[k].cmd[0] - 50, r[k].cmd[1] - 15) - R));
    }
    assert_true(on > 100);
    if (worst > bound)
        fail_msg("arc radius off by %g mm, bound %g", worst, bound);
    double vel, acc;
    worst_ratios(r, n, &cfg, &vel, &acc);
    assert_true(vel <= 1 + 1e-9 && acc <= 1 + 1e-9);
    free(r);
}

/* The fine interpolation is smooth: between rough points the servo-rate
 * velocity does not step (a linear fill would jump by a Tp every Tp). */
static void test_fine_points_between_rough(void **state)
{
    (void)state;
    struct ncp_machine_cfg cfg;
    ipo_cfg(&cfg, NCP_PROFILE_TRAPEZOID);
    struct ncp_nck_result res;
    size_t n;
    /* a rapid: cruises at the axis's velocity limit, decelerates at the end */
    struct row *r = run_text("G21 G90 G0 X100\nM2\n", &cfg, &n, &res);
    const double T = cfg.servo_period, a = cfg.axis[0].max_acc;
    int distinct = 0;
    for (size_t k = 2; k < n; k++) {
        double v = fabs(r[k].cmd[0] - r[k - 1].cmd[0]) / T;
        if (v > cfg.axis[0].max_vel + 2 * PRINT_Q / T)
            fail_msg("velocity %g at row %zu", v, k);
        double acc = (r[k].cmd[0] - 2 * r[k - 1].cmd[0] + r[k - 2].cmd[0]) / (T * T);
        if (fabs(acc) > a + 4 * PRINT_Q / (T * T))
            fail_msg("acc %g at row %zu t %g x %.6f %.6f %.6f", acc, k, r[k].t, r[k - 2].cmd[0], r[k - 1].cmd[0], r[k].cmd[0]);
        distinct += r[k].cmd[0] != r[k - 1].cmd[0];
    }
    /* every servo cycle in motion gets its own point, not one per rough period */
    double t_move = res.program_time;
    assert_true(distinct > 0.9 * t_move / T);
    assert_true(r[n - 1].cmd[0] == 100);
    free(r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ini_planning_period),
        cmocka_unit_test(test_corners_keep_limits_trapezoid),
        cmocka_unit_test(test_corners_keep_limits_scurve),
        cmocka_unit_test(test_g61_ends_and_arc_radius),
        cmocka_unit_test(test_fine_points_between_rough),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
