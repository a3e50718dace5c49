/* Blocks straight from the program text, lexed by the thread that analyzes
 * them (module-internal header): the serial reference's feed, and the
 * pipeline's with no lexer threads (-j 0). */
#ifndef NCP_PIPELINE_TEXT_FEED_H
#define NCP_PIPELINE_TEXT_FEED_H

#include "ncpar/feeder.h"
#include "ncpar/lex.h"

struct ncp_text_feed {
    const struct ncp_source *src;
    uint64_t off;
    uint32_t line;
    uint64_t blocks;            /* blocks lexed so far */
    struct ncp_block block;     /* the one the analyzer holds */
};

static inline void ncp_text_feed_start(struct ncp_text_feed *f, const struct ncp_source *src)
{
    f->src = src;
    f->off = src->begin;
    f->line = src->begin_line;
    f->blocks = 0;
}

/* struct ncp_block_feed's next(): the next line, or NULL at the end */
static inline const struct ncp_block *ncp_text_feed_next(void *ctx)
{
    struct ncp_text_feed *f = ctx;
    if (f->off >= f->src->end)
        return NULL;
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

#endif
