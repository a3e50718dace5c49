/* The ring's sleep protocol against the wake-up that came too early: a waker
 * paying a wake-up it owed from an earlier publish takes a waiter's sleeper
 * flag the moment the waiter raised it, and bumps the event. That once made
 * the waiter sleep with no flag for later publishers to see (make bench-parse
 * hung in 1 of 30 runs of att -j 2); the waiter must read its futex key before
 * it raises the flag. The window is two instructions wide, so this test opens
 * it on purpose: ring.c built with NCP_RING_TEST_HOOKS calls back right after
 * the flag goes up, and the callback plays the early waker there. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include <limits.h>
#include <linux/futex.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

#include "../../src/pipeline/ring.h"

extern void (*ncp_ring_test_flag_raised)(struct ncp_ring_stage *st);

static _Atomic int steals_left;

/* The early waker: what ring.c's wake_sleeper does for a debt. */
static void steal_flag(struct ncp_ring_stage *st)
{
    if (atomic_load(&steals_left) <= 0 || !atomic_exchange(&st->sleepers, 0))
        return;
    atomic_fetch_sub(&steals_left, 1);
    atomic_fetch_add(&st->event, 1);
    syscall(SYS_futex, (uint32_t *)&st->event, FUTEX_WAKE_PRIVATE, INT_MAX, NULL, NULL, 0);
}

struct waiter {
    struct ncp_ring *r;
    _Atomic int got;
};

static void *wait_for_one(void *arg)
{
    struct waiter *w = arg;
    const uint64_t *v = ncp_ring_peek(w->r);
    atomic_store(&w->got, v && *v == 42 ? 1 : -1);
    return NULL;
}

static void test_waiter_survives_a_stolen_flag(void **state)
{
    (void)state;
    struct ncp_ring *r = aligned_alloc(64, sizeof *r);
    assert_non_null(r);
    assert_int_equal(ncp_ring_init(r, sizeof(uint64_t), 16), 0);
    ncp_ring_test_flag_raised = steal_flag;
    atomic_store(&steals_left, 3);
    struct waiter w = { r, 0 };
    pthread_t t;
    assert_int_equal(pthread_create(&t, NULL, wait_for_one, &w), 0);
    /* the waiter spins, then raises its flag and has it taken, three times */
    for (int i = 0; i < 2000 && atomic_load(&steals_left) > 0; i++)
        usleep(1000);
    assert_int_equal(atomic_load(&steals_left), 0);
    usleep(20000); /* let it go to sleep for good, if it is going to */
    uint64_t *slot = ncp_ring_reserve(r);
    assert_non_null(slot);
    *slot = 42;
    ncp_ring_commit(r);
    ncp_ring_wake_owed(); /* publish now, not at the end of a batch */
    int got = 0;
    for (int i = 0; i < 2000 && (got = atomic_load(&w.got)) == 0; i++)
        usleep(1000);
    if (got == 0) {
        ncp_ring_abort(r); /* free the waiter before failing */
        pthread_join(t, NULL);
        fail_msg("the waiter slept through a publish after its flag was taken (lost wake-up)");
    }
    pthread_join(t, NULL);
    assert_int_equal(got, 1);
    ncp_ring_test_flag_raised = NULL;
    ncp_ring_destroy(r);
    free(r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_waiter_survives_a_stolen_flag),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
