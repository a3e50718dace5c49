/* Lexer: one source block (one line) -> one fixed-size parsed block.
 * Pure: no shared mutable state, so n lexer threads can run it in parallel.
 * Expressions that are constant fold to a number; those that read parameters are
 * compiled to a small stack bytecode evaluated later by the analyzer with
 * ncp_expr_eval(). Syntax errors are stored in the block (err.code != NCP_OK)
 * and reported when the analyzer reaches the block. */
#ifndef NCPAR_LEX_H
#define NCPAR_LEX_H

#include <stddef.h>
#include <math.h>
#include <stdint.h>
#include "ncpar/diag.h"

#define NCP_LINE_MAX 256      /* rs274 rejects longer lines ("Command too long") */
#define NCP_BLOCK_MAX_WORDS 64
#define NCP_BLOCK_MAX_ASSIGN 32
#define NCP_BLOCK_MAX_CODE 256 /* bytecode instructions per block */
#define NCP_BLOCK_POOL 512     /* names and comment text, NUL-terminated strings */
#define NCP_OWORD_MAX_ARGS 30

/* Stack bytecode. Every instruction pushes or pops doubles. */
enum ncp_bc_op {
    NCP_BC_CONST,   /* push k */
    NCP_BC_PARAM,   /* pop index, push #index (index rounded as rs274 does) */
    NCP_BC_NAMED,   /* push #<name>; name = pool + a, length b */
    NCP_BC_EXISTS,  /* push 1/0: EXISTS[#<name>], name = pool + a, length b */
    NCP_BC_NEG,     /* unary minus */
    NCP_BC_NOT,     /* reserved */
    /* binary: pop rhs, pop lhs, push result */
    NCP_BC_POW, NCP_BC_MUL, NCP_BC_DIV, NCP_BC_MOD, NCP_BC_ADD, NCP_BC_SUB,
    NCP_BC_EQ, NCP_BC_NE, NCP_BC_GT, NCP_BC_GE, NCP_BC_LT, NCP_BC_LE,
    NCP_BC_AND, NCP_BC_OR, NCP_BC_XOR,
    /* unary functions */
    NCP_BC_ABS, NCP_BC_ACOS, NCP_BC_ASIN, NCP_BC_ATAN2 /* binary: ATAN[a]/[b] */,
    NCP_BC_COS, NCP_BC_EXP, NCP_BC_FIX, NCP_BC_FUP, NCP_BC_LN, NCP_BC_ROUND,
    NCP_BC_SIN, NCP_BC_SQRT, NCP_BC_TAN,
    NCP_BC_EXISTS_NUM /* unary: 1/0, EXISTS[#n] with n computed: n a valid number */
};

struct ncp_bc_ins {
    uint8_t op;      /* enum ncp_bc_op */
    uint8_t pad;
    uint16_t a, b;   /* operands (name offset/length) */
    uint16_t col;    /* source column, for run-time errors (div by zero, ...) */
    double k;        /* constant */
};

/* A value: a folded constant, or code[start .. start+len) of the same block. */
struct ncp_expr {
    double value;     /* valid when is_const */
    uint16_t start, len;
    uint8_t is_const;
};

struct ncp_word {
    char letter;      /* upper-case 'A'..'Z' (never 'O' or '#': those have own fields) */
    uint16_t col;     /* 1-based column of the letter */
    struct ncp_expr v;
};

enum ncp_assign_kind { NCP_ASSIGN_NUMBERED, NCP_ASSIGN_NAMED };

/* #index = value  or  #<name> = value. rs274 evaluates all expressions of a block
 * with the parameter values from before the block, then assigns in order. */
struct ncp_assign {
    uint8_t kind;            /* enum ncp_assign_kind */
    uint16_t col;
    struct ncp_expr index;   /* NUMBERED: index expression (#[1+2]=... allowed) */
    uint16_t name_off, name_len; /* NAMED: name in pool, lower-cased, spaces removed */
    struct ncp_expr value;
};

enum ncp_oword_kind {
    NCP_O_NONE = 0, NCP_O_SUB, NCP_O_ENDSUB, NCP_O_CALL, NCP_O_RETURN,
    NCP_O_IF, NCP_O_ELSEIF, NCP_O_ELSE, NCP_O_ENDIF,
    NCP_O_WHILE, NCP_O_ENDWHILE, NCP_O_DO, NCP_O_REPEAT, NCP_O_ENDREPEAT,
    NCP_O_BREAK, NCP_O_CONTINUE,
    /* Fanuc-style subroutines, as rs274 2.9 reads them:
     * FANUC: a bare "O100" line (a definition, run into at level 0);
     * M98:   a line whose first item (after '/' and N) is M98: the call, its
     *        P (the sub's number) and L (repeats) among the block's words, the
     *        M98 itself not; the rest of the line is read as words, not run;
     * M99:   a line whose first item is M99, lexed as usual (M99 one of its
     *        words): a return inside a sub, an end (like M2) at level 0;
     * M_VALUE: a line whose first item is an M with a value from parameters
     *        ("M#1", "M[#2+1]"), lexed as usual (the M its first word): rs274
     *        reads the value as it reads the line, and a 98, or a 99 inside a
     *        sub, makes it one of the two above (ncp_lex_block_fanuc). */
    NCP_O_FANUC, NCP_O_M98, NCP_O_M99, NCP_O_M_VALUE
};

struct ncp_oword {
    uint8_t kind;             /* enum ncp_oword_kind */
    uint8_t nargs;            /* CALL: number of [args] */
    uint16_t col;
    uint16_t tail_col;        /* M99: column of the first thing after "m99" that
                                 is no comment (an error there in a sub), 0 none */
    /* the O-word's name: numeric ("o100" -> "100", leading zeros stripped) or
     * named ("o<foo>" -> "foo", lower-cased), as text in the pool; a number
     * that reads parameters ("o#1", "o[#1+1]") is num instead (name_computed,
     * name_len 0): rs274 evaluates it each time it reads the line */
    uint16_t name_off, name_len;
    struct ncp_expr cond;     /* IF/ELSEIF/WHILE/REPEAT count/RETURN value/ENDSUB value */
    uint8_t has_cond;
    uint8_t name_computed;
    struct ncp_expr num;
    struct ncp_expr args[NCP_OWORD_MAX_ARGS];
};

enum ncp_comment_kind {
    NCP_CMT_NONE = 0, NCP_CMT_PLAIN, NCP_CMT_MSG, NCP_CMT_DEBUG, NCP_CMT_PRINT,
    NCP_CMT_LOGOPEN, NCP_CMT_LOGAPPEND, NCP_CMT_LOGCLOSE, NCP_CMT_LOG,
    NCP_CMT_ABORT             /* (ABORT,text): rs274 stops with text as the error */
};

/* Laid out for the parallel pipeline, where blocks cross cores in ring slots:
 * what every block sets or reads (header, counts, the first words) comes first
 * and is contiguous, the large rarely used arrays last, so a typical block
 * touches a few cache lines of its slot, not kilobytes. */
struct ncp_block {
    uint64_t offset;          /* byte offset of the block in the program text */
    uint32_t line;            /* 1-based source line */
    uint16_t length;          /* bytes of the block, without the newline */
    uint8_t block_delete;     /* leading '/' */
    uint8_t has_n;            /* N word present (value in n_number) */
    uint8_t words_only;       /* 1: constant words and nothing else, as the one-pass
                                 reader makes them (0 says nothing: check) */
    double n_number;
    uint16_t n_words, n_assign, n_code, pool_used;
    /* rs274 keeps the last comment of a line; MSG/DEBUG/PRINT text after the comma */
    uint8_t comment_kind;     /* enum ncp_comment_kind */
    uint16_t comment_off, comment_len; /* in pool */
    struct ncp_oword oword;   /* kind NCP_O_NONE when no O-word (kind is its first byte) */
    struct ncp_word words[NCP_BLOCK_MAX_WORDS]; /* in source order, G/M may repeat */
    struct ncp_diag err;      /* err.code != NCP_OK: syntax error, rest undefined */
    struct ncp_assign assign[NCP_BLOCK_MAX_ASSIGN];
    struct ncp_bc_ins code[NCP_BLOCK_MAX_CODE];
    char pool[NCP_BLOCK_POOL];
};

/* rs274 converts doubles to int with a 32-bit cvttsd2si: out-of-range values and
 * NaN become INT_MIN (then "Negative ... used"). C leaves such a cast undefined,
 * so every double -> int conversion of program values goes through this. */
static inline int ncp_trunc_int(double t)
{
    if (t > -2147483649.0 && t < 2147483648.0)
        return (int)t;
    return (-2147483647 - 1);
}

/* rs274's "integer value" (read_integer_value): the floor, or the ceiling
 * when within 0.0001 of it; 0 and *out, or -1 for a value further from an
 * integer ("Non integer value for integer"). */
static inline int ncp_rs274_int(double v, int *out)
{
    int i = ncp_trunc_int(floor(v));
    if (v - (double)i > 0.9999)
        i = ncp_trunc_int(ceil(v));
    else if (v - (double)i > 0.0001)
        return -1;
    *out = i;
    return 0;
}

/* Nearest integer, halves away from zero (lround), INT_MIN when out of range. */
static inline int ncp_trunc_int_round(double t)
{
    return ncp_trunc_int(round(t));
}

/* Parameters a program may read but not set (rs274's readonly_parameters):
 * the spindle's tool entry #5400-#5413 and the current point #5420-#5428. */
static inline int ncp_param_readonly(int index)
{
    return (index >= 5400 && index <= 5413) || (index >= 5420 && index <= 5428);
}

/* Packed blocks (the parallel pipeline's lexer -> analyzer records): only the
 * used parts, in whole units of NCP_PACK_UNIT bytes. ncp_block_pack writes
 * ncp_block_packed_size(b) bytes (at most NCP_BLOCK_PACK_MAX) to dst and
 * returns that size; ncp_block_unpack restores every field a reader of the
 * block may use; ncp_block_packed_units reads a record's size from its start. */
#define NCP_PACK_UNIT 8u
#define NCP_BLOCK_PACK_MAX (sizeof(struct ncp_block) + 64u)
size_t ncp_block_packed_size(const struct ncp_block *b);
size_t ncp_block_pack(const struct ncp_block *b, void *dst);
size_t ncp_block_packed_units(const void *src);
void ncp_block_unpack(const void *src, struct ncp_block *b);
/* ncp_block_unpack into a block that only these calls write, one record
 * after another: what every plain block has alike is written once, not per
 * block (most of a plain record's unpacking). *plain is the calls' own state:
 * 0 to start with, and again whenever anything else has written b. Returns
 * the record's size in units, as ncp_block_packed_units. */
size_t ncp_block_unpack_over(const void *src, struct ncp_block *b, unsigned *plain);
/* ncp_lex_line (line number 0) and ncp_block_pack in one: the line at text
 * lexed straight into a packed record at dst, which has room bytes (what
 * follows the record there may be overwritten). The record's size, or 0 if
 * it does not fit. scratch: where the general reader builds the block of a
 * line the one-pass reader leaves to it. */
size_t ncp_lex_line_packed(const char *text, size_t avail, uint64_t offset, void *dst,
                           size_t room, struct ncp_block *scratch, size_t *next);
/* A one-unit filler record meaning "nothing more up to the end of the buffer"
 * (a ring's wrap-around point), and its test. */
void ncp_block_pack_pad(void *dst);
int ncp_block_packed_is_pad(const void *src);
/* A one-unit record meaning "the blocks of this piece of the program end
 * here" (the pipeline's chunk boundary), and its test. */
void ncp_block_pack_end_mark(void *dst);
int ncp_block_packed_is_end_mark(const void *src);

/* Parse text[0..len) (one line, no newline) into *out. Always fills out->err.
 * Returns out->err.code. Never reads outside text[0..len). */
int ncp_lex_block(const char *text, size_t len, uint32_t line, uint64_t offset,
                  struct ncp_block *out);
/* An NCP_O_M_VALUE line as rs274 reads it once its M is known to be m (98 or
 * 99): an M98 or M99 line, read from three characters on as always ("m#1"
 * happens to be three characters; "m#10" leaves a bad character '0'). */
int ncp_lex_block_fanuc(const char *text, size_t len, uint32_t line, uint64_t offset, int m,
                        struct ncp_block *out);
/* ncp_lex_block as rs274 reads the blocks of a G70-G72 profile subroutine:
 * U and W (incremental X and Z there) are words, not bad characters. */
int ncp_lex_block_profile(const char *text, size_t len, uint32_t line, uint64_t offset,
                          struct ncp_block *out);
/* The line at the start of text[0..avail) (the rest of the program or of a
 * chunk), lexed as ncp_lex_block lexes it, with *next = the bytes up to and
 * past its line end (as ncp_source_span splits lines: "\n" ends a line, a
 * "\r" before it or at the very end is not part of it). Splitting and lexing
 * in one pass: the common line is read once, not searched for its end first. */
int ncp_lex_line(const char *text, size_t avail, uint32_t line, uint64_t offset,
                 struct ncp_block *out, size_t *next);

/* Parameter access for expression evaluation, implemented by the analyzer. */
struct ncp_param_ops {
    void *ctx;
    /* return 0 on success, or fill d and return its code */
    int (*get_numbered)(void *ctx, int index, double *out, struct ncp_diag *d);
    int (*get_named)(void *ctx, const char *name, size_t len, double *out,
                     struct ncp_diag *d);
    int (*exists_named)(void *ctx, const char *name, size_t len);
};

/* Evaluate e (of block b). Returns NCP_OK or fills *d (with b->line and the
 * failing instruction's column) and returns d->code. */
int ncp_expr_eval(const struct ncp_block *b, const struct ncp_expr *e,
                  const struct ncp_param_ops *p, double *out, struct ncp_diag *d);

#endif
