/* A program in memory handed to the analyzer block by block, as the
 * pipeline's feeder and lexers would, for the tests that drive the
 * analyzer alone. Include after ncpar/analyzer.h, feeder.h and lex.h. */
#ifndef NCP_TEST_MEM_FEED_H
#define NCP_TEST_MEM_FEED_H

struct mem_feed {
    struct ncp_source src;
    uint64_t off;
    uint32_t line;
    struct ncp_block block;
};

static const struct ncp_block *mf_next(void *ctx)
{
    struct mem_feed *f = ctx;
    struct ncp_span sp;
    if (ncp_source_span(&f->src, f->off, f->line, &sp) != 0)
        return NULL;
    ncp_lex_block(f->src.text + sp.off, sp.len, sp.line, sp.off, &f->block);
    f->off = sp.next;
    f->line++;
    return &f->block;
}

static void mf_release(void *ctx)
{
    (void)ctx;
}

#endif
