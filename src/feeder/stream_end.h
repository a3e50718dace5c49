/* Where a program read from a pipe ends (module-internal header).
 *
 * A pipe may never end (`yes 'G1 X1' | cnc-run parse -`), so its reader
 * stops where the program certainly has: at the closing '%' of a program
 * that opened with one, or after an M2 or M30 that the interpreter must
 * reach, one outside every o-word block, in a program that calls nothing
 * (an o-word or M98 call may find its sub further down, as rs274 does). It
 * also stops after a line too long to lex that the interpreter must reach:
 * the run stops there with "Command too long" whatever follows. Anything
 * less certain reads on, up to the limit the reader sets. */
#ifndef NCP_FEEDER_STREAM_END_H
#define NCP_FEEDER_STREAM_END_H

#include <stddef.h>

#define NCP_STREAM_END_DEPTH 64

struct ncp_stream_end {
    size_t off;         /* the first line not looked at yet */
    int started;        /* a non-blank line was seen */
    int percent;        /* the program opened with '%' */
    int calls;          /* a call was seen: nothing below may be left unread */
    int depth;          /* open o-word blocks; > NCP_STREAM_END_DEPTH: lost count */
    char kind[NCP_STREAM_END_DEPTH];    /* 'd' for an open do, else 'b' */
    char label[NCP_STREAM_END_DEPTH][16];
};

/* ncp_text_stop_fn: 0 to read on, or how much of text is the program. */
size_t ncp_stream_end_scan(void *ctx, const char *text, size_t len);

#endif
