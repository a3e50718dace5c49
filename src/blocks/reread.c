/* Blocks read again by position, with a cache of lexed ones (ncpar/blocks.h).
 * A loop body runs many times: its lines are lexed once, then served from
 * here while they stay in the cache. */
#include "ncpar/blocks.h"

#include <stdlib.h>
#include <string.h>

#define REREAD_BITS 8
#define REREAD_SLOTS (1u << REREAD_BITS) /* blocks kept lexed (~2 MB) */

struct reread_slot {
    struct ncp_block blk;
    uint64_t next;
    uint32_t file;
    int valid;
};

struct ncp_block_reread {
    struct reread_slot slot[REREAD_SLOTS];
};

struct ncp_block_reread *ncp_block_reread_new(void)
{
    return calloc(1, sizeof(struct ncp_block_reread));
}

void ncp_block_reread_free(struct ncp_block_reread *r)
{
    free(r);
}

/* O-word lines, and M98 lines, which rs274 reads even where it skips */
static int reread_may_be_oword(const char *s, size_t n)
{
    return memchr(s, 'o', n) || memchr(s, 'O', n) || memchr(s, 'm', n) || memchr(s, 'M', n);
}

int ncp_block_reread_at(struct ncp_block_reread *r, const struct ncp_source *src,
                        uint32_t file, int skipping, uint64_t *off, uint32_t *line,
                        const struct ncp_block **out)
{
    uint64_t key = *off ^ (uint64_t)file << 40;
    struct reread_slot *c = &r->slot[(key * 0x9E3779B97F4A7C15ull) >> (64 - REREAD_BITS)];
    if (c->valid && c->blk.offset == *off && c->file == file) {
        *off = c->next;
        *line = c->blk.line + 1;
        *out = &c->blk;
        return 0;
    }
    struct ncp_span sp;
    if (ncp_source_span(src, *off, *line, &sp) != 0)
        return 1;
    *off = sp.next;
    *line = sp.line + 1;
    const char *text = src->text + sp.off;
    if (skipping && !reread_may_be_oword(text, sp.len)) {
        *out = NULL;
        return 0;
    }
    ncp_lex_block(text, sp.len, sp.line, sp.off, &c->blk);
    c->next = sp.next;
    c->file = file;
    c->valid = 1;
    *out = &c->blk;
    return 0;
}
