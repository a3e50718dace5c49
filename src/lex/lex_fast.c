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

static const double pow10_tab[23] = {
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11,
    1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22
};

static int is_blank(char c)
{
    return c == ' ' || c == '\t';
}

static int is_digit(char c)
{
    return c >= '0' && c <= '9';
}

/* [sign] digits [. digits] starting at text[*i], converted as ncp_lex_number
 * converts it (exact mantissa / exact power of ten), or 0 to give up. */
static int plain_number(const char *text, size_t len, size_t *i, double *out)
{
    size_t p = *i;
    int neg = 0;
    if (p < len && (text[p] == '+' || text[p] == '-'))
        neg = text[p++] == '-';
    uint64_t m = 0;
    int ndig = 0, frac = 0;
    for (; p < len && is_digit(text[p]); p++, ndig++)
        m = m * 10 + (uint64_t)(text[p] - '0');
    if (p < len && text[p] == '.') {
        for (p++; p < len && is_digit(text[p]); p++, frac++)
            m = m * 10 + (uint64_t)(text[p] - '0');
        ndig += frac;
    }
    if (ndig == 0 || ndig > 19 || m >= (UINT64_C(1) << 53) || frac > 22)
        return 0;
    if (p < len && text[p] == '.')
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
static int line_end(const char *text, size_t avail, size_t lim, size_t i, size_t *len,
                    size_t *next)
{
    if (i == lim) {
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

static int is_letter(char c)
{
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z');
}

/* Where the next word or the line end starts after the word ending at p
 * (p > 0), past blanks; 0 when something else follows them (a digit: "X1 2"
 * is X12 to the general reader; a comment), which is not this reader's. */
static size_t word_ends(const char *text, size_t len, size_t p)
{
    size_t k = p;
    while (k < len && is_blank(text[k]))
        k++;
    return k >= len || is_letter(text[k]) || text[k] == '\n' || text[k] == '\r' ? k : 0;
}

/* A leading N word (line number, what many CAM posts put on every line),
 * read as the general reader reads it: digits accumulated in a double. Returns
 * where the next word starts, or 0 to give up ("N10.5", "N 10", a comment or
 * a digit after it). */
static size_t line_number(const char *text, size_t len, size_t i, struct ncp_block *out)
{
    size_t p = i + 1;
    if (p >= len || !is_digit(text[p]))
        return 0;
    double v = 0.0;
    while (p < len && is_digit(text[p]))
        v = v * 10.0 + (text[p++] - '0');
    size_t j = p < len && text[p] == '.' ? 0 : word_ends(text, len, p);
    if (j == 0)
        return 0;
    out->has_n = 1;
    out->n_number = v;
    return j;
}

int ncp_lex_fast_line(const char *text, size_t avail, uint32_t line, uint64_t offset,
                      struct ncp_block *out, size_t *next)
{
    /* never further than the general reader's line limit */
    size_t len = avail;
    if (len > NCP_LEX_TOO_LONG)
        len = NCP_LEX_TOO_LONG;
    ncp_lex_init_block(out, 0, line, offset);
    uint32_t seen = 0;
    size_t i = 0;
    while (i < len && is_blank(text[i]))
        i++;
    if (i < len && (text[i] == 'N' || text[i] == 'n') && (i = line_number(text, len, i, out)) == 0)
        return 0;
    for (;;) {
        while (i < len && is_blank(text[i]))
            i++;
        size_t line_len = 0;
        int end = line_end(text, avail, len, i, &line_len, next);
        if (end != 0) {
            out->length = (uint16_t)line_len;
            return end > 0;
        }
        char c = text[i];
        if (c >= 'A' && c <= 'Z')
            c = (char)(c + 32);
        /* n, o: N and O words; u, v, w: not axes here (rs274 -g rejects them) */
        if (c < 'a' || c > 'z' || c == 'n' || c == 'o' || (c >= 'u' && c <= 'w'))
            return 0;
        if (c != 'g' && c != 'm') {
            uint32_t bit = 1u << (c - 'a');
            if (seen & bit)
                return 0; /* "Multiple X words": the general reader's error */
            seen |= bit;
        }
        if (out->n_words >= NCP_BLOCK_MAX_WORDS)
            return 0;
        size_t letter = i++;
        double v;
        if (!plain_number(text, len, &i, &v))
            return 0;
        size_t j = word_ends(text, len, i);
        if (j == 0)
            return 0;
        struct ncp_word *w = &out->words[out->n_words++];
        w->letter = (char)(c - 32);
        w->col = (uint16_t)(letter + 1);
        w->v.value = v;
        w->v.start = w->v.len = 0;
        w->v.is_const = 1;
        i = j;
    }
}

int ncp_lex_fast(const char *text, size_t len, uint32_t line, uint64_t offset,
                 struct ncp_block *out)
{
    size_t next;
    /* the whole of text[0..len) must be the line, as the general reader takes it */
    return ncp_lex_fast_line(text, len, line, offset, out, &next) && next == len &&
           out->length == len;
}
