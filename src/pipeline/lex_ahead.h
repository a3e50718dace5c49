/* Lexing ahead without lexer threads (-j 0, executors 0): the analyzer lexes
 * the text itself, and the output thread, whenever it has no command to write,
 * lexes a chunk further down the text for it (module-internal header).
 *
 * On two cores -j 0 is two busy threads: analyzer (lexing + analysis) and
 * output (execution + text). Which one is the slower changes with the program
 * and with the speed of each core (a virtual CPU's speed can change by 2x for
 * minutes), and a fixed split then leaves one core idle. Here the idle one
 * takes lexing work off the other: balance without a third busy thread.
 *
 * The text is cut into chunks of about `chunk_bytes` that end at line ends:
 * chunk k begins after the first '\n' at or after begin + k * chunk_bytes - 1,
 * so the analyzer and the helper find the same cuts without talking. Each
 * chunk is lexed by exactly one of the two, decided by a compare-and-swap on
 * the tag of the chunk's slot (chunk k uses slot k mod NCP_AHEAD_SLOTS): the
 * analyzer claims every chunk as it reaches it; the helper claims chunks at
 * least two ahead of the analyzer's, packs their blocks into the slot and
 * marks the slot ready. A chunk the helper holds is one the analyzer unpacks
 * instead of lexing: same blocks, only the line numbers are set on arrival
 * (the helper cannot know them without counting every line end before).
 * The analyzer gives a slot back when it leaves the chunk, so the helper is
 * never more than NCP_AHEAD_SLOTS chunks ahead and memory stays fixed. */
#ifndef NCP_PIPELINE_LEX_AHEAD_H
#define NCP_PIPELINE_LEX_AHEAD_H

#include <stdalign.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

#include "ncpar/feeder.h"
#include "ncpar/lex.h"
#include "ncpar/mem.h"
#include "ncpar/blocks.h"

#define NCP_AHEAD_SLOTS 8u

struct ncp_ahead_slot {
    alignas(64) _Atomic uint64_t tag; /* chunk * 4 + state (lex_ahead.c) */
    uint64_t stop;                    /* helper: text offset it lexed up to */
    uint32_t blocks;                  /* helper: packed blocks in buf */
    unsigned char *buf;
};

struct ncp_lex_ahead {
    const struct ncp_source *src;
    uint64_t chunk_bytes;
    uint64_t n_chunks;
    size_t buf_bytes;                 /* per slot */
    struct ncp_mem mem;               /* all slot buffers, prefaulted */
    struct ncp_ahead_slot slot[NCP_AHEAD_SLOTS];

    /* shared */
    alignas(64) _Atomic uint64_t a_chunk; /* the chunk the analyzer is in */
    _Atomic uint32_t done;            /* futex word: bumped per chunk made ready */
    _Atomic uint32_t a_sleeps;        /* 1: the analyzer sleeps on done */
    _Atomic uint32_t over;            /* the analyzer has finished: no more help */

    /* helper only */
    alignas(64) uint64_t h_next;      /* no chunk below this is worth trying */
    uint64_t h_chunks, h_blocks;
    struct ncp_block h_block;

    /* analyzer only */
    alignas(64) struct ncp_text_feed feed;
    uint64_t chunk, chunk_end;        /* its chunk and where that ends in the text */
    uint64_t a_waits, a_slept;        /* chunks it found still being lexed; slept for */
    unsigned plain;                   /* feed.block's state for ncp_block_unpack_over */
    const unsigned char *rec;         /* the helper's next packed block */
    uint32_t recs_left;
    uint64_t rec_stop;
};

/* Slot buffers for chunks of chunk_bytes (>= 1). 0, or -1 when out of memory. */
int ncp_lex_ahead_init(struct ncp_lex_ahead *la, uint64_t chunk_bytes);
void ncp_lex_ahead_destroy(struct ncp_lex_ahead *la);
/* Start on src: only while neither side is inside a call below. */
void ncp_lex_ahead_start(struct ncp_lex_ahead *la, const struct ncp_source *src);

/* The analyzer's side, as struct ncp_block_feed's next() (its release() is
 * ncp_text_feed_release: the block is the feed's, overwritten by the next
 * one): every block of the text in order, exactly as ncp_text_feed_next
 * gives them. */
const struct ncp_block *ncp_lex_ahead_next(void *ctx);
/* The analyzer has stopped: the helper wants no more work. */
void ncp_lex_ahead_finish(struct ncp_lex_ahead *la);

/* The helper's side: lex one chunk ahead of the analyzer if one is free.
 * 1 if it did, 0 if there was none (none left, too far ahead, finished).
 * Never waits. */
int ncp_lex_ahead_help(struct ncp_lex_ahead *la);

#endif
