/* The serving NCK driven in-process through its commands, on the virtual
 * clock: homing, programs, pause and resume along the path, stop, single
 * block, run from a line, MDI with the live modal state, jogs, E-stop and
 * the commands each state refuses. (tests/service drives the same NCK over
 * LCM with cnc-ctl.) */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "trace_rows.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "ncpar/nck.h"

struct svc {
    struct ncp_machine_cfg cfg;
    struct ncp_nck *nck;
    FILE *trace;
    char prog[64];
};

static void nap_ms(int ms)
{
    struct timespec ts = { 0, ms * 1000000L };
    nanosleep(&ts, NULL);
}

static void start_history(struct svc *s, int with_trace, const char *history)
{
    memset(s, 0, sizeof *s);
    ncp_machine_cfg_default(&s->cfg);
    snprintf(s->cfg.op.history_file, sizeof s->cfg.op.history_file, "%s", history);
    s->cfg.position.priority = 0;
    s->trace = with_trace ? tmpfile() : NULL;
    struct ncp_nck_setup setup = { .cfg = &s->cfg, .virtual_clock = 1, .trace = s->trace,
                                   .mode = NCP_MODE_SERIAL, .virtual_pace = 10 };
    struct ncp_diag d;
    memset(&d, 0, sizeof d);
    s->nck = ncp_nck_new(&setup, &d);
    assert_non_null(s->nck);
}

static void start(struct svc *s, int with_trace)
{
    start_history(s, with_trace, "");
}

static void stop(struct svc *s)
{
    ncp_nck_free(s->nck);
    if (s->trace)
        fclose(s->trace);
    if (s->prog[0])
        unlink(s->prog);
}

static int cmd_now(struct svc *s, int kind, const char *text, double v0, int i0, char *why)
{
    struct ncp_nck_cmd c;
    memset(&c, 0, sizeof c);
    c.kind = kind;
    snprintf(c.text, sizeof c.text, "%s", text ? text : "");
    c.value[0] = v0;
    c.ivalue[0] = i0;
    char local[256];
    return ncp_nck_command(s->nck, &c, why ? why : local, 256);
}

static void nap_ms(int ms);

/* A pending command's answer, once there (60 s of wall time at most). */
static int answer(struct svc *s, char *why)
{
    for (int i = 0; i < 60000; i++) {
        int rc = ncp_nck_pending(s->nck, why, 256);
        if (rc != NCP_NCK_CMD_PENDING)
            return rc;
        nap_ms(1);
    }
    fail_msg("a pending command got no answer within 60 s");
    return NCP_NCK_CMD_PENDING;
}

/* A command and its answer: a load's comes once its check has ended. */
static int cmd(struct svc *s, int kind, const char *text, double v0, int i0, char *why)
{
    char local[256];
    int rc = cmd_now(s, kind, text, v0, i0, why ? why : local);
    return rc == NCP_NCK_CMD_PENDING ? answer(s, why ? why : local) : rc;
}

static int state(struct svc *s)
{
    struct ncp_nck_snapshot st;
    ncp_nck_get_status(s->nck, &st);
    return st.state;
}

/* Polls until the state is want (or 60 s of wall time). */
static void wait_state(struct svc *s, int want)
{
    for (int i = 0; i < 60000; i++) {
        ncp_nck_poll(s->nck);
        if (state(s) == want)
            return;
        nap_ms(1);
    }
    fail_msg("state %s never reached (now %s)", ncp_nck_state_name(want),
             ncp_nck_state_name(state(s)));
}

static void write_prog(struct svc *s, const char *text)
{
    snprintf(s->prog, sizeof s->prog, "/tmp/ncp-svc-%d.ngc", (int)getpid());
    FILE *f = fopen(s->prog, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

static void home_all(struct svc *s)
{
    assert_int_equal(cmd(s, NCP_CMD_HOME, "all", 0, 0, NULL), 0);
    wait_state(s, NCP_ST_IDLE);
}

static void pos(struct svc *s, double p[3])
{
    struct ncp_nck_snapshot st;
    ncp_nck_poll(s->nck);
    ncp_nck_get_status(s->nck, &st);
    memcpy(p, st.pos_cmd, 3 * sizeof p[0]);
}

static const char *square =
    "G21 G90 G64 P0.01\nG0 X0 Y0 Z5\nG1 Z-1 F600\nG1 X20 F1500\nY20\nX0\nY0\n"
    "G2 X10 Y10 I5 J5\nG0 Z5\nM2\n";

static void test_refusals(void **state_)
{
    (void)state_;
    struct svc s;
    start(&s, 0);
    char why[256];
    assert_int_equal(cmd(&s, NCP_CMD_RUN, NULL, 0, 0, why), -1);
    assert_non_null(strstr(why, "no program"));
    assert_int_equal(cmd(&s, NCP_CMD_MDI, "G0 X1", 0, 0, why), -1);
    assert_non_null(strstr(why, "not homed"));
    assert_int_equal(cmd(&s, NCP_CMD_RESUME, NULL, 0, 0, why), -1);
    assert_int_equal(cmd(&s, NCP_CMD_JOG, "Q", 0, 1, why), -1);
    assert_int_equal(cmd(&s, NCP_CMD_OVERRIDE, NULL, 150, 0, why), -1);
    write_prog(&s, "G1 X1 F100\nG1 X2 Y\nM2\n");
    assert_int_equal(cmd(&s, NCP_CMD_LOAD, s.prog, 0, 0, why), -1);
    assert_non_null(strstr(why, ":2:"));
    home_all(&s);
    write_prog(&s, "G1 X50 F600\nM2\n");
    assert_int_equal(cmd(&s, NCP_CMD_LOAD, s.prog, 0, 0, why), 0);
    assert_int_equal(cmd(&s, NCP_CMD_RUN, NULL, 0, 0, why), 0);
    assert_int_equal(cmd(&s, NCP_CMD_MDI, "G0 X1", 0, 0, why), -1);
    assert_non_null(strstr(why, "while running"));
    assert_int_equal(cmd(&s, NCP_CMD_JOG, "X", 0, 1, why), -1);
    assert_int_equal(cmd(&s, NCP_CMD_HOME, "all", 0, 0, why), -1);
    wait_state(&s, NCP_ST_IDLE);
    stop(&s);
}

static double mono_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + (double)t.tv_nsec * 1e-9;
}

/* A load's check runs beside the caller: the NCK answers everything else
 * meanwhile, refuses what would use the program, and a shutdown or a free
 * does not wait for the check to end. */
static void test_load_in_background(void **state_)
{
    (void)state_;
    struct svc s;
    char why[256];
    start(&s, 0);
    home_all(&s);
    write_prog(&s, "#1=0\no1 while [#1 lt 3000000]\n#1=[#1+1]\no1 endwhile\nG1 X5 F3000\nM2\n");
    assert_int_equal(cmd_now(&s, NCP_CMD_LOAD, s.prog, 0, 0, why), NCP_NCK_CMD_PENDING);
    assert_int_equal(ncp_nck_pending(s.nck, why, sizeof why), NCP_NCK_CMD_PENDING);
    assert_int_equal(cmd_now(&s, NCP_CMD_RUN, NULL, 0, 0, why), -1);
    assert_non_null(strstr(why, "is being checked"));
    assert_int_equal(cmd_now(&s, NCP_CMD_MDI, "G0 X1", 0, 0, why), -1);
    assert_int_equal(cmd_now(&s, NCP_CMD_OVERRIDE, NULL, 50, 0, why), 0);
    ncp_nck_poll(s.nck);
    assert_int_equal(state(&s), NCP_ST_IDLE);
    assert_int_equal(answer(&s, why), 0);
    assert_int_equal(cmd(&s, NCP_CMD_RUN, NULL, 0, 0, why), 0);
    wait_state(&s, NCP_ST_IDLE);
    double p[3];
    pos(&s, p);
    assert_true(fabs(p[0] - 5) < 1e-9);

    /* an error after the loop is the load's answer, with its line */
    write_prog(&s, "#1=0\no1 while [#1 lt 3000000]\n#1=[#1+1]\no1 endwhile\nG1 X5 Y\nM2\n");
    assert_int_equal(cmd(&s, NCP_CMD_LOAD, s.prog, 0, 0, why), -1);
    assert_non_null(strstr(why, ":5:"));

    /* a shutdown ends the check at once and refuses the load */
    write_prog(&s, "#1=0\no1 while [#1 lt 9000000]\n#1=[#1+1]\no1 endwhile\nM2\n");
    assert_int_equal(cmd_now(&s, NCP_CMD_LOAD, s.prog, 0, 0, why), NCP_NCK_CMD_PENDING);
    double t0 = mono_s();
    ncp_nck_request_shutdown(s.nck);
    ncp_nck_poll(s.nck);
    assert_false(ncp_nck_shutdown_requested(s.nck));   /* not before the answer */
    assert_int_equal(answer(&s, why), -1);
    assert_non_null(strstr(why, "shutting down"));
    assert_true(mono_s() - t0 < 0.5);
    ncp_nck_poll(s.nck);
    assert_true(ncp_nck_shutdown_requested(s.nck));
    stop(&s);

    /* freed during the check of a long program without loops: no wait */
    start(&s, 0);
    write_prog(&s, "");
    FILE *f = fopen(s.prog, "w");
    assert_non_null(f);
    for (int i = 0; i < 3000000; i++)
        fprintf(f, "G1 X%d F1000\n", i % 100);
    fputs("M2\n", f);
    fclose(f);
    assert_int_equal(cmd_now(&s, NCP_CMD_LOAD, s.prog, 0, 0, why), NCP_NCK_CMD_PENDING);
    t0 = mono_s();
    stop(&s);
    assert_true(mono_s() - t0 < 0.5);
}

/* The NCK's own measure of how long a cancelled check took to end, from
 * its load's refusal: "(ended 0.3 ms after it)". */
static double ended_ms(const char *why)
{
    const char *p = strstr(why, "(ended ");
    return p ? strtod(p + 7, NULL) : 1e9;
}

/* A check that never ends (two nested loops of 9 million laps each, or a
 * program of millions of blocks without loops) is ended by stop, abort,
 * E-stop, reset or a new load within 100 ms; the load's answer names what
 * ended it, and the NCK takes a new load at once. */
static void test_check_ended(void **state_)
{
    (void)state_;
    static const char *const endless =
        "#1=0\no1 while [#1 lt 9000000]\n#2=0\no2 while [#2 lt 9000000]\n"
        "#2=[#2+1]\no2 endwhile\n#1=[#1+1]\no1 endwhile\nM2\n";
    static const struct { int kind; const char *name; } ends[] = {
        { NCP_CMD_STOP, "stop" }, { NCP_CMD_ABORT, "abort" }, { NCP_CMD_ESTOP, "E-stop" },
        { NCP_CMD_RESET, "reset" }, { NCP_CMD_LOAD, "a new load" },
    };
    struct svc s;
    char why[256], path[80], small[80];
    start(&s, 0);
    home_all(&s);
    snprintf(path, sizeof path, "/tmp/ncp-svc-endless-%d.ngc", (int)getpid());
    snprintf(small, sizeof small, "/tmp/ncp-svc-small-%d.ngc", (int)getpid());
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(endless, f);
    fclose(f);
    f = fopen(small, "w");
    assert_non_null(f);
    fputs("G1 X3 F3000\nM2\n", f);
    fclose(f);
    for (size_t k = 0; k < sizeof ends / sizeof ends[0]; k++) {
        assert_int_equal(cmd_now(&s, NCP_CMD_LOAD, path, 0, 0, why), NCP_NCK_CMD_PENDING);
        nap_ms(50);
        assert_int_equal(ncp_nck_pending(s.nck, why, sizeof why), NCP_NCK_CMD_PENDING);
        double t0 = mono_s();
        int rc = cmd_now(&s, ends[k].kind, ends[k].kind == NCP_CMD_LOAD ? small : NULL, 0, 0,
                         why);
        assert_int_equal(rc, ends[k].kind == NCP_CMD_LOAD ? NCP_NCK_CMD_PENDING : 0);
        /* the ended load's answer, then (after a new load) the new one's */
        assert_int_equal(answer(&s, why), -1);
        double wall = mono_s() - t0;
        print_message("check ended by %s: %s (%.1f ms wall)\n", ends[k].name, why,
                      wall * 1e3);
        assert_non_null(strstr(why, "cancelled by"));
        assert_non_null(strstr(why, ends[k].name));
        assert_true(ended_ms(why) < 100);
        assert_true(wall < 1.0);
        if (ends[k].kind == NCP_CMD_ESTOP) {
            wait_state(&s, NCP_ST_ESTOP);
            assert_int_equal(cmd(&s, NCP_CMD_RESET, NULL, 0, 0, why), 0);
            wait_state(&s, NCP_ST_IDLE);
        }
        /* usable at once: the next load is checked and taken */
        rc = ends[k].kind == NCP_CMD_LOAD ? answer(&s, why)
                                          : cmd(&s, NCP_CMD_LOAD, small, 0, 0, why);
        assert_int_equal(rc, 0);
    }
    /* right after a stop, an MDI line is taken without waiting for the
     * service to collect the ended load's answer */
    assert_int_equal(cmd_now(&s, NCP_CMD_LOAD, path, 0, 0, why), NCP_NCK_CMD_PENDING);
    nap_ms(20);
    assert_int_equal(cmd_now(&s, NCP_CMD_STOP, NULL, 0, 0, why), 0);
    assert_int_equal(cmd_now(&s, NCP_CMD_MDI, "G0 X1", 0, 0, why), 0);
    assert_int_equal(ncp_nck_pending(s.nck, why, sizeof why), -1);
    assert_non_null(strstr(why, "cancelled by stop"));
    wait_state(&s, NCP_ST_IDLE);
    stop(&s);
    unlink(path);
    unlink(small);

    /* between the blocks of a long program without loops, and at free */
    for (int by_free = 0; by_free < 2; by_free++) {
        start(&s, 0);
        f = fopen(path, "w");
        assert_non_null(f);
        for (int i = 0; i < 1000000; i++)
            fprintf(f, "G1 X%d F1000\n", i % 100);
        fputs("M2\n", f);
        fclose(f);
        assert_int_equal(cmd_now(&s, NCP_CMD_LOAD, path, 0, 0, why), NCP_NCK_CMD_PENDING);
        nap_ms(30);
        assert_int_equal(ncp_nck_pending(s.nck, why, sizeof why), NCP_NCK_CMD_PENDING);
        double t0 = mono_s();
        if (by_free) {
            stop(&s);
            assert_true(mono_s() - t0 < 0.1);
        } else {
            assert_int_equal(cmd_now(&s, NCP_CMD_STOP, NULL, 0, 0, why), 0);
            assert_int_equal(answer(&s, why), -1);
            assert_non_null(strstr(why, "cancelled by stop"));
            assert_true(ended_ms(why) < 100);
            stop(&s);
        }
        unlink(path);
    }
}

/* The path of a paused and resumed run is the uninterrupted run's. */
static void test_pause_resume_path(void **state_)
{
    (void)state_;
    struct svc a, b;
    start(&a, 1);
    home_all(&a);
    write_prog(&a, square);
    assert_int_equal(cmd(&a, NCP_CMD_LOAD, a.prog, 0, 0, NULL), 0);
    assert_int_equal(cmd(&a, NCP_CMD_RUN, NULL, 0, 0, NULL), 0);
    wait_state(&a, NCP_ST_IDLE);
    start(&b, 1);
    home_all(&b);
    assert_int_equal(cmd(&b, NCP_CMD_LOAD, a.prog, 0, 0, NULL), 0);
    assert_int_equal(cmd(&b, NCP_CMD_RUN, NULL, 0, 0, NULL), 0);
    int pauses = 0, last = 0;
    for (int i = 0; i < 200000 && state(&b) != NCP_ST_IDLE; i++) {
        ncp_nck_poll(b.nck);
        struct ncp_nck_snapshot st;
        ncp_nck_get_status(b.nck, &st);
        if (st.state == NCP_ST_RUNNING && st.vel > 0 && pauses < 3 && i > last + 20) {
            assert_int_equal(cmd(&b, NCP_CMD_PAUSE, NULL, 0, 0, NULL), 0);
            pauses++;
            nap_ms(30);
            ncp_nck_poll(b.nck);
            assert_int_equal(state(&b), NCP_ST_PAUSED);
            assert_int_equal(cmd(&b, NCP_CMD_RESUME, NULL, 0, 0, NULL), 0);
            last = i;
        }
        nap_ms(1);
    }
    assert_true(pauses >= 1);
    fflush(a.trace);
    fflush(b.trace);
    size_t na, nb;
    struct row *ra = read_trace(a.trace, &na), *rb = read_trace(b.trace, &nb);
    /* every commanded point of the paused run lies on the uninterrupted path:
     * its distance to the nearest chord of that run's samples (the chords of
     * a 1 ms path are far inside 1 um of the curve at these speeds) */
    double worst = 0;
    size_t k = 0;
    for (size_t i = 0; i < nb; i++) {
        double best = INFINITY;
        size_t at = k;
        for (size_t m = k > 50 ? k - 50 : 0; m + 1 < na && m < k + 5000; m++) {
            double ab2 = 0, ap = 0, d2 = 0;
            for (int j = 0; j < 3; j++) {
                ab2 += (ra[m + 1].cmd[j] - ra[m].cmd[j]) * (ra[m + 1].cmd[j] - ra[m].cmd[j]);
                ap += (rb[i].cmd[j] - ra[m].cmd[j]) * (ra[m + 1].cmd[j] - ra[m].cmd[j]);
            }
            double f = ab2 > 0 ? fmin(1, fmax(0, ap / ab2)) : 0;
            for (int j = 0; j < 3; j++) {
                double q = ra[m].cmd[j] + f * (ra[m + 1].cmd[j] - ra[m].cmd[j]) - rb[i].cmd[j];
                d2 += q * q;
            }
            if (d2 < best) {
                best = d2;
                at = m;
            }
        }
        k = at;
        worst = fmax(worst, sqrt(best));
    }
    double tail[3], end[3];
    pos(&a, tail);
    pos(&b, end);
    for (int j = 0; j < 3; j++)
        assert_true(fabs(tail[j] - end[j]) < 1e-6);
    assert_true(worst < 1e-3);
    free(ra);
    free(rb);
    stop(&a);
    b.prog[0] = 0;
    stop(&b);
}

static void test_stop_then_run_again(void **state_)
{
    (void)state_;
    struct svc s;
    start(&s, 0);
    home_all(&s);
    write_prog(&s, "G21 G90 G55\nG1 X100 F3000\nG1 X0\nM2\n");
    assert_int_equal(cmd(&s, NCP_CMD_LOAD, s.prog, 0, 0, NULL), 0);
    assert_int_equal(cmd(&s, NCP_CMD_RUN, NULL, 0, 0, NULL), 0);
    for (int i = 0; i < 20000; i++) {
        struct ncp_nck_snapshot st;
        ncp_nck_poll(s.nck);
        ncp_nck_get_status(s.nck, &st);
        if (st.pos_cmd[0] > 30)
            break;
        nap_ms(1);
    }
    assert_int_equal(cmd(&s, NCP_CMD_STOP, NULL, 0, 0, NULL), 0);
    wait_state(&s, NCP_ST_IDLE);
    double p[3];
    pos(&s, p);
    assert_true(p[0] > 30 && p[0] < 100);
    struct ncp_nck_snapshot st;
    ncp_nck_get_status(s.nck, &st);
    assert_int_equal(st.g5x_index, 1);   /* back to G54 as at M2 */
    assert_int_equal(cmd(&s, NCP_CMD_RUN, NULL, 0, 0, NULL), 0);
    wait_state(&s, NCP_ST_IDLE);
    pos(&s, p);
    assert_true(fabs(p[0]) < 1e-6);
    stop(&s);
}

static void test_mdi_keeps_modal_state(void **state_)
{
    (void)state_;
    struct svc s;
    start(&s, 0);
    home_all(&s);
    const char *lines[] = { "G10 L2 P2 X10 Y5", "G55", "G91", "G0 X1 Y1", "G0 X1",
                            "G90 G1 X0 Y0 F1000", "G2 X2 Y0 I1 J0" };
    /* machine coordinates: G91 moves from where the machine is, G90 to G55's */
    double want[][2] = { { 0, 0 }, { 0, 0 }, { 0, 0 }, { 1, 1 }, { 2, 1 }, { 10, 5 },
                         { 12, 5 } };
    for (size_t i = 0; i < sizeof lines / sizeof lines[0]; i++) {
        char why[256];
        assert_int_equal(cmd(&s, NCP_CMD_MDI, lines[i], 0, 0, why), 0);
        wait_state(&s, NCP_ST_IDLE);
        double p[3];
        pos(&s, p);
        assert_true(fabs(p[0] - want[i][0]) < 1e-6);
        assert_true(fabs(p[1] - want[i][1]) < 1e-6);
    }
    char why[256];
    assert_int_equal(cmd(&s, NCP_CMD_MDI, "G1 X1 Y1 Q", 0, 0, why), 0);
    wait_state(&s, NCP_ST_IDLE);
    struct ncp_nck_snapshot st;
    ncp_nck_get_status(s.nck, &st);
    assert_true(st.error[0] != 0);
    /* a mistyped line changes nothing else: still G55, still G90 */
    assert_int_equal(st.g5x_index, 2);
    assert_int_equal(cmd(&s, NCP_CMD_MDI, "G0 X1 Y1", 0, 0, why), 0);
    wait_state(&s, NCP_ST_IDLE);
    double p[3];
    pos(&s, p);
    assert_true(fabs(p[0] - 11) < 1e-6 && fabs(p[1] - 6) < 1e-6);
    stop(&s);
}

/* A jog of X: dir, speed mm/min (0: the default), distance mm (0: continuous). */
static struct ncp_nck_cmd jog_x(int dir, double speed, double distance)
{
    struct ncp_nck_cmd c;
    memset(&c, 0, sizeof c);
    c.kind = NCP_CMD_JOG;
    strcpy(c.text, "x");
    c.ivalue[0] = dir;
    c.value[0] = speed;
    c.value[1] = distance;
    return c;
}

static void test_jogs(void **state_)
{
    (void)state_;
    struct svc s;
    start(&s, 0);
    struct ncp_nck_cmd c = jog_x(1, 600, 2.5);
    char why[256];
    assert_int_equal(ncp_nck_command(s.nck, &c, why, sizeof why), 0);
    wait_state(&s, NCP_ST_IDLE);
    double p[3];
    pos(&s, p);
    assert_true(fabs(p[0] - 2.5) < 1e-9);
    /* continuous, towards the limit, stopped by the missing keep-alive */
    c.value[1] = 0;
    c.value[0] = 6000;
    assert_int_equal(ncp_nck_command(s.nck, &c, why, sizeof why), 0);
    wait_state(&s, NCP_ST_STOPPING);
    wait_state(&s, NCP_ST_IDLE);
    pos(&s, p);
    assert_true(p[0] > 2.5 && p[0] < 500);
    /* incremental beyond the soft limit stops at it */
    c.value[1] = 1000;
    assert_int_equal(ncp_nck_command(s.nck, &c, why, sizeof why), 0);
    wait_state(&s, NCP_ST_IDLE);
    pos(&s, p);
    assert_true(fabs(p[0] - s.cfg.axis[0].max_limit) < 1e-9);
    assert_int_equal(ncp_nck_command(s.nck, &c, why, sizeof why), -1);
    stop(&s);
}

/* A jog that makes no sense is refused with the reason, never run at the
 * default speed; a speed above the axis's MAX_VELOCITY jogs at it and
 * says so. */
static void test_jog_input(void **state_)
{
    (void)state_;
    struct svc s;
    start(&s, 0);
    static const struct { int dir; double speed, dist; const char *why; } bad[] = {
        { 5, 600, 1, "direction is +1 or -1, not 5" },
        { 0, 600, 1, "direction" },
        { -2, 600, 1, "direction" },
        { 1, -1e308, 1, "speed" },
        { 1, -1, 0, "speed" },
        { 1, NAN, 1, "speed" },
        { 1, INFINITY, 1, "speed" },
        { 1, 600, -1, "distance" },
        { 1, 600, NAN, "distance" },
        { -1, 600, INFINITY, "distance" },
    };
    char why[256];
    struct ncp_nck_cmd c;
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        c = jog_x(bad[k].dir, bad[k].speed, bad[k].dist);
        assert_int_equal(ncp_nck_command(s.nck, &c, why, sizeof why), -1);
        assert_non_null(strstr(why, bad[k].why));
        ncp_nck_poll(s.nck);
        assert_int_equal(state(&s), NCP_ST_IDLE);
    }
    /* 1e308 mm/min: at MAX_VELOCITY, said in an event */
    c = jog_x(1, 1e308, 50);
    assert_int_equal(ncp_nck_command(s.nck, &c, why, sizeof why), 0);
    double vmax = 0;
    for (int i = 0; i < 60000 && state(&s) != NCP_ST_IDLE; i++) {
        struct ncp_nck_snapshot st;
        ncp_nck_poll(s.nck);
        ncp_nck_get_status(s.nck, &st);
        vmax = fmax(vmax, st.vel);
        nap_ms(1);
    }
    assert_true(vmax > 0 && vmax <= s.cfg.axis[0].max_vel * 60 * (1 + 1e-9));
    struct ncp_nck_event ev;
    int said = 0;
    while (ncp_nck_next_event(s.nck, &ev))
        said |= strstr(ev.text, "MAX_VELOCITY") != NULL;
    assert_true(said);
    double p[3];
    pos(&s, p);
    assert_true(fabs(p[0] - 50) < 1e-9);
    stop(&s);
}

/* Runs the loaded program until X has passed x (20 s of wall time at most). */
static void run_past_x(struct svc *s, double x)
{
    assert_int_equal(cmd(s, NCP_CMD_RUN, NULL, 0, 0, NULL), 0);
    for (int i = 0; i < 20000; i++) {
        double p[3];
        pos(s, p);
        if (p[0] > x)
            break;
        nap_ms(1);
    }
}

static void test_estop_reset(void **state_)
{
    (void)state_;
    struct svc s;
    start(&s, 0);
    home_all(&s);
    write_prog(&s, "G1 X200 F6000\nM2\n");
    assert_int_equal(cmd(&s, NCP_CMD_LOAD, s.prog, 0, 0, NULL), 0);
    run_past_x(&s, 20);
    assert_int_equal(cmd(&s, NCP_CMD_ESTOP, NULL, 0, 0, NULL), 0);
    /* what the operator reads from the ACK on, before the job is dropped */
    assert_int_equal(state(&s), NCP_ST_ESTOP);
    wait_state(&s, NCP_ST_ESTOP);
    double p1[3], p2[3];
    pos(&s, p1);
    nap_ms(50);
    pos(&s, p2);
    assert_true(p1[0] == p2[0]);
    char why[256];
    assert_int_equal(cmd(&s, NCP_CMD_RUN, NULL, 0, 0, why), -1);
    assert_non_null(strstr(why, "estop"));
    assert_int_equal(cmd(&s, NCP_CMD_RESET, NULL, 0, 0, why), 0);
    wait_state(&s, NCP_ST_IDLE);
    assert_int_equal(cmd(&s, NCP_CMD_MDI, "G0 X0", 0, 0, why), 0);
    wait_state(&s, NCP_ST_IDLE);
    pos(&s, p1);
    assert_true(fabs(p1[0]) < 1e-9);

    /* a reset sent in the same breath as the E-stop, while its drop is
     * still under way, ends in idle with the setpoints let go */
    run_past_x(&s, 20);
    assert_int_equal(cmd_now(&s, NCP_CMD_ESTOP, NULL, 0, 0, why), 0);
    assert_int_equal(state(&s), NCP_ST_ESTOP);
    assert_int_equal(cmd_now(&s, NCP_CMD_RESET, NULL, 0, 0, why), 0);
    wait_state(&s, NCP_ST_IDLE);
    assert_int_equal(cmd(&s, NCP_CMD_MDI, "G0 X1", 0, 0, why), 0);
    wait_state(&s, NCP_ST_IDLE);
    pos(&s, p1);
    assert_true(fabs(p1[0] - 1) < 1e-9);
    stop(&s);
}

static void test_single_block_and_from_line(void **state_)
{
    (void)state_;
    struct svc s;
    start(&s, 0);
    home_all(&s);
    write_prog(&s, "G21 G90\nG0 Z10\nG1 X10 F3000\nG1 Y10\nG1 Z-2\nG1 X0\nM2\n");
    assert_int_equal(cmd(&s, NCP_CMD_LOAD, s.prog, 0, 0, NULL), 0);
    assert_int_equal(cmd(&s, NCP_CMD_STEP, NULL, 0, 1, NULL), 0);
    assert_int_equal(cmd(&s, NCP_CMD_RUN, NULL, 0, 0, NULL), 0);
    assert_int_equal(state(&s), NCP_ST_STEPPING);
    double want[][3] = { { 0, 0, 10 }, { 10, 0, 10 }, { 10, 10, 10 }, { 10, 10, -2 },
                         { 0, 10, -2 } };
    for (int k = 0; k < 5; k++) {
        double p[3] = { 0, 0, 0 };
        for (int i = 0; i < 20000; i++) {
            nap_ms(1);
            pos(&s, p);
            if (fabs(p[0] - want[k][0]) + fabs(p[1] - want[k][1]) + fabs(p[2] - want[k][2]) < 1e-9)
                break;
        }
        nap_ms(50);
        pos(&s, p);
        for (int j = 0; j < 3; j++)
            assert_true(fabs(p[j] - want[k][j]) < 1e-9);
        assert_int_equal(cmd(&s, NCP_CMD_RESUME, NULL, 0, 0, NULL), 0);
    }
    wait_state(&s, NCP_ST_IDLE);
    assert_int_equal(cmd(&s, NCP_CMD_STEP, NULL, 0, 0, NULL), 0);
    /* from line 5 (G1 Z-2): up to Z10, over to X10 Y10, down, then on */
    assert_int_equal(cmd(&s, NCP_CMD_MDI, "G0 X50 Y50 Z0", 0, 0, NULL), 0);
    wait_state(&s, NCP_ST_IDLE);
    assert_int_equal(cmd(&s, NCP_CMD_RUN, NULL, 0, 5, NULL), 0);
    wait_state(&s, NCP_ST_IDLE);
    double p[3];
    pos(&s, p);
    assert_true(fabs(p[0]) < 1e-9 && fabs(p[1] - 10) < 1e-9 && fabs(p[2] + 2) < 1e-9);
    struct ncp_nck_event ev;
    int saw = 0;
    while (ncp_nck_next_event(s.nck, &ev))
        saw |= strstr(ev.text, "run from line 5") != NULL;
    assert_true(saw);
    stop(&s);
}

/* Polls until an event holds text (60 s of wall time at most). */
static void wait_event(struct svc *s, const char *text)
{
    struct ncp_nck_event ev;
    for (int i = 0; i < 60000; i++) {
        ncp_nck_poll(s->nck);
        while (ncp_nck_next_event(s->nck, &ev))
            if (strstr(ev.text, text))
                return;
        nap_ms(1);
    }
    fail_msg("no event with '%s'", text);
}

/* One history line from the FIFO the writer appends to: opening its
 * reading end lets the writer's open go on. */
static void read_history_line(const char *fifo, char *line, size_t cap)
{
    int fd = open(fifo, O_RDONLY | O_NONBLOCK);
    assert_true(fd >= 0);
    size_t n = 0;
    for (int i = 0; i < 60000 && (n == 0 || line[n - 1] != '\n') && n + 1 < cap; i++) {
        ssize_t r = read(fd, line + n, cap - 1 - n);
        if (r > 0)
            n += (size_t)r;
        else
            nap_ms(1);
    }
    line[n] = 0;
    close(fd);
}

/* A disk that does not answer (the history is a FIFO nobody reads yet: the
 * writer's open waits): the job's state stays until its line is written,
 * and meanwhile the NCK answers at once; what needs the disk waits for it
 * (pending), what moves nothing is taken or refused, an E-stop acts, and a
 * reset ends a wait for the disk. */
static void test_slow_disk(void **state_)
{
    (void)state_;
    char fifo[64], why[256], line[2048];
    snprintf(fifo, sizeof fifo, "/tmp/ncp-svc-hist-%d", (int)getpid());
    unlink(fifo);
    assert_int_equal(mkfifo(fifo, 0600), 0);
    struct svc s;
    start_history(&s, 0, fifo);
    home_all(&s);
    write_prog(&s, "G1 X5 F3000\nM2\n");
    assert_int_equal(cmd(&s, NCP_CMD_LOAD, s.prog, 0, 0, why), 0);
    assert_int_equal(cmd(&s, NCP_CMD_RUN, NULL, 0, 0, why), 0);
    wait_event(&s, "program finished");
    for (int i = 0; i < 20; i++) {
        ncp_nck_poll(s.nck);
        nap_ms(1);
    }
    assert_int_equal(state(&s), NCP_ST_RUNNING);
    assert_int_equal(cmd_now(&s, NCP_CMD_PAUSE, NULL, 0, 0, why), -1);
    assert_non_null(strstr(why, "has ended"));
    assert_int_equal(cmd_now(&s, NCP_CMD_OVERRIDE, NULL, 50, 0, why), 0);
    assert_int_equal(cmd_now(&s, NCP_CMD_FILES, "history", 0, 0, why), NCP_NCK_CMD_PENDING);
    assert_int_equal(ncp_nck_pending(s.nck, why, sizeof why), NCP_NCK_CMD_PENDING);
    assert_int_equal(cmd_now(&s, NCP_CMD_LOAD, s.prog, 0, 0, why), -1);
    assert_non_null(strstr(why, "another command waits"));
    read_history_line(fifo, line, sizeof line);
    assert_non_null(strstr(line, "\"result\": \"done\""));
    assert_int_equal(answer(&s, why), 0);
    assert_string_equal(why, fifo);
    wait_state(&s, NCP_ST_IDLE);

    assert_int_equal(cmd(&s, NCP_CMD_RUN, NULL, 0, 0, why), 0);
    wait_event(&s, "program finished");
    assert_int_equal(cmd_now(&s, NCP_CMD_ESTOP, NULL, 0, 0, why), 0);
    assert_int_equal(state(&s), NCP_ST_ESTOP);
    assert_int_equal(cmd_now(&s, NCP_CMD_FILES, "history", 0, 0, why), NCP_NCK_CMD_PENDING);
    assert_int_equal(cmd_now(&s, NCP_CMD_RESET, NULL, 0, 0, why), 0);
    assert_int_equal(ncp_nck_pending(s.nck, why, sizeof why), -1);
    assert_non_null(strstr(why, "reset came while it waited for the disk"));
    read_history_line(fifo, line, sizeof line);
    assert_non_null(strstr(line, "\"result\": \"done\""));
    wait_state(&s, NCP_ST_IDLE);
    stop(&s);
    unlink(fifo);
}

int main(int argc, char **argv)
{
    if (argc > 1)
        cmocka_set_test_filter(argv[1]);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_refusals),
        cmocka_unit_test(test_load_in_background),
        cmocka_unit_test(test_check_ended),
        cmocka_unit_test(test_pause_resume_path),
        cmocka_unit_test(test_stop_then_run_again),
        cmocka_unit_test(test_mdi_keeps_modal_state),
        cmocka_unit_test(test_jogs),
        cmocka_unit_test(test_jog_input),
        cmocka_unit_test(test_estop_reset),
        cmocka_unit_test(test_single_block_and_from_line),
        cmocka_unit_test(test_slow_disk),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
