/* Where `cnc-run parse --canon FILE` puts the canonical text (CLI-internal). */
#ifndef NCP_CLI_CANON_WRITER_H
#define NCP_CLI_CANON_WRITER_H

#include "ncpar/canon.h"

struct canon_writer;

/* path "-" is standard output. An existing plain file is replaced rather than
 * truncated, its pages freed by a short thread of its own (canon_writer.c
 * says why). NULL, with a message on stderr, when the file cannot be opened
 * or memory is short. */
struct canon_writer *canon_writer_open(const char *path);
/* ncp_output.emit: appends a slot's text; non-zero once a write has failed. */
int canon_writer_emit(void *ctx, const struct ncp_cmd *cmd);
/* ncp_output.reserve/commit: the slot's text formatted straight into the
 * buffer (NULL once a write has failed, then emit is used). */
char *canon_writer_reserve(void *ctx);
int canon_writer_commit(void *ctx, const struct ncp_cmd *cmd);
/* Writes what is left, closes, frees; 0, or the errno of the first write
 * that failed. */
int canon_writer_close(struct canon_writer *w);

#endif
