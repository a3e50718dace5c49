/* Limits the motion runtime must keep, checked from the --trace CSV of whole
 * virtual-clock runs: velocity, acceleration and (S-curve) jerk per axis from
 * the first, second and third differences of the commanded positions; live
 * feed override and feed hold; slowing down for an underrun. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "trace_rows.h"

#include <math.h>
#include <pthread.h>
#include <sched.h>
#include <stdio.h>
#include <time.h>
#include <stdlib.h>
#include <string.h>

#include "ncpar/feeder.h"
#include "ncpar/motion.h"
#include "ncpar/pipeline.h"
#include "ncpar/nck.h"
#include "gcode_src.h"

/* The trace prints positions with 6 decimals: a k-th difference may be off by
 * 2^k half-units of the last digit, divided by T^k. */
#define PRINT_Q 0.5e-6

/* Worst ratio of |k-th difference| / limit over all axes (1 = at the limit). */
struct worst {
    double vel, acc, jerk;
    unsigned jerk_line;
};

static struct worst check_limits(const struct row *r, size_t n, const struct ncp_machine_cfg *c)
{
    const double T = c->servo_period;
    struct worst w = { 0, 0, 0, 0 };
    for (size_t k = 3; k < n; k++) {
        assert_true(fabs(r[k].t - r[k - 1].t - T) < 1e-7);  /* one row per period */
        for (int j = 0; j < 3; j++) {
            const struct ncp_axis_cfg *a = &c->axis[j];
            double p0 = r[k - 3].cmd[j], p1 = r[k - 2].cmd[j], p2 = r[k - 1].cmd[j],
                   p3 = r[k].cmd[j];
            double v = fabs(p3 - p2) / T, acc = fabs(p3 - 2 * p2 + p1) / (T * T);
            double jerk = fabs(p3 - 3 * p2 + 3 * p1 - p0) / (T * T * T);
            w.vel = fmax(w.vel, (v - 2 * PRINT_Q / T) / a->max_vel);
            w.acc = fmax(w.acc, (acc - 4 * PRINT_Q / (T * T)) / a->max_acc);
            double rj = (jerk - 8 * PRINT_Q / (T * T * T)) / a->max_jerk;
            if (rj > w.jerk) {
                w.jerk = rj;
                w.jerk_line = r[k].line;
            }
        }
    }
    return w;
}

static void scurve_cfg(struct ncp_machine_cfg *c)
{
    ncp_machine_cfg_default(c);
    c->profile = NCP_PROFILE_SCURVE;
    c->axis[2].max_vel = 100;
    c->axis[2].max_acc = 1000;
    c->axis[2].max_jerk = 50000;
}

static void test_scurve_trace_within_jerk(void **state)
{
    (void)state;
    struct ncp_machine_cfg cfg;
    scurve_cfg(&cfg);
    struct ncp_nck_result res;
    size_t n;
    struct row *r = run_text(corners_prog, &cfg, &n, &res);
    struct worst w = check_limits(r, n, &cfg);
    if (w.vel > 1 + 1e-9 || w.acc > 1 + 1e-9 || w.jerk > 1 + 1e-9)
        fail_msg("vel %.4f acc %.4f jerk %.4f (line %u) of the limits", w.vel, w.acc, w.jerk,
                 w.jerk_line);
    /* it really is jerk-limited motion that uses the machine, not a crawl */
    assert_true(w.acc > 0.3 && w.jerk > 0.3);
    assert_true(r[n - 1].cmd[2] == 5 && r[n - 1].v == 0);
    free(r);
}

/* The same program as a trapezoid breaks the jerk limit (which is what the
 * S-curve is for) but keeps velocity and acceleration. */
static void test_trapezoid_is_not_jerk_limited(void **state)
{
    (void)state;
    struct ncp_machine_cfg cfg;
    scurve_cfg(&cfg);
    cfg.profile = NCP_PROFILE_TRAPEZOID;
    struct ncp_nck_result res;
    size_t n;
    struct row *r = run_text(corners_prog, &cfg, &n, &res);
    struct worst w = check_limits(r, n, &cfg);
    assert_true(w.vel <= 1 + 1e-9 && w.acc <= 1 + 1e-9);
    assert_true(w.jerk > 2);
    free(r);
}

/* A long line takes the analytical S-curve time: two ramps of v/a + a/j. */
static void test_scurve_long_line_time(void **state)
{
    (void)state;
    struct ncp_machine_cfg cfg;
    scurve_cfg(&cfg);
    struct ncp_nck_result res;
    size_t n;
    struct row *r = run_text("G21 G90 G1 X300 F6000\nM2\n", &cfg, &n, &res);
    double v = 100, a = 2000, j = 0.5 * 100000;  /* half the jerk: corners keep the rest */
    double ramp = v / a + a / j, expect = 300 / v + ramp;
    assert_true(fabs(res.program_time - expect) / expect < 0.01);
    assert_true(r[n - 1].cmd[0] == 300);
    free(r);
}

/* Every bundled program, with both profiles: the trace stays within velocity and
 * acceleration, and with the S-curve within jerk too. */
static void check_bundled_programs(enum ncp_profile profile)
{
    static const char *const progs[] = {
        "ncprograms/demo.ngc", "ncprograms/helical-bore.ngc", "ncprograms/engrave.ngc",
        "ncprograms/inch-slots.ngc", "ncprograms/part998.ngc", "ncprograms/surface3d.ngc"
    };
    struct ncp_machine_cfg cfg;
    scurve_cfg(&cfg);
    cfg.profile = profile;
    for (size_t i = 0; i < sizeof progs / sizeof progs[0]; i++) {
        struct gcode_ctx g;
        struct ncp_diag d;
        memset(&g, 0, sizeof g);
        g.acfg.tool_table_path = "rt-config/tools.tbl";
        if (ncp_source_open(&g.src, progs[i], &d) != NCP_OK) {
            print_message("skipping %s (run from the source tree)\n", progs[i]);
            continue;
        }
        FILE *f = tmpfile();
        struct ncp_nck_opts o = { .cfg = &cfg, .interpret = gcode_run, .interp_ctx = &g,
                                  .virtual_clock = 1, .feed_override = 1.0, .trace = f };
        struct ncp_nck_result res;
        int rc = ncp_nck_run(&o, &res);
        size_t n;
        struct row *r = read_trace(f, &n);
        struct worst w = check_limits(r, n, &cfg);
        double jerk = profile == NCP_PROFILE_SCURVE ? w.jerk : 0;
        if (rc != 0 || w.vel > 1 + 1e-9 || w.acc > 1 + 1e-9 || jerk > 1 + 1e-9)
            fail_msg("%s: rc %d vel %.4f acc %.4f jerk %.4f (line %u)", progs[i], rc, w.vel,
                     w.acc, w.jerk, w.jerk_line);
        free(r);
        fclose(f);
        ncp_source_close(&g.src);
    }
}

static void test_scurve_programs(void **state)
{
    (void)state;
    check_bundled_programs(NCP_PROFILE_SCURVE);
}

static void test_trapezoid_programs(void **state)
{
    (void)state;
    check_bundled_programs(NCP_PROFILE_TRAPEZOID);
}

/* ---- live feed override and feed hold ------------------------------------------ */

struct live {
    struct ncp_nck_ctl ctl;
    double at_s[4];        /* machine times of the actions */
    int action[4];         /* 0 override 30 %, 1 override 100 %, 2 hold, 3 resume */
    int n;
    double done_at[4];     /* machine time just after each action was issued */
};

static void *live_driver(void *arg)
{
    struct live *l = arg;
    for (int i = 0; i < l->n; i++) {
        /* the virtual clock stands still at at_s until the action is done */
        while (atomic_load(&l->ctl.now_ns) < atomic_load(&l->ctl.pause_at_ns)) {
            struct timespec ts = { 0, 20000 };
            nanosleep(&ts, NULL);
        }
        switch (l->action[i]) {
        case 0: ncp_nck_set_feed_override(&l->ctl, 0.3); break;
        case 1: ncp_nck_set_feed_override(&l->ctl, 1.0); break;
        case 2: ncp_nck_feed_hold(&l->ctl, 1); break;
        default: ncp_nck_feed_hold(&l->ctl, 0); break;
        }
        l->done_at[i] = (double)atomic_load(&l->ctl.now_ns) * 1e-9;
        atomic_store(&l->ctl.pause_at_ns,
                     i + 1 < l->n ? (int64_t)llround(l->at_s[i + 1] * 1e9) : INT64_MAX);
    }
    return NULL;
}

static struct row *run_live(const char *text, const struct ncp_machine_cfg *cfg, struct live *l,
                            size_t *n)
{
    struct gcode_ctx g;
    struct ncp_diag d;
    memset(&g, 0, sizeof g);
    assert_int_equal(ncp_source_from_memory(&g.src, text, strlen(text), "t.ngc", &d), NCP_OK);
    FILE *f = tmpfile();
    ncp_nck_ctl_init(&l->ctl, 1.0);
    atomic_store(&l->ctl.pause_at_ns, (int64_t)llround(l->at_s[0] * 1e9));
    struct ncp_nck_opts o = { .cfg = cfg, .interpret = gcode_run, .interp_ctx = &g,
                              .virtual_clock = 1, .feed_override = 1.0, .trace = f,
                              .ctl = &l->ctl };
    pthread_t th;
    assert_int_equal(pthread_create(&th, NULL, live_driver, l), 0);
    struct ncp_nck_result res;
    assert_int_equal(ncp_nck_run(&o, &res), 0);
    pthread_join(th, NULL);
    struct row *r = read_trace(f, n);
    fclose(f);
    ncp_source_close(&g.src);
    return r;
}

static void test_live_override_keeps_limits(void **state)
{
    (void)state;
    struct ncp_machine_cfg cfg;
    ncp_machine_cfg_default(&cfg);
    struct live l = { .at_s = { 0.9, 1.6 }, .action = { 0, 1 }, .n = 2 };
    size_t n;
    struct row *r = run_live(corners_prog, &cfg, &l, &n);
    struct worst w = check_limits(r, n, &cfg);
    if (w.vel > 1 + 1e-9 || w.acc > 1 + 1e-9)
        fail_msg("vel %.4f acc %.4f of the limits", w.vel, w.acc);
    /* between the two calls the feed really was 30 % of the planned one */
    double vmax = 0;
    for (size_t k = 0; k < n; k++)
        if (r[k].t > l.done_at[0] + 0.1 && r[k].t < l.at_s[1] && r[k].line == 4)
            vmax = fmax(vmax, r[k].v);
    assert_true(vmax > 0.9 * 0.3 * 4000 / 60.0 && vmax <= 0.3 * 4000 / 60.0 + 1e-6);
    assert_true(r[n - 1].cmd[2] == 5);  /* and the program ran to its end */
    free(r);
}

static void test_live_hold_stops_within_braking_distance(void **state)
{
    (void)state;
    struct ncp_machine_cfg cfg;
    ncp_machine_cfg_default(&cfg);
    struct live l = { .at_s = { 0.5, 1.5 }, .action = { 2, 3 }, .n = 2 };
    size_t n;
    struct row *r = run_live("G21 G90 G1 X300 F6000\nM2\n", &cfg, &l, &n);
    struct worst w = check_limits(r, n, &cfg);
    assert_true(w.vel <= 1 + 1e-9 && w.acc <= 1 + 1e-9);
    /* the hold took effect by done_at[0]: from there to the stop at most the
     * braking distance at the position loop's deceleration (half the weakest
     * axis) plus a period of travel */
    size_t k0 = 0, k1;
    while (k0 < n && r[k0].t < l.done_at[0])
        k0++;
    assert_true(k0 < n && l.done_at[0] < l.at_s[1]);
    for (k1 = k0; k1 < n && r[k1].v > 0; k1++)
        ;
    assert_true(k1 < n && r[k1].t < l.at_s[1]);
    double v = 100, brake = v * v / (2 * 0.5 * cfg.axis[0].max_acc);
    assert_true(r[k1].cmd[0] - r[k0].cmd[0] <= brake + v * cfg.servo_period);
    /* it stays put until the resume, then finishes the line */
    for (size_t k = k1; k < n && r[k].t < l.at_s[1]; k++)
        assert_true(r[k].cmd[0] == r[k1].cmd[0]);
    assert_true(r[n - 1].cmd[0] == 300);
    free(r);
}

/* ---- S-curve: jerk-limited hold, resume and override steps ---------------------------- */

static void assert_within(const struct worst *w, int jerk, const char *what)
{
    if (w->vel > 1 + 1e-9 || w->acc > 1 + 1e-9 || (jerk && w->jerk > 1 + 1e-9))
        fail_msg("%s: vel %.4f acc %.4f jerk %.4f (line %u) of the limits", what, w->vel,
                 w->acc, w->jerk, w->jerk_line);
}

/* Distance a jerk-limited stop from v takes at deceleration a and jerk j. */
static double scurve_brake(double v, double a, double j)
{
    return v > a * a / j ? 0.5 * v * (v / a + a / j) : v * sqrt(v / j);
}

static void test_scurve_hold_resume_keeps_jerk(void **state)
{
    (void)state;
    struct ncp_machine_cfg cfg;
    scurve_cfg(&cfg);
    struct live l = { .at_s = { 0.5, 1.5 }, .action = { 2, 3 }, .n = 2 };
    size_t n;
    struct row *r = run_live("G21 G90 G1 X300 F6000\nM2\n", &cfg, &l, &n);
    struct worst w = check_limits(r, n, &cfg);
    assert_within(&w, 1, "hold and resume on a line");
    /* the hold took effect by done_at[0]: from there to the stop at most the
     * jerk-limited braking distance of the position loop's rate change
     * (src/rt/scaler.c): path jerk a quarter of the weakest axis's, path
     * deceleration half the weakest axis's but at most v * rd_cap, rd_cap =
     * min(MAX_JERK / MAX_ACCELERATION) / 12; plus a period of travel */
    size_t k0 = 0, k1;
    while (k0 < n && r[k0].t < l.done_at[0])
        k0++;
    for (k1 = k0; k1 < n && r[k1].v > 0; k1++)
        ;
    assert_true(k1 < n && r[k1].t < l.at_s[1]);
    double v = 100, rd_cap = 50000.0 / 1000 / 12;
    double brake = scurve_brake(v, fmin(0.5 * 1000, rd_cap * v), 0.25 * 50000);
    double went = r[k1].cmd[0] - r[k0].cmd[0];
    if (went > brake + v * cfg.servo_period)
        fail_msg("hold took %.4f mm, the S-curve braking distance is %.4f mm", went, brake);
    assert_true(went > 0.9 * brake);  /* and it does brake that hard */
    for (size_t k = k1; k < n && r[k].t < l.at_s[1]; k++)
        assert_true(r[k].cmd[0] == r[k1].cmd[0]);
    assert_true(r[n - 1].cmd[0] == 300);
    free(r);
}

static void test_scurve_override_steps_keep_jerk(void **state)
{
    (void)state;
    struct ncp_machine_cfg cfg;
    scurve_cfg(&cfg);
    struct live l = { .at_s = { 0.9, 1.6 }, .action = { 0, 1 }, .n = 2 };
    size_t n;
    struct row *r = run_live(corners_prog, &cfg, &l, &n);
    struct worst w = check_limits(r, n, &cfg);
    assert_within(&w, 1, "override 30 % and back");
    double vmax = 0;
    for (size_t k = 0; k < n; k++)
        if (r[k].t > l.done_at[0] + 0.2 && r[k].t < l.at_s[1] && r[k].line == 4)
            vmax = fmax(vmax, r[k].v);
    assert_true(vmax > 0.9 * 0.3 * 4000 / 60.0 && vmax <= 0.3 * 4000 / 60.0 + 1e-6);
    assert_true(r[n - 1].cmd[2] == 5);
    free(r);
}

/* Holds that come while the path turns: in a G64 corner, on an arc, in a helix. */
static void test_scurve_holds_on_curves_keep_jerk(void **state)
{
    (void)state;
    static const double at[][4] = { { 1.05, 1.6, 2.3, 2.9 }, { 1.9, 2.4, 3.4, 3.9 } };
    for (size_t i = 0; i < sizeof at / sizeof at[0]; i++) {
        struct ncp_machine_cfg cfg;
        scurve_cfg(&cfg);
        struct live l = { .at_s = { at[i][0], at[i][1], at[i][2], at[i][3] },
                          .action = { 2, 3, 2, 3 }, .n = 4 };
        size_t n;
        struct row *r = run_live(corners_prog, &cfg, &l, &n);
        struct worst w = check_limits(r, n, &cfg);
        assert_within(&w, 1, i ? "hold on the arcs" : "hold in the corners");
        assert_true(r[n - 1].cmd[2] == 5);
        free(r);
    }
}

/* The same with fine interpolation (rough period 4 servo periods): holds and
 * override steps on the corner program keep velocity, acceleration and jerk. */
static void test_scurve_fine_ipo_holds_keep_jerk(void **state)
{
    (void)state;
    struct ncp_machine_cfg cfg;
    scurve_cfg(&cfg);
    cfg.planning_period = 4 * cfg.servo_period;
    struct live l = { .at_s = { 0.6, 1.2, 1.9, 2.6 }, .action = { 2, 3, 0, 1 }, .n = 4 };
    size_t n;
    struct row *r = run_live(corners_prog, &cfg, &l, &n);
    struct worst w = check_limits(r, n, &cfg);
    assert_within(&w, 1, "fine interpolation, hold, resume, override 30 % and back");
    int held = 0;
    for (size_t k = 0; k < n; k++)
        held |= r[k].t > l.done_at[0] && r[k].t < l.at_s[1] && r[k].v == 0;
    assert_true(held);
    assert_true(r[n - 1].cmd[2] == 5);
    free(r);
}

/* ---- underrun: braking along the path keeps the acceleration limit ------------------ */

/* A stream along X that cruises at 100 mm/s and then brakes at the axis's full
 * limit; the scaler is told to stop (an underrun in the making) right when the
 * stream starts braking. Returns the worst |second difference| / T^2. */
static double underrun_worst_acc(int governed)
{
    const double T = 1e-3, v = 100, a = 2000;
    struct ncp_spsc ring;
    assert_int_equal(ncp_spsc_init(&ring, sizeof(struct ncp_setpoint), 1024), 0);
    double zero[NCP_AXES] = { 0 }, x = 0, vel = v;
    struct ncp_scaler s;
    ncp_scaler_init(&s, zero, 0.5 * a, T);
    if (governed)
        for (int j = 0; j < NCP_AXES; j++)
            s.amax[j] = a;
    for (int k = 0; k < 400; k++) {
        struct ncp_setpoint sp;
        memset(&sp, 0, sizeof sp);
        if (k >= 100)
            vel = fmax(0, vel - a * T);
        x += vel * T;
        sp.pos[0] = x;
        sp.v = vel;
        sp.dir[0] = 1;
        assert_int_equal(ncp_spsc_push(&ring, &sp), 0);
    }
    double p[3] = { 0, 0, 0 }, worst = 0;
    for (int k = 0; k < 600; k++) {
        struct ncp_setpoint out;
        ncp_scaler_step(&s, k < 100 ? 1.0 : 0.0, &ring, &out);
        p[0] = p[1];
        p[1] = p[2];
        p[2] = out.pos[0];
        if (k >= 2)
            worst = fmax(worst, fabs(p[2] - 2 * p[1] + p[0]) / (T * T));
        assert_true(out.pos[0] <= x + 1e-12);
    }
    ncp_spsc_destroy(&ring);
    return worst;
}

static void test_underrun_braking_keeps_accel_limit(void **state)
{
    (void)state;
    /* without the per-axis check the two decelerations add up (the flaw) */
    assert_true(underrun_worst_acc(0) > 1.3 * 2000);
    assert_true(underrun_worst_acc(1) <= 2000 * (1 + 1e-9));
}

/* The same with the S-curve: a stream that cruises along (3,4)/5 at 100 mm/s and
 * then brakes jerk-limited (path jerk 25000, deceleration 1000); the scaler,
 * given the machine's S-curve limits, is told to stop just before the stream
 * starts braking, and to go on later. Every axis keeps its acceleration and
 * jerk (second and third differences), and the output stays on the path. */
static double underrun_scurve_worst(int jerk_limited, double *worst_acc)
{
    struct ncp_machine_cfg cfg;
    scurve_cfg(&cfg);
    const double T = cfg.servo_period, J = 25000, A = 1000;
    struct ncp_spsc ring;
    assert_int_equal(ncp_spsc_init(&ring, sizeof(struct ncp_setpoint), 2048), 0);
    double zero[NCP_AXES] = { 0 }, s = 0, vel = 100, acc = 0;
    struct ncp_scaler sc;
    ncp_scaler_init(&sc, zero, 0.5 * 1000, T);
    ncp_scaler_limits(&sc, &cfg);
    if (!jerk_limited) {  /* linear rate ramps, as with the trapezoid */
        sc.jerk = 0;
        for (int j = 0; j < NCP_AXES; j++)
            sc.jmax[j] = INFINITY;
    }
    /* jerk -J until the deceleration is A, then hold it, then +J to rest:
     * each period integrated exactly, as the planner's samples are */
    const double t_ramp = A / J, t_hold = vel / A - t_ramp;
    for (int k = 0; k < 1200; k++) {
        struct ncp_setpoint sp;
        memset(&sp, 0, sizeof sp);
        double t = (k - 150) * T, jerk = 0;
        if (t >= 0 && t < t_ramp)
            jerk = -J;
        else if (t >= t_ramp + t_hold && t < 2 * t_ramp + t_hold)
            jerk = J;
        s += vel * T + acc * T * T / 2 + jerk * T * T * T / 6;
        vel = fmax(0, vel + acc * T + jerk * T * T / 2);
        acc += jerk * T;
        if (t >= 2 * t_ramp + t_hold)
            vel = acc = 0;
        sp.pos[0] = 0.6 * s;
        sp.pos[1] = 0.8 * s;
        sp.v = vel;
        sp.dir[0] = vel > 0 ? 0.6 : 0;
        sp.dir[1] = vel > 0 ? 0.8 : 0;
        assert_int_equal(ncp_spsc_push(&ring, &sp), 0);
    }
    double p[4][2] = { { 0 } }, wa = 0, wj = 0;
    int stopped = 0;
    for (int k = 0; k < 2400; k++) {
        struct ncp_setpoint out;
        ncp_scaler_step(&sc, k < 120 || k > 700 ? 1.0 : 0.0, &ring, &out);
        memmove(p[1], p[0], 3 * sizeof p[0]);
        p[0][0] = out.pos[0];
        p[0][1] = out.pos[1];
        assert_true(fabs(out.pos[1] - out.pos[0] * 4.0 / 3.0) < 1e-9);
        stopped |= k > 120 && k < 700 && out.v == 0;
        for (int j = 0; j < 2 && k >= 3; j++) {
            double a2 = fabs(p[0][j] - 2 * p[1][j] + p[2][j]) / (T * T);
            double j3 = fabs(p[0][j] - 3 * p[1][j] + 3 * p[2][j] - p[3][j]) / (T * T * T);
            wa = fmax(wa, a2 / cfg.axis[j].max_acc);
            wj = fmax(wj, j3 / cfg.axis[j].max_jerk);
        }
    }
    assert_true(stopped);
    assert_true(p[0][0] == 0.6 * s);  /* and then ran the stream to its end */
    ncp_spsc_destroy(&ring);
    *worst_acc = wa;
    return wj;
}

static void test_underrun_scurve_keeps_jerk(void **state)
{
    (void)state;
    double wa, wj = underrun_scurve_worst(1, &wa);
    if (wa > 1 + 1e-9 || wj > 1 + 1e-9)
        fail_msg("acceleration %.4f, jerk %.4f of the limits", wa, wj);
    /* linear rate ramps step the acceleration: what the S-curve rate avoids */
    wj = underrun_scurve_worst(0, &wa);
    if (!(wj > 2))
        fail_msg("linear ramps: jerk %.4f of the limit", wj);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_scurve_trace_within_jerk),
        cmocka_unit_test(test_trapezoid_is_not_jerk_limited),
        cmocka_unit_test(test_scurve_long_line_time),
        cmocka_unit_test(test_scurve_programs),
        cmocka_unit_test(test_trapezoid_programs),
        cmocka_unit_test(test_live_override_keeps_limits),
        cmocka_unit_test(test_live_hold_stops_within_braking_distance),
        cmocka_unit_test(test_underrun_braking_keeps_accel_limit),
        cmocka_unit_test(test_scurve_hold_resume_keeps_jerk),
        cmocka_unit_test(test_scurve_override_steps_keep_jerk),
        cmocka_unit_test(test_scurve_holds_on_curves_keep_jerk),
        cmocka_unit_test(test_scurve_fine_ipo_holds_keep_jerk),
        cmocka_unit_test(test_underrun_scurve_keeps_jerk),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
