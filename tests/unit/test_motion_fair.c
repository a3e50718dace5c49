/* Fairing of CAM chains (src/motion/fair.c), from whole virtual-clock runs on
 * LinuxCNC-like limits (100 mm/s, 1000 mm/s^2 per axis, 1 ms): a curve
 * sampled by 0.02-0.2 mm chords whose heading wanders and whose Z steps per
 * block (bench/gen-planner.py's tiny, here with its own random numbers) runs
 * faster once its vertices are moved within half of P towards their
 * neighbours' chords, while every sample stays within P of the programmed
 * polyline and every axis within its limits. */
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

#define CHORDS 400
#define P_TOL 0.01

static double pts[CHORDS + 1][3];

/* A fixed sequence in [0, 1), the same on every machine. */
static double next_unit(uint64_t *s)
{
    *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*s >> 11) / 9007199254740992.0;
}

/* The program, its points rounded as written (4 decimals). */
static char *cam_chain(void)
{
    char *prog = malloc((size_t)64 * (CHORDS + 4));
    assert_non_null(prog);
    int len = sprintf(prog, "G21 G90 G17 G94 G64 P%.2f Q0\nG1 F3000\n", P_TOL);
    uint64_t seed = 44;
    double x = 0, y = 0, h = 0, dh = 0;
    memset(pts[0], 0, sizeof pts[0]);
    for (int i = 1; i <= CHORDS; i++) {
        dh = fmax(-0.3, fmin(0.3, dh + 0.1 * next_unit(&seed) - 0.05));
        h += dh;
        double step = 0.02 + 0.18 * next_unit(&seed);
        x += step * cos(h);
        y += step * sin(h);
        double z = -0.5 - 0.3 * sin(i * 0.05);
        len += sprintf(prog + len, "G1 X%.4f Y%.4f Z%.4f\n", x, y, z);
        pts[i][0] = round(x * 1e4) / 1e4;
        pts[i][1] = round(y * 1e4) / 1e4;
        pts[i][2] = round(z * 1e4) / 1e4;
    }
    sprintf(prog + len, "M2\n");
    return prog;
}

/* Distance from p to the programmed polyline, near chord i. */
static double dist_chain(const double p[3], int *i)
{
    return chain_dist((const double(*)[3])pts, CHORDS, p, i, 20, 20);
}

static void run_chain(enum ncp_profile profile, double *time, double *dev, double *acc)
{
    char *prog = cam_chain();
    struct ncp_machine_cfg cfg;
    lcnc_like_cfg(&cfg);
    cfg.profile = profile;
    struct ncp_nck_result res;
    size_t n;
    struct row *r = run_text(prog, &cfg, &n, &res);
    free(prog);
    int at = 0;
    *dev = 0;
    for (size_t k = 0; k < n; k++)
        *dev = fmax(*dev, dist_chain(r[k].cmd, &at));
    *acc = worst_acc(r, n, cfg.servo_period);
    *time = (double)n * cfg.servo_period;
    free(r);
}

/* Before fairing the chain took 2.508 s (its corners held by the uneven turns
 * of single vertices); faired, 2.221 s. */
static void test_cam_chain_faired_within_p(void **state)
{
    (void)state;
    double t, dev, w;
    run_chain(NCP_PROFILE_TRAPEZOID, &t, &dev, &w);
    if (t > 2.35 || dev > P_TOL + 1e-6 || w > 1 + 1e-9)
        fail_msg("chain ran %.3f s (want <= 2.35), deviation %.5f mm (P %.2f), axis acceleration "
                 "%.4f of the limit", t, dev, P_TOL, w);
}

/* The S-curve takes the same moved vertices: still within P. */
static void test_cam_chain_scurve_within_p(void **state)
{
    (void)state;
    double t, dev, w;
    run_chain(NCP_PROFILE_SCURVE, &t, &dev, &w);
    if (dev > P_TOL + 1e-6 || w > 1 + 1e-9)
        fail_msg("S-curve: deviation %.5f mm (P %.2f), axis acceleration %.4f of the limit", dev,
                 P_TOL, w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cam_chain_faired_within_p),
        cmocka_unit_test(test_cam_chain_scurve_within_p),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
