/* Real-time support and the NCK runtime on the virtual clock: SPSC ring, the
 * periodic loop, the simulated plant, and whole runs from hand-built command
 * slots (trace checks, faults, soft limits, program errors). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "trace_rows.h"

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ncpar/backend.h"
#include "ncpar/feeder.h"
#include "ncpar/motion.h"
#include "ncpar/pipeline.h"
#include "ncpar/nck.h"
#include "gcode_src.h"

/* ---- SPSC ring ----------------------------------------------------------------- */

static void test_spsc_basic(void **state)
{
    (void)state;
    struct ncp_spsc r;
    assert_int_equal(ncp_spsc_init(&r, sizeof(int), 5), 0);
    assert_int_equal(ncp_spsc_capacity(&r), 8);
    int v, i;
    for (i = 0; i < 8; i++)
        assert_int_equal(ncp_spsc_push(&r, &i), 0);
    assert_int_equal(ncp_spsc_push(&r, &i), -1);
    for (i = 0; i < 8; i++) {
        assert_int_equal(ncp_spsc_pop(&r, &v), 0);
        assert_int_equal(v, i);
    }
    assert_int_equal(ncp_spsc_pop(&r, &v), -1);
    ncp_spsc_destroy(&r);
}

#define XFER 200000
static void *producer(void *arg)
{
    struct ncp_spsc *r = arg;
    for (uint32_t i = 0; i < XFER; i++)
        while (ncp_spsc_push(r, &i) != 0)
            ;
    return NULL;
}

static void test_spsc_threads(void **state)
{
    (void)state;
    struct ncp_spsc r;
    assert_int_equal(ncp_spsc_init(&r, sizeof(uint32_t), 64), 0);
    pthread_t t;
    pthread_create(&t, NULL, producer, &r);
    for (uint32_t want = 0; want < XFER;) {
        uint32_t v;
        if (ncp_spsc_pop(&r, &v) == 0) {
            assert_int_equal(v, want);
            want++;
        }
    }
    pthread_join(t, NULL);
    ncp_spsc_destroy(&r);
}

/* ---- periodic loop ---------------------------------------------------------------- */

struct count_ctx {
    int n, limit;
    int64_t last;
    int bad;
};

static int count_cycle(void *ctx, int64_t now)
{
    struct count_ctx *c = ctx;
    if (c->n && now - c->last < 1000000)
        c->bad++;
    c->last = now;
    return ++c->n >= c->limit ? NCP_RT_STOP : NCP_RT_CONTINUE;
}

static void run_loop(int virt, int cycles, struct ncp_rt_loop *l, struct count_ctx *c)
{
    memset(l, 0, sizeof *l);
    memset(c, 0, sizeof *c);
    c->limit = cycles;
    l->cfg = (struct ncp_rt_loop_cfg){ 1000000, 90, -1, virt, 0 };
    l->cycle = count_cycle;
    l->ctx = c;
    assert_int_equal(ncp_rt_loop_start(l), 0);
    ncp_rt_loop_join(l);
}

static void test_loop_virtual(void **state)
{
    (void)state;
    struct ncp_rt_loop l;
    struct count_ctx c;
    run_loop(1, 100000, &l, &c);
    assert_int_equal(c.n, 100000);
    assert_int_equal(c.bad, 0);
    assert_int_equal(c.last, (int64_t)99999 * 1000000);
    assert_int_equal(l.stats.cycles, 100000);
    assert_int_equal(l.stats.misses, 0);
    assert_int_equal(l.fifo, 0);
}

static void test_loop_real(void **state)
{
    (void)state;
    struct ncp_rt_loop l;
    struct count_ctx c;
    run_loop(0, 200, &l, &c);
    assert_int_equal(c.n, 200);
    assert_int_equal(c.bad, 0);  /* never two cycles closer than a period */
    assert_true(l.stats.cycles == 200);
    assert_true(l.stats.lat_min_ns <= l.stats.lat_max_ns);
    uint64_t sum = l.stats.overflow;
    for (int i = 0; i < NCP_RT_HIST_BINS; i++)
        sum += l.stats.hist[i];
    assert_int_equal(sum, 200);
    /* either FIFO, or a warning says why not */
    assert_true(l.fifo || l.warning[0]);
}

/* ---- simulated plant ----------------------------------------------------------------- */

static void test_sim_steady_following(void **state)
{
    (void)state;
    struct ncp_machine_cfg cfg;
    ncp_machine_cfg_default(&cfg);
    struct ncp_sim s;
    double zero[NCP_AXES] = { 0 };
    ncp_sim_init(&s, &cfg, zero);
    double v = 1000.0 / 60.0, T = cfg.servo_period, act[NCP_AXES], worst = 0;
    /* a 1000 mm/min line from rest with a 2000 mm/s^2 ramp */
    double x = 0, vel = 0;
    for (int k = 0; k < 3000; k++) {
        double cmd[NCP_AXES] = { x, 0, 0 };
        double nv = fmin(v, vel + 2000 * T);
        double nx = x + 0.5 * (vel + nv) * T;
        double next[NCP_AXES] = { nx, 0, 0 };
        ncp_sim_step(&s, cmd, next, act);
        if (k > 100)
            worst = fmax(worst, fabs(cmd[0] - act[0]));
        x = nx;
        vel = nv;
    }
    assert_true(worst < 0.01);
    /* and 1 m/s as well, on an axis made for that speed and ramped within
     * its acceleration, as the planner would (the drive saturates at a
     * multiple of the axis's limits, so a step to 1 m/s is no steady line) */
    cfg.axis[0].max_vel = 1000.0;
    ncp_machine_joints_from_axes(&cfg);
    ncp_sim_init(&s, &cfg, zero);
    x = 0;
    vel = 0;
    worst = 0;
    for (int k = 0; k < 3000; k++) {
        double cmd[NCP_AXES] = { x, 0, 0 };
        double nv = fmin(1000.0, vel + 2000 * T);
        double nx = x + 0.5 * (vel + nv) * T;
        double next[NCP_AXES] = { nx, 0, 0 };
        ncp_sim_step(&s, cmd, next, act);
        if (k > 1000)
            worst = fmax(worst, fabs(cmd[0] - act[0]));
        x = nx;
        vel = nv;
    }
    assert_true(worst < 0.01);
}

/* The worst of a period's travel over v_peak T, the speed over v_peak and a
 * period's change of speed over a_peak T, on X and Y, along a planned ramp
 * (X out, Y back) that a setpoint jump interrupts at period 300, as a lost
 * or late setpoint does; timed: under io latency and late sampling. */
static double drive_worst(const struct ncp_machine_cfg *cfg, int timed, double jump)
{
    struct ncp_sim s;
    static struct ncp_sim_timed tm;
    memset(&tm, 0, sizeof tm);
    double zero[NCP_AXES] = { 0 }, act[NCP_AXES], T = cfg->servo_period;
    ncp_sim_init(&s, cfg, zero);
    const struct ncp_inject_ev ev = { .sample_s = 0.2 * T, .io_s = 0.3 * T };
    double x = 0, vel = 0, worst = 0;
    for (int k = 0; k < 600; k++) {
        double nv = fmin(1000.0 / 60.0, vel + 400 * T);
        double nx = x + 0.5 * (vel + nv) * T + (k == 300 ? jump : 0.0);
        double cmd[NCP_AXES] = { x, -x, 0 }, next[NCP_AXES] = { nx, -nx, 0 };
        struct ncp_sim_axis was[2] = { s.ax[0], s.ax[1] };
        if (timed)
            ncp_sim_step_timed(&s, &tm, &ev, cmd, next, act);
        else
            ncp_sim_step(&s, cmd, next, act);
        for (int i = 0; i < 2; i++) {
            double vp = NCP_SIM_PEAK * cfg->joint[i].max_vel;
            double ap = NCP_SIM_PEAK * cfg->joint[i].max_acc;
            worst = fmax(worst, fabs(s.ax[i].x - was[i].x) / (vp * T));
            worst = fmax(worst, fabs(s.ax[i].v) / vp);
            worst = fmax(worst, fabs(s.ax[i].v - was[i].v) / (ap * T));
        }
        x = nx;
        vel = nv;
    }
    return worst;
}

/* Every gain in its documented range ([SIM] KP .. FF2 up to 1e9) leaves the
 * axis within what its saturating drive can do in each period: KP = 1e9 once
 * threw it 30 mm in a period on a 1 um error. */
static void test_sim_drive_saturates(void **state)
{
    (void)state;
    struct ncp_machine_cfg cfg;
    ncp_machine_cfg_default(&cfg);
    cfg.axis[1].max_vel = 50.0;     /* the joints' own limits, not one for all */
    cfg.axis[1].max_acc = 500.0;
    ncp_machine_joints_from_axes(&cfg);
    /* the shipped gains on a planned path stay far from the peak */
    assert_true(drive_worst(&cfg, 0, 0.0) < 1.5 / NCP_SIM_PEAK);
    assert_true(drive_worst(&cfg, 1, 0.0) < 1.5 / NCP_SIM_PEAK);
    for (int g = 0; g < 5; g++) {
        struct ncp_machine_cfg c = cfg;
        double *gain[5] = { &c.kp, &c.ki, &c.kd, &c.ff1, &c.ff2 };
        *gain[g] = 1e9;
        for (int timed = 0; timed < 2; timed++) {
            double w = drive_worst(&c, timed, 5.0);
            if (!(w <= 1.0 + 1e-9))
                print_error("gain %d = 1e9, %s step: %.3g times the drive's peak\n", g,
                            timed ? "timed" : "plain", w);
            assert_true(w <= 1.0 + 1e-9);
        }
    }
}

/* ---- underrun: slow down along the path and resume ------------------------------ */

static void test_scaler_slows_along_path(void **state)
{
    (void)state;
    const double T = 1e-3, v = 100, decel = 1000;
    struct ncp_spsc ring;
    assert_int_equal(ncp_spsc_init(&ring, sizeof(struct ncp_setpoint), 4096), 0);
    struct ncp_scaler s;
    double zero[NCP_AXES] = { 0 };
    ncp_scaler_init(&s, zero, decel, T);
    /* a line at 100 mm/s along (3,4,0)/5, already at speed */
    for (int k = 1; k <= 2000; k++) {
        struct ncp_setpoint sp;
        memset(&sp, 0, sizeof sp);
        sp.pos[0] = 0.6 * v * T * k;
        sp.pos[1] = 0.8 * v * T * k;
        sp.v = v;
        sp.dir[0] = 0.6;
        sp.dir[1] = 0.8;
        assert_int_equal(ncp_spsc_push(&ring, &sp), 0);
    }
    double prev[2][2] = { { 0, 0 }, { 0, 0 } };
    int stopped_at = -1;
    for (int k = 0; k < 1500; k++) {
        double target = k < 200 ? 1 : k < 600 ? 0 : 1;
        struct ncp_setpoint out;
        assert_int_equal(ncp_scaler_step(&s, target, &ring, &out), 0);
        /* on the path: y = 4/3 x */
        assert_true(fabs(out.pos[1] - out.pos[0] * 4.0 / 3.0) < 1e-9);
        if (k >= 2) {
            double vel = hypot(out.pos[0] - prev[1][0], out.pos[1] - prev[1][1]) / T;
            double vel0 = hypot(prev[1][0] - prev[0][0], prev[1][1] - prev[0][1]) / T;
            assert_true(vel <= v * (1 + 1e-9));
            assert_true(fabs(vel - vel0) <= decel * T * (1 + 1e-6) + 1e-9);  /* no jump */
            if (stopped_at < 0 && k > 200 && vel == 0)
                stopped_at = k;
        }
        prev[0][0] = prev[1][0];
        prev[0][1] = prev[1][1];
        prev[1][0] = out.pos[0];
        prev[1][1] = out.pos[1];
        if (k == 599)
            assert_true(out.v == 0);
    }
    /* stopped within v / decel (+ a period), then came back to full speed */
    assert_true(stopped_at > 200 && stopped_at <= 200 + (int)(v / decel / T) + 2);
    assert_true(s.r == 1);
    /* a ring that runs dry in motion holds at the last sample and says so */
    struct ncp_setpoint out;
    int dry = 0;
    for (int k = 0; k < 2000 && !dry; k++)
        dry = ncp_scaler_step(&s, 1, &ring, &out) != 0;
    assert_true(dry);
    assert_true(out.pos[0] == 0.6 * v * T * 2000);
    ncp_spsc_destroy(&ring);
}

/* ---- whole runs from hand-built slots -------------------------------------------------- */

struct prog {
    struct ncp_cmd *cmds;
    size_t n;
    size_t error_at;      /* slot index that carries an error, or SIZE_MAX */
    /* the error only in this run of the program (1: the check before
     * motion, 2: the run itself), 0: in every run */
    unsigned error_in_run, runs;
};

static int prog_run(void *ctx, const struct ncp_output *out, struct ncp_diag *d)
{
    struct prog *p = ctx;
    p->runs++;
    for (size_t i = 0; i < p->n; i++) {
        if (i == p->error_at && (!p->error_in_run || p->error_in_run == p->runs))
            return ncp_diag_set(d, NCP_ERR_SEMANTIC, p->cmds[i].line, 3, "bad word");
        if (out->emit(out->ctx, &p->cmds[i]))
            break;
    }
    return NCP_OK;
}

static struct ncp_cmd *add(struct prog *p, uint32_t line)
{
    p->cmds = realloc(p->cmds, (p->n + 1) * sizeof *p->cmds);
    assert_non_null(p->cmds);
    struct ncp_cmd *c = &p->cmds[p->n++];
    memset(c, 0, sizeof *c);
    c->line = line;
    return c;
}

static void op(struct ncp_cmd *c, int kind, double a, double b, double z)
{
    struct ncp_canon *o = &c->ops[c->n_ops++];
    o->kind = (uint16_t)kind; /* the first three numbers of any kind, by position */
    o->raw.d[0] = a;
    o->raw.d[1] = b;
    o->raw.d[2] = z;
}

static void arc(struct ncp_cmd *c, double x, double y, double cx, double cy, int rot)
{
    struct ncp_canon *o = &c->ops[c->n_ops++];
    o->kind = NCP_C_ARC_FEED;
    o->arc_feed.first_end = x;
    o->arc_feed.second_end = y;
    o->arc_feed.first_axis = cx;
    o->arc_feed.second_axis = cy;
    o->arc_feed.rotation = rot;
}

static int run(struct prog *p, struct ncp_machine_cfg *cfg, FILE *trace,
               struct ncp_nck_result *res)
{
    struct ncp_nck_opts o = { .cfg = cfg, .interpret = prog_run, .interp_ctx = p,
                              .virtual_clock = 1, .feed_override = 1.0, .trace = trace };
    return ncp_nck_run(&o, res);
}

static void test_run_long_line_time(void **state)
{
    (void)state;
    struct ncp_machine_cfg cfg;
    ncp_machine_cfg_default(&cfg);
    struct prog p = { NULL, 0, SIZE_MAX, 0, 0 };
    struct ncp_cmd *c = add(&p, 1);
    op(c, NCP_C_SET_FEED_RATE, 9000, 0, 0);
    op(c, NCP_C_STRAIGHT_FEED, 300, 200, 0);
    struct ncp_nck_result res;
    FILE *f = tmpfile();
    assert_int_equal(run(&p, &cfg, f, &res), 0);
    /* 150 mm/s along (300,200): the X share caps nothing (< 200 mm/s), a = 2000 */
    double L = hypot(300, 200), v = 150, a = cfg.axis[0].max_acc / (300 / L);
    a = fmin(a, cfg.axis[1].max_acc / (200 / L));
    double expect = L / v + v / a;
    assert_true(fabs(res.program_time - expect) / expect < 0.01);
    assert_true(fabs(res.path_length - L) < 1e-9);
    assert_true(res.ferr_max < 0.05);
    size_t n;
    struct row *r = read_trace(f, &n);
    assert_true(n > 1000);
    /* the machine arrives and settles */
    assert_true(r[n - 1].cmd[0] == 300 && r[n - 1].cmd[1] == 200);
    assert_true(fabs(r[n - 1].act[0] - 300) < 0.001);
    free(r);
    fclose(f);
    free(p.cmds);
}

static void test_run_arc_radius_in_trace(void **state)
{
    (void)state;
    struct ncp_machine_cfg cfg;
    ncp_machine_cfg_default(&cfg);
    struct prog p = { NULL, 0, SIZE_MAX, 0, 0 };
    struct ncp_cmd *c = add(&p, 1);
    op(c, NCP_C_SET_FEED_RATE, 6000, 0, 0);
    op(c, NCP_C_STRAIGHT_FEED, 40, 0, 0);
    c = add(&p, 2);
    arc(c, 40, 0, 0, 0, 1);  /* full circle r = 40 */
    struct ncp_nck_result res;
    FILE *f = tmpfile();
    assert_int_equal(run(&p, &cfg, f, &res), 0);
    size_t n, on = 0;
    struct row *r = read_trace(f, &n);
    double T = cfg.servo_period;
    for (size_t k = 0; k < n; k++) {
        if (r[k].line != 2)
            continue;
        on++;
        /* the trace prints 6 decimals: 1 um leaves room for that rounding */
        assert_true(fabs(hypot(r[k].cmd[0], r[k].cmd[1]) - 40) < 1e-6 + 1e-6);
        if (k >= 2) {
            for (int j = 0; j < 2; j++) {
                double acc = (r[k].cmd[j] - 2 * r[k - 1].cmd[j] + r[k - 2].cmd[j]) / (T * T);
                /* 2e-6 mm of print rounding over T^2 */
                assert_true(fabs(acc) <= cfg.axis[j].max_acc + 2e-6 / (T * T));
            }
        }
    }
    assert_true(on > 1000);
    assert_true(res.contour_max < 0.02);
    free(r);
    fclose(f);
    free(p.cmds);
}

static void test_run_following_fault(void **state)
{
    (void)state;
    struct ncp_machine_cfg cfg;
    ncp_machine_cfg_default(&cfg);
    cfg.axis[1].ferror = 0.0005;
    struct prog p = { NULL, 0, SIZE_MAX, 0, 0 };
    struct ncp_cmd *c = add(&p, 10);
    op(c, NCP_C_SET_FEED_RATE, 6000, 0, 0);
    op(c, NCP_C_STRAIGHT_FEED, 20, 0, 0);
    c = add(&p, 11);
    op(c, NCP_C_STRAIGHT_FEED, 20, 100, 0);
    struct ncp_nck_result res;
    assert_int_equal(run(&p, &cfg, NULL, &res), NCP_NCK_FAULT);
    assert_true(res.fault);
    assert_int_equal(res.fault_axis, 1);
    assert_int_equal(res.fault_line, 11);
    assert_true(res.program_time < 1.0);
    free(p.cmds);
}

static void test_run_soft_limit_before_motion(void **state)
{
    (void)state;
    struct ncp_machine_cfg cfg;
    ncp_machine_cfg_default(&cfg);
    struct prog p = { NULL, 0, SIZE_MAX, 0, 0 };
    struct ncp_cmd *c = add(&p, 1);
    op(c, NCP_C_SET_FEED_RATE, 6000, 0, 0);
    for (uint32_t i = 0; i < 500; i++) {
        c = add(&p, 2 + i);
        op(c, NCP_C_STRAIGHT_FEED, i % 2 ? 10 : 0, 0, 0);
    }
    c = add(&p, 600);
    op(c, NCP_C_STRAIGHT_TRAVERSE, 0, 0, 51);
    struct ncp_nck_result res;
    FILE *f = tmpfile();
    assert_int_equal(run(&p, &cfg, f, &res), NCP_NCK_FAULT);
    assert_true(res.limit_violation);
    assert_int_equal(res.diag.line, 600);
    fseek(f, 0, SEEK_END);
    assert_int_equal(ftell(f), 0);  /* not a single servo cycle ran */
    fclose(f);
    free(p.cmds);
}

static void test_run_program_error_stops_cleanly(void **state)
{
    (void)state;
    struct ncp_machine_cfg cfg;
    ncp_machine_cfg_default(&cfg);
    struct prog p = { NULL, 0, 3, 0, 0 };
    struct ncp_cmd *c = add(&p, 1);
    op(c, NCP_C_SET_FEED_RATE, 6000, 0, 0);
    op(c, NCP_C_STRAIGHT_FEED, 10, 0, 0);
    c = add(&p, 2);
    op(c, NCP_C_STRAIGHT_FEED, 10, 10, 0);
    c = add(&p, 3);
    op(c, NCP_C_STRAIGHT_FEED, 10, 10, -5);
    c = add(&p, 4);
    op(c, NCP_C_STRAIGHT_FEED, 50, 50, -5);
    struct ncp_nck_result res;
    /* found by the check before motion: refused, not a single cycle ran */
    FILE *f = tmpfile();
    assert_int_equal(run(&p, &cfg, f, &res), NCP_NCK_PROGRAM_ERROR);
    assert_true(res.refused);
    assert_int_equal(res.diag.line, 4);
    fseek(f, 0, SEEK_END);
    assert_int_equal(ftell(f), 0);
    fclose(f);
    /* an error only the run meets (a check cut short by --for) */
    p.error_in_run = 2;
    p.runs = 0;
    f = tmpfile();
    assert_int_equal(run(&p, &cfg, f, &res), NCP_NCK_PROGRAM_ERROR);
    assert_false(res.refused);
    assert_int_equal(res.diag.line, 4);
    size_t n;
    struct row *r = read_trace(f, &n);
    /* last good block reached at rest, and nothing of line 4 moved */
    assert_true(r[n - 1].cmd[2] == -5 && r[n - 1].cmd[0] == 10 && r[n - 1].v == 0);
    for (size_t k = 0; k < n; k++)
        assert_true(r[k].line != 4);
    free(r);
    fclose(f);
    free(p.cmds);
}

/* --for is a feed hold: the machine brakes along the path within the braking
 * distance (half the weakest axis's acceleration) and stays on the path. */
static void test_run_for_seconds(void **state)
{
    (void)state;
    struct ncp_machine_cfg cfg;
    ncp_machine_cfg_default(&cfg);
    struct prog p = { NULL, 0, SIZE_MAX, 0, 0 };
    struct ncp_cmd *c = add(&p, 1);
    op(c, NCP_C_SET_FEED_RATE, 6000, 0, 0);
    op(c, NCP_C_STRAIGHT_FEED, 300, 0, 0);
    FILE *f = tmpfile();
    struct ncp_nck_opts o = { .cfg = &cfg, .interpret = prog_run, .interp_ctx = &p,
                              .virtual_clock = 1, .feed_override = 1.0, .for_s = 0.5,
                              .trace = f };
    struct ncp_nck_result res;
    assert_int_equal(ncp_nck_run(&o, &res), 0);
    assert_true(res.for_expired);
    size_t n, k0 = 0;
    struct row *r = read_trace(f, &n);
    while (k0 < n && r[k0].t < 0.5)
        k0++;
    assert_true(k0 < n && fabs(r[k0].v - 100) < 1e-9);
    double decel = 0.5 * cfg.axis[0].max_acc, brake = 100.0 * 100.0 / (2 * decel);
    double moved = r[n - 1].cmd[0] - r[k0].cmd[0];
    assert_true(moved <= brake + 100 * cfg.servo_period);
    assert_true(moved >= 0.9 * brake);
    assert_true(r[n - 1].v == 0 && r[n - 1].cmd[0] < 300);
    assert_true(fabs(res.path_length - r[n - 1].cmd[0]) < 1e-6);
    free(r);
    fclose(f);
    free(p.cmds);
}

/* ---- through the real interpreter ---------------------------------------------- */

static void test_run_gcode_g61_corners(void **state)
{
    (void)state;
    static const char prog[] = "G21 G90 G17 G61.1\n"
                               "G0 X10 Y5 Z2\n"
                               "G1 Z-1 F600\n"
                               "G1 X50 F3000\n"
                               "G2 X60 Y15 I0 J10\n"
                               "G1 Y40\n"
                               "G20 G1 X1\n"
                               "M2\n";
    struct ncp_machine_cfg cfg;
    ncp_machine_cfg_default(&cfg);
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
    for (size_t k = 0; k < n; k++)
        if (r[k].line == 5)
            assert_true(fabs(hypot(r[k].cmd[0] - 50, r[k].cmd[1] - 15) - 10) < 2e-6);
    free(r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_spsc_basic),
        cmocka_unit_test(test_spsc_threads),
        cmocka_unit_test(test_loop_virtual),
        cmocka_unit_test(test_loop_real),
        cmocka_unit_test(test_sim_steady_following),
        cmocka_unit_test(test_sim_drive_saturates),
        cmocka_unit_test(test_scaler_slows_along_path),
        cmocka_unit_test(test_run_long_line_time),
        cmocka_unit_test(test_run_arc_radius_in_trace),
        cmocka_unit_test(test_run_following_fault),
        cmocka_unit_test(test_run_soft_limit_before_motion),
        cmocka_unit_test(test_run_program_error_stops_cleanly),
        cmocka_unit_test(test_run_for_seconds),
        cmocka_unit_test(test_run_gcode_g61_corners),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
