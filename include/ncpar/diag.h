/* Diagnostics travel with the block that caused them and are printed once, in
 * program order, as PROG:LINE:COL: error: message. */
#ifndef NCPAR_DIAG_H
#define NCPAR_DIAG_H

#include <stdint.h>

#define NCP_DIAG_MSG_MAX 256

enum ncp_status {
    NCP_OK = 0,
    NCP_ERR_SYNTAX,    /* lexer: malformed block */
    NCP_ERR_SEMANTIC,  /* analyzer: rs274 rule broken */
    NCP_ERR_GEOMETRY,  /* executor: arc/comp geometry impossible */
    NCP_ERR_LIMIT,     /* configurable limit hit (loop count, call depth, ...) */
    NCP_ERR_IO,
    NCP_END            /* not an error: program ended (M2/M30/%/EOF) */
};

struct ncp_diag {
    uint32_t line;              /* 1-based source line, 0 = no location */
    uint16_t col;               /* 1-based column, 0 = whole line */
    uint16_t code;              /* enum ncp_status */
    /* NULL: the program's own file; else the subroutine file the line is in
     * (a name from ncp_diag_file_of_tag, valid for the life of the process) */
    const char *file;
    char msg[NCP_DIAG_MSG_MAX]; /* machinist-readable, no trailing newline */
};

/* printf-style setter; returns d->code so callers can `return ncp_diag_set(...)`. */
int ncp_diag_set(struct ncp_diag *d, enum ncp_status code, uint32_t line,
                 uint16_t col, const char *fmt, ...)
    __attribute__((format(printf, 5, 6)));

/* Lasting copies of file names, for struct ncp_diag's file: diagnostics
 * outlive whatever read the file (they are printed after the run). A name's
 * tag is 1, 2, ... in the order first named (0: the table is full, or out of
 * memory), small enough for records that have no room for a pointer; the
 * same name always gives the same tag and the same copy. Thread-safe. */
#define NCP_DIAG_FILE_TAGS 8191u
unsigned ncp_diag_file_tag(const char *name);
const char *ncp_diag_file_of_tag(unsigned tag);

#endif
