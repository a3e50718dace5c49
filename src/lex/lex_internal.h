/* Lexer internals: the state of one ncp_lex_block() call and the readers
 * that share it. Module-private. */
#ifndef NCP_LEX_INTERNAL_H
#define NCP_LEX_INTERNAL_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include "ncpar/lex.h"

/* rs274 reads lines with fgets(buf, 255): a line of 253 characters or more
 * (254 with its newline) is "Command too long". */
#define NCP_LEX_TOO_LONG 253
#define NCP_LEX_PAD 8
/* Nesting bound for values inside values, so a lexer thread's stack use is
 * bounded (about 20 KB); rs274 has none, real programs nest a few levels. */
#define NCP_LEX_MAX_DEPTH 40

/* The line as rs274's reader sees it: blanks removed and letters lower-cased
 * outside comments, NUL-terminated, with the source column of every byte. */
struct ncp_lexer {
    struct ncp_block *b;
    int pos;               /* read position in buf */
    int n;                 /* length of buf */
    int depth;             /* nesting of values being read */
    int cmt_pos, cmt_len;  /* last (...) comment seen, inside buf; cmt_pos < 0: none */
    int uw_words;          /* U and W are words (a G7x profile), not bad characters */
    int fanuc_m;           /* 98 or 99: the first M's value, known (M_VALUE lines); 0 */
    char buf[NCP_LEX_TOO_LONG + NCP_LEX_PAD];
    uint8_t col[NCP_LEX_TOO_LONG + NCP_LEX_PAD]; /* 1-based source column */
};

/* A value being compiled: a constant, or code[start .. b->n_code). */
struct ncp_lex_val {
    double k;
    uint16_t start;
    uint8_t is_const;
};

/* lex_floor.c: a block as it is before anything was read from its line */
void ncp_lex_init_block(struct ncp_block *b, size_t len, uint32_t line, uint64_t offset);
/* lex_block.c: ncp_lex_block without the fast path (the differential test calls it) */
int ncp_lex_block_general(const char *text, size_t len, uint32_t line, uint64_t offset,
                          struct ncp_block *out);

/* lex_fast.c: 1 and *out filled exactly as the general reader fills it when
 * the line is words with plain numbers only (what CAM output mostly is); 0
 * for anything else, errors included, which the general reader then reads. */
int ncp_lex_fast(const char *text, size_t len, uint32_t line, uint64_t offset,
                 struct ncp_block *out);
/* The same for the line at the start of text[0..avail), found while reading
 * it: *next = the bytes up to and past its line end. */
int ncp_lex_fast_line(const char *text, size_t avail, uint32_t line, uint64_t offset,
                      struct ncp_block *out, size_t *next);

/* The same again, the block written straight as a plain packed record to
 * dst (room for NCP_LEX_PLAIN_MAX bytes; what follows the record there is
 * overwritten) with line number 0: its size, or 0 for a line the one-pass
 * reader leaves to the general one. */
size_t ncp_lex_fast_line_packed(const char *text, size_t avail, uint64_t offset, void *dst,
                                size_t *next);

/* ---- packed records (lex_pack.c; lex_fast.c writes plain ones) ---------- */

/* 32 bytes; the N number follows only when the block has one. The first 18
 * bytes (offset .. form) are those of a plain record too (below). */
struct packed_head {
    uint64_t offset;
    uint32_t line;
    uint16_t units;           /* the record's size in NCP_PACK_UNIT bytes */
    uint16_t length;
    uint8_t n_words, form;    /* form: FORM_* bits */
    uint8_t n_assign, block_delete, has_n, comment_kind, oword_kind, oword_nargs;
    uint16_t n_code, pool_used, comment_off, comment_len;
};

/* A plain block (constant words only; no assignment, bytecode, pool text,
 * comment, O-word or error: every CAM line) packs into the common 18 bytes,
 * its N number and 11 bytes a word, and unpacks without looking at the parts
 * it does not have: "G1 X Y Z" is 64 bytes, one cache line, where the general
 * form takes 96, and both sides spend a fraction of the general form's
 * instructions on it (most of the lexing-ahead hand-over on CAM text). */
enum {
    FORM_PLAIN = 1,           /* a plain record */
    FORM_ERR = 2,             /* general: the block carries a syntax error */
    FORM_BLOCK_DELETE = 4,    /* plain: leading '/' */
    FORM_HAS_N = 8,           /* plain: the N number follows the head */
};
#define PLAIN_HEAD 18u
#define PLAIN_WORD 11u        /* value, col, letter */
/* room a plain record may take while it is written (8 past the last word) */
#define NCP_LEX_PLAIN_MAX (PLAIN_HEAD + 8u + NCP_BLOCK_MAX_WORDS * PLAIN_WORD + 8u)

/* A plain record's head and words, as the packer and the one-pass reader's
 * packed build both write them (unpack_plain reads them back). form: FORM_PLAIN
 * and the plain bits. */
static inline void ncp_plain_put_head(unsigned char *pk, uint64_t offset, uint32_t line,
                                      size_t units, size_t length, unsigned n_words,
                                      unsigned form)
{
    uint16_t u = (uint16_t)units, l = (uint16_t)length;
    memcpy(pk + offsetof(struct packed_head, offset), &offset, sizeof offset);
    memcpy(pk + offsetof(struct packed_head, line), &line, sizeof line);
    memcpy(pk + offsetof(struct packed_head, units), &u, sizeof u);
    memcpy(pk + offsetof(struct packed_head, length), &l, sizeof l);
    pk[offsetof(struct packed_head, n_words)] = (unsigned char)n_words;
    pk[offsetof(struct packed_head, form)] = (unsigned char)form;
}

static inline void ncp_plain_put_word(unsigned char *wp, double value, uint16_t col, char letter)
{
    memcpy(wp, &value, sizeof value);
    memcpy(wp + 8, &col, sizeof col);
    wp[10] = (unsigned char)letter;
}

/* lex_floor.c: stores a syntax error at buf position pos; returns
 * NCP_ERR_SYNTAX. */
int ncp_lex_fail(struct ncp_lexer *lx, int pos, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* lex_text.c: close_and_downcase + line checks */
int ncp_lex_squeeze(struct ncp_lexer *lx, const char *text, size_t len);

/* lex_number.c: decimal literal at lx->pos (rs274 read_real_number) */
int ncp_lex_number(struct ncp_lexer *lx, double *out);

/* lex_expr.c */
int ncp_lex_real_value(struct ncp_lexer *lx, struct ncp_lex_val *v);
int ncp_lex_expression(struct ncp_lexer *lx, struct ncp_lex_val *v);
int ncp_lex_integer_value(struct ncp_lexer *lx, struct ncp_lex_val *v);
int ncp_lex_read_name(struct ncp_lexer *lx, uint16_t *off, uint16_t *len);
void ncp_lex_to_expr(const struct ncp_lexer *lx, const struct ncp_lex_val *v,
                     struct ncp_expr *e);

/* lex_comment.c */
int ncp_lex_comment(struct ncp_lexer *lx);
void ncp_lex_store_comment(struct ncp_lexer *lx);

/* lex_oword.c */
int ncp_lex_oword(struct ncp_lexer *lx);

#endif
