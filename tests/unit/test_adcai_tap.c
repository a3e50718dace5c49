/* The distributed ADCAI's record path without the network: what the chain
 * taps (the sums a DP2 or DP3 HLC sends, or a DP1 LLC's own NCK hands over)
 * fed through one axis's own stages, as a cnc-axis does, gives every
 * setpoint of the central chain exactly, and each tap says whether any axis
 * moves in it; and the DP2 / DP3 messages' codec against lcm-gen's. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "ncpar/adcai.h"
#include "ncpar/dist.h"
#include "seg_line.h"

#define MAXTAP 200000

struct taps {
    size_t n;
    struct ncp_adcai_tap *t;
};

static void on_tap(void *ctx, const struct ncp_adcai_tap *t)
{
    struct taps *c = ctx;
    if (c->n < MAXTAP)
        c->t[c->n++] = *t;
}

/* Lines at several feeds, continuous and with exact stops, on a machine of
 * profile prof and ratio servo periods per rough period. */
static void replay_case(enum ncp_profile prof, int ratio, int dp)
{
    struct ncp_machine_cfg c;
    ncp_machine_cfg_default(&c);
    c.profile = prof;
    c.nck = NCP_NCK_ADCAI;
    c.planning_period = ratio * c.servo_period;
    const double o[NCP_AXES] = { 1, -2, 0.5 };
    struct ncp_adcai *a = ncp_adcai_new(&c, o);
    assert_non_null(a);
    struct taps taps = { 0, calloc(MAXTAP, sizeof(struct ncp_adcai_tap)) };
    assert_non_null(taps.t);
    ncp_adcai_set_tap(a, on_tap, &taps);
    double p[3] = { 1, -2, 0.5 };
    for (int k = 0; k < 12; k++) {
        double q[3] = { p[0] + 3 + k % 4, p[1] + (k % 2 ? 2.5 : -1.25), p[2] - 0.1 * (k % 3) };
        struct ncp_seg s = line_seg(p, q, k % 3 ? 3000 : 700, k % 5 == 4 ? NCP_TERM_STOP
                                                                          : NCP_TERM_CONTINUOUS);
        ncp_adcai_push(a, &s);
        memcpy(p, q, sizeof p);
    }
    ncp_adcai_finish(a);
    struct ncp_setpoint sp;
    int guard = 0;
    while (ncp_adcai_step(a, &sp) && ++guard < MAXTAP)
        ;
    assert_true(taps.n > 1000);
    /* a standstill is a sample no axis moves in: DP1's LLCs split the
     * samples into motion runs there, as the HLC splits its path */
    int64_t prev[NCP_AXES] = { 0 };
    for (int j = 0; j < 3; j++)
        prev[j] = ncp_adcai_quantise(o[j]);
    size_t rests = 0;
    for (size_t i = 0; i < taps.n; i++) {
        int moved = 0;
        for (int j = 0; j < NCP_AXES; j++)
            moved |= taps.t[i].pos[j] != prev[j];
        if (moved != taps.t[i].moved)
            fail_msg("setpoint %zu: moved %d, its positions say %d", i, taps.t[i].moved, moved);
        rests += !moved;
        memcpy(prev, taps.t[i].pos, sizeof prev);
    }
    assert_true(rests > 0);
    int n[2];
    assert_int_equal(ncp_adcai_windows(&c, c.servo_period * ratio, n), 0);
    for (int j = 0; j < 3; j++) {
        /* one LLC: its axis's input only, the others left at zero */
        struct ncp_adcai_accdec *acc = ncp_adcai_accdec_new(n[0], n[1]);
        struct ncp_adcai_fine *fine =
            ncp_adcai_fine_new(ratio, prof == NCP_PROFILE_SCURVE ? 2 : 1);
        int32_t in_sum = 0;
        int64_t pos = ncp_adcai_quantise(o[j]);
        for (size_t i = 0; i < taps.n; i++) {
            const struct ncp_adcai_tap *t = &taps.t[i];
            int32_t out[NCP_AXES];
            if (t->start) {
                int32_t in[NCP_AXES] = { 0 };
                int32_t sum = dp == 2 ? t->rough[j] : t->accdec[j];
                in[j] = (int32_t)((uint32_t)sum - (uint32_t)in_sum);
                in_sum = sum;
                if (dp == 2) {
                    ncp_adcai_accdec_step(acc, in, out);
                    in[j] = out[j];
                }
                ncp_adcai_fine_load(fine, in);
            }
            ncp_adcai_fine_step(fine, out);
            pos += out[j];
            if (pos != t->pos[j])
                fail_msg("DP%d axis %d setpoint %zu: %lld nm, the chain %lld", dp, j, i,
                         (long long)pos, (long long)t->pos[j]);
        }
        ncp_adcai_accdec_free(acc);
        ncp_adcai_fine_free(fine);
    }
    free(taps.t);
    ncp_adcai_free(a);
}

static void test_dp2_trapezoid(void **state)
{
    (void)state;
    replay_case(NCP_PROFILE_TRAPEZOID, 1, 2);
}

static void test_dp2_scurve_ratio10(void **state)
{
    (void)state;
    replay_case(NCP_PROFILE_SCURVE, 10, 2);
}

static void test_dp3_scurve_ratio4(void **state)
{
    (void)state;
    replay_case(NCP_PROFILE_SCURVE, 4, 3);
}

static void test_codec(void **state)
{
    (void)state;
    ncp_dist_ai_init();
    for (int dp = 2; dp <= 3; dp++) {
        struct ncp_dist_ai r = { 7, NCP_DIST_HLC_ID, 987654321000LL, -3, 1, 3,
                                   { -1, 2147483647, 5 } };
        uint8_t buf[128];
        int len = ncp_dist_encode_ai(buf, sizeof buf, dp, &r);
        /* the paper's 1+4N (DP2) or 4N (DP3), plus fingerprint, seq, sender,
         * stream index, job, n */
        assert_int_equal(len, 8 + 4 + 2 + 8 + 4 + (dp == 2) + 1 + 4 * 3);
        struct ncp_dist_ai h;
        assert_int_equal(ncp_dist_decode_ai(buf, (size_t)len, dp, &h), 0);
        assert_memory_equal(h.sum_nm, r.sum_nm, 3 * sizeof(int32_t));
        assert_true(h.seq == 7 && h.k == r.k && h.job == -3 && h.n == 3 && h.flag == (dp == 2));
        if (dp == 2) {
            ncp_rough_ipo_t g;
            memset(&g, 0, sizeof g);
            assert_int_equal(ncp_rough_ipo_t_decode(buf, 0, len, &g), len);
            assert_int_equal(g.sum_nm[1], 2147483647);
            assert_int_equal(g.flag, 1);
            assert_int_equal(g.job, -3);
            ncp_rough_ipo_t_decode_cleanup(&g);
        } else {
            ncp_accdec_ai_t g;
            memset(&g, 0, sizeof g);
            assert_int_equal(ncp_accdec_ai_t_decode(buf, 0, len, &g), len);
            assert_int_equal(g.sum_nm[0], -1);
            ncp_accdec_ai_t_decode_cleanup(&g);
        }
        /* the other point's type, truncated, padded */
        assert_int_equal(ncp_dist_decode_ai(buf, (size_t)len, 5 - dp, &h), -1);
        assert_int_equal(ncp_dist_decode_ai(buf, (size_t)len - 1, dp, &h), -1);
        assert_int_equal(ncp_dist_decode_ai(buf, (size_t)len + 1, dp, &h), -1);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_dp2_trapezoid),
        cmocka_unit_test(test_dp2_scurve_ratio10),
        cmocka_unit_test(test_dp3_scurve_ratio4),
        cmocka_unit_test(test_codec),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
