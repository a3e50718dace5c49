/* The pipeline's lock-free ring: in-place use, wrap-around, 2- and 3-stage
 * stress across threads, end of data, and shutdown of blocked stages. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "../../src/pipeline/ring.h"

static struct ncp_ring *ring_new(size_t elem, uint32_t cap, unsigned stages)
{
    struct ncp_ring *r = aligned_alloc(64, sizeof *r);
    assert_non_null(r);
    assert_int_equal(ncp_ring_init_staged(r, elem, cap, stages), 0);
    return r;
}

static void ring_free(struct ncp_ring *r)
{
    ncp_ring_destroy(r);
    free(r);
}

static void sleep_ms(int ms)
{
    struct timespec ts = { 0, ms * 1000000L };
    nanosleep(&ts, NULL);
}

static void test_capacity_rounds_up(void **state)
{
    (void)state;
    assert_int_equal(ncp_ring_capacity(0), 1);
    assert_int_equal(ncp_ring_capacity(1), 1);
    assert_int_equal(ncp_ring_capacity(5), 8);
    assert_int_equal(ncp_ring_capacity(64), 64);
    assert_int_equal(ncp_ring_capacity(UINT32_MAX), NCP_RING_MAX_CAPACITY);
    struct ncp_ring r;
    assert_int_not_equal(ncp_ring_init_staged(&r, 8, 4, 1), 0);
    assert_int_not_equal(ncp_ring_init_staged(&r, 0, 4, 2), 0);
}

/* A big element is written through the reserved pointer and read back through
 * the very same memory: nothing is copied. */
struct big {
    uint64_t seq;
    char payload[5000];
};

static void test_in_place_reserve_commit(void **state)
{
    (void)state;
    struct ncp_ring *r = ring_new(sizeof(struct big), 3, 2);
    assert_int_equal(ncp_ring_cap(r), 4);
    struct big *w = ncp_ring_reserve(r);
    assert_non_null(w);
    assert_int_equal((uintptr_t)w % 64, 0);
    w->seq = 42;
    memset(w->payload, 'x', sizeof w->payload);
    ncp_ring_commit(r);
    struct big *rd = ncp_ring_peek(r);
    assert_ptr_equal(rd, w);
    assert_int_equal(rd->seq, 42);
    assert_int_equal(rd->payload[4999], 'x');
    /* peek again without release: still the same element */
    assert_ptr_equal(ncp_ring_peek(r), w);
    ncp_ring_release(r);
    ring_free(r);
}

static void test_wrap_around_single_thread(void **state)
{
    (void)state;
    struct ncp_ring *r = ring_new(sizeof(uint32_t), 4, 2);
    for (uint32_t round = 0; round < 100; round++) {
        /* fill completely, then drain: every lap crosses the wrap point */
        for (uint32_t i = 0; i < 4; i++) {
            uint32_t *s = ncp_ring_reserve(r);
            assert_non_null(s);
            *s = round * 4 + i;
            ncp_ring_commit(r);
        }
        for (uint32_t i = 0; i < 4; i++) {
            assert_int_equal(*(uint32_t *)ncp_ring_stage_peek(r, 1, i), round * 4 + i);
        }
        for (uint32_t i = 0; i < 4; i++) {
            uint32_t *s = ncp_ring_peek(r);
            assert_int_equal(*s, round * 4 + i);
            ncp_ring_release(r);
        }
    }
    assert_int_equal(ncp_ring_waits(r, 0), 0);
    ring_free(r);
}

static void test_close_drains_then_ends(void **state)
{
    (void)state;
    struct ncp_ring *r = ring_new(sizeof(int), 8, 2);
    for (int i = 0; i < 3; i++) {
        int *s = ncp_ring_reserve(r);
        *s = i;
        ncp_ring_commit(r);
    }
    ncp_ring_close(r);
    assert_null(ncp_ring_reserve(r));
    for (int i = 0; i < 3; i++) {
        int *s = ncp_ring_peek(r);
        assert_non_null(s);
        assert_int_equal(*s, i);
        ncp_ring_release(r);
    }
    assert_null(ncp_ring_peek(r));
    assert_null(ncp_ring_peek(r));
    ring_free(r);
}

/* ---- runs of elements: variable-length records across threads ------------ */

#define RUNS_N 200000u
#define RUN_PAD 0xFFFFFFFFu

/* A record of 1..17 units: its length, then its sequence number repeated. */
static uint32_t run_len(uint32_t i)
{
    return 1 + (i * 7u) % 17u;
}

static void *runs_producer(void *arg)
{
    struct ncp_ring *r = arg;
    for (uint32_t i = 0; i < RUNS_N; i++) {
        uint32_t k = run_len(i);
        uint32_t to_end = ncp_ring_to_end(r, 0);
        if (k > to_end) {
            uint32_t *pad = ncp_ring_reserve_n(r, to_end);
            if (!pad)
                return NULL;
            pad[0] = RUN_PAD;
            ncp_ring_commit_n(r, to_end);
        }
        uint32_t *rec = ncp_ring_reserve_n(r, k);
        if (!rec)
            return NULL;
        rec[0] = k;
        for (uint32_t u = 1; u < k; u++)
            rec[u] = i;
        ncp_ring_commit_n(r, k);
    }
    ncp_ring_close(r);
    ncp_ring_wake_owed();
    return NULL;
}

static void test_runs_across_threads(void **state)
{
    (void)state;
    struct ncp_ring *r = ring_new(sizeof(uint32_t), 64, 2);
    ncp_ring_set_batch(r, 8);
    pthread_t t;
    assert_int_equal(pthread_create(&t, NULL, runs_producer, r), 0);
    uint32_t i = 0, bad = 0;
    for (;;) {
        const uint32_t *rec = ncp_ring_stage_peek(r, 1, 0);
        if (!rec)
            break;
        if (rec[0] == RUN_PAD) {
            ncp_ring_stage_release_n(r, 1, ncp_ring_to_end(r, 1));
            continue;
        }
        uint32_t k = rec[0];
        bad += k != run_len(i);
        if (k > 1 && !ncp_ring_stage_peek(r, 1, k - 1)) {
            bad++;
            break;
        }
        /* the whole record lies in one piece of memory */
        for (uint32_t u = 1; u < k; u++)
            bad += rec[u] != i;
        ncp_ring_stage_release_n(r, 1, k);
        i++;
    }
    ncp_ring_wake_owed();
    pthread_join(t, NULL);
    assert_int_equal(bad, 0);
    assert_int_equal(i, RUNS_N);
    ring_free(r);
}

static void test_reserve_n_limits(void **state)
{
    (void)state;
    struct ncp_ring *r = ring_new(sizeof(uint32_t), 16, 2);
    assert_null(ncp_ring_reserve_n(r, 0));
    assert_null(ncp_ring_reserve_n(r, 17));
    assert_non_null(ncp_ring_reserve_n(r, 16));
    ncp_ring_commit_n(r, 10);
    assert_int_equal(ncp_ring_to_end(r, 0), 6);
    assert_non_null(ncp_ring_stage_peek(r, 1, 9));
    ncp_ring_stage_release_n(r, 1, 10);
    assert_int_equal(ncp_ring_to_end(r, 1), 6);
    ring_free(r);
}

/* ---- two threads ---------------------------------------------------------- */

#define STRESS_N 300000u

struct stress {
    struct ncp_ring *r;
    uint64_t bad;
    uint64_t got;
};

static void *stress_producer(void *arg)
{
    struct stress *s = arg;
    for (uint64_t i = 0; i < STRESS_N; i++) {
        uint64_t *slot = ncp_ring_reserve(s->r);
        if (!slot)
            break;
        slot[0] = i;
        slot[1] = ~i;
        ncp_ring_commit(s->r);
    }
    ncp_ring_close(s->r);
    return NULL;
}

static void *stress_consumer(void *arg)
{
    struct stress *s = arg;
    const uint64_t *slot;
    uint64_t expect = 0;
    while ((slot = ncp_ring_peek(s->r)) != NULL) {
        if (slot[0] != expect || slot[1] != ~expect)
            s->bad++;
        expect++;
        ncp_ring_release(s->r);
    }
    s->got = expect;
    return NULL;
}

/* no_spin: every wait goes straight to the futex (more threads than CPUs);
 * the hand-off must lose and repeat nothing either way. */
static void spsc_stress(int no_spin)
{
    /* a tiny ring forces constant full/empty waits and sleeps */
    struct stress s = { ring_new(2 * sizeof(uint64_t), 16, 2), 0, 0 };
    if (no_spin)
        ncp_ring_set_spin(s.r, 0);
    pthread_t p, c;
    pthread_create(&c, NULL, stress_consumer, &s);
    pthread_create(&p, NULL, stress_producer, &s);
    pthread_join(p, NULL);
    pthread_join(c, NULL);
    assert_int_equal(s.bad, 0);
    assert_int_equal(s.got, STRESS_N);
    if (no_spin)
        assert_true(ncp_ring_sleeps(s.r, 0) + ncp_ring_sleeps(s.r, 1) > 0);
    ring_free(s.r);
}

static void test_spsc_stress_two_threads(void **state)
{
    (void)state;
    spsc_stress(0);
}

static void test_spsc_stress_no_spin(void **state)
{
    (void)state;
    spsc_stress(1);
}

/* producer -> middle (completes in place) -> last (checks, hands back) */
static void *stage_middle(void *arg)
{
    struct stress *s = arg;
    uint64_t *slot;
    while ((slot = ncp_ring_stage_peek(s->r, 1, 0)) != NULL) {
        slot[1] = slot[0] * 3;
        ncp_ring_stage_release(s->r, 1);
    }
    return NULL;
}

static void *stage_last(void *arg)
{
    struct stress *s = arg;
    const uint64_t *slot;
    uint64_t expect = 0;
    while ((slot = ncp_ring_stage_peek(s->r, 2, 0)) != NULL) {
        if (slot[0] != expect || slot[1] != expect * 3)
            s->bad++;
        expect++;
        ncp_ring_stage_release(s->r, 2);
    }
    s->got = expect;
    return NULL;
}

static void *staged_producer(void *arg)
{
    struct stress *s = arg;
    for (uint64_t i = 0; i < STRESS_N / 2; i++) {
        uint64_t *slot = ncp_ring_reserve(s->r);
        if (!slot)
            break;
        slot[0] = i;
        slot[1] = 0;
        ncp_ring_commit(s->r);
    }
    ncp_ring_close(s->r);
    return NULL;
}

static void test_three_stage_stress(void **state)
{
    (void)state;
    struct stress s = { ring_new(2 * sizeof(uint64_t), 8, 3), 0, 0 };
    pthread_t p, m, l;
    pthread_create(&l, NULL, stage_last, &s);
    pthread_create(&m, NULL, stage_middle, &s);
    pthread_create(&p, NULL, staged_producer, &s);
    pthread_join(p, NULL);
    pthread_join(m, NULL);
    pthread_join(l, NULL);
    assert_int_equal(s.bad, 0);
    assert_int_equal(s.got, STRESS_N / 2);
    ring_free(s.r);
}

/* ---- shutdown of blocked stages ------------------------------------------- */

struct blocked {
    struct ncp_ring *r;
    void *result;
};

static void *block_in_peek(void *arg)
{
    struct blocked *b = arg;
    b->result = ncp_ring_peek(b->r);
    return NULL;
}

static void *block_in_reserve(void *arg)
{
    struct blocked *b = arg;
    b->result = ncp_ring_reserve(b->r);
    return NULL;
}

static void test_close_wakes_blocked_consumer(void **state)
{
    (void)state;
    struct blocked b = { ring_new(sizeof(int), 4, 2), (void *)1 };
    pthread_t t;
    pthread_create(&t, NULL, block_in_peek, &b);
    sleep_ms(20); /* long enough for it to give up spinning and sleep */
    ncp_ring_close(b.r);
    pthread_join(t, NULL);
    assert_null(b.result);
    ring_free(b.r);
}

static void test_abort_wakes_blocked_producer(void **state)
{
    (void)state;
    struct blocked b = { ring_new(sizeof(int), 2, 2), (void *)1 };
    for (int i = 0; i < 2; i++) {
        assert_non_null(ncp_ring_reserve(b.r));
        ncp_ring_commit(b.r);
    }
    pthread_t t;
    pthread_create(&t, NULL, block_in_reserve, &b);
    sleep_ms(20);
    ncp_ring_abort(b.r);
    pthread_join(t, NULL);
    assert_null(b.result);
    assert_true(ncp_ring_aborted(b.r));
    /* abort beats data still in the ring */
    assert_null(ncp_ring_peek(b.r));
    assert_true(ncp_ring_waits(b.r, 0) >= 1);
    ring_free(b.r);
}

static void test_abort_wakes_blocked_middle_stage(void **state)
{
    (void)state;
    struct ncp_ring *r = ring_new(sizeof(int), 4, 3);
    struct blocked b = { r, (void *)1 };
    pthread_t t;
    pthread_create(&t, NULL, block_in_peek, &b); /* last stage: waits for stage 1 */
    assert_non_null(ncp_ring_reserve(r));
    ncp_ring_commit(r);
    sleep_ms(20);
    ncp_ring_abort(r);
    pthread_join(t, NULL);
    assert_null(b.result);
    ring_free(r);
}

/* A released slot wakes a sleeping producer (the futex path, not the spin). */
static void test_release_wakes_sleeping_producer(void **state)
{
    (void)state;
    struct blocked b = { ring_new(sizeof(int), 1, 2), NULL };
    assert_non_null(ncp_ring_reserve(b.r));
    ncp_ring_commit(b.r);
    pthread_t t;
    pthread_create(&t, NULL, block_in_reserve, &b);
    sleep_ms(20);
    assert_non_null(ncp_ring_peek(b.r));
    ncp_ring_release(b.r);
    pthread_join(t, NULL);
    assert_non_null(b.result);
    assert_true(ncp_ring_sleeps(b.r, 0) >= 1);
    ring_free(b.r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_capacity_rounds_up),
        cmocka_unit_test(test_in_place_reserve_commit),
        cmocka_unit_test(test_wrap_around_single_thread),
        cmocka_unit_test(test_close_drains_then_ends),
        cmocka_unit_test(test_spsc_stress_two_threads),
        cmocka_unit_test(test_spsc_stress_no_spin),
        cmocka_unit_test(test_three_stage_stress),
        cmocka_unit_test(test_close_wakes_blocked_consumer),
        cmocka_unit_test(test_abort_wakes_blocked_producer),
        cmocka_unit_test(test_abort_wakes_blocked_middle_stage),
        cmocka_unit_test(test_release_wakes_sleeping_producer),
        cmocka_unit_test(test_runs_across_threads),
        cmocka_unit_test(test_reserve_n_limits),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
