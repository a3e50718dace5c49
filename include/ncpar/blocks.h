/* Block source: every way the interpreter turns text into blocks, behind one
 * header, so that each reading of text sits in one place and reads alike:
 *  - the program's blocks in file order, lexed by the thread that takes them
 *    (struct ncp_text_feed: the serial reference's feed, and the pipeline's
 *    with no lexer threads; the lexer threads lex the same lines);
 *  - any block again by its position, through a cache of lexed blocks
 *    (loops and calls going back; struct ncp_block_reread), and every block
 *    of a subroutine file (found, opened and numbered here: struct
 *    ncp_sub_files; read through the same cache);
 *  - a block read again another way: an M#1 line once its M is known to be
 *    98 or 99, a line of a G70-G72 profile (U and W are words there);
 *  - a line of text the interpreter builds itself (G70-G72's call line, M72's
 *    restore lines: ncp_blocks_lex_text);
 *  - every line of a source with what a reader finds wrong in it (check:
 *    ncp_blocks_check_next). */
#ifndef NCPAR_BLOCKS_H
#define NCPAR_BLOCKS_H

#include <stddef.h>
#include <stdint.h>
#include "ncpar/diag.h"
#include "ncpar/feeder.h"
#include "ncpar/lex.h"

/* ---- the program in file order ---- */

/* Where the analyzer gets blocks in file order. The pipeline serves them from the
 * parsed ring (pre-lexed in parallel) or a struct ncp_text_feed, as the serial
 * reference does.
 * next() returns the next block in file order (or NULL at the end of the body)
 * and keeps it valid until release(). The analyzer re-reads earlier blocks for
 * loops and calls itself, from src->text, through struct ncp_block_reread below,
 * and returns to next() once it is back at the block after the last one taken. */
struct ncp_block_feed {
    void *ctx;
    const struct ncp_block *(*next)(void *ctx);
    void (*release)(void *ctx);
    const struct ncp_source *src;
};

struct ncp_text_feed {
    const struct ncp_source *src;
    uint64_t off;
    uint32_t line;
    uint64_t blocks;            /* blocks lexed so far */
    struct ncp_source_window win; /* the mapped text this reader holds */
    struct ncp_block block;     /* the one the analyzer holds */
};

static inline void ncp_text_feed_start(struct ncp_text_feed *f, const struct ncp_source *src)
{
    f->src = src;
    f->off = src->begin;
    f->line = src->begin_line;
    f->blocks = 0;
    ncp_source_window_start(&f->win, src, NCP_SOURCE_WINDOW_LAG);
}

/* struct ncp_block_feed's next(): the next line, or NULL at the end. Inline:
 * it is the serial run's whole per-block reading. */
static inline const struct ncp_block *ncp_text_feed_next(void *ctx)
{
    struct ncp_text_feed *f = ctx;
    if (f->off >= f->src->end)
        return NULL;
    ncp_source_window_at(&f->win, f->off);
    size_t next;
    ncp_lex_line(f->src->text + f->off, f->src->end - f->off, f->line, f->off, &f->block,
                 &next);
    f->off += next;
    f->line++;
    f->blocks++;
    return &f->block;
}

static inline void ncp_text_feed_release(void *ctx)
{
    (void)ctx; /* the block is overwritten by the next one */
}

/* ---- any block again ---- */

/* Blocks read again by position (loops and calls going back), lexed once and
 * kept in a small cache keyed by file and offset. */
struct ncp_block_reread;

struct ncp_block_reread *ncp_block_reread_new(void); /* NULL: out of memory */
void ncp_block_reread_free(struct ncp_block_reread *r);
/* The block at *off (line number *line) of src, which is file number `file`
 * of the run; *off and *line move on to the block after it. With skipping
 * set, a line that cannot hold an O-word or an M98 line is not lexed: *out
 * is NULL. 0, or 1 at the end of src. */
int ncp_block_reread_at(struct ncp_block_reread *r, const struct ncp_source *src,
                        uint32_t file, int skipping, uint64_t *off, uint32_t *line,
                        const struct ncp_block **out);

/* ---- subroutine files ---- */

/* The subroutine files a run has opened, numbered from 1 (0 is the program). */
#define NCP_SUB_FILES_MAX 64
struct ncp_sub_files;

struct ncp_sub_files *ncp_sub_files_new(void); /* NULL: out of memory */
void ncp_sub_files_free(struct ncp_sub_files *t);
/* name.ngc (name_len bytes of name, a path as written in the call) in the
 * current folder, then in each folder of sub_path (colon-separated, may be
 * NULL), as rs274 looks for a called sub: *file = its number, opened and
 * read whole the first time, or 0 when there is none. Errors (too many
 * files, one that cannot be read) name line and col. */
int ncp_sub_files_open(struct ncp_sub_files *t, const char *name, size_t name_len,
                       const char *sub_path, uint32_t line, uint16_t col, uint32_t *file,
                       struct ncp_diag *d);
const struct ncp_source *ncp_sub_files_src(const struct ncp_sub_files *t, uint32_t file);
const char *ncp_sub_files_name(const struct ncp_sub_files *t, uint32_t file);
unsigned ncp_sub_files_tag(const struct ncp_sub_files *t, uint32_t file);

/* ---- a block read another way ---- */

/* Block b of src (an NCP_O_M_VALUE line whose M turned out to be m, 98 or
 * 99) read again as rs274 reads such a line (ncp_lex_block_fanuc). 0, or 1
 * when b is not a line of src. */
int ncp_blocks_relex_fanuc(const struct ncp_source *src, const struct ncp_block *b, int m,
                           struct ncp_block *out);
/* Block b of src read again as rs274 reads a line of a G70-G72 profile, where
 * U and W are words (ncp_lex_block_profile). 0, or 1 when b is not a line of
 * src. */
int ncp_blocks_relex_profile(const struct ncp_source *src, const struct ncp_block *b,
                             struct ncp_block *out);

/* ---- text built by the interpreter ---- */

/* One line of text that is not the program's (text need not end in a line
 * end), lexed as a program line would be, numbered `line` and placed at
 * `offset` for diagnostics: the line of the program it stands for. The
 * block's err holds what is wrong with it. */
void ncp_blocks_lex_text(const char *text, size_t len, uint32_t line, uint64_t offset,
                         struct ncp_block *out);

/* ---- every line, for a syntax check ---- */

struct ncp_blocks_lines {
    const struct ncp_source *src;
    uint64_t off;
    uint32_t line;
    struct ncp_source_window win; /* the mapped text this reader holds */
};

void ncp_blocks_lines_start(struct ncp_blocks_lines *it, const struct ncp_source *src);
/* The next line of the body: 0 and *sp set, 1 at the end. *bad is 1 when a
 * reader of the program rejects the line (its error in b->err): neither as
 * a block nor as a line of a G70-G72 profile (U and W words, which only the
 * run can tell apart); '%' lines, tape delimiters, are never bad here. */
int ncp_blocks_check_next(struct ncp_blocks_lines *it, struct ncp_span *sp,
                          struct ncp_block *b, int *bad);

#endif
