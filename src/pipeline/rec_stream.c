/* Records through a ring, the slow paths (see rec_stream.h). */
#include "rec_stream.h"

/* Units a writer reserves at a time: about the ring's publishing batch
 * (4 KB), never a large part of a small ring. */
static uint32_t run_units(const struct ncp_ring *r)
{
    uint32_t run = 4096u / NCP_PACK_UNIT, eighth = ncp_ring_cap(r) / 8u;
    return run < eighth ? run : eighth;
}

void *ncp_rec_reserve_slow(struct ncp_rec_writer *w, uint32_t units)
{
    struct ncp_ring *r = w->r;
    w->room = 0;
    uint32_t to_end = ncp_ring_to_end(r, 0);
    if (units > to_end) {
        void *pad = ncp_ring_reserve_n(r, to_end);
        if (!pad)
            return NULL;
        w->kind->pad(pad);
        ncp_ring_commit_n(r, to_end);
        to_end = ncp_ring_to_end(r, 0);
    }
    uint32_t want = run_units(r);
    if (want > to_end)
        want = to_end;
    if (want < units)
        want = units;
    unsigned char *dst = ncp_ring_reserve_n(r, want);
    if (!dst)
        return NULL;
    w->cur = dst;
    w->room = want;
    for (uint32_t off = 0; off < NCP_REC_PREFETCH && off < (size_t)want * NCP_PACK_UNIT;
         off += 64u)
        ncp_prefetch_w(dst + off);
    return dst;
}

/* The run the reader knows of from where it stands, never past the ring's
 * end (records do not wrap). */
static void known_run(struct ncp_rec_reader *rd, const void *at)
{
    uint32_t known = ncp_ring_stage_known(rd->r, 1), to_end = ncp_ring_to_end(rd->r, 1);
    rd->cur = at;
    rd->avail = known < to_end ? known : to_end;
}

const void *ncp_rec_take_slow(struct ncp_rec_reader *rd, uint32_t *units)
{
    struct ncp_ring *r = rd->r;
    for (;;) {
        if (rd->avail > 0 && !ncp_ring_aborted(r)) {
            const unsigned char *rec = rd->cur;
            if (rd->kind->is_pad(rec)) {
                ncp_ring_stage_release_n(r, 1, ncp_ring_to_end(r, 1));
                rd->avail = 0;
                continue;
            }
            uint32_t n = (uint32_t)rd->kind->units(rec);
            if (n == 0 || n > ncp_ring_to_end(r, 1))
                return NULL; /* no writer makes such a record */
            if (n <= rd->avail) {
                *units = n;
                return rec;
            }
            /* (published positions fall between records: not expected) */
            if (!ncp_ring_stage_peek(r, 1, n - 1))
                return NULL;
            known_run(rd, rec);
            continue;
        }
        const void *rec = ncp_ring_stage_peek(r, 1, 0);
        if (!rec) {
            rd->avail = 0;
            return NULL;
        }
        known_run(rd, rec);
    }
}
