/* Records of their own size (packed blocks, packed commands) through a ring
 * of 8-byte units, one record after another (module-internal header).
 *
 * Going through the ring's calls for every record (room, wrap, reserve,
 * prefetch; then peek for the head, peek for the tail, pad test) costs the
 * two sides as much as packing the command. Both ends
 * here keep a run of the ring to themselves: the writer a run it reserved,
 * the reader a run it knows is published; the ring is asked only when a run
 * is used up. Every record is still committed and released on its own, so
 * the ring's batching, publishing and wake-ups work as before, and a run
 * held by one side is never what the other side waits for: the writer's
 * run is room the reader cannot use anyway, and the reader lets go of a
 * record as soon as it is done with it. Published positions always fall
 * between records (every commit is a whole record), so a record whose first
 * unit is published is published whole. Records never wrap: the writer pads
 * to the ring's end first. */
#ifndef NCP_PIPELINE_REC_STREAM_H
#define NCP_PIPELINE_REC_STREAM_H

#include <stddef.h>
#include <stdint.h>

#include "ncpar/lex.h"
#include "ring.h"

struct ncp_record_kind {
    void (*pad)(void *dst);
    int (*is_pad)(const void *src);
    size_t (*units)(const void *src);
};

struct ncp_rec_writer {
    struct ncp_ring *r;
    const struct ncp_record_kind *kind;
    unsigned char *cur;      /* the next record goes here ... */
    uint32_t room;           /* ... and this many units from it are reserved */
};

struct ncp_rec_reader {
    struct ncp_ring *r;
    const struct ncp_record_kind *kind;
    const unsigned char *cur; /* the next record ... */
    uint32_t avail;           /* ... and this many units from it are published */
};

static inline void ncp_rec_writer_start(struct ncp_rec_writer *w, struct ncp_ring *r,
                                        const struct ncp_record_kind *kind)
{
    w->r = r;
    w->kind = kind;
    w->cur = NULL;
    w->room = 0;
}

static inline void ncp_rec_reader_start(struct ncp_rec_reader *rd, struct ncp_ring *r,
                                        const struct ncp_record_kind *kind)
{
    rd->r = r;
    rd->kind = kind;
    rd->cur = NULL;
    rd->avail = 0;
}

/* Room for a record of `units`: a new run when the one held is used up. */
void *ncp_rec_reserve_slow(struct ncp_rec_writer *w, uint32_t units);

/* Where to write a record of `units` (<= the ring's capacity); NULL once the
 * ring is closed or aborted. Write it, then ncp_rec_commit(units). */
static inline void *ncp_rec_reserve(struct ncp_rec_writer *w, uint32_t units)
{
    if (units <= w->room)
        return w->cur;
    return ncp_rec_reserve_slow(w, units);
}

/* How far ahead (bytes) the writer claims the lines it is about to write:
 * the reader last had them, on its own core. */
#define NCP_REC_PREFETCH 1024u

static inline void ncp_rec_commit(struct ncp_rec_writer *w, uint32_t units)
{
    w->cur += (size_t)units * NCP_PACK_UNIT;
    w->room -= units;
    ncp_ring_commit_n(w->r, units);
    if ((size_t)w->room * NCP_PACK_UNIT > NCP_REC_PREFETCH + 128u) {
        ncp_prefetch_w(w->cur + NCP_REC_PREFETCH);
        ncp_prefetch_w(w->cur + NCP_REC_PREFETCH + 64u);
    }
}

/* The next record and its size in units; NULL at the end of the data or on
 * abort. Read it, then ncp_rec_release(units). */
const void *ncp_rec_take_slow(struct ncp_rec_reader *rd, uint32_t *units);

/* ncp_rec_take with the reader's kind given where it is known at compile
 * time (a static const struct): its tests are then direct calls the compiler
 * can inline, not two calls through pointers per record. */
static inline const void *ncp_rec_take_as(struct ncp_rec_reader *rd,
                                          const struct ncp_record_kind *kind, uint32_t *units)
{
    if (rd->avail == 0 || ncp_ring_aborted(rd->r))
        return ncp_rec_take_slow(rd, units);
    const unsigned char *rec = rd->cur;
    if (kind->is_pad(rec))
        return ncp_rec_take_slow(rd, units);
    uint32_t n = (uint32_t)kind->units(rec);
    if (n > rd->avail || n == 0)
        return ncp_rec_take_slow(rd, units);
    if ((size_t)rd->avail * NCP_PACK_UNIT > NCP_REC_PREFETCH + 128u) {
        __builtin_prefetch(rec + NCP_REC_PREFETCH, 0);
        __builtin_prefetch(rec + NCP_REC_PREFETCH + 64u, 0);
    }
    *units = n;
    return rec;
}

static inline const void *ncp_rec_take(struct ncp_rec_reader *rd, uint32_t *units)
{
    return ncp_rec_take_as(rd, rd->kind, units);
}

static inline void ncp_rec_release(struct ncp_rec_reader *rd, uint32_t units)
{
    rd->cur += (size_t)units * NCP_PACK_UNIT;
    rd->avail -= units;
    ncp_ring_stage_release_n(rd->r, 1, units);
}

/* Whether a record is there to take without waiting: 1 yes, 0 not yet, -1
 * never (end of data, abort). */
static inline int ncp_rec_poll(const struct ncp_rec_reader *rd)
{
    if (rd->avail > 0)
        return 1;
    return ncp_ring_stage_poll(rd->r, 1, 0);
}

#endif
