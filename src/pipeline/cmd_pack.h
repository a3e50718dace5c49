/* Packed commands: what crosses from the analyzer's core to the output
 * thread's when the output thread executes (executors = 0). A command slot is
 * about 3.5 KB so that any block's calls fit; a STRAIGHT_FEED uses the header
 * and one 120-byte call of it. Packed, only those parts travel, in a ring of
 * 8-byte units published 4 KB at a time (module-internal header). */
#ifndef NCP_PIPELINE_CMD_PACK_H
#define NCP_PIPELINE_CMD_PACK_H

#include <stddef.h>
#include "ncpar/canon.h"

/* Bytes ncp_cmd_pack writes for c (a multiple of 8, at most NCP_CMD_PACK_MAX). */
size_t ncp_cmd_packed_size(const struct ncp_cmd *c);
#define NCP_CMD_PACK_MAX (sizeof(struct ncp_cmd) + 64u)
/* The analyzer writes each command straight into the ring, as a struct
 * ncp_cmd of which this many bytes (all but the executor's output) have
 * room; ncp_cmd_pack_in_place then makes the record of it where it stands
 * (its first ncp_cmd_packed_size(c) bytes, returned). */
#define NCP_CMD_IN_PLACE_BYTES offsetof(struct ncp_cmd, out)
size_t ncp_cmd_pack_in_place(struct ncp_cmd *c);
size_t ncp_cmd_packed_units(const void *src);
/* Restores what formatting and emitting read: header, calls, text, error. */
void ncp_cmd_unpack(const void *src, struct ncp_cmd *c);
/* Whether a record is head and calls only (no error, no text: every CAM
 * command). Such a record can be executed where it stands, read as a struct
 * ncp_cmd: its head and calls are where a slot has them, and executing it
 * touches nothing past them but out_len (over the record's msg_len, which a
 * calls-only record does not use) and an error, which goes elsewhere
 * (ncp_exec_cmd_into_diag). */
int ncp_cmd_packed_calls_only(const void *src);
/* Header, calls and out_len of a command executed in place, to a slot of its
 * own (the error's, which is not copied): where it is emitted from when
 * executing it found an error. */
void ncp_cmd_copy_calls(const struct ncp_cmd *src, struct ncp_cmd *dst);
/* A filler up to the end of the ring (no command has the id 2^64 - 1). */
void ncp_cmd_pack_pad(void *dst);
int ncp_cmd_packed_is_pad(const void *src);

#endif
