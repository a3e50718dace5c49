/* src/dist and the transport's injection switch: the setpoint codec against
 * lcm-gen's own decoder, the LLC buffer's gap / duplicate / stale accounting,
 * and the dice that lose messages (same seed, same losses). */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>
#include <time.h>

#include "ncpar/dist.h"
#include "ncpar/msg.h"

#define T 1000000LL /* 1 ms */

static void fine_round_trip(void **state)
{
    (void)state;
    ncp_dist_init();
    struct ncp_dist_fine f = { 42, NCP_DIST_HLC_ID, 123456789000LL, 3, { -5, 2147483647, -2147483647 - 1 } };
    uint8_t buf[256];
    int n = ncp_dist_encode_fine(buf, sizeof buf, &f);
    /* the payload of the distributed-NCK paper's fineIPObuf is 4N; ours adds
     * fingerprint, seq, sender, period, n */
    assert_int_equal(n, 8 + 4 + 2 + 8 + 1 + 4 * 3);
    ncp_fine_ipo_t g;
    memset(&g, 0, sizeof g);
    assert_int_equal(ncp_fine_ipo_t_decode(buf, 0, n, &g), n);
    assert_int_equal(g.seq, 42);
    assert_int_equal(g.n, 3);
    assert_int_equal(g.pos_nm[1], 2147483647);
    ncp_fine_ipo_t_decode_cleanup(&g);
    struct ncp_dist_fine h;
    assert_int_equal(ncp_dist_decode_fine(buf, (size_t)n, &h), 0);
    assert_memory_equal(&h.pos_nm, &f.pos_nm, 3 * sizeof(int32_t));
    assert_true(h.t_ns == f.t_ns && h.sender == f.sender && h.seq == 42);
    /* truncated, padded, wrong fingerprint, too many axes */
    assert_int_equal(ncp_dist_decode_fine(buf, (size_t)n - 1, &h), -1);
    assert_int_equal(ncp_dist_decode_fine(buf, (size_t)n + 1, &h), -1);
    buf[0] ^= 1;
    assert_int_equal(ncp_dist_decode_fine(buf, (size_t)n, &h), -1);
    buf[0] ^= 1;
    buf[22] = 10;
    assert_int_equal(ncp_dist_decode_fine(buf, 23 + 40, &h), -1);
}

static void nm_range(void **state)
{
    (void)state;
    int32_t nm = 0;
    assert_int_equal(ncp_dist_mm_to_nm(1.0000004, &nm), 0);
    assert_int_equal(nm, 1000000);
    assert_int_equal(ncp_dist_mm_to_nm(-0.0000016, &nm), 0);
    assert_int_equal(nm, -2);
    assert_int_equal(ncp_dist_mm_to_nm(2200.0, &nm), -1);
}

static void rx_in_order(void **state)
{
    (void)state;
    struct ncp_dist_rx r;
    ncp_dist_rx_init(&r, T, 7);
    assert_int_equal(ncp_dist_rx_play(&r, 1 * T), 7);   /* nothing yet: the start */
    assert_int_equal(r.held, 0);
    for (int k = 2; k < 10; k++)
        assert_int_equal(ncp_dist_rx_put(&r, k, (int64_t)k * T, k * 100), NCP_DIST_RX_NEW);
    assert_int_equal(ncp_dist_rx_level(&r, 1 * T), 8);
    for (int k = 2; k < 10; k++)
        assert_int_equal(ncp_dist_rx_play(&r, (int64_t)k * T), k * 100);
    assert_int_equal(r.lost + r.stale + r.duplicate + r.held, 0);
}

static void rx_gap_held_and_counted(void **state)
{
    (void)state;
    struct ncp_dist_rx r;
    ncp_dist_rx_init(&r, T, 0);
    ncp_dist_rx_put(&r, 1, 1 * T, 100);
    ncp_dist_rx_put(&r, 4, 4 * T, 400);   /* 2 and 3 lost */
    assert_int_equal(r.lost, 2);
    assert_int_equal(ncp_dist_rx_play(&r, 1 * T), 100);
    /* 2 is bridged on the way to 4 */
    assert_int_equal(ncp_dist_rx_play(&r, 2 * T), 200);
    assert_int_equal(r.bridged, 1);
    /* 3 comes late but in time: not lost after all */
    assert_int_equal(ncp_dist_rx_put(&r, 3, 3 * T, 300), NCP_DIST_RX_NEW);
    assert_int_equal(r.lost, 1);
    assert_int_equal(r.reordered, 1);
    assert_int_equal(ncp_dist_rx_play(&r, 3 * T), 300);
    assert_int_equal(ncp_dist_rx_play(&r, 4 * T), 400);
    /* nothing after 4: 5 holds */
    assert_int_equal(ncp_dist_rx_play(&r, 5 * T), 400);
    assert_int_equal(r.held, 1);
    /* 2 now: its period is past */
    assert_int_equal(ncp_dist_rx_put(&r, 2, 2 * T, 200), NCP_DIST_RX_STALE);
    assert_int_equal(r.stale, 1);
}

/* Feed-forward looks one period ahead: where that one is lost and a later
 * one here, the look is what the play will bridge to, not a guess. */
static void rx_peek_sees_the_bridge(void **state)
{
    (void)state;
    struct ncp_dist_rx r;
    ncp_dist_rx_init(&r, T, 0);
    int32_t nm = -1;
    assert_int_equal(ncp_dist_rx_put(&r, 1, 1 * T, 100), NCP_DIST_RX_NEW);
    assert_int_equal(ncp_dist_rx_put(&r, 2, 2 * T, 200), NCP_DIST_RX_NEW);
    assert_int_equal(ncp_dist_rx_peek(&r, 1 * T, &nm), 1);
    assert_int_equal(nm, 100);
    assert_int_equal(ncp_dist_rx_play(&r, 1 * T), 100);
    assert_int_equal(ncp_dist_rx_play(&r, 2 * T), 200);
    /* nothing after 2T yet: no look ahead */
    assert_int_equal(ncp_dist_rx_peek(&r, 3 * T, &nm), 0);
    assert_int_equal(ncp_dist_rx_put(&r, 4, 4 * T, 500), NCP_DIST_RX_NEW);
    assert_int_equal(ncp_dist_rx_peek(&r, 3 * T, &nm), 2);
    assert_int_equal(nm, 350);
    /* only the next period: one further on is not looked at */
    assert_int_equal(ncp_dist_rx_peek(&r, 5 * T, &nm), 0);
    assert_int_equal(ncp_dist_rx_play(&r, 3 * T), 350);
    assert_int_equal(r.bridged, 1);
    assert_int_equal(ncp_dist_rx_peek(&r, 4 * T, &nm), 1);
    assert_int_equal(nm, 500);
}

static void rx_duplicates_and_stale_ignored(void **state)
{
    (void)state;
    struct ncp_dist_rx r;
    ncp_dist_rx_init(&r, T, 0);
    assert_int_equal(ncp_dist_rx_put(&r, 10, 10 * T, 1), NCP_DIST_RX_NEW);
    assert_int_equal(ncp_dist_rx_put(&r, 10, 10 * T, 999), NCP_DIST_RX_DUPLICATE);
    assert_int_equal(ncp_dist_rx_put(&r, 11, 10 * T, 999), NCP_DIST_RX_DUPLICATE);
    assert_int_equal(ncp_dist_rx_play(&r, 10 * T), 1);
    assert_int_equal(ncp_dist_rx_put(&r, 10, 10 * T, 999), NCP_DIST_RX_STALE);
    assert_int_equal(ncp_dist_rx_put(&r, 3, 3 * T, 999), NCP_DIST_RX_STALE);
    assert_int_equal(ncp_dist_rx_put(&r, 500, 500 * T, 999), NCP_DIST_RX_EARLY);
    assert_int_equal(ncp_dist_rx_play(&r, 11 * T), 1);
    assert_int_equal(r.duplicate, 2);
    assert_int_equal(r.stale, 2);
    assert_int_equal(r.lost, 0);
}

static void dice_same_seed_same_losses(void **state)
{
    (void)state;
    struct ncp_msg_dice a, b, c;
    ncp_msg_dice_seed(&a, 7);
    ncp_msg_dice_seed(&b, 7);
    ncp_msg_dice_seed(&c, 8);
    int lost = 0, differ = 0;
    for (int i = 0; i < 100000; i++) {
        int x = ncp_msg_dice_drop(&a, 0.05), y = ncp_msg_dice_drop(&b, 0.05);
        assert_int_equal(x, y);
        differ += x != ncp_msg_dice_drop(&c, 0.05);
        lost += x;
    }
    assert_in_range(lost, 4700, 5300);
    assert_true(differ > 1000);
    ncp_msg_dice_seed(&a, 1);
    for (int i = 0; i < 1000; i++) {
        assert_false(ncp_msg_dice_drop(&a, 0.0));
        assert_true(ncp_msg_dice_drop(&a, 1.0));
    }
}

/* ACCDECbuf records: through the LCM type and back bit for bit, and the
 * LLC's ring tells gaps, duplicates and stale copies apart. */
static void recs_round_trip_and_ring(void **state)
{
    (void)state;
    struct ncp_accdec a, b;
    memset(&a, 0, sizeof a);
    a.s.kind = NCP_SEG_ARC;
    a.s.line = 42;
    a.s.start[0] = 0.1;
    a.s.end[8] = 1.0 / 3.0;
    a.s.axial = -2.0 / 7.0;
    a.s.r1 = 5e-17;
    a.trap.j = 1e9 / 3.0;
    a.dur = 0.123456789012345678;
    a.blend = 1;
    ncp_accdec_burst_t m, back;
    memset(&m, 0, sizeof m);
    m.count = 1;
    ncp_dist_rec_encode(&a, &m.recs[0]);
    uint8_t buf[8192];
    int n = ncp_accdec_burst_t_encode(buf, 0, sizeof buf, &m);
    assert_true(n > 0);
    assert_int_equal(ncp_accdec_burst_t_decode(buf, 0, n, &back), n);
    ncp_dist_rec_decode(&back.recs[0], &b);
    assert_memory_equal(&a.s, &b.s, sizeof a.s);
    assert_memory_equal(&a.trap, &b.trap, sizeof a.trap);
    assert_memory_equal(&a.dur, &b.dur, sizeof a.dur);
    assert_int_equal(b.blend, 1);

    union ncp_dist_rec u, got;
    u.a = a;
    struct ncp_dist_recs q;
    assert_int_equal(ncp_dist_recs_init(&q), 0);
    ncp_dist_recs_put(&q, 0, &u);
    ncp_dist_recs_put(&q, 2, &u);   /* 1 lost */
    assert_int_equal(q.have, 1);
    assert_int_equal(q.top, 3);
    assert_int_equal(q.gaps, 1);
    ncp_dist_recs_put(&q, 2, &u);
    assert_int_equal(q.duplicate, 1);
    ncp_dist_recs_put(&q, 1, &u);   /* the resend */
    assert_int_equal(q.have, 3);
    assert_int_equal(ncp_dist_recs_level(&q), 3);
    assert_int_equal(ncp_dist_recs_peek(&q, &got), 1);
    assert_memory_equal(&got.a, &a, sizeof a);
    ncp_dist_recs_pop(&q);
    ncp_dist_recs_put(&q, 0, &u);
    assert_int_equal(q.stale, 1);
    ncp_dist_recs_put(&q, 1 + NCP_DIST_RECS, &u);
    assert_int_equal(q.early, 1);
    ncp_dist_recs_pop(&q);
    ncp_dist_recs_pop(&q);
    assert_int_equal(ncp_dist_recs_peek(&q, &got), 0);
    ncp_dist_recs_free(&q);
}

/* An abort's void: the records below it are neither run nor asked for again
 * (have jumps past a gap), and those above it that came already stay. */
static void recs_skip_voids_an_abort(void **state)
{
    (void)state;
    union ncp_dist_rec u;
    memset(&u, 0, sizeof u);
    struct ncp_dist_recs q;
    assert_int_equal(ncp_dist_recs_init(&q), 0);
    ncp_dist_recs_put(&q, 0, &u);
    ncp_dist_recs_put(&q, 1, &u);
    ncp_dist_recs_put(&q, 4, &u);   /* 2 and 3 lost, 4 the next job's */
    assert_int_equal(q.have, 2);
    ncp_dist_recs_skip(&q, 4);
    assert_int_equal(q.next, 4);
    assert_int_equal(q.have, 5);
    assert_int_equal(ncp_dist_recs_level(&q), 1);
    union ncp_dist_rec got;
    assert_int_equal(ncp_dist_recs_peek(&q, &got), 1);
    ncp_dist_recs_pop(&q);
    ncp_dist_recs_skip(&q, 3);      /* an older word changes nothing */
    assert_int_equal(q.next, 5);
    ncp_dist_recs_skip(&q, 9);      /* past all received: the next come from 9 */
    assert_int_equal(q.next, 9);
    assert_int_equal(q.have, 9);
    assert_int_equal(q.top, 9);
    ncp_dist_recs_put(&q, 8, &u);
    assert_int_equal(q.stale, 1);
    ncp_dist_recs_free(&q);
}

/* DP3's and DP2's records: every double (and the op, its step) comes back
 * bit for bit through a burst. */
static void la_and_int_round_trip(void **state)
{
    (void)state;
    struct ncp_la la, la2;
    memset(&la, 0, sizeof la);
    la.s.kind = NCP_SEG_ARC;
    la.s.line = 7;
    la.s.end[8] = 1.0 / 3.0;
    la.s.u[2] = -1.0 / 7.0;
    la.s.dwell = 0.25;
    la.vmax = 100.0 / 3.0;
    la.kappa = 1e-300;
    la.v_end = 2.0 / 9.0;
    la.blend = 1;
    la.box_kappa = 1.0 / 11.0;
    la.box_a[1] = INFINITY;
    la.box_b[2] = 5.0 / 13.0;
    ncp_la_burst_t m, back;
    memset(&m, 0, sizeof m);
    m.count = 1;
    ncp_dist_la_encode(&la, &m.recs[0]);
    uint8_t buf[8192];
    int n = ncp_la_burst_t_encode(buf, 0, sizeof buf, &m);
    assert_true(n > 0);
    assert_int_equal(ncp_la_burst_t_decode(buf, 0, n, &back), n);
    ncp_dist_la_decode(&back.recs[0], &la2);
    assert_memory_equal(&la.s, &la2.s, sizeof la.s);
    assert_true(la2.vmax == la.vmax && la2.kappa == la.kappa && la2.v_end == la.v_end);
    assert_true(la2.box_kappa == la.box_kappa && isinf(la2.box_a[1]) && la2.box_b[2] == la.box_b[2]);
    assert_int_equal(la2.blend, 1);

    struct ncp_dist_op o, o2;
    memset(&o, 0, sizeof o);
    o.op = NCP_INT_REC_T_RESET;
    o.step = 123456;
    o.s = la.s;
    ncp_int_burst_t mi, backi;
    memset(&mi, 0, sizeof mi);
    mi.count = 1;
    ncp_dist_op_encode(&o, &mi.recs[0]);
    n = ncp_int_burst_t_encode(buf, 0, sizeof buf, &mi);
    assert_true(n > 0);
    assert_int_equal(ncp_int_burst_t_decode(buf, 0, n, &backi), n);
    ncp_dist_op_decode(&backi.recs[0], &o2);
    assert_int_equal(o2.op, NCP_INT_REC_T_RESET);
    assert_int_equal(o2.step, 123456);
    assert_memory_equal(&o.s, &o2.s, sizeof o.s);
}

/* A probe whose request took `up` ns and whose answer took `down`, to an HLC
 * `off` ns ahead that held it `hold` ns. */
static void probe_with(struct ncp_dist_clock *c, int64_t t1, int64_t off, int64_t up,
                       int64_t down, int64_t hold)
{
    int64_t t2 = t1 + up + off, t3 = t2 + hold, t4 = t3 - off + down;
    assert_int_equal(ncp_dist_clock_add(c, t1, t2, t3, t4), 0);
}

static void clock_shortest_round_trip_wins(void **state)
{
    (void)state;
    struct ncp_dist_clock c;
    struct ncp_dist_clock_est e;
    ncp_dist_clock_init(&c);
    assert_int_equal(ncp_dist_clock_estimate(&c, &e), -1);
    const int64_t off = -50000000;   /* the HLC's clock 50 ms behind */
    /* symmetric: exact, whatever the HLC's own time */
    probe_with(&c, 1000000000, off, 40000, 40000, 7000);
    assert_int_equal(ncp_dist_clock_estimate(&c, &e), 0);
    assert_int_equal(e.offset_ns, off);
    assert_int_equal(e.rtt_ns, 80000);
    assert_int_equal(e.jitter_ns, 0);
    /* one-sided waits lengthen the round trip and are outweighed */
    probe_with(&c, 1100000000, off, 300000, 20000, 5000);
    probe_with(&c, 1200000000, off, 20000, 500000, 5000);
    probe_with(&c, 1300000000, off, 12000, 10000, 5000);
    assert_int_equal(ncp_dist_clock_estimate(&c, &e), 0);
    assert_int_equal(e.offset_ns, off + 1000);   /* within half its round trip */
    assert_int_equal(e.rtt_ns, 22000);
    assert_int_equal(e.probes, 4);
    assert_true(e.jitter_ns > 100000);           /* the scatter the waits made */
    /* the window forgets: 8 more, each 1 us further on (drift) */
    for (int i = 0; i < NCP_DIST_CLOCK_WINDOW; i++)
        probe_with(&c, 2000000000 + i * 50000000LL, off + 1000 * i, 30000, 30000, 5000);
    assert_int_equal(ncp_dist_clock_estimate(&c, &e), 0);
    assert_int_equal(e.probes, NCP_DIST_CLOCK_WINDOW);
    assert_int_equal(e.rtt_ns, 60000);
    /* of equal round trips the newest */
    assert_int_equal(e.offset_ns, off + 1000 * (NCP_DIST_CLOCK_WINDOW - 1));
    /* nonsense is refused: the HLC held it longer than the round trip */
    assert_int_equal(ncp_dist_clock_add(&c, 0, 10, 1000, 500), -1);
    assert_int_equal(ncp_dist_clock_add(&c, 100, 10, 5, 500), -1);
}

static void clock_slew_is_bounded(void **state)
{
    (void)state;
    assert_int_equal(ncp_dist_clock_slew(0, 5000, 1000), 1000);
    assert_int_equal(ncp_dist_clock_slew(0, -5000, 1000), -1000);
    assert_int_equal(ncp_dist_clock_slew(4500, 5000, 1000), 5000);
    /* clocks far apart (a REALTIME against a MONOTONIC) do not wrap */
    assert_true(ncp_dist_clock_slew(-4000000000000000000LL, 4000000000000000000LL, 1000) ==
                -4000000000000000000LL + 1000);
}

static int64_t now_of(clockid_t id)
{
    struct timespec t;
    clock_gettime(id, &t);
    return (int64_t)t.tv_sec * 1000000000LL + t.tv_nsec;
}

/* realtime less monotonic, read within a bracket of both clocks (a 1 us
 * slack for the clocks' own steps): sign and units, however it is read */
static void realtime_offset_within_its_bracket(void **state)
{
    (void)state;
    for (int i = 0; i < 100; i++) {
        int64_t m0 = now_of(CLOCK_MONOTONIC), r0 = now_of(CLOCK_REALTIME);
        int64_t off = ncp_dist_realtime_offset();
        int64_t r1 = now_of(CLOCK_REALTIME), m1 = now_of(CLOCK_MONOTONIC);
        assert_true(off >= r0 - m1 - 1000);
        assert_true(off <= r1 - m0 + 1000);
    }
}

static void clock_url_next_port(void **state)
{
    (void)state;
    char buf[128];
    struct ncp_diag d;
    memset(&d, 0, sizeof d);
    assert_int_equal(ncp_dist_clock_url("udpm://239.255.76.67:7667?ttl=1&recv_buf_size=65536",
                                        buf, sizeof buf, &d), NCP_OK);
    assert_string_equal(buf, "udpm://239.255.76.67:7668?ttl=1");
    assert_int_equal(ncp_dist_clock_url("udpm://239.1.2.3", buf, sizeof buf, &d), NCP_OK);
    assert_string_equal(buf, "udpm://239.1.2.3:7668?ttl=0");
    assert_int_not_equal(ncp_dist_clock_url("udpm://239.1.2.3:65535", buf, sizeof buf, &d),
                         NCP_OK);
    assert_non_null(strstr(d.msg, "next port"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(fine_round_trip),
        cmocka_unit_test(nm_range),
        cmocka_unit_test(rx_in_order),
        cmocka_unit_test(rx_gap_held_and_counted),
        cmocka_unit_test(rx_peek_sees_the_bridge), cmocka_unit_test(rx_duplicates_and_stale_ignored),
        cmocka_unit_test(dice_same_seed_same_losses),
        cmocka_unit_test(recs_skip_voids_an_abort),
        cmocka_unit_test(recs_round_trip_and_ring),
        cmocka_unit_test(la_and_int_round_trip),
        cmocka_unit_test(clock_shortest_round_trip_wins),
        cmocka_unit_test(clock_slew_is_bounded),
        cmocka_unit_test(clock_url_next_port),
        cmocka_unit_test(realtime_offset_within_its_bracket),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
