/* Output files written whole or not at all (CLI-internal).
 *
 * A regular file (new, or existing with one name) is written to a temporary
 * file beside it and renamed over it when the run has written everything:
 * two runs writing the same name leave one run's whole output, and a failed
 * write (a full disk) leaves the old file as it was, the temporary removed.
 * A symlink's target is replaced the same way, the link kept; the old
 * file's mode, owner (as far as we may) and extended attributes carry over.
 * Written in place, as O_TRUNC does, and so not atomically: standard output
 * ("-"), devices, FIFOs and sockets (/dev/null, /dev/stdout), anything under
 * /dev or /proc, a file with more than one hard link (a rename would
 * leave its other names on the old text), and a file we may write in a
 * folder we may not. No output may be one of the
 * run's input files (the same device and inode, whatever the name), and an
 * output that cannot be written is refused before anything runs. */
#ifndef NCPAR_CLI_OUTFILE_H
#define NCPAR_CLI_OUTFILE_H

#include <stdint.h>

/* A file the run reads, that no output may overwrite. */
struct ncp_file_id {
    uint64_t dev, ino;
    const char *what;   /* "the program", "the tool table" */
};

struct ncp_outfile {
    const char *path;   /* as given: for messages */
    char *target;       /* what the rename replaces (symlinks resolved) */
    char *tmp;          /* the temporary file beside target; NULL: written in place */
    int fd;             /* -1 when not open */
    int old_fd;         /* the replaced file, closed by a thread of its own; -1 */
    int sync;           /* fsync before the rename */
};

/* The id of a file the run reads (path may be NULL or name no file:
 * then nothing is added). Returns the number of ids now in ids. */
int ncp_file_id_add(struct ncp_file_id *ids, int n, const char *path, const char *what);

enum {
    NCP_OUT_SYNC = 1,       /* on the disk before it is in place (fsync) */
    /* a live record (the run's trace): written in place, readable while it
     * grows and kept whole-row by row if the process is killed; an
     * exclusive lock keeps a second run from writing into it meanwhile */
    NCP_OUT_LIVE = 2,
};

/* Opens path ("-": standard output) for writing, as described above. 0, or
 * -1 with "cnc-run: cannot write PATH: cause" on stderr. */
int ncp_outfile_open(struct ncp_outfile *of, const char *path, const struct ncp_file_id *ids,
                     int n_ids, int flags);
/* Puts the output in place: fsync if asked, close, rename. 0, or the errno
 * of what failed (then the temporary file is gone and the old file kept). */
int ncp_outfile_commit(struct ncp_outfile *of);
/* The run failed: the temporary file is removed, the old one kept. */
void ncp_outfile_discard(struct ncp_outfile *of);

/* Removes every temporary file still open; async-signal-safe, for a
 * handler about to end the process. */
void ncp_outfile_discard_all_now(void);

#endif
