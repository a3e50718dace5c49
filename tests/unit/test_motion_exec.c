/* The stages below the look-ahead on their own: fed the records the planner
 * started (its tap: the distributed-NCK paper's ACCDECbuf of the ADCBI NCK), the interpolator
 * (ncp_exec, exec.c) gives the planner's samples bit for bit, and so does the
 * ACC/DEC stage (ncp_la_profile) run on the look-ahead's records (LAbuf):
 * what lets an LLC at DP4 or DP3 run the stages below for its axis. A source
 * that falls behind is told apart from the end of the program. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "ncpar/motion.h"
#include "canon_ops.h"

/* corners blended within P, an arc, a helix, a dwell, an exact stop, a rapid */
static size_t program(struct ncp_canon *ops)
{
    size_t n = 0;
    ops[n++] = op_feed(3000);
    ops[n++] = op_mode(2, 0.01);
    ops[n++] = op6(NCP_C_STRAIGHT_FEED, 10, 0, 0);
    ops[n++] = op6(NCP_C_STRAIGHT_FEED, 10, 8, 0);
    ops[n++] = op6(NCP_C_STRAIGHT_FEED, 3, 12, -1);
    ops[n++] = op_arc(-3, 12, 0, 12, 1, -1);
    ops[n++] = op_arc(-3, 12, 0, 12, 2, -3);
    ops[n++] = op6(NCP_C_STRAIGHT_FEED, -3, 0.5, -3);
    ops[n++] = op_dwell(0.05);
    ops[n++] = op6(NCP_C_STRAIGHT_TRAVERSE, 20, 20, 2);
    ops[n++] = op_mode(0, 0);
    ops[n++] = op6(NCP_C_STRAIGHT_FEED, 21, 20, 2);
    ops[n++] = op6(NCP_C_STRAIGHT_FEED, 21, 21, 2);
    ops[n++] = op_mode(2, 0.01);
    for (int k = 0; k < 40; k++)   /* short CAM moves, blended */
        ops[n++] = op6(NCP_C_STRAIGHT_FEED, 21 + 0.3 * k, 21 + 0.2 * sin(k), 2);
    return n;
}

struct recs {
    size_t n, cap, next;
    struct ncp_accdec *r;
    struct ncp_la *la;
    enum ncp_profile profile;
};

static void tap(void *ctx, const struct ncp_la *la, const struct ncp_accdec *rec)
{
    struct recs *rs = ctx;
    if (rs->n == rs->cap) {
        rs->cap = rs->cap ? 2 * rs->cap : 256;
        rs->r = realloc(rs->r, rs->cap * sizeof *rs->r);
        rs->la = realloc(rs->la, rs->cap * sizeof *rs->la);
        assert_non_null(rs->r);
        assert_non_null(rs->la);
    }
    rs->la[rs->n] = *la;
    rs->r[rs->n++] = *rec;
}

/* the LLC at DP3: ACC/DEC on each look-ahead record as it is needed */
static int from_la(void *ctx, double v0, struct ncp_accdec *rec)
{
    struct recs *rs = ctx;
    if (rs->next == rs->n)
        return -1;
    ncp_la_profile(rs->profile, &rs->la[rs->next], v0, rec);
    return 1;
}

static int from_array(void *ctx, double v0, struct ncp_accdec *rec)
{
    struct recs *rs = ctx;
    (void)v0;
    if (rs->next == rs->n)
        return -1;
    *rec = rs->r[rs->next];
    return 1;
}

static void array_done(void *ctx)
{
    ((struct recs *)ctx)->next++;
}

static void sp_equal(const struct ncp_setpoint *a, const struct ncp_setpoint *b, size_t k)
{
    if (memcmp(a->pos, b->pos, sizeof a->pos) || memcmp(a->dir, b->dir, sizeof a->dir) ||
        memcmp(&a->v, &b->v, sizeof a->v) || a->line != b->line || a->flags != b->flags ||
        a->aux != b->aux || memcmp(&a->tool_z, &b->tool_z, sizeof a->tool_z))
        fail_msg("sample %zu differs: x %.17g/%.17g v %.17g/%.17g line %u/%u flags %u/%u", k,
                 a->pos[0], b->pos[0], a->v, b->v, a->line, b->line, a->flags, b->flags);
}

static void replay_equals_planner(enum ncp_profile prof, int ratio)
{
    struct ncp_machine_cfg cfg;
    ncp_machine_cfg_default(&cfg);
    cfg.profile = prof;
    cfg.planning_period = ratio * cfg.servo_period;
    struct ncp_canon ops[64];
    size_t nops = program(ops);
    double zero[NCP_AXES] = { 0 };
    struct ncp_canon_map m;
    ncp_canon_map_init(&m, &cfg, zero, 1.0);
    struct ncp_planner *p = ncp_planner_new(&cfg, zero);
    assert_non_null(p);
    struct recs rs = { .profile = prof };
    ncp_planner_set_tap(p, tap, &rs);
    size_t nsp = 0, cap = 1 << 16, i = 0, segs = 0;
    struct ncp_setpoint *sp = malloc(cap * sizeof *sp);
    assert_non_null(sp);
    for (;;) {
        while (i < nops && !ncp_planner_full(p)) {
            struct ncp_seg s;
            struct ncp_diag d;
            int r = ncp_canon_map_op(&m, &ops[i], (uint32_t)(i + 1), &s, &d);
            assert_true(r == 0 || r == 1);
            if (r == 1) {
                ncp_planner_push(p, &s);
                segs++;
            }
            i++;
        }
        if (i == nops)
            ncp_planner_finish(p);
        assert_true(nsp < cap);
        if (!ncp_planner_step(p, &sp[nsp]))
            break;
        nsp++;
    }
    ncp_planner_free(p);
    /* every programmed segment and the corner arcs between them; an arc may
     * come in pieces, one after the other on the same line */
    size_t blends = 0, pieces = 0;
    for (size_t k = 0; k < rs.n; k++) {
        blends += rs.r[k].blend;
        if (k > 0 && !rs.r[k].blend && !rs.r[k - 1].blend && rs.la[k].s.kind == NCP_SEG_ARC &&
            rs.la[k - 1].s.kind == NCP_SEG_ARC && rs.la[k].s.line == rs.la[k - 1].s.line &&
            !memcmp(rs.la[k].s.start, rs.la[k - 1].s.end, sizeof rs.la[k].s.start))
            pieces++;
    }
    if (blends < 5)
        fail_msg("%zu corner arcs among %zu records", blends, rs.n);
    assert_int_equal(rs.n - blends - pieces, segs);

    for (int stage = 0; stage < 2; stage++) {   /* ACCDECbuf records, then LAbuf */
        struct ncp_exec e;
        ncp_exec_init(&e, zero, cfg.planning_period);
        const struct ncp_exec_source src = { stage ? from_la : from_array, array_done, &rs };
        rs.next = 0;
        for (size_t k = 0; k < nsp; k++) {
            struct ncp_setpoint out;
            assert_int_equal(ncp_exec_step(&e, &src, &out), 1);
            sp_equal(&sp[k], &out, k);
        }
        struct ncp_setpoint out;
        assert_int_equal(ncp_exec_step(&e, &src, &out), 0);
        assert_true(out.flags & NCP_SP_END);
        assert_int_equal(rs.next, rs.n);
    }
    free(sp);
    free(rs.r);
    free(rs.la);
}

static void test_replay_trapezoid(void **st)
{
    (void)st;
    replay_equals_planner(NCP_PROFILE_TRAPEZOID, 1);
}

static void test_replay_scurve(void **st)
{
    (void)st;
    replay_equals_planner(NCP_PROFILE_SCURVE, 1);
}

static void test_replay_rough_period(void **st)
{
    (void)st;
    replay_equals_planner(NCP_PROFILE_TRAPEZOID, 4);
}

/* a record that ends at speed with nothing after it: the source fell behind */
static int one_then_nothing(void *ctx, double v0, struct ncp_accdec *rec)
{
    struct recs *rs = ctx;
    (void)v0;
    if (rs->next > 0)
        return 0;
    *rec = rs->r[0];
    return 1;
}

static void test_underrun_is_not_the_end(void **st)
{
    (void)st;
    struct ncp_accdec r;
    memset(&r, 0, sizeof r);
    r.s.kind = NCP_SEG_LINE;
    r.s.end[0] = 10;
    r.s.length = 10;
    r.s.line = 7;
    ncp_trap_plan(&r.trap, 10, 0, 20, 50, 1000);   /* ends at 20 mm/s */
    r.dur = ncp_trap_duration(&r.trap);
    struct recs rs = { .n = 1, .cap = 1, .r = &r };
    const struct ncp_exec_source src = { one_then_nothing, array_done, &rs };
    struct ncp_exec e;
    ncp_exec_init(&e, NULL, 0.001);
    struct ncp_setpoint out;
    int starved = 0;
    for (int k = 0; k < 1000 && !starved; k++) {
        assert_int_equal(ncp_exec_step(&e, &src, &out), 1);
        starved = (out.flags & NCP_SP_STARVED) != 0;
    }
    assert_true(starved);
    assert_true(out.pos[0] == 10 && out.v == 0 && out.line == 7);
    assert_int_equal(rs.next, 1);
    /* and it waits at rest, still not the end */
    assert_int_equal(ncp_exec_step(&e, &src, &out), 1);
    assert_true((out.flags & NCP_SP_STARVED) && !(out.flags & NCP_SP_END) && out.pos[0] == 10);
}

int main(void)
{
    const struct CMUnitTest t[] = {
        cmocka_unit_test(test_replay_trapezoid),
        cmocka_unit_test(test_replay_scurve),
        cmocka_unit_test(test_replay_rough_period),
        cmocka_unit_test(test_underrun_is_not_the_end),
    };
    return cmocka_run_group_tests(t, NULL, NULL);
}
