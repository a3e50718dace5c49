/* Lexing ahead (see lex_ahead.h). */
#include "lex_ahead.h"

#include "futex.h"
#include "ring.h"

#include <string.h>

/* A slot's tag: the chunk it is for, and who has that chunk. */
enum { AHEAD_OPEN = 0, AHEAD_HELPER = 1, AHEAD_READY = 2, AHEAD_ANALYZER = 3 };
#define TAG(chunk, state) ((chunk) * 4u + (state))
#define TAG_CHUNK(tag) ((tag) / 4u)

/* The analyzer spins this long for a chunk the helper is still lexing
 * (a chunk takes tens of microseconds), then sleeps. */
#define AHEAD_SPIN 256

/* How far ahead (bytes) each side warms the slot buffer: the lines were last
 * in the other core's cache, and a transfer between two cores is slow enough
 * to stall a reader that waits for it. */
#define AHEAD_PREFETCH 768u

/* A plain block of ~30 bytes of text packs to 96 bytes: room for the usual
 * chunk, and for two of the largest blocks in any case. A chunk that does not
 * fit is lexed partly; the analyzer lexes the rest itself. */
static size_t slot_bytes(uint64_t chunk_bytes)
{
    size_t want = (size_t)chunk_bytes * 4u;
    if (want < 2u * NCP_BLOCK_PACK_MAX)
        want = 2u * NCP_BLOCK_PACK_MAX;
    return (want + 63u) / 64u * 64u;
}

int ncp_lex_ahead_init(struct ncp_lex_ahead *la, uint64_t chunk_bytes)
{
    memset(la, 0, sizeof *la);
    if (chunk_bytes == 0 || chunk_bytes > (UINT64_C(1) << 30))
        return -1;
    la->chunk_bytes = chunk_bytes;
    la->buf_bytes = slot_bytes(chunk_bytes);
    /* prefaulted: first-touch faults cost microseconds each in a VM */
    if (ncp_mem_map(&la->mem, la->buf_bytes * NCP_AHEAD_SLOTS) != 0)
        return -1;
    for (unsigned s = 0; s < NCP_AHEAD_SLOTS; s++)
        la->slot[s].buf = (unsigned char *)la->mem.p + (size_t)s * la->buf_bytes;
    atomic_init(&la->done, 0);
    return 0;
}

void ncp_lex_ahead_destroy(struct ncp_lex_ahead *la)
{
    ncp_mem_unmap(&la->mem);
}

/* Where chunk k begins: a line start, the same for both sides. */
static uint64_t chunk_start(const struct ncp_lex_ahead *la, uint64_t k)
{
    const struct ncp_source *src = la->src;
    if (k == 0)
        return src->begin;
    if (k >= la->n_chunks)
        return src->end;
    uint64_t at = src->begin + k * la->chunk_bytes; /* < end: k < n_chunks */
    const char *nl = memchr(src->text + at - 1, '\n', (size_t)(src->end - (at - 1)));
    return nl ? (uint64_t)(nl - src->text) + 1 : src->end;
}

static void enter_chunk(struct ncp_lex_ahead *la, uint64_t k);

void ncp_lex_ahead_start(struct ncp_lex_ahead *la, const struct ncp_source *src)
{
    la->src = src;
    uint64_t len = src->end > src->begin ? src->end - src->begin : 0;
    la->n_chunks = (len + la->chunk_bytes - 1) / la->chunk_bytes;
    for (unsigned s = 0; s < NCP_AHEAD_SLOTS; s++) {
        atomic_store_explicit(&la->slot[s].tag, TAG((uint64_t)s, AHEAD_OPEN),
                              memory_order_relaxed);
        la->slot[s].stop = 0;
        la->slot[s].blocks = 0;
    }
    /* `done` keeps counting across runs: a futex word that went back could
     * match a stale key */
    atomic_store_explicit(&la->a_sleeps, 0, memory_order_relaxed);
    atomic_store_explicit(&la->over, 0, memory_order_relaxed);
    la->h_next = 0;
    la->h_chunks = la->h_blocks = 0;
    la->a_waits = la->a_slept = 0;
    ncp_text_feed_start(&la->feed, src);
    la->recs_left = 0;
    la->rec = NULL;
    la->plain = 0;
    enter_chunk(la, 0);
}

/* ---- the helper --------------------------------------------------------- */

/* Lex chunk k into its slot as the analyzer would lex it, line numbers left
 * at 0; stop early if the slot is full. */
static void lex_chunk(struct ncp_lex_ahead *la, uint64_t k, struct ncp_ahead_slot *s)
{
    const struct ncp_source *src = la->src;
    uint64_t off = chunk_start(la, k), end = chunk_start(la, k + 1);
    unsigned char *dst = s->buf;
    size_t room = la->buf_bytes;
    uint32_t n = 0;
    while (off < end) {
        size_t next;
        if (room > AHEAD_PREFETCH + 128u) {
            ncp_prefetch_w(dst + AHEAD_PREFETCH);
            ncp_prefetch_w(dst + AHEAD_PREFETCH + 64);
        }
        size_t size = ncp_lex_line_packed(src->text + off, src->end - off, off, dst, room,
                                          &la->h_block, &next);
        if (size == 0)
            break;
        dst += size;
        room -= size;
        n++;
        off += next;
    }
    s->blocks = n;
    s->stop = off;
    la->h_blocks += n;
    la->h_chunks++;
}

int ncp_lex_ahead_help(struct ncp_lex_ahead *la)
{
    if (atomic_load_explicit(&la->over, memory_order_relaxed))
        return 0;
    /* Two ahead: the analyzer is somewhere in its chunk and may be at its
     * end; the one after gives the helper a whole chunk of the analyzer's
     * time to finish before it is wanted. */
    uint64_t k = atomic_load_explicit(&la->a_chunk, memory_order_relaxed) + 2;
    if (k < la->h_next)
        k = la->h_next;
    for (; k < la->n_chunks; k++) {
        struct ncp_ahead_slot *s = &la->slot[k % NCP_AHEAD_SLOTS];
        uint64_t tag = atomic_load_explicit(&s->tag, memory_order_acquire);
        if (TAG_CHUNK(tag) < k)
            return 0; /* the slot still holds an earlier chunk: far enough ahead */
        if (tag != TAG(k, AHEAD_OPEN))
            continue; /* the analyzer has it, or has been through it */
        /* acquire: the analyzer's reads of the slot's last chunk are over */
        if (!atomic_compare_exchange_strong_explicit(&s->tag, &tag, TAG(k, AHEAD_HELPER),
                                                     memory_order_acquire,
                                                     memory_order_relaxed))
            continue; /* it got there first */
        lex_chunk(la, k, s);
        la->h_next = k + 1;
        /* seq_cst, and the flag read after the bump: either the analyzer sees
         * the slot ready, or this thread sees it asleep (see wait_ready) */
        atomic_store(&s->tag, TAG(k, AHEAD_READY));
        atomic_fetch_add(&la->done, 1);
        if (atomic_load(&la->a_sleeps))
            ncp_futex_wake_all(&la->done);
        return 1;
    }
    return 0;
}

/* ---- the analyzer ------------------------------------------------------- */

static void wait_ready(struct ncp_lex_ahead *la, struct ncp_ahead_slot *s, uint64_t k)
{
    uint64_t ready = TAG(k, AHEAD_READY);
    if (atomic_load_explicit(&s->tag, memory_order_acquire) == ready)
        return;
    la->a_waits++;
    for (int i = 0; i < AHEAD_SPIN; i++) {
        ncp_cpu_relax();
        if (atomic_load_explicit(&s->tag, memory_order_acquire) == ready)
            return;
    }
    for (;;) {
        /* the key before the flag, as in the rings */
        uint32_t key = atomic_load(&la->done);
        atomic_store(&la->a_sleeps, 1);
        if (atomic_load(&s->tag) != ready) {
            la->a_slept++;
            ncp_futex_wait(&la->done, key, NULL);
        }
        atomic_store_explicit(&la->a_sleeps, 0, memory_order_relaxed);
        if (atomic_load_explicit(&s->tag, memory_order_acquire) == ready)
            return;
    }
}

/* Claim chunk k, or take what the helper made of it. */
static void enter_chunk(struct ncp_lex_ahead *la, uint64_t k)
{
    struct ncp_ahead_slot *s = &la->slot[k % NCP_AHEAD_SLOTS];
    la->chunk = k;
    la->chunk_end = chunk_start(la, k + 1);
    /* the helper reads ahead of here, never behind */
    ncp_source_window_at(&la->feed.win, chunk_start(la, k));
    atomic_store_explicit(&la->a_chunk, k, memory_order_relaxed);
    uint64_t tag = TAG(k, AHEAD_OPEN);
    if (atomic_compare_exchange_strong_explicit(&s->tag, &tag, TAG(k, AHEAD_ANALYZER),
                                                memory_order_relaxed, memory_order_relaxed))
        return; /* lexed here, as ncp_text_feed does */
    /* the slot was given back for k when the analyzer left k - SLOTS, so the
     * tag is k's: the helper has it */
    wait_ready(la, s, k);
    for (unsigned off = 0; off < AHEAD_PREFETCH; off += 64)
        __builtin_prefetch(s->buf + off, 0);
    la->rec = s->buf;
    la->recs_left = s->blocks;
    la->rec_stop = s->stop;
    if (la->recs_left == 0)
        la->feed.off = la->rec_stop;
}

/* Give chunk k's slot back for chunk k + SLOTS; release: the reads of its
 * buffer come before the helper's next writes. */
static void leave_chunk(struct ncp_lex_ahead *la)
{
    uint64_t k = la->chunk;
    atomic_store_explicit(&la->slot[k % NCP_AHEAD_SLOTS].tag,
                          TAG(k + NCP_AHEAD_SLOTS, AHEAD_OPEN), memory_order_release);
}

static const struct ncp_block *take_record(struct ncp_lex_ahead *la)
{
    struct ncp_text_feed *f = &la->feed;
    struct ncp_block *b = &f->block;
    __builtin_prefetch(la->rec + AHEAD_PREFETCH, 0);
    __builtin_prefetch(la->rec + AHEAD_PREFETCH + 64, 0);
    la->rec += ncp_block_unpack_over(la->rec, b, &la->plain) * NCP_PACK_UNIT;
    b->line = f->line;
    b->err.line = f->line; /* the lexer's, error or not */
    f->line++;
    f->blocks++;
    if (--la->recs_left == 0)
        f->off = la->rec_stop;
    return b;
}

const struct ncp_block *ncp_lex_ahead_next(void *ctx)
{
    struct ncp_lex_ahead *la = ctx;
    struct ncp_text_feed *f = &la->feed;
    for (;;) {
        if (la->recs_left > 0)
            return take_record(la);
        if (f->off >= f->src->end)
            return NULL;
        if (f->off < la->chunk_end) {
            la->plain = 0; /* the block is lexed over */
            return ncp_text_feed_next(f);
        }
        leave_chunk(la);
        enter_chunk(la, la->chunk + 1);
    }
}

void ncp_lex_ahead_finish(struct ncp_lex_ahead *la)
{
    atomic_store_explicit(&la->over, 1, memory_order_relaxed);
}
