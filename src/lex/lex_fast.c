/* The common line in one pass over the source text: letters followed by plain
 * numbers ("G1 X12.253 Y-3.7 F600"), blanks between words. The general reader
 * first copies the line without its blanks and with a column for every byte,
 * then reads words from the copy; for CAM output that copy and its per-digit
 * loops were most of the lexing time. Anything this reader does not take
 * exactly as the general one would (comments, expressions, parameters, O
 * words, an N word with a fraction or not first, blanks inside a number, signs
 * beyond one, errors of any kind) makes it give up and the general reader
 * reads the line from the start, so both paths give the same block;
 * tests/unit/test_lex.c checks that they do. */
#include "lex_internal.h"

#include <stdint.h>
#include <string.h>

static const double pow10_tab[23] = {
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11,
    1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22
};

/* Every reader below comes in two builds. Unbounded: the caller has found the
 * line's '\n' at or before `len`, and since a '\n' is no blank, digit, sign,
 * dot or letter, every scan stops there by itself: no length test per byte,
 * a third of the instructions of the whole lexer on CAM text. Bounded: the
 * last line of a text without a newline, and blocks handed over without
 * theirs, where every scan also stops at len. The flag is a constant in each
 * build, so the compiler drops the tests from the first. */
#define NCP_IN(p) (!bounded || (p) < len)

static inline __attribute__((always_inline)) int is_blank(char c)
{
    return c == ' ' || c == '\t';
}

static inline __attribute__((always_inline)) unsigned digit_of(char c)
{
    return (unsigned)((unsigned char)c - '0'); /* < 10 for a digit */
}

/* [sign] digits [. digits] starting at text[*i], converted as ncp_lex_number
 * converts it (exact mantissa / exact power of ten), or 0 to give up. */
static inline __attribute__((always_inline)) int
plain_number(const char *text, size_t len, size_t *i, double *out, const int bounded)
{
    size_t p = *i;
    int neg = 0;
    if (NCP_IN(p) && (text[p] == '+' || text[p] == '-'))
        neg = text[p++] == '-';
    size_t first = p;
    uint64_t m = 0;
    unsigned d;
    for (; NCP_IN(p) && (d = digit_of(text[p])) < 10; p++)
        m = m * 10 + d;
    size_t ndig = p - first, frac = 0;
    if (NCP_IN(p) && text[p] == '.') {
        size_t dot = ++p;
        for (; NCP_IN(p) && (d = digit_of(text[p])) < 10; p++)
            m = m * 10 + d;
        frac = p - dot;
        ndig += frac;
    }
    if (ndig == 0 || ndig > 19 || m >= (UINT64_C(1) << 53) || frac > 22)
        return 0;
    if (NCP_IN(p) && text[p] == '.')
        return 0; /* "1.2.3": the general reader's error */
    double v = (double)m / pow10_tab[frac];
    *out = neg ? -v : v;
    *i = p;
    return 1;
}

/* Where the line starting at text ends, seen from position i (a blank run
 * already skipped): 1 with its length and the bytes up to and past its line
 * end, 0 if text[i] is no line end. As ncp_source_span: "\n" ends it, a "\r"
 * right before that or at the end of the text is not part of it. */
static inline __attribute__((always_inline)) int
line_end(const char *text, size_t avail, size_t lim, size_t i, size_t *len, size_t *next,
         const int bounded)
{
    if (bounded && i == lim) {
        if (lim < avail)
            return -1; /* too long for this reader: the general one says so */
        *len = *next = i;
        return 1;
    }
    if (text[i] == '\n') {
        *len = i;
        *next = i + 1;
        return 1;
    }
    if (text[i] == '\r' && (i + 1 == avail || text[i + 1] == '\n')) {
        *len = i;
        *next = i + 1 + (i + 1 < avail);
        return 1;
    }
    return 0;
}

static inline __attribute__((always_inline)) int is_letter(char c)
{
    return (unsigned)((unsigned char)c | 32u) - 'a' < 26u;
}

/* Where the next word or the line end starts after the word ending at p
 * (p > 0), past blanks; 0 when something else follows them (a digit: "X1 2"
 * is X12 to the general reader; a comment), which is not this reader's. */
static inline __attribute__((always_inline)) size_t
word_ends(const char *text, size_t len, size_t p, const int bounded)
{
    size_t k = p;
    while (NCP_IN(k) && is_blank(text[k]))
        k++;
    return (bounded && k >= len) || is_letter(text[k]) || text[k] == '\n' || text[k] == '\r'
               ? k : 0;
}

/* A leading N word (line number, what many CAM posts put on every line),
 * read as the general reader reads it: digits accumulated in a double. Returns
 * where the next word starts, or 0 to give up ("N10.5", "N 10", a comment or
 * a digit after it). */
static inline __attribute__((always_inline)) size_t
line_number(const char *text, size_t len, size_t i, double *out, const int bounded)
{
    size_t p = i + 1;
    unsigned d;
    if (!NCP_IN(p) || digit_of(text[p]) >= 10)
        return 0;
    double v = 0.0;
    for (; NCP_IN(p) && (d = digit_of(text[p])) < 10; p++)
        v = v * 10.0 + d;
    size_t j = NCP_IN(p) && text[p] == '.' ? 0 : word_ends(text, len, p, bounded);
    if (j == 0)
        return 0;
    *out = v;
    return j;
}

/* The line in text[0..len) (len: its '\n' when unbounded, the reader's limit
 * or the text's end when bounded), into *out, or, with pk, straight into a
 * plain packed record there (its size returned): the same words either way,
 * the packed build a constant in each caller. */
static inline __attribute__((always_inline)) size_t
fast_line(const char *text, size_t avail, size_t len, uint64_t offset, struct ncp_block *out,
          size_t *next, const int bounded, unsigned char *pk)
{
    uint32_t seen = 0;
    size_t i = 0;
    unsigned n_words = 0;
    int has_n = 0;
    unsigned char *wp = pk ? pk + PLAIN_HEAD : NULL; /* the packed build's next word */
    while (NCP_IN(i) && is_blank(text[i]))
        i++;
    if (NCP_IN(i) && (text[i] == 'N' || text[i] == 'n')) {
        double nv;
        if ((i = line_number(text, len, i, &nv, bounded)) == 0)
            return 0;
        has_n = 1;
        if (pk) {
            memcpy(wp, &nv, sizeof nv);
            wp += sizeof nv;
        } else {
            out->has_n = 1;
            out->n_number = nv;
        }
    }
    /* M first on the line (M98, M99: Fanuc-style calls and returns) is the
     * general reader's: tested once a line, where a test of each word costs
     * more on CAM text, whose few M lines lose little */
    while (NCP_IN(i) && is_blank(text[i]))
        i++;
    if (NCP_IN(i) && (text[i] | 32) == 'm')
        return 0;
    for (;;) {
        while (NCP_IN(i) && is_blank(text[i]))
            i++;
        size_t line_len = 0;
        int end = line_end(text, avail, len, i, &line_len, next, bounded);
        if (end != 0) {
            if (end < 0)
                return 0;
            if (!pk) {
                out->n_words = (uint16_t)n_words;
                out->length = (uint16_t)line_len;
                out->words_only = 1;
                return 1;
            }
            size_t used = (size_t)(wp - pk), total = (used + NCP_PACK_UNIT - 1) / NCP_PACK_UNIT;
            uint64_t zero = 0; /* the padding (and up to 8 bytes past the record) */
            memcpy(wp, &zero, sizeof zero);
            ncp_plain_put_head(pk, offset, 0, total, line_len, n_words,
                               FORM_PLAIN | (has_n ? FORM_HAS_N : 0));
            return total * NCP_PACK_UNIT;
        }
        char c = (char)(text[i] | 32); /* letters to lower case; others fail below */
        /* n, o: N and O words; u, v, w: not axes here (rs274 -g rejects them) */
        if (!is_letter(text[i]) || c == 'n' || c == 'o' || (c >= 'u' && c <= 'w'))
            return 0;
        if (c != 'g' && c != 'm') {
            uint32_t bit = 1u << (c - 'a');
            if (seen & bit)
                return 0; /* "Multiple X words": the general reader's error */
            seen |= bit;
        }
        if (n_words >= NCP_BLOCK_MAX_WORDS)
            return 0;
        size_t letter = i++;
        double v;
        if (!plain_number(text, len, &i, &v, bounded))
            return 0;
        size_t j = word_ends(text, len, i, bounded);
        if (j == 0)
            return 0;
        uint16_t col = (uint16_t)(letter + 1);
        if (pk) {
            ncp_plain_put_word(wp, v, col, (char)(c - 32));
            wp += PLAIN_WORD;
        } else {
            struct ncp_word *w = &out->words[n_words];
            w->letter = (char)(c - 32);
            w->col = col;
            w->v.value = v;
            w->v.start = w->v.len = 0;
            w->v.is_const = 1;
        }
        n_words++;
        i = j;
    }
}

int ncp_lex_fast_line(const char *text, size_t avail, uint32_t line, uint64_t offset,
                      struct ncp_block *out, size_t *next)
{
    /* never further than the general reader's line limit */
    size_t lim = avail < NCP_LEX_TOO_LONG ? avail : NCP_LEX_TOO_LONG;
    const char *nl = memchr(text, '\n', lim);
    ncp_lex_init_block(out, 0, line, offset);
    if (nl)
        return fast_line(text, avail, (size_t)(nl - text), offset, out, next, 0, NULL) != 0;
    if (avail > NCP_LEX_TOO_LONG)
        return 0; /* too long for this reader: the general one says so */
    return fast_line(text, avail, avail, offset, out, next, 1, NULL) != 0;
}

size_t ncp_lex_fast_line_packed(const char *text, size_t avail, uint64_t offset, void *dst,
                                size_t *next)
{
    size_t lim = avail < NCP_LEX_TOO_LONG ? avail : NCP_LEX_TOO_LONG;
    const char *nl = memchr(text, '\n', lim);
    if (nl)
        return fast_line(text, avail, (size_t)(nl - text), offset, NULL, next, 0, dst);
    if (avail > NCP_LEX_TOO_LONG)
        return 0;
    return fast_line(text, avail, avail, offset, NULL, next, 1, dst);
}

int ncp_lex_fast(const char *text, size_t len, uint32_t line, uint64_t offset,
                 struct ncp_block *out)
{
    size_t next;
    /* the whole of text[0..len) must be the line, as the general reader takes it */
    return ncp_lex_fast_line(text, len, line, offset, out, &next) && next == len &&
           out->length == len;
}
