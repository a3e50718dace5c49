/* Blocks from text that is not read in file order by the feed: lines the
 * interpreter builds, and every line for a syntax check (ncpar/blocks.h). */
#include "ncpar/blocks.h"

void ncp_blocks_lex_text(const char *text, size_t len, uint32_t line, uint64_t offset,
                         struct ncp_block *out)
{
    size_t next;
    ncp_lex_line(text, len, line, offset, out, &next);
}

void ncp_blocks_lines_start(struct ncp_blocks_lines *it, const struct ncp_source *src)
{
    it->src = src;
    it->off = src->begin;
    it->line = src->begin_line;
    ncp_source_window_start(&it->win, src, NCP_SOURCE_WINDOW_LAG);
}

int ncp_blocks_check_next(struct ncp_blocks_lines *it, struct ncp_span *sp,
                          struct ncp_block *b, int *bad)
{
    ncp_source_window_at(&it->win, it->off);
    if (ncp_source_span(it->src, it->off, it->line, sp) != 0)
        return 1;
    it->off = sp->next;
    it->line++;
    const char *s = it->src->text + sp->off;
    *bad = !ncp_source_percent_line(s, sp->len) &&
           ncp_lex_block(s, sp->len, sp->line, sp->off, b) != NCP_OK &&
           ncp_lex_block_profile(s, sp->len, sp->line, sp->off, b) != NCP_OK;
    return 0;
}

int ncp_blocks_relex_fanuc(const struct ncp_source *src, const struct ncp_block *b, int m,
                           struct ncp_block *out)
{
    struct ncp_span sp;
    if (ncp_source_span(src, b->offset, b->line, &sp) != 0)
        return 1;
    ncp_lex_block_fanuc(src->text + sp.off, sp.len, b->line, b->offset, m, out);
    return 0;
}

int ncp_blocks_relex_profile(const struct ncp_source *src, const struct ncp_block *b,
                             struct ncp_block *out)
{
    if (b->length >= 0xffff || b->offset + b->length > src->len)
        return 1;
    ncp_lex_block_profile(src->text + b->offset, b->length, b->line, b->offset, out);
    return 0;
}
