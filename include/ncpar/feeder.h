/* Feeder: loads the program text and splits it into blocks (lines).
 * The split is a pure function of the text so that the analyzer can re-read any
 * earlier block (loops, subroutine calls) from the same text without the file. */
#ifndef NCPAR_FEEDER_H
#define NCPAR_FEEDER_H

#include <stddef.h>
#include <stdint.h>
#include "ncpar/diag.h"

struct ncp_source {
    const char *text;   /* whole program text (mapped file, or a copy: huge pages or heap) */
    size_t len;
    size_t begin, end;  /* program body: after a leading '%' line, before the closing '%' */
    uint32_t begin_line;/* line number of the first body byte */
    const char *name;   /* file name for diagnostics ("-" for stdin) */
    int mapped;         /* 1 if the file is mapped: each page faults on its first touch */
    int owned;          /* 1 if text is a heap copy freed by ncp_source_close */
    void *copy;         /* the anonymous mapping holding a copy of the text, or NULL */
    size_t copy_len;
    int has_percent;    /* program was delimited by '%' lines */
    int fd;             /* a mapped file's, kept to tell whether it changed; else -1 */
    uint64_t dev, ino;  /* the file read (0, 0 for memory and pipes): no output may be it */
    int64_t file_size, mtime_ns;    /* the file as it was read */
};

/* A block's position: text[off .. off+len) excluding the line terminator;
 * `next` is the offset of the following block. */
struct ncp_span {
    uint64_t off;
    uint32_t len;       /* may exceed NCP_LINE_MAX: the lexer reports it */
    uint32_t line;
    uint64_t next;
};

/* Above this a program is mapped, not copied: a copy is anonymous memory the
 * process holds whole until the run ends, a mapped program only a window of
 * it at a time (struct ncp_source_window), so that no program, however long,
 * takes more than a few tens of MB of the process's own memory. */
#define NCP_SOURCE_COPY_MAX ((size_t)32 << 20)

/* Standard input or another pipe is read up to the program's end (a closing
 * '%', or an M2 or M30 the interpreter must reach), at most this much. */
#define NCP_SOURCE_STREAM_MAX ((size_t)256 << 20)
/* From this size on a file whose first line cannot be lexed is refused at
 * once ("Command too long" at 1:1) instead of being read whole first. */
#define NCP_SOURCE_LONG_LINE_CHECK ((size_t)1 << 20)

/* Load a file or "-" (stdin). A regular file up to NCP_SOURCE_COPY_MAX bytes
 * is read into memory on huge pages where the kernel offers them, a larger one
 * is mapped; a pipe is read into memory. Fills d on failure. */
int ncp_source_open(struct ncp_source *src, const char *path, struct ncp_diag *d);
/* Wrap an in-memory buffer (fuzzing, tests). The buffer must outlive src. */
int ncp_source_from_memory(struct ncp_source *src, const char *text, size_t len,
                           const char *name, struct ncp_diag *d);
void ncp_source_close(struct ncp_source *src);
/* 1 if the file behind src changed (size or modification time) since it was
 * opened: a mapped file is read as long as the run lasts, a copy is checked
 * when it is made ("input changed while reading" from ncp_source_open). */
int ncp_source_changed(const struct ncp_source *src);

/* A tape delimiter line: '%' first after blanks (what follows does not matter). */
int ncp_source_percent_line(const char *s, size_t n);

/* Split the block starting at `off` (which has line number `line`). Returns 0 and
 * fills *out, or 1 when off >= src->end (no more blocks). \n and \r\n end a
 * block (a lone \r is left to the lexer, which treats it as a blank). */
int ncp_source_span(const struct ncp_source *src, uint64_t off, uint32_t line,
                    struct ncp_span *out);

/* How much of a mapped program the process holds: the pages its last reader
 * in file order (the analyzer, or the feeder with lexer threads) has gone
 * past are handed back (MADV_DONTNEED), `lag` bytes behind it, and the next
 * stretch is asked for ahead (MADV_WILLNEED, read into the page cache
 * without being mapped). The file stays in the page cache, the kernel's to
 * keep or drop; the process maps a window of it, however long the program.
 * A block read again later (a loop's, a call's) faults its page in again.
 * Each reader keeps its own window; for a copy or a memory source it does
 * nothing. */
struct ncp_source_window {
    const char *text;   /* the mapping, or NULL: nothing to do */
    uint64_t end;       /* bytes of text mapped */
    uint64_t next;      /* the reader's offset from which to act again */
    uint64_t dropped;   /* text below this has been handed back */
    uint64_t lag;
};
/* How far the reader goes between two calls of the kernel. */
#define NCP_SOURCE_WINDOW_STEP ((uint64_t)4 << 20)
/* What a reader keeps behind it unless it says otherwise. */
#define NCP_SOURCE_WINDOW_LAG ((uint64_t)8 << 20)

void ncp_source_window_start(struct ncp_source_window *w, const struct ncp_source *src,
                             uint64_t lag);
void ncp_source_window_move(struct ncp_source_window *w, uint64_t off);
/* The reader is at off: every NCP_SOURCE_WINDOW_STEP bytes, move the window. */
static inline void ncp_source_window_at(struct ncp_source_window *w, uint64_t off)
{
    if (off >= w->next)
        ncp_source_window_move(w, off);
}

/* Chunks: where a piece of about `want` bytes from off ends, just after a
 * line end (or at src->end), and how many line ends text[off .. end) holds,
 * which is how many blocks a chunk that ends after one has. Lets the feeder
 * hand out the program in pieces of many blocks without splitting it. */
uint64_t ncp_source_chunk_end(const struct ncp_source *src, uint64_t off, size_t want);
uint64_t ncp_source_count_newlines(const struct ncp_source *src, uint64_t off, uint64_t end);

/* The next of the span at off whose length (ncp_span.len) is len, found from
 * the line end behind it instead of searching the line again. */
uint64_t ncp_source_after(const struct ncp_source *src, uint64_t off, size_t len);

#endif
