/* Packed commands: what crosses from the analyzer's core to the output
 * thread's when the output thread executes (executors = 0). A command slot is
 * about 3.5 KB so that any block's calls fit; a STRAIGHT_FEED uses the header
 * and one 120-byte call of it. Packed, only those parts travel, in a ring of
 * 8-byte units published 4 KB at a time (module-internal header). */
#ifndef NCP_PIPELINE_CMD_PACK_H
#define NCP_PIPELINE_CMD_PACK_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include "ncpar/canon.h"

/* Records are whole units of this many bytes (the ring's element). */
#define NCP_CMD_UNIT 8u

/* A record's head: a slot's own first 24 bytes, but for units and msg_len,
 * which lie over the slot's padding and out_len. Calls, then the error and
 * the text, follow it. */
struct ncp_packed_cmd_head {
    uint64_t cmd_id;
    uint32_t line;
    uint16_t n_ops, flags;
    uint16_t text_used, units;
    uint32_t msg_len;          /* with F_ERROR: the diagnostic's text, without NUL */
};

/* Bytes ncp_cmd_pack writes for c (a multiple of 8, at most NCP_CMD_PACK_MAX). */
size_t ncp_cmd_packed_size(const struct ncp_cmd *c);
#define NCP_CMD_PACK_MAX (sizeof(struct ncp_cmd) + 64u)
/* The analyzer writes each command straight into the ring, as a struct
 * ncp_cmd of which this many bytes (all but the executor's output) have
 * room; ncp_cmd_pack_in_place then makes the record of it where it stands
 * (its first ncp_cmd_packed_size(c) bytes, returned). */
#define NCP_CMD_IN_PLACE_BYTES offsetof(struct ncp_cmd, out)
/* ncp_cmd_pack_in_place for any command, out of line. */
size_t ncp_cmd_pack_general(struct ncp_cmd *c);
/* Every command the analyzer publishes goes through this and most are calls
 * only: that case is inline, its record being the slot's head and calls
 * already, with its size written in. */
static inline size_t ncp_cmd_pack_in_place(struct ncp_cmd *c)
{
    if ((c->flags & NCP_CMD_F_ERROR) || c->text_used != 0 || c->n_ops > NCP_CMD_MAX_OPS)
        return ncp_cmd_pack_general(c);
    uint16_t units = (uint16_t)((sizeof(struct ncp_packed_cmd_head) +
                                 c->n_ops * sizeof(struct ncp_canon)) / NCP_CMD_UNIT);
    uint32_t msg_len = 0;
    unsigned char *base = (unsigned char *)c;
    memcpy(base + offsetof(struct ncp_packed_cmd_head, units), &units, sizeof units);
    memcpy(base + offsetof(struct ncp_packed_cmd_head, msg_len), &msg_len, sizeof msg_len);
    return (size_t)units * NCP_CMD_UNIT;
}

static inline size_t ncp_cmd_packed_units(const void *src)
{
    uint16_t units;
    memcpy(&units, (const unsigned char *)src + offsetof(struct ncp_packed_cmd_head, units),
           sizeof units);
    return units;
}

/* Restores what formatting and emitting read: header, calls, text, error. */
void ncp_cmd_unpack(const void *src, struct ncp_cmd *c);
/* Whether a record is head and calls only (no error, no text: every CAM
 * command). Such a record can be executed where it stands, read as a struct
 * ncp_cmd: its head and calls are where a slot has them, and executing it
 * touches nothing past them but out_len (over the record's msg_len, which a
 * calls-only record does not use) and an error, which goes elsewhere
 * (ncp_exec_cmd_into_diag). */
static inline int ncp_cmd_packed_calls_only(const void *src)
{
    struct ncp_packed_cmd_head h;
    memcpy(&h, src, sizeof h);
    return !(h.flags & NCP_CMD_F_ERROR) && h.text_used == 0 && h.n_ops <= NCP_CMD_MAX_OPS;
}
/* Header, calls and out_len of a command executed in place, to a slot of its
 * own (the error's, which is not copied): where it is emitted from when
 * executing it found an error. */
void ncp_cmd_copy_calls(const struct ncp_cmd *src, struct ncp_cmd *dst);
/* A filler up to the end of the ring (no command has the id 2^64 - 1). */
static inline void ncp_cmd_pack_pad(void *dst)
{
    const uint64_t pad_id = UINT64_MAX;
    memcpy(dst, &pad_id, sizeof pad_id);
}

static inline int ncp_cmd_packed_is_pad(const void *src)
{
    uint64_t v;
    memcpy(&v, src, sizeof v);
    return v == UINT64_MAX;
}

#endif
