/* Staged lock-free ring (see ring.h). Each position is written by its own stage
 * only, with release stores; the other stages read it with acquire loads, which
 * is what hands the slot contents over. Sleeping uses an event count per
 * position: a waiter reads `event`, announces itself in `sleepers`, re-checks
 * its condition and sleeps only if `event` is unchanged; a stage that moves its
 * position and sees a sleeper bumps `event` and wakes it. The seq_cst fence on
 * one side and seq_cst accesses on the other make a lost wake-up impossible. */
#include "ring.h"

#include "futex.h"

#include <stdlib.h>
#include <string.h>

/* Short: the machine may have fewer cores than pipeline threads, and a spinning
 * thread then steals the CPU from the one it waits for. */
#define NCP_RING_SPIN 128
#define NCP_RING_MAX_BATCH 32u

/* Slots are prefaulted before the start (ncpar/mem.h): the stage threads
 * then never stop for a first-touch page fault, which costs microseconds
 * each in a virtual machine. They are on 4 KB pages (mem.h says why). */
uint32_t ncp_ring_capacity(uint32_t want)
{
    uint32_t c = 1;
    while (c < want && c < NCP_RING_MAX_CAPACITY)
        c <<= 1;
    return c;
}

int ncp_ring_init_staged(struct ncp_ring *r, size_t elem_size, uint32_t capacity,
                         unsigned n_stages)
{
    memset(r, 0, sizeof *r);
    if (n_stages < 2 || n_stages > NCP_RING_MAX_STAGES || elem_size == 0)
        return -1;
    uint32_t cap = ncp_ring_capacity(capacity);
    /* Large slots get their own cache lines so neighbouring stages do not
     * share one; small ones are packed. */
    size_t align = elem_size >= 64 ? 64 : 8;
    size_t stride = (elem_size + align - 1) / align * align;
    size_t bytes = ((size_t)cap * stride + 63) / 64 * 64;
    if (ncp_mem_map(&r->mem, bytes) != 0)
        return -1;
    r->slots = r->mem.p;
    r->n_stages = n_stages;
    r->mask = cap - 1;
    r->stride = stride;
    r->batch = cap / 8 > NCP_RING_MAX_BATCH ? NCP_RING_MAX_BATCH : cap / 8 ? cap / 8 : 1;
    r->spin = NCP_RING_SPIN;
    for (unsigned s = 0; s < NCP_RING_MAX_STAGES; s++) {
        atomic_init(&r->stage[s].pos, 0);
        atomic_init(&r->stage[s].sleepers, 0);
        atomic_init(&r->stage[s].event, 0);
        atomic_init(&r->stage[s].wake_at, 0);
        r->stage[s].next = 0;
    }
    atomic_init(&r->state, 0);
    return 0;
}

void ncp_ring_reset(struct ncp_ring *r)
{
    for (unsigned s = 0; s < NCP_RING_MAX_STAGES; s++) {
        struct ncp_ring_stage *st = &r->stage[s];
        atomic_store(&st->pos, 0);
        atomic_store(&st->sleepers, 0);
        atomic_store(&st->wake_at, 0);
        /* event keeps counting: a futex word that went back could match the
         * key of a waiter from the last run that has not yet gone to sleep */
        st->next = 0;
        st->seen = 0;
        st->waits = 0;
        st->sleeps = 0;
    }
    atomic_store(&r->state, 0);
}

int ncp_ring_init(struct ncp_ring *r, size_t elem_size, uint32_t capacity)
{
    return ncp_ring_init_staged(r, elem_size, capacity, 2);
}

static void forget(const struct ncp_ring *r);

void ncp_ring_destroy(struct ncp_ring *r)
{
    forget(r);
    ncp_mem_unmap(&r->mem);
    r->slots = NULL;
}

uint32_t ncp_ring_cap(const struct ncp_ring *r)
{
    return r->mask + 1;
}

static void *slot_at(const struct ncp_ring *r, uint32_t pos)
{
    return r->slots + (size_t)(pos & r->mask) * r->stride;
}

static unsigned awaited_stage(const struct ncp_ring *r, unsigned s)
{
    return s == 0 ? r->n_stages - 1 : s - 1;
}

/* 1: stage s may proceed to its k-th element, 0: must wait, -1: never will. */
static int ready(struct ncp_ring *r, unsigned s, uint32_t k, memory_order mo)
{
    struct ncp_ring_stage *st = &r->stage[s];
    uint32_t own = st->next;
    uint32_t state = atomic_load_explicit(&r->state, mo);
    if (state & NCP_RING_ABORT)
        return -1;
    if (s == 0) { /* the producer: room for k + 1 elements */
        if (state & NCP_RING_EOF)
            return -1;
        st->seen = atomic_load_explicit(&r->stage[r->n_stages - 1].pos, mo);
        return own + k - st->seen <= r->mask ? 1 : 0;
    }
    st->seen = atomic_load_explicit(&r->stage[s - 1].pos, mo);
    if (st->seen - own > k)
        return 1;
    if (!(state & NCP_RING_EOF))
        return 0;
    /* EOF was published after the producer's last commit, so pos[0] is final
     * here; the data ended for us once the stage before has passed it all. */
    return st->seen == atomic_load_explicit(&r->stage[0].pos, mo) ? -1 : 0;
}

/* Sleepers not yet worth waking (below their wake_at), owed a wake-up by this
 * thread before it waits itself: without that, two stages could each sleep
 * waiting for the other's next batch. */
#define NCP_RING_MAX_OWED 32
static _Thread_local struct ncp_ring_stage *owed[NCP_RING_MAX_OWED];
static _Thread_local int n_owed;

static void wake(struct ncp_ring_stage *st)
{
    atomic_fetch_add(&st->event, 1);
    ncp_futex_wake_all(&st->event);
}

/* Each position has at most one sleeper (its one awaiting stage), and taking
 * its flag makes sure a batch of advances costs a single wake syscall. */
static void wake_sleeper(struct ncp_ring_stage *st)
{
    if (atomic_exchange(&st->sleepers, 0) != 0)
        wake(st);
}

/* Stages whose position this thread has moved but not yet published. */
struct ncp_ring_unpublished {
    struct ncp_ring *r;
    unsigned s;
};
static _Thread_local struct ncp_ring_unpublished unpublished[NCP_RING_MAX_OWED];
static _Thread_local int n_unpublished;

static void publish(struct ncp_ring *r, unsigned s);

static void pay_owed(void)
{
    /* first: publishing may defer more wake-ups */
    for (int i = 0; i < n_unpublished; i++)
        publish(unpublished[i].r, unpublished[i].s);
    n_unpublished = 0;
    for (int i = 0; i < n_owed; i++)
        wake_sleeper(owed[i]);
    n_owed = 0;
}

void ncp_ring_wake_owed(void)
{
    pay_owed();
}

/* A ring going away must not stay on this thread's lists (the stage threads
 * emptied theirs before they exited). */
static void forget(const struct ncp_ring *r)
{
    int k = 0;
    for (int i = 0; i < n_unpublished; i++)
        if (unpublished[i].r != r)
            unpublished[k++] = unpublished[i];
    n_unpublished = k;
    k = 0;
    for (int i = 0; i < n_owed; i++) {
        int mine = 0;
        for (unsigned s = 0; s < NCP_RING_MAX_STAGES; s++)
            mine |= owed[i] == &r->stage[s];
        if (!mine)
            owed[k++] = owed[i];
    }
    n_owed = k;
}

static void owe(struct ncp_ring_stage *st)
{
    for (int i = 0; i < n_owed; i++)
        if (owed[i] == st)
            return;
    if (n_owed == NCP_RING_MAX_OWED)
        wake_sleeper(st);
    else
        owed[n_owed++] = st;
}

/* The awaited position at which stage s wants waking: enough for its k-th
 * element plus up to half a ring more, so one wake-up serves a batch. */
static uint32_t wake_target(const struct ncp_ring *r, unsigned s, uint32_t k)
{
    uint32_t own = r->stage[s].next;
    uint32_t cap = r->mask + 1;
    uint32_t batch = cap / 2 > 0 ? cap / 2 - 1 : 0;
    if (batch > r->mask - k)
        batch = r->mask - k;
    if (s == 0)
        return own + k - r->mask + batch;
    if (batch > r->mask - k)
        batch = r->mask - k;
    return own + k + 1 + batch;
}

#ifdef NCP_RING_TEST_HOOKS
/* tests/unit/test_ring_race.c: called the moment a waiter has raised its
 * sleeper flag, to play a waker that takes it there. Not in the library. */
void (*ncp_ring_test_flag_raised)(struct ncp_ring_stage *st);
#define FLAG_RAISED(st)                                                        \
    do {                                                                       \
        if (ncp_ring_test_flag_raised)                                         \
            ncp_ring_test_flag_raised(st);                                     \
    } while (0)
#else
#define FLAG_RAISED(st) ((void)0)
#endif

static int wait_ready(struct ncp_ring *r, unsigned s, uint32_t k)
{
    struct ncp_ring_stage *st = &r->stage[s];
    struct ncp_ring_stage *aw = &r->stage[awaited_stage(r, s)];
    int rc = ready(r, s, k, memory_order_acquire);
    if (rc > 0)
        return rc;
    pay_owed();
    /* this thread's own unpublished items may have been what was missing */
    rc = ready(r, s, k, memory_order_acquire);
    if (rc != 0)
        return rc;
    st->waits++;
    for (uint32_t i = 0; i < r->spin; i++) {
        ncp_cpu_relax();
        rc = ready(r, s, k, memory_order_acquire);
        if (rc != 0)
            return rc;
    }
    for (;;) {
        /* The key before the flag: a waker may take the flag the moment it is
         * set (paying a wake-up it owed from an earlier publish) and bump the
         * event; read after the flag, the key would already include that bump,
         * the futex would sleep, and with the flag gone no later publish would
         * wake it. Read first, the bump makes the futex return at once. */
        uint32_t key = atomic_load(&aw->event);
        atomic_store_explicit(&aw->wake_at, wake_target(r, s, k), memory_order_relaxed);
        atomic_store(&aw->sleepers, 1);
        FLAG_RAISED(aw);
        rc = ready(r, s, k, memory_order_seq_cst);
        if (rc == 0) {
            st->sleeps++;
            ncp_futex_wait(&aw->event, key, NULL);
            rc = ready(r, s, k, memory_order_acquire);
        }
        atomic_store_explicit(&aw->sleepers, 0, memory_order_relaxed);
        if (rc != 0)
            return rc;
    }
}

/* Publish stage s's position and wake whoever sleeps on it, once its batch
 * is complete. */
static void publish(struct ncp_ring *r, unsigned s)
{
    struct ncp_ring_stage *st = &r->stage[s];
    uint32_t p = st->next;
    if (atomic_load_explicit(&st->pos, memory_order_relaxed) == p)
        return;
    atomic_store_explicit(&st->pos, p, memory_order_release);
    atomic_thread_fence(memory_order_seq_cst);
    /* acquire: the sleeper's wake_at was stored before its flag */
    if (atomic_load_explicit(&st->sleepers, memory_order_acquire) == 0)
        return;
    if ((int32_t)(p - atomic_load_explicit(&st->wake_at, memory_order_relaxed)) >= 0)
        wake_sleeper(st);
    else
        owe(st);
}

/* Stage s passed one more element on: published at the end of a batch, else
 * remembered so this thread publishes it before it can wait. */
static void advance_n(struct ncp_ring *r, unsigned s, uint32_t k)
{
    struct ncp_ring_stage *st = &r->stage[s];
    uint32_t pos = atomic_load_explicit(&st->pos, memory_order_relaxed);
    uint32_t before = st->next - pos;
    st->next += k;
    if (st->next - pos >= r->batch) {
        publish(r, s);
        return;
    }
    if (before > 0)
        return;                          /* listed when its batch began */
    for (int i = 0; i < n_unpublished; i++)
        if (unpublished[i].r == r && unpublished[i].s == s)
            return;
    if (n_unpublished == NCP_RING_MAX_OWED) {
        publish(r, s);
        return;
    }
    unpublished[n_unpublished++] = (struct ncp_ring_unpublished){ r, s };
}

static void advance(struct ncp_ring *r, unsigned s)
{
    advance_n(r, s, 1);
}

void *ncp_ring_reserve_n(struct ncp_ring *r, uint32_t k)
{
    struct ncp_ring_stage *st = &r->stage[0];
    uint32_t own = st->next;
    if (k == 0 || k > r->mask + 1)
        return NULL;
    if (own + k - 1 - st->seen <= r->mask &&
        !atomic_load_explicit(&r->state, memory_order_relaxed))
        return slot_at(r, own);
    if (wait_ready(r, 0, k - 1) < 0)
        return NULL;
    return slot_at(r, own);
}

void ncp_ring_commit_n(struct ncp_ring *r, uint32_t k)
{
    advance_n(r, 0, k);
}

void ncp_ring_stage_release_n(struct ncp_ring *r, unsigned s, uint32_t k)
{
    advance_n(r, s, k);
}

uint32_t ncp_ring_to_end(const struct ncp_ring *r, unsigned s)
{
    return r->mask + 1 - (r->stage[s].next & r->mask);
}

void ncp_ring_set_batch(struct ncp_ring *r, uint32_t batch)
{
    uint32_t most = (r->mask + 1) / 8 ? (r->mask + 1) / 8 : 1;
    r->batch = batch == 0 ? 1 : batch > most ? most : batch;
}

void ncp_ring_set_spin(struct ncp_ring *r, uint32_t spins)
{
    r->spin = spins;
}

void *ncp_ring_reserve(struct ncp_ring *r)
{
    struct ncp_ring_stage *st = &r->stage[0];
    uint32_t own = st->next;
    /* Fast path: room known from the cached consumer position. */
    if (own - st->seen <= r->mask &&
        !atomic_load_explicit(&r->state, memory_order_relaxed))
        return slot_at(r, own);
    if (wait_ready(r, 0, 0) < 0)
        return NULL;
    return slot_at(r, own);
}

void ncp_ring_commit(struct ncp_ring *r)
{
    advance(r, 0);
}

void *ncp_ring_stage_peek(struct ncp_ring *r, unsigned s, uint32_t k)
{
    struct ncp_ring_stage *st = &r->stage[s];
    uint32_t own = st->next;
    if (k > r->mask)
        return NULL;
    /* Fast path: the element is known to be there from the cached position;
     * the acquire load that cached it already ordered its contents. */
    if (st->seen - own > k && !atomic_load_explicit(&r->state, memory_order_relaxed))
        return slot_at(r, own + k);
    if (wait_ready(r, s, k) < 0)
        return NULL;
    return slot_at(r, own + k);
}

int ncp_ring_stage_poll(struct ncp_ring *r, unsigned s, uint32_t k)
{
    struct ncp_ring_stage *st = &r->stage[s];
    if (k > r->mask)
        return -1;
    if (st->seen - st->next > k && !atomic_load_explicit(&r->state, memory_order_relaxed))
        return 1;
    return ready(r, s, k, memory_order_acquire);
}

const void *ncp_ring_stage_ahead(const struct ncp_ring *r, unsigned s, uint32_t k)
{
    const struct ncp_ring_stage *st = &r->stage[s];
    return k <= r->mask && st->seen - st->next > k ? slot_at(r, st->next + k) : NULL;
}

void *ncp_ring_reserve_ahead(const struct ncp_ring *r, uint32_t k)
{
    const struct ncp_ring_stage *st = &r->stage[0];
    return k <= r->mask && st->next + k - st->seen <= r->mask ? slot_at(r, st->next + k) : NULL;
}

void ncp_ring_stage_release(struct ncp_ring *r, unsigned s)
{
    advance(r, s);
}

void *ncp_ring_peek(struct ncp_ring *r)
{
    return ncp_ring_stage_peek(r, r->n_stages - 1, 0);
}

void ncp_ring_release(struct ncp_ring *r)
{
    advance(r, r->n_stages - 1);
}

static void set_state(struct ncp_ring *r, uint32_t bit)
{
    atomic_fetch_or(&r->state, bit);
    for (unsigned s = 0; s < r->n_stages; s++)
        wake(&r->stage[s]);
}

void ncp_ring_close(struct ncp_ring *r)
{
    /* the consumers take pos[0] as final once they see EOF */
    publish(r, 0);
    set_state(r, NCP_RING_EOF);
}

void ncp_ring_abort(struct ncp_ring *r)
{
    set_state(r, NCP_RING_ABORT);
}

uint32_t ncp_ring_stage_known(const struct ncp_ring *r, unsigned s)
{
    const struct ncp_ring_stage *st = &r->stage[s];
    return st->seen - st->next;
}

uint32_t ncp_ring_between(const struct ncp_ring *r, unsigned s)
{
    uint32_t to = atomic_load_explicit(&r->stage[s + 1].pos, memory_order_relaxed);
    uint32_t from = atomic_load_explicit(&r->stage[s].pos, memory_order_relaxed);
    uint32_t n = from - to;
    /* the two loads are not one snapshot: never more than the ring holds */
    return n > r->mask + 1 ? r->mask + 1 : n;
}

uint64_t ncp_ring_waits(const struct ncp_ring *r, unsigned s)
{
    return r->stage[s].waits;
}

uint64_t ncp_ring_sleeps(const struct ncp_ring *r, unsigned s)
{
    return r->stage[s].sleeps;
}
