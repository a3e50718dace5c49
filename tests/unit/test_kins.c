/* Kinematics (src/kins/): forward after inverse is the identity for both
 * table-rotary-tilting machines, over poses, pivots and tool lengths; known
 * poses give the joints worked out by hand; the inverse equals LinuxCNC's
 * trtfuncs formulas written out term by term. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>

#include "ncpar/kins.h"

#define TOL 1e-9

static double rnd(double lo, double hi)
{
    return lo + (hi - lo) * ((double)rand() / RAND_MAX);
}

static void round_trip(int type)
{
    srand(25);
    for (int k = 0; k < 10000; k++) {
        struct ncp_kins kin = { type, { rnd(-50, 50), rnd(-50, 50), rnd(-50, 50) },
                                { rnd(-80, 80), rnd(-80, 80), rnd(-80, 80) } };
        double tz = rnd(0, 150);
        double pos[NCP_KINS_JOINTS], j[NCP_KINS_JOINTS], back[NCP_KINS_JOINTS];
        for (int i = 0; i < NCP_KINS_JOINTS; i++)
            pos[i] = i < 3 ? rnd(-300, 300) : rnd(-720, 720);
        ncp_kins_inverse(&kin, tz, pos, j);
        ncp_kins_forward(&kin, tz, j, back);
        for (int i = 0; i < NCP_KINS_JOINTS; i++)
            assert_true(fabs(back[i] - pos[i]) < TOL);
        /* and joints -> axes -> joints */
        ncp_kins_forward(&kin, tz, pos, j);
        ncp_kins_inverse(&kin, tz, j, back);
        for (int i = 0; i < NCP_KINS_JOINTS; i++)
            assert_true(fabs(back[i] - pos[i]) < TOL);
    }
}

static void test_round_trip_xyzac(void **state)
{
    (void)state;
    round_trip(NCP_KINS_XYZAC_TRT);
}

static void test_round_trip_xyzbc(void **state)
{
    (void)state;
    round_trip(NCP_KINS_XYZBC_TRT);
}

static void expect(const struct ncp_kins *k, double tz, const double pos[NCP_KINS_JOINTS],
                   double jx, double jy, double jz)
{
    double j[NCP_KINS_JOINTS];
    ncp_kins_inverse(k, tz, pos, j);
    assert_true(fabs(j[0] - jx) < TOL);
    assert_true(fabs(j[1] - jy) < TOL);
    assert_true(fabs(j[2] - jz) < TOL);
    for (int i = 3; i < NCP_KINS_JOINTS; i++)   /* the angles are their own joints */
        assert_true(j[i] == pos[i]);
}

static void test_known_poses(void **state)
{
    (void)state;
    struct ncp_kins ac = { NCP_KINS_XYZAC_TRT, { 0, 0, 0 }, { 0, 0, 0 } };
    struct ncp_kins bc = { NCP_KINS_XYZBC_TRT, { 0, 0, 0 }, { 0, 0, 0 } };
    /* untilted, unturned: the joints are the axes, whatever the pivots */
    struct ncp_kins off = { NCP_KINS_XYZAC_TRT, { 5, 6, 7 }, { 0, 8, 9 } };
    expect(&off, 40, (double[NCP_KINS_JOINTS]){ 1, 2, 3 }, 1, 2, 3);
    /* C +90 brings the work's +X under the tool's +Y */
    expect(&ac, 0, (double[NCP_KINS_JOINTS]){ 10, 0, 0, 0, 0, 90 }, 0, 10, 0);
    /* A +90 lifts the work's +Y to +Z */
    expect(&ac, 0, (double[NCP_KINS_JOINTS]){ 0, 10, 0, 90, 0, 0 }, 0, 0, 10);
    /* B +90 turns the work's +X to -Z */
    expect(&bc, 0, (double[NCP_KINS_JOINTS]){ 10, 0, 0, 0, 90, 0 }, 0, 0, -10);
    /* about a pivot: C turns about the rot point (10, 0): X20 goes to Y10 */
    struct ncp_kins rp = { NCP_KINS_XYZAC_TRT, { 10, 0, 0 }, { 0, 0, 0 } };
    expect(&rp, 0, (double[NCP_KINS_JOINTS]){ 20, 0, 0, 0, 0, 90 }, 10, 10, 0);
    /* A tilts about its pivot 50 below the table: the table top's origin,
     * 50 above the pivot, swings to 50 along -Y */
    struct ncp_kins za = { NCP_KINS_XYZAC_TRT, { 0, 0, 0 }, { 0, 0, -50 } };
    expect(&za, 0, (double[NCP_KINS_JOINTS]){ 0, 0, 0, 90, 0, 0 }, 0, -50, -50);
    /* a 30 mm tool: the spindle nose is 30 above the tip, along the tool
     * (Z); the tip, not the nose, turns about the pivot */
    expect(&za, 30, (double[NCP_KINS_JOINTS]){ 0, 0, 30, 90, 0, 0 }, 0, -50, -20);
    /* the other axes pass through */
    double pos[NCP_KINS_JOINTS] = { 1, 2, 3, 4, 5, 6, 7, 8, 9 }, j[NCP_KINS_JOINTS];
    struct ncp_kins triv = { NCP_KINS_TRIVIAL, { 1, 2, 3 }, { 4, 5, 6 } };
    ncp_kins_inverse(&triv, 100, pos, j);
    for (int i = 0; i < NCP_KINS_JOINTS; i++)
        assert_true(j[i] == pos[i]);
}

/* xyzacKinematicsInverse / xyzbcKinematicsInverse of trtfuncs.c */
static void lcnc_inverse(int type, const double r[3], const double o[3], double dt,
                         const double p[NCP_KINS_JOINTS], double j[3])
{
    double c = p[5] * M_PI / 180, sc = sin(c), cc = cos(c);
    double x = p[0] - r[0], y = p[1] - r[1], z = p[2] - r[2];
    if (type == NCP_KINS_XYZAC_TRT) {
        double a = p[3] * M_PI / 180, sa = sin(a), ca = cos(a), dy = o[1], dz = o[2] + dt;
        j[0] = cc * x - sc * y + r[0];
        j[1] = sc * ca * x + cc * ca * y - sa * z - ca * dy + sa * dz + dy + r[1];
        j[2] = sc * sa * x + cc * sa * y + ca * z - sa * dy - ca * dz + dz + r[2];
    } else {
        double b = p[4] * M_PI / 180, sb = sin(b), cb = cos(b), dx = o[0], dz = o[2] + dt;
        j[0] = cc * cb * x - sc * cb * y + sb * z + (-cb * dx - sb * dz + dx) + r[0];
        j[1] = sc * x + cc * y + r[1];
        j[2] = -cc * sb * x + sc * sb * y + cb * z + (sb * dx - cb * dz + dz) + r[2];
    }
}

static void test_equals_linuxcnc(void **state)
{
    (void)state;
    srand(43);
    for (int type = NCP_KINS_XYZAC_TRT; type <= NCP_KINS_XYZBC_TRT; type++) {
        for (int k = 0; k < 10000; k++) {
            struct ncp_kins kin = { type, { rnd(-50, 50), rnd(-50, 50), rnd(-50, 50) },
                                    { rnd(-80, 80), rnd(-80, 80), rnd(-80, 80) } };
            double tz = rnd(0, 150), pos[NCP_KINS_JOINTS], j[NCP_KINS_JOINTS], want[3];
            for (int i = 0; i < NCP_KINS_JOINTS; i++)
                pos[i] = i < 3 ? rnd(-300, 300) : rnd(-720, 720);
            ncp_kins_inverse(&kin, tz, pos, j);
            lcnc_inverse(type, kin.rot_point, kin.offset, tz, pos, want);
            for (int i = 0; i < 3; i++)
                assert_true(fabs(j[i] - want[i]) < TOL);
        }
    }
}

static void test_names(void **state)
{
    (void)state;
    assert_int_equal(ncp_kins_parse("trivkins"), NCP_KINS_TRIVIAL);
    assert_int_equal(ncp_kins_parse("XYZAC-TRT"), NCP_KINS_XYZAC_TRT);
    assert_int_equal(ncp_kins_parse("xyzbc-trt"), NCP_KINS_XYZBC_TRT);
    assert_int_equal(ncp_kins_parse("xyzac-trt-kins"), -1);
    assert_int_equal(ncp_kins_parse(""), -1);
    assert_string_equal(ncp_kins_name(NCP_KINS_XYZBC_TRT), "xyzbc-trt");
    assert_int_equal(ncp_kins_tilt_axis(NCP_KINS_XYZAC_TRT), 3);
    assert_int_equal(ncp_kins_tilt_axis(NCP_KINS_XYZBC_TRT), 4);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_round_trip_xyzac), cmocka_unit_test(test_round_trip_xyzbc),
        cmocka_unit_test(test_known_poses),      cmocka_unit_test(test_equals_linuxcnc),
        cmocka_unit_test(test_names),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
