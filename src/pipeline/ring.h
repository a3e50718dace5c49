/* Bounded lock-free ring of fixed-size elements, written and read in place
 * (module-internal header).
 *
 * A ring has 2 or more stages. Stage 0 is the producer (reserve/commit); every
 * later stage takes the elements in order after the stage before it has
 * released them (peek/release), and the last stage hands the slots back to the
 * producer. With 2 stages it is a plain SPSC ring; 3 stages let the executor
 * complete a slot in place and pass it on to the output without a copy.
 *
 * Each stage is one thread. Positions are 32-bit counters on their own cache
 * lines (acquire/release); a stage that must wait spins briefly, then sleeps on
 * a futex, and the other side only makes the wake syscall when a sleeper has
 * announced itself, and only once half a ring of work is ready for it (or when
 * the poster itself has to wait: a stalled pipeline always wakes up).
 *
 * A stage publishes its position once per batch of items (an eighth of the
 * ring, at most 32), not per item: the store, the fence and the cache-line
 * transfer are paid once a batch. Whatever a thread has not yet published it
 * publishes before it waits on any ring, when it closes a ring it produces,
 * and in ncp_ring_wake_owed (which every stage thread calls before it exits),
 * so no stage can sleep on an item another stage holds back. */
#ifndef NCP_PIPELINE_RING_H
#define NCP_PIPELINE_RING_H

#include <stdalign.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

#include "ncpar/mem.h"

#define NCP_RING_MAX_STAGES 3

enum { NCP_RING_EOF = 1u, NCP_RING_ABORT = 2u }; /* struct ncp_ring's state */
#define NCP_RING_MAX_CAPACITY (1u << 24)

/* Owned by one stage: its position and what it last saw of the stage it
 * waits for (so the fast path rarely touches the other side's line). */
struct ncp_ring_stage {
    alignas(64) _Atomic uint32_t pos;    /* elements this stage has published */
    _Atomic uint32_t sleepers;           /* 1: the awaiting stage sleeps until pos moves */
    _Atomic uint32_t event;              /* futex word, bumped to wake them */
    _Atomic uint32_t wake_at;            /* the sleeper wants waking at this pos */
    /* Owner-private, on a line of their own so the per-item bump does not
     * pull the published line away from the stages polling it. */
    alignas(64) uint32_t next;           /* elements passed on, published or not */
    uint32_t seen;                       /* cache of the awaited pos */
    uint64_t waits;                      /* waits that found no room/data */
    uint64_t sleeps;                     /* waits that slept */
};

struct ncp_ring {
    struct ncp_ring_stage stage[NCP_RING_MAX_STAGES];
    alignas(64) _Atomic uint32_t state;  /* NCP_RING_EOF | NCP_RING_ABORT */
    unsigned n_stages;
    uint32_t batch;                      /* publish a stage's position every batch items */
    uint32_t spin;                       /* polls before a waiting stage sleeps */
    uint32_t mask;                       /* capacity - 1 */
    size_t stride;
    unsigned char *slots;
    struct ncp_mem mem;                  /* where the slots are */
};

/* Elements stage s has published that stage s + 1 has not (s + 1 below
 * n_stages), from the published positions with relaxed loads: a gauge for
 * another thread, up to a batch behind. */
uint32_t ncp_ring_between(const struct ncp_ring *r, unsigned s);
/* Round up to a power of two within [1, NCP_RING_MAX_CAPACITY]. */
uint32_t ncp_ring_capacity(uint32_t want);

/* Plain SPSC ring. capacity is rounded up to a power of two. 0 or -1 (ENOMEM). */
int ncp_ring_init(struct ncp_ring *r, size_t elem_size, uint32_t capacity);
/* A ring of n_stages (2..NCP_RING_MAX_STAGES) stages. */
int ncp_ring_init_staged(struct ncp_ring *r, size_t elem_size, uint32_t capacity,
                         unsigned n_stages);
void ncp_ring_destroy(struct ncp_ring *r);
/* Empty and open again, its slots kept (a pre-started pipeline's next run).
 * Only while no thread uses the ring and none owes it a publish or a wake
 * (every stage thread called ncp_ring_wake_owed when it finished). */
void ncp_ring_reset(struct ncp_ring *r);

uint32_t ncp_ring_cap(const struct ncp_ring *r);

/* Producer: the next free slot (waits while the ring is full), NULL once
 * closed or aborted. Write it, then commit. */
void *ncp_ring_reserve(struct ncp_ring *r);
void ncp_ring_commit(struct ncp_ring *r);

/* Last stage (SPSC consumer): the oldest element not yet released, waiting for
 * it; NULL when the producer closed the ring and everything was taken, or on
 * abort. Valid until release. */
void *ncp_ring_peek(struct ncp_ring *r);
void ncp_ring_release(struct ncp_ring *r);

/* Stage s >= 1: the k-th element after the last one it released (k < capacity),
 * waiting for it; NULL at the end of the data or on abort. Releases go in
 * order, one element each. */
void *ncp_ring_stage_peek(struct ncp_ring *r, unsigned s, uint32_t k);
void ncp_ring_stage_release(struct ncp_ring *r, unsigned s);
/* Stage s (>= 1) without waiting: 1 if its k-th element is there, 0 if it
 * would have to wait for it, -1 if it never comes (end of data, abort). */
int ncp_ring_stage_poll(struct ncp_ring *r, unsigned s, uint32_t k);

/* For prefetching, never waiting and touching no shared line: stage s's k-th
 * element after its next one if the stage before is already known to have
 * passed it on, else NULL; and the producer's k-th slot after the next one to
 * reserve if it is known to be free, else NULL. Blocks cross cores through
 * these rings, and a stage that first touches each slot as it takes it waits
 * a full cache-to-cache transfer per block. */
const void *ncp_ring_stage_ahead(const struct ncp_ring *r, unsigned s, uint32_t k);
void *ncp_ring_reserve_ahead(const struct ncp_ring *r, uint32_t k);
/* Stage s (>= 1): how many elements from its next one it already knows to be
 * there (no waiting, no shared line touched); at least 1 right after a
 * successful ncp_ring_stage_peek(r, s, 0). */
uint32_t ncp_ring_stage_known(const struct ncp_ring *r, unsigned s);

/* Runs of elements (records of several units, e.g. packed blocks): the
 * producer reserves k elements at once (waiting for room) and commits them
 * together; a consumer stage waits for its (k-1)-th element with
 * ncp_ring_stage_peek and releases k at once. The k elements are contiguous in
 * memory only if k <= ncp_ring_to_end(r, stage): a record must not wrap, so the
 * producer fills the rest of the ring with padding first. */
void *ncp_ring_reserve_n(struct ncp_ring *r, uint32_t k);
void ncp_ring_commit_n(struct ncp_ring *r, uint32_t k);
void ncp_ring_stage_release_n(struct ncp_ring *r, unsigned s, uint32_t k);
uint32_t ncp_ring_to_end(const struct ncp_ring *r, unsigned s);
/* Publish positions every `batch` elements (default: an eighth of the ring, at
 * most 32): rings of small units want larger batches. */
void ncp_ring_set_batch(struct ncp_ring *r, uint32_t batch);
/* How long a stage that finds no data or room polls before it sleeps
 * (NCP_RING_SPIN by default). 0: sleep at once, for when the run has more
 * threads than CPUs and the one polling would hold up the one it waits for. */
void ncp_ring_set_spin(struct ncp_ring *r, uint32_t spins);

/* Producer: no more data. Later stages drain what is there, then get NULL. */
void ncp_ring_close(struct ncp_ring *r);
/* Anyone: shut down now. Every waiting or later call returns NULL. The slots
 * stay allocated until ncp_ring_destroy, so a stage still writing one is safe. */
void ncp_ring_abort(struct ncp_ring *r);
static inline int ncp_ring_aborted(const struct ncp_ring *r)
{
    return (atomic_load_explicit(&((struct ncp_ring *)r)->state, memory_order_acquire) &
            NCP_RING_ABORT) != 0;
}

/* Publish every position this thread holds back (its open batches) and wake
 * every sleeper it deferred. Ring calls that wait or end do it; a stage thread
 * calls it before it exits, and a thread handing a ring's slots to anyone
 * other than a ring stage (e.g. reading them after join) must have done it. */
void ncp_ring_wake_owed(void);

/* Owner-side counters of stage s; read them once its thread was joined. */
uint64_t ncp_ring_waits(const struct ncp_ring *r, unsigned s);
uint64_t ncp_ring_sleeps(const struct ncp_ring *r, unsigned s);

/* Ask for a line in the state a store needs. A producer writes slots its
 * consumer on another core read a lap ago: a plain store waits in the store
 * buffer until that core gave the line up, and a full store buffer stalls the
 * producer's own work. __builtin_prefetch(p, 1) is a read prefetch unless the
 * build targets PRFCHW, so x86 gets the instruction itself (a NOP on CPUs
 * that predate it). */
static inline void ncp_prefetch_w(const void *p)
{
#if defined(__x86_64__) || defined(__i386__)
    __asm__ volatile("prefetchw %0" : : "m"(*(const char *)p));
#else
    __builtin_prefetch(p, 1);
#endif
}

#endif
