/* Arcs fitted through CAM chains (src/motion/fit.c), from whole virtual-clock
 * runs on LinuxCNC-like limits (100 mm/s, 1000 mm/s^2 per axis, 1 ms): two
 * turns of a 1 mm radius circle written as G1 chords of 0.02 and 0.08 mm in
 * turn (0.05 mm on average), G64 P0.01. A corner's blend may use only half
 * of its shorter chord, so each vertex's parabola turns over 0.02 mm what
 * the circle turns over 0.05: about 20 mm/s. Run as arcs at the circle's
 * radius the chain reaches sqrt(0.99 a r) = 31 mm/s, while every sample
 * stays within P of the programmed chords, every axis within its limits and
 * every sample keeps its block's line number.
 *
 * A wave along the diagonal, written the same way, turns on radii down to
 * 1 mm with its normal never more than 17 degrees off the diagonal: each
 * fitted arc's sweep leaves each axis about cos(28 degrees) of the normal
 * acceleration, so the arcs may turn at 1.1-1.2 times the 990 mm/s^2 the
 * disc every direction gets would allow. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "chord_dist.h"
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

#define RADIUS 1.0
#define TURNS 2
#define P_TOL 0.01
#define FIRST_LINE 3   /* the program's first chord is on its line 3 */
#define MAX_CHORDS 400

static double pts[MAX_CHORDS + 1][3];
static int chords;

/* A shape's next point: its parameter *at advanced by about one chord of
 * length c, the point there in xy; 0 once past the end. */
typedef int (*chain_step)(double *at, double c, double xy[2]);

/* The program: chords of 0.02 and 0.08 mm in turn along a shape from the
 * origin, its points rounded as written. */
static char *write_chain(chain_step step)
{
    char *prog = malloc((size_t)64 * (MAX_CHORDS + 4));
    assert_non_null(prog);
    int len = sprintf(prog, "G21 G90 G17 G94 G64 P%.2f Q0\nG1 F3000\n", P_TOL);
    double at = 0, xy[2];
    memset(pts[0], 0, sizeof pts[0]);
    chords = 0;
    while (chords < MAX_CHORDS && step(&at, chords % 2 ? 0.08 : 0.02, xy)) {
        len += sprintf(prog + len, "G1 X%.4f Y%.4f Z0\n", xy[0], xy[1]);
        chords++;
        pts[chords][0] = round(xy[0] * 1e4) / 1e4;
        pts[chords][1] = round(xy[1] * 1e4) / 1e4;
        pts[chords][2] = 0;
    }
    sprintf(prog + len, "M2\n");
    return prog;
}

/* TURNS round the circle through the origin, centred at (0, RADIUS). */
static int circle_step(double *ang, double c, double xy[2])
{
    double end = TURNS * 2 * M_PI;
    if (*ang >= end - 1e-9)
        return 0;
    *ang = fmin(end, *ang + 2 * asin(c / (2 * RADIUS)));
    xy[0] = RADIUS * sin(*ang);
    xy[1] = RADIUS - RADIUS * cos(*ang);
    return 1;
}

/* A wave of amplitude WAVE_A and wavenumber WAVE_K along the diagonal y = x,
 * WAVE_LEN mm long in its own parameter. */
#define WAVE_A 0.09
#define WAVE_K (10.0 / 3)
#define WAVE_LEN 12.0
static int wave_step(double *s, double c, double xy[2])
{
    if (*s >= WAVE_LEN - 1e-9)
        return 0;
    *s = fmin(WAVE_LEN, *s + c);
    double w = WAVE_A * sin(WAVE_K * *s);
    xy[0] = sqrt(0.5) * (*s - w);
    xy[1] = sqrt(0.5) * (*s + w);
    return 1;
}

static double dist_chord(const double p[3], int k)
{
    return chord_dist(p, pts[k], pts[k + 1]);
}

/* Distance from p to the programmed chords near chord *i (taken in order:
 * the circle's second turn runs over its first). */
static double dist_chain(const double p[3], int *i)
{
    return chain_dist((const double(*)[3])pts, chords, p, i, 4, 20);
}

/* The whole chain on LinuxCNC-like limits, trapezoid profile, virtual clock. */
static struct row *run_chain(chain_step step, struct ncp_machine_cfg *cfg, size_t *n)
{
    char *prog = write_chain(step);
    lcnc_like_cfg(cfg);
    cfg->profile = NCP_PROFILE_TRAPEZOID;
    struct ncp_nck_result res;
    struct row *r = run_text(prog, cfg, n, &res);
    free(prog);
    return r;
}

/* Frees the rows; every sample within P and every axis within its limit. */
static void check_band_and_limits(struct row *r, size_t n, double period, double dev,
                                  const char *speed_is, double speed)
{
    double acc = worst_acc(r, n, period);
    free(r);
    print_message("%d chords, %.3f s, %s %.1f mm/s, deviation %.5f mm, axis acceleration %.4f "
                  "of the limit\n", chords, (double)n * period, speed_is, speed, dev, acc);
    if (dev > P_TOL + 1e-6 || acc > 1 + 1e-9)
        fail_msg("deviation %.5f mm (P %.2f), axis acceleration %.4f of the limit", dev, P_TOL,
                 acc);
}

static void test_circle_chords_run_as_arcs(void **state)
{
    (void)state;
    struct ncp_machine_cfg cfg;
    size_t n;
    struct row *r = run_chain(circle_step, &cfg, &n);
    int at = 0;
    double dev = 0, vtop = 0;
    for (size_t k = 0; k < n; k++) {
        dev = fmax(dev, dist_chain(r[k].cmd, &at));
        /* each moving sample on a block of the chain, near its chord:
         * within P of it or of a neighbour's (a sample just past a vertex) */
        if (k > 0 && r[k].v > 0) {
            int c = (int)r[k].line - FIRST_LINE;
            if (c < 0 || c >= chords)
                fail_msg("sample %zu on line %u, not a chord's", k, r[k].line);
            double near = dist_chord(r[k].cmd, c);
            if (c > 0)
                near = fmin(near, dist_chord(r[k].cmd, c - 1));
            if (c + 1 < chords)
                near = fmin(near, dist_chord(r[k].cmd, c + 1));
            if (near > P_TOL + 1e-6)
                fail_msg("sample %zu of line %u lies %.5f mm from its chord", k, r[k].line, near);
            if (r[k].motion != 1)
                fail_msg("sample %zu of line %u is not marked a feed (motion %d)", k, r[k].line,
                         r[k].motion);
        }
        /* the second turn, where the chain runs at its own pace */
        if (k * cfg.servo_period > 0.25 && k + 100 < n)
            vtop = fmax(vtop, r[k].v);
    }
    check_band_and_limits(r, n, cfg.servo_period, dev, "top speed", vtop);
    /* sqrt(0.99 a r) = 31.5 mm/s on the circle (more where a fitted arc's
     * sweep leaves its axes room); the blends reach about 20 */
    if (vtop < 28)
        fail_msg("the chain reached only %.1f mm/s (want >= 28: the circle's radius)", vtop);
}

static void test_diagonal_wave_reads_each_axis(void **state)
{
    (void)state;
    struct ncp_machine_cfg cfg;
    size_t n;
    struct row *r = run_chain(wave_step, &cfg, &n);
    int at = 0;
    double dev = 0, vlow = INFINITY;
    for (size_t k = 0; k < n; k++) {
        dev = fmax(dev, dist_chain(r[k].cmd, &at));
        /* the middle, away from the ramps at both ends: the slowest speed is
         * at the tightest turns (1 mm), where the disc allows
         * sqrt(0.99 a r) = 31.5 mm/s (32-33 before: the fit flattens them) */
        double along = sqrt(0.5) * (r[k].cmd[0] + r[k].cmd[1]);
        if (along > 2 && along < WAVE_LEN - 2)
            vlow = fmin(vlow, r[k].v);
    }
    check_band_and_limits(r, n, cfg.servo_period, dev, "slowest in the middle", vlow);
    if (vlow < 34.5)
        fail_msg("the wave slowed to %.1f mm/s (want >= 34.5: each axis's own room)", vlow);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_circle_chords_run_as_arcs),
        cmocka_unit_test(test_diagonal_wave_reads_each_axis),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
