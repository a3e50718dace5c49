/* Where `cnc-run parse --canon FILE` puts the canonical text (CLI-internal). */
#ifndef NCP_CLI_CANON_WRITER_H
#define NCP_CLI_CANON_WRITER_H

#include "ncpar/canon.h"
#include "outfile.h"

struct canon_writer;

/* path "-" is standard output; a file is written whole or not at all
 * (outfile.h), and never over one of the inputs. NULL, with a message on
 * stderr, when the file cannot be written or memory is short. */
struct canon_writer *canon_writer_open(const char *path, const struct ncp_file_id *inputs,
                                      int n_inputs);
/* ncp_output.emit: appends a slot's text; non-zero once a write has failed. */
int canon_writer_emit(void *ctx, const struct ncp_cmd *cmd);
/* ncp_output.reserve/commit: the slot's text formatted straight into the
 * buffer (NULL once a write has failed, then emit is used). */
char *canon_writer_reserve(void *ctx);
int canon_writer_commit(void *ctx, const struct ncp_cmd *cmd);
/* Writes what is left and puts the file in place (keep) or removes it (!keep:
 * the run is not to be trusted); frees. 0, or the errno of the first write
 * that failed (then the old file is kept). */
int canon_writer_close(struct canon_writer *w, int keep);

#endif
