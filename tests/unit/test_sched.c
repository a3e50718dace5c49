/* The scheduling strategies of the task-scheduling paper: the static and data-flow priority
 * functions (fills in, priorities out), [SCHED]'s keys, and one data-flow
 * round on real threads where SCHED_FIFO is permitted. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <pthread.h>
#include <sched.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "ncpar/sched.h"

static void test_static_by_distance(void **state)
{
    (void)state;
    int p[3];
    ncp_sched_static(3, 1, 89, p);   /* job, planner, fine interpolation */
    assert_int_equal(p[2], 89);
    assert_int_equal(p[1], 88);
    assert_int_equal(p[0], 87);
    ncp_sched_static(3, 88, 89, p);  /* a narrow band: clamped at its floor */
    assert_int_equal(p[0], 88);
    assert_int_equal(p[2], 89);
}

/* job (source) -> segs -> planner -> setpoints -> (position loop) */
static void test_dataflow_raises_the_starved(void **state)
{
    (void)state;
    int p[2];
    /* the setpoint ring runs dry while segments pile up: the planner on top */
    struct ncp_sched_fill starved[2] = { { 0, 0, 900, 1024 }, { 900, 1024, 2, 1024 } };
    ncp_sched_dataflow(starved, 2, 10, 89, p);
    assert_int_equal(p[1], 89);
    assert_int_equal(p[0], 88);
    /* the segment ring is empty and the setpoints are full: the planner cannot
     * run, it goes to the bottom and the job on top */
    struct ncp_sched_fill fed[2] = { { 0, 0, 0, 1024 }, { 0, 1024, 1024, 1024 } };
    ncp_sched_dataflow(fed, 2, 10, 89, p);
    assert_int_equal(p[0], 89);
    assert_int_equal(p[1], 10);
    /* equal pressure: the task nearer the position loop wins */
    struct ncp_sched_fill tie[2] = { { 0, 0, 512, 1024 }, { 512, 1024, 0, 1024 } };
    ncp_sched_dataflow(tie, 2, 10, 89, p);
    assert_int_equal(p[1], 89);
    assert_int_equal(p[0], 88);
}

/* Whatever the fills, every priority stays within the band: the position
 * loop (ceiling + 1) stays above every task. */
static void test_dataflow_bounded(void **state)
{
    (void)state;
    struct ncp_sched_fill f[6];
    int p[6];
    unsigned x = 12345;
    for (int round = 0; round < 2000; round++) {
        for (int i = 0; i < 6; i++) {
            x = x * 1103515245u + 12345u;
            size_t cap = 1 + (x >> 8) % 64;
            f[i] = (struct ncp_sched_fill){ (x >> 4) % (cap + 1), i ? cap : 0,
                                            (x >> 12) % (cap + 1), i < 5 ? cap : 0 };
        }
        ncp_sched_dataflow(f, 6, 80, 84, p);
        for (int i = 0; i < 6; i++) {
            assert_true(p[i] >= 80);
            assert_true(p[i] <= 84);
        }
    }
}

static void test_ini_keys(void **state)
{
    (void)state;
    struct ncp_sched_cfg c;
    char why[80];
    ncp_sched_cfg_default(&c);
    assert_int_equal(c.strategy, NCP_SCHED_NONE);
    assert_int_equal(ncp_sched_ini_key(&c, "STRATEGY", "dataflow", why, sizeof why), 1);
    assert_int_equal(c.strategy, NCP_SCHED_DATAFLOW);
    assert_int_equal(ncp_sched_ini_key(&c, "strategy", "STATIC", why, sizeof why), 1);
    assert_int_equal(c.strategy, NCP_SCHED_STATIC);
    assert_int_equal(ncp_sched_ini_key(&c, "STRATEGY", "edf", why, sizeof why), -1);
    assert_non_null(strstr(why, "dataflow"));
    assert_int_equal(ncp_sched_ini_key(&c, "PERIOD_MS", "0", why, sizeof why), -1);
    assert_int_equal(ncp_sched_ini_key(&c, "PERIOD_MS", "5", why, sizeof why), 1);
    assert_int_equal(c.period_ms, 5);
    assert_int_equal(ncp_sched_ini_key(&c, "TRACE_RINGS", "2", why, sizeof why), -1);
    assert_int_equal(ncp_sched_ini_key(&c, "COLOUR", "2", why, sizeof why), 0);
}

static void test_dataflow_ranked_ties(void **state)
{
    (void)state;
    /* equal pressure: the task nearer the position loop (higher rank) wins,
     * whatever its place in the array; without ranks, the later index */
    struct ncp_sched_fill f[3] = { { 8, 16, 8, 16 }, { 8, 16, 8, 16 }, { 8, 16, 8, 16 } };
    int rank[3] = { 6, 0, 3 }, p[3];
    ncp_sched_dataflow_ranked(f, rank, 3, 10, 89, p);
    assert_int_equal(p[0], 89);
    assert_int_equal(p[2], 88);
    assert_int_equal(p[1], 87);
    ncp_sched_dataflow(f, 3, 10, 89, p);
    assert_int_equal(p[2], 89);
    assert_int_equal(p[0], 87);
}

/* ---- one round on real threads ---------------------------------------------- */

static size_t fill_in, fill_out;
static size_t in_fill(void *ctx) { (void)ctx; return fill_in; }
static size_t out_fill(void *ctx) { (void)ctx; return fill_out; }

static void *parked(void *arg)
{
    struct ncp_sched_task *t = arg;
    ncp_sched_enter(t);
    while (t->ctx == NULL)   /* released by the test */
        usleep(1000);
    ncp_sched_leave(t);
    return NULL;
}

static int fifo_permitted(void)
{
    struct sched_param sp = { .sched_priority = 1 };
    if (sched_setscheduler(0, SCHED_FIFO, &sp) != 0)
        return 0;
    sp.sched_priority = 0;
    sched_setscheduler(0, SCHED_OTHER, &sp);
    return 1;
}

static void test_round_applies_within_bounds(void **state)
{
    (void)state;
    if (!fifo_permitted()) {
        printf("SKIP: SCHED_FIFO not permitted here: the data-flow round is not applied\n");
        return;
    }
    static struct ncp_sched s;
    memset(&s, 0, sizeof s);
    ncp_sched_cfg_default(&s.cfg);
    s.cfg.strategy = NCP_SCHED_DATAFLOW;
    s.cfg.floor = 5;
    s.ceiling = ncp_sched_ceiling(10);
    s.n = 1;
    s.task[0] = (struct ncp_sched_task){ .name = "planner", .in_fill = in_fill,
                                         .out_fill = out_fill, .in_cap = 64, .out_cap = 64 };
    pthread_t th;
    assert_int_equal(pthread_create(&th, NULL, parked, &s.task[0]), 0);
    while (!atomic_load(&s.task[0].tid))
        usleep(1000);
    int tid = atomic_load(&s.task[0].tid);
    fill_in = 60, fill_out = 1;   /* starved output, full input */
    assert_int_equal(ncp_sched_round(&s), 1);
    struct sched_param sp;
    assert_int_equal(sched_getparam(tid, &sp), 0);
    assert_int_equal(sched_getscheduler(tid), SCHED_FIFO);
    assert_int_equal(sp.sched_priority, 9);
    assert_int_equal(ncp_sched_round(&s), 0);   /* unchanged: no system call */
    fill_in = 0;                                /* nothing to do: bottom of the band */
    assert_int_equal(ncp_sched_round(&s), 1);
    assert_int_equal(sched_getparam(tid, &sp), 0);
    assert_int_equal(sp.sched_priority, 5);
    assert_int_equal(s.task[0].prio_max, 9);
    s.task[0].ctx = &s;
    pthread_join(th, NULL);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_static_by_distance),
        cmocka_unit_test(test_dataflow_raises_the_starved),
        cmocka_unit_test(test_dataflow_bounded),
        cmocka_unit_test(test_dataflow_ranked_ties),
        cmocka_unit_test(test_ini_keys),
        cmocka_unit_test(test_round_applies_within_bounds),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
