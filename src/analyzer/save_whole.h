/* Writing a file the operator must never find torn (the parameter file, the
 * tool table): the new text goes to a temporary file beside it, which is
 * flushed to the disk and then renamed over the old one, and the folder is
 * flushed too, so that a crash (kill -9, a power cut) leaves either the old
 * file or the new one, whole. Blocking file I/O: never on the real-time
 * path. */
#ifndef NCP_ANALYZER_SAVE_WHOLE_H
#define NCP_ANALYZER_SAVE_WHOLE_H

#include <stddef.h>
#include "ncpar/diag.h"

/* what names the file in errors ("parameter file", "tool table").
 * Returns NCP_OK or NCP_ERR_IO with d->msg. The new file keeps the old
 * one's permission bits (0644 when there was none). */
int ncp_save_whole(const char *path, const char *text, size_t len, const char *what,
                   struct ncp_diag *d);

#endif
