/* Packed blocks: what crosses from a lexer's core to the analyzer's. A parsed
 * block is a fixed 8 KB struct so that any line fits; a plain "G1 X1 Y2 Z3"
 * uses about 130 bytes of it, spread over several cache lines. Packed, only
 * the used parts travel, back to back and without padding (96 bytes for that
 * block), so one block costs one or two cache line transfers instead of five
 * or more, and the lines arrive in sequence for the hardware prefetcher. Unpacking restores every field the analyzer
 * may read (arrays up to their counts), so it sees the very block the lexer
 * produced. */
#include "lex_internal.h"

#include <string.h>

/* A word in 16 bytes instead of struct ncp_word's 24 (its padding does not
 * travel): "G1 X Y Z" packs into 96 bytes, a cache line and a half. */
struct packed_word {
    double value;
    uint16_t start, len;
    uint16_t col;
    char letter;
    uint8_t is_const;
};

#define ARGS_OFF offsetof(struct ncp_oword, args)

static size_t round_unit(size_t n)
{
    return (n + NCP_PACK_UNIT - 1) / NCP_PACK_UNIT * NCP_PACK_UNIT;
}

static unsigned clampu(unsigned v, unsigned max)
{
    return v < max ? v : max;
}

/* Counts clamped to their arrays: a block with a syntax error may carry
 * partial counts, and the packer must never read past an array. */
struct pack_counts {
    unsigned words, assign, code, pool, nargs, msg;
};

static struct pack_counts counts_of(const struct ncp_block *b)
{
    struct pack_counts c;
    c.words = clampu(b->n_words, NCP_BLOCK_MAX_WORDS);
    c.assign = clampu(b->n_assign, NCP_BLOCK_MAX_ASSIGN);
    c.code = clampu(b->n_code, NCP_BLOCK_MAX_CODE);
    c.pool = clampu(b->pool_used, NCP_BLOCK_POOL);
    c.nargs = b->oword.kind != NCP_O_NONE ? clampu(b->oword.nargs, NCP_OWORD_MAX_ARGS) : 0;
    c.msg = b->err.code != NCP_OK ? (unsigned)strnlen(b->err.msg, NCP_DIAG_MSG_MAX - 1) + 1 : 0;
    return c;
}

static size_t bytes_of(const struct ncp_block *b, const struct pack_counts *c)
{
    size_t n = sizeof(struct packed_head);
    if (b->has_n)
        n += sizeof b->n_number;
    if (b->err.code != NCP_OK)
        n += offsetof(struct ncp_diag, msg) + c->msg;
    n += c->words * sizeof(struct packed_word) + c->assign * sizeof(struct ncp_assign);
    if (b->oword.kind != NCP_O_NONE)
        n += ARGS_OFF + c->nargs * sizeof(struct ncp_expr);
    n += c->code * sizeof(struct ncp_bc_ins) + c->pool;
    return round_unit(n);
}

/* Whether b packs as a plain record. Blocks with a syntax error may carry
 * any counts: those are never plain. */
static int is_plain(const struct ncp_block *b)
{
    if (b->words_only)
        return 1;
    if ((b->n_assign | b->n_code | b->pool_used | b->comment_kind | b->comment_off |
         b->comment_len | b->oword.kind | b->err.code) != 0 ||
        b->n_words > NCP_BLOCK_MAX_WORDS)
        return 0;
    for (unsigned k = 0; k < b->n_words; k++) {
        const struct ncp_expr *v = &b->words[k].v;
        if (!v->is_const || (v->start | v->len) != 0)
            return 0;
    }
    return 1;
}

static size_t plain_bytes(const struct ncp_block *b)
{
    size_t n = PLAIN_HEAD + (b->has_n ? sizeof b->n_number : 0) + (size_t)b->n_words * PLAIN_WORD;
    return round_unit(n);
}

size_t ncp_block_packed_size(const struct ncp_block *b)
{
    if (is_plain(b))
        return plain_bytes(b);
    struct pack_counts c = counts_of(b);
    return bytes_of(b, &c);
}

/* Most parts of a plain block are empty (no assignments, bytecode or pool):
 * a library call to copy nothing costs more than the test. */
static unsigned char *put(unsigned char *p, const void *src, size_t n)
{
    if (n)
        memcpy(p, src, n);
    return p + n;
}

static const unsigned char *get(const unsigned char *p, void *dst, size_t n)
{
    if (n)
        memcpy(dst, p, n);
    return p + n;
}

/* Header and words are written field by field straight to their place: built
 * on the stack and copied whole, their mixed-width stores could not be
 * forwarded to the wide load of the copy, a stall per block and per word,
 * which cost more than the packing itself. */
/* PUT_AT's ctype must be the field's type: with these sizes and no padding,
 * a wrong one would overlap its neighbour (and the round-trip tests fail). */
_Static_assert(sizeof(struct packed_head) == 32, "packed_head: 8+4+6*2+8*1 bytes");
_Static_assert(offsetof(struct packed_head, form) == PLAIN_HEAD - 1, "plain head is a prefix");
_Static_assert(sizeof(struct packed_word) == 16, "packed_word: 8+3*2+2*1 bytes");

static void put_at(unsigned char *base, size_t off, const void *v, size_t n)
{
    memcpy(base + off, v, n);
}
#define PUT_AT(base, type, field, ctype, val)                                   \
    do {                                                                        \
        ctype v_ = (val);                                                       \
        put_at((base), offsetof(type, field), &v_, sizeof v_);                  \
    } while (0)
#define HEAD(field, ctype, val) PUT_AT(p, struct packed_head, field, ctype, val)
#define WORD(field, ctype, val) PUT_AT(p, struct packed_word, field, ctype, val)

static size_t pack_plain(const struct ncp_block *b, unsigned char *p)
{
    size_t total = plain_bytes(b);
    uint64_t zero = 0;
    memcpy(p + total - sizeof zero, &zero, sizeof zero); /* the padding, if any */
    ncp_plain_put_head(p, b->offset, b->line, total / NCP_PACK_UNIT, b->length, b->n_words,
                       FORM_PLAIN | (b->block_delete ? FORM_BLOCK_DELETE : 0) |
                           (b->has_n ? FORM_HAS_N : 0));
    p += PLAIN_HEAD;
    if (b->has_n) {
        memcpy(p, &b->n_number, sizeof b->n_number);
        p += sizeof b->n_number;
    }
    for (unsigned k = 0; k < b->n_words; k++, p += PLAIN_WORD)
        ncp_plain_put_word(p, b->words[k].v.value, b->words[k].col, b->words[k].letter);
    return total;
}

size_t ncp_block_pack(const struct ncp_block *b, void *dst)
{
    if (is_plain(b))
        return pack_plain(b, dst);
    struct pack_counts c = counts_of(b);
    size_t total = bytes_of(b, &c);
    uint8_t has_n = b->has_n, has_err = b->err.code != NCP_OK, oword_kind = b->oword.kind;
    unsigned char *p = dst;
    HEAD(offset, uint64_t, b->offset);
    HEAD(line, uint32_t, b->line);
    HEAD(units, uint16_t, (uint16_t)(total / NCP_PACK_UNIT));
    HEAD(length, uint16_t, b->length);
    HEAD(n_code, uint16_t, (uint16_t)c.code);
    HEAD(pool_used, uint16_t, (uint16_t)c.pool);
    HEAD(comment_off, uint16_t, b->comment_off);
    HEAD(comment_len, uint16_t, b->comment_len);
    HEAD(n_words, uint8_t, (uint8_t)c.words);
    HEAD(form, uint8_t, (uint8_t)(has_err ? FORM_ERR : 0));
    HEAD(n_assign, uint8_t, (uint8_t)c.assign);
    HEAD(block_delete, uint8_t, b->block_delete);
    HEAD(has_n, uint8_t, has_n);
    HEAD(comment_kind, uint8_t, b->comment_kind);
    HEAD(oword_kind, uint8_t, oword_kind);
    HEAD(oword_nargs, uint8_t, (uint8_t)c.nargs);
    p += sizeof(struct packed_head);
    if (has_n)
        p = put(p, &b->n_number, sizeof b->n_number);
    if (has_err) {
        p = put(p, &b->err, offsetof(struct ncp_diag, msg));
        p = put(p, b->err.msg, c.msg - 1);
        *p++ = '\0';
    }
    for (unsigned k = 0; k < c.words; k++, p += sizeof(struct packed_word)) {
        const struct ncp_word *w = &b->words[k];
        WORD(value, double, w->v.value);
        WORD(start, uint16_t, w->v.start);
        WORD(len, uint16_t, w->v.len);
        WORD(col, uint16_t, w->col);
        WORD(letter, char, w->letter);
        WORD(is_const, uint8_t, w->v.is_const);
    }
    p = put(p, b->assign, c.assign * sizeof b->assign[0]);
    if (oword_kind != NCP_O_NONE) {
        p = put(p, &b->oword, ARGS_OFF);
        p = put(p, b->oword.args, c.nargs * sizeof b->oword.args[0]);
    }
    p = put(p, b->code, c.code * sizeof b->code[0]);
    p = put(p, b->pool, c.pool);
    size_t used = (size_t)(p - (unsigned char *)dst);
    if (total > used)
        memset(p, 0, total - used);
    return total;
}

size_t ncp_lex_line_packed(const char *text, size_t avail, uint64_t offset, void *dst,
                           size_t room, struct ncp_block *scratch, size_t *next)
{
    if (room >= NCP_LEX_PLAIN_MAX) {
        size_t n = ncp_lex_fast_line_packed(text, avail, offset, dst, next);
        if (n)
            return n; /* no block built and then copied: most of CAM text */
    }
    ncp_lex_line(text, avail, 0, offset, scratch, next);
    size_t size = ncp_block_packed_size(scratch);
    return size <= room ? ncp_block_pack(scratch, dst) : 0;
}

size_t ncp_block_packed_units(const void *src)
{
    uint16_t units; /* a plain record may be shorter than the general head */
    memcpy(&units, (const unsigned char *)src + offsetof(struct packed_head, units), sizeof units);
    return units;
}

/* What every plain block has alike (nothing of what it does not have, as
 * the lexer leaves it), and its words' parts that are the same in every
 * plain word, for words [from, to). */
static void plain_constants(struct ncp_block *b, unsigned from, unsigned to)
{
    b->words_only = 1;
    b->n_assign = b->n_code = b->pool_used = 0;
    b->comment_kind = NCP_CMT_NONE;
    b->comment_off = b->comment_len = 0;
    b->err.code = NCP_OK;
    b->err.col = 0;
    b->err.file = NULL;
    b->err.msg[0] = '\0';
    b->oword.kind = NCP_O_NONE;
    for (unsigned k = from; k < to; k++) {
        struct ncp_word *w = &b->words[k];
        w->v.start = w->v.len = 0;
        w->v.is_const = 1;
    }
}

/* What differs from one plain block to the next. */
static inline void unpack_plain_parts(const unsigned char *p, struct ncp_block *b)
{
    uint64_t offset;
    uint32_t line;
    uint16_t length;
    memcpy(&offset, p + offsetof(struct packed_head, offset), sizeof offset);
    memcpy(&line, p + offsetof(struct packed_head, line), sizeof line);
    memcpy(&length, p + offsetof(struct packed_head, length), sizeof length);
    unsigned n_words = p[offsetof(struct packed_head, n_words)];
    unsigned form = p[offsetof(struct packed_head, form)];
    b->offset = offset;
    b->line = line;
    b->err.line = line;
    b->length = length;
    b->block_delete = (form & FORM_BLOCK_DELETE) != 0;
    b->has_n = (form & FORM_HAS_N) != 0;
    b->n_words = (uint16_t)n_words;
    p += PLAIN_HEAD;
    b->n_number = 0.0;
    if (form & FORM_HAS_N) {
        memcpy(&b->n_number, p, sizeof b->n_number);
        p += sizeof b->n_number;
    }
    for (unsigned k = 0; k < n_words; k++, p += PLAIN_WORD) {
        struct ncp_word *w = &b->words[k];
        memcpy(&w->v.value, p, sizeof w->v.value);
        memcpy(&w->col, p + 8, sizeof w->col);
        w->letter = (char)p[10];
    }
}

static unsigned plain_words(const unsigned char *p)
{
    return p[offsetof(struct packed_head, n_words)];
}

static void unpack_plain(const unsigned char *p, struct ncp_block *b)
{
    plain_constants(b, 0, plain_words(p));
    unpack_plain_parts(p, b);
}

/* Anything but a plain record over a block already set up for as many
 * words: out of line, so the common case below saves no registers. */
static __attribute__((noinline)) size_t unpack_over_slow(const unsigned char *p,
                                                          struct ncp_block *b, unsigned *plain)
{
    if (!(p[offsetof(struct packed_head, form)] & FORM_PLAIN)) {
        ncp_block_unpack(p, b);
        *plain = 0;
        return ncp_block_packed_units(p);
    }
    unsigned n = plain_words(p);
    plain_constants(b, *plain ? *plain - 1 : 0, n);
    unpack_plain_parts(p, b);
    *plain = n + 1;
    return ncp_block_packed_units(p);
}

size_t ncp_block_unpack_over(const void *src, struct ncp_block *b, unsigned *plain)
{
    const unsigned char *p = src;
    /* *plain - 1 words set up: a plain record of no more words than that */
    if (!(p[offsetof(struct packed_head, form)] & FORM_PLAIN) || plain_words(p) >= *plain)
        return unpack_over_slow(p, b, plain);
    unpack_plain_parts(p, b);
    uint16_t units;
    memcpy(&units, p + offsetof(struct packed_head, units), sizeof units);
    return units;
}

void ncp_block_unpack(const void *src, struct ncp_block *b)
{
    if (((const unsigned char *)src)[offsetof(struct packed_head, form)] & FORM_PLAIN) {
        unpack_plain(src, b);
        return;
    }
    struct packed_head h;
    const unsigned char *p = get(src, &h, sizeof h);
    b->offset = h.offset;
    b->line = h.line;
    b->length = h.length;
    b->block_delete = h.block_delete;
    b->has_n = h.has_n;
    b->words_only = 0;
    b->n_number = 0.0;
    if (h.has_n)
        p = get(p, &b->n_number, sizeof b->n_number);
    b->n_words = h.n_words;
    b->n_assign = h.n_assign;
    b->n_code = h.n_code;
    b->pool_used = h.pool_used;
    b->comment_kind = h.comment_kind;
    b->comment_off = h.comment_off;
    b->comment_len = h.comment_len;
    if (h.form & FORM_ERR) {
        p = get(p, &b->err, offsetof(struct ncp_diag, msg));
        size_t n = strnlen((const char *)p, NCP_DIAG_MSG_MAX - 1);
        p = get(p, b->err.msg, n);
        b->err.msg[n] = '\0';
        p++;
    } else {
        b->err.code = NCP_OK;
        b->err.line = h.line;
        b->err.col = 0;
        b->err.file = NULL;
        b->err.msg[0] = '\0';
    }
    for (unsigned k = 0; k < h.n_words; k++) {
        struct packed_word pw;
        p = get(p, &pw, sizeof pw);
        struct ncp_word *w = &b->words[k];
        w->letter = pw.letter;
        w->col = pw.col;
        w->v.value = pw.value;
        w->v.start = pw.start;
        w->v.len = pw.len;
        w->v.is_const = pw.is_const;
    }
    p = get(p, b->assign, h.n_assign * sizeof b->assign[0]);
    if (h.oword_kind != NCP_O_NONE) {
        p = get(p, &b->oword, ARGS_OFF);
        p = get(p, b->oword.args, h.oword_nargs * sizeof b->oword.args[0]);
    } else {
        b->oword.kind = NCP_O_NONE;
    }
    p = get(p, b->code, h.n_code * sizeof b->code[0]);
    get(p, b->pool, h.pool_used);
}

/* Records no real block can start with (its offset would be 2^64 - 1 or - 2). */
static const uint64_t pad_marker = UINT64_MAX;
static const uint64_t end_marker = UINT64_MAX - 1;

static int starts_with(const void *src, uint64_t marker)
{
    uint64_t v;
    memcpy(&v, src, sizeof v);
    return v == marker;
}

void ncp_block_pack_end_mark(void *dst)
{
    memcpy(dst, &end_marker, sizeof end_marker);
}

int ncp_block_packed_is_end_mark(const void *src)
{
    return starts_with(src, end_marker);
}

void ncp_block_pack_pad(void *dst)
{
    memcpy(dst, &pad_marker, sizeof pad_marker);
}

int ncp_block_packed_is_pad(const void *src)
{
    return starts_with(src, pad_marker);
}
