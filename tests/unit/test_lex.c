/* Lexer: rs274's reading rules (squeezing, numbers, words, comments, O-words,
 * parameter settings), expression compilation and constant folding, run-time
 * evaluation, and every error path. Expected messages and values were checked
 * against LinuxCNC's rs274 (2.9) on the same lines. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ncpar/feeder.h"
#include "ncpar/lex.h"
#include "../../src/lex/lex_internal.h"

static struct ncp_block blk;

static int lex(const char *s)
{
    return ncp_lex_block(s, strlen(s), 42, 100, &blk);
}

/* ---- parameters seen by the evaluator: #n = n/2, #<x> = 1.5, #<zero> = 0 */

static int get_num(void *ctx, int index, double *out, struct ncp_diag *d)
{
    (void)ctx;
    (void)d;
    *out = index / 2.0;
    return 0;
}

static int get_named(void *ctx, const char *name, size_t len, double *out,
                     struct ncp_diag *d)
{
    (void)ctx;
    if (len == 1 && name[0] == 'x') {
        *out = 1.5;
        return 0;
    }
    if (len == 4 && memcmp(name, "zero", 4) == 0) {
        *out = 0.0;
        return 0;
    }
    return ncp_diag_set(d, NCP_ERR_SEMANTIC, 0, 0, "Named parameter #<%.*s> not defined",
                        (int)len, name);
}

static int exists_named(void *ctx, const char *name, size_t len)
{
    (void)ctx;
    return len == 1 && name[0] == 'x';
}

static const struct ncp_param_ops ops = { 0, get_num, get_named, exists_named };

static double eval_ok(const struct ncp_expr *e)
{
    struct ncp_diag d;
    double v = -12345.0;
    int rc = ncp_expr_eval(&blk, e, &ops, &v, &d);
    if (rc)
        fail_msg("eval failed: %s", d.msg);
    return v;
}

/* value of the single word of `line` */
static double word_value(const char *line)
{
    if (lex(line) != NCP_OK)
        fail_msg("'%s': %s", line, blk.err.msg);
    assert_int_equal(blk.n_words, 1);
    return eval_ok(&blk.words[0].v);
}

static void expect_word(const char *line, double v)
{
    double got = word_value(line);
    if (!(got == v || (isnan(v) && isnan(got))))
        fail_msg("'%s': got %.17g, want %.17g", line, got, v);
}

static void expect_error(const char *line, const char *msg, int col)
{
    int rc = lex(line);
    if (rc == NCP_OK)
        fail_msg("'%s': no error, want '%s'", line, msg);
    assert_int_equal(rc, NCP_ERR_SYNTAX);
    assert_int_equal(blk.err.code, NCP_ERR_SYNTAX);
    assert_int_equal(blk.err.line, 42);
    if (strcmp(blk.err.msg, msg) != 0)
        fail_msg("'%s': got '%s', want '%s'", line, blk.err.msg, msg);
    if (col >= 0 && blk.err.col != col)
        fail_msg("'%s': col %d, want %d", line, blk.err.col, col);
}

static void expect_eval_error(const char *line, const char *msg, int col)
{
    struct ncp_diag d;
    double v;
    if (lex(line) != NCP_OK)
        fail_msg("'%s': %s", line, blk.err.msg);
    assert_int_equal(blk.n_words, 2);
    assert_false(blk.words[1].v.is_const);
    assert_int_not_equal(ncp_expr_eval(&blk, &blk.words[1].v, &ops, &v, &d), NCP_OK);
    assert_int_equal(d.line, 42);
    if (strcmp(d.msg, msg) != 0)
        fail_msg("'%s': got '%s', want '%s'", line, d.msg, msg);
    if (col >= 0 && d.col != col)
        fail_msg("'%s': col %d, want %d", line, d.col, col);
}

/* ---------------------------------------------------------------- numbers */

static void test_numbers(void **state)
{
    static const char *const nums[] = {
        "1", "1.", ".5", "+1", "-.5", "-0", "00.5", "12.345", "-6.789", "0.1",
        "123456789012345", "0.000000000000000000001", "3.14159265358979323846",
        "99999999999999999999999", "1234567890.0987654321", "0.30000000000000004",
        "9007199254740993", "4.35", "1.0000000000000002",
    };
    size_t i;
    char line[80];
    (void)state;
    for (i = 0; i < sizeof nums / sizeof nums[0]; i++) {
        snprintf(line, sizeof line, "X%s", nums[i]);
        expect_word(line, strtod(nums[i], 0));
    }
    assert_true(signbit(word_value("X-0")));
    expect_word("X+-1", -1.0);
    expect_word("X--1", 1.0);
    expect_word("X-+1", -1.0);
    expect_word("X - - 1", 1.0);
    expect_word("X 1 . 5", 1.5);
    expect_word("x1 2", 12.0);
    assert_true(blk.words[0].v.is_const);
}

/* The 8-characters-at-a-time reader against strtod, on numbers of every
 * shape around its limits (0-10 digits each side, signs, a point or not),
 * followed by what may follow a number on a line. Bit-identical values, and
 * the next word read from the right place. */
static void test_numbers_match_strtod(void **state)
{
    (void)state;
    static const char *const after[] = { "", " Y7", "Y7", "(c)", ";x", "\tY7" };
    uint64_t seed = 0x9E3779B97F4A7C15u;
    char num[40], line[80];
    for (int iter = 0; iter < 200000; iter++) {
        seed = seed * 6364136223846793005u + 1442695040888963407u;
        uint64_t r = seed >> 11;
        int n = 0, n_int = (int)(r % 11), n_frac = (int)(r / 11 % 11);
        int point = (r >> 8) % 4 != 0, sign = (int)((r >> 10) % 3);
        if (!point)
            n_frac = 0;
        if (n_int + n_frac == 0)
            n_int = 1;
        if (sign)
            num[n++] = sign == 1 ? '-' : '+';
        for (int i = 0; i < n_int; i++)
            num[n++] = (char)('0' + (r >> (12 + i * 3)) % 10);
        if (point)
            num[n++] = '.';
        for (int i = 0; i < n_frac; i++)
            num[n++] = (char)('0' + (r >> (20 + i * 3)) % 10);
        num[n] = '\0';
        const char *tail = after[(r >> 40) % (sizeof after / sizeof *after)];
        snprintf(line, sizeof line, "X%s%s", num, tail);
        if (lex(line) != NCP_OK)
            fail_msg("'%s': %s", line, blk.err.msg);
        double want = strtod(num, 0), got = blk.words[0].v.value;
        if (memcmp(&want, &got, sizeof want) != 0)
            fail_msg("'%s': %.17g, strtod %.17g", line, got, want);
        if (tail[0] && strchr(tail, 'Y') && (blk.n_words != 2 || blk.words[1].v.value != 7.0))
            fail_msg("'%s': the word after the number was not read", line);
    }
    /* the characters just outside '0'..'9' end a number */
    expect_error("X12/", "Bad character '/' used", 4);
    expect_error("X1.5:", "Bad character ':' used", 5);
    expect_error("X123456789.12345678/", "Bad character '/' used", 20);
}

static void test_number_errors(void **state)
{
    (void)state;
    expect_error("G1 X. F1", "bad number format (conversion failed) parsing '.'", 5);
    expect_error("G1 X1.2.3", "bad number format (trailing characters) parsing '1.2.3'", 5);
    expect_error("G1 X..", "bad number format (conversion failed) parsing '..'", 5);
    expect_error("G1 X.1.", "bad number format (trailing characters) parsing '.1.'", 5);
    expect_error("G1 X+.", "bad number format (conversion failed) parsing '+.'", 5);
    expect_error("G1 F1 X-", "bad number format (conversion failed) parsing '-'", 8);
    expect_error("G1 X] F1", "bad number format (conversion failed) parsing ''", 5);
    expect_error("G1 X; F1", "bad number format (conversion failed) parsing ''", 5);
    expect_error("G1 F1 X", "No characters found in reading real value", 8);
    expect_error("G1 X- F1", "Unknown word starting with f", 7);
    expect_error("G1 X1- F1", "Bad character '-' used", 6);
}

/* ------------------------------------------------------------- words, N, / */

static void test_words(void **state)
{
    (void)state;
    assert_int_equal(lex("G1 X12.345 Y-6.789 Z0.5 F1200"), NCP_OK);
    assert_int_equal(blk.n_words, 5);
    assert_int_equal(blk.words[0].letter, 'G');
    assert_int_equal(blk.words[1].letter, 'X');
    assert_int_equal(blk.words[1].col, 4);
    assert_int_equal(blk.words[4].letter, 'F');
    assert_true(blk.words[2].v.is_const);
    assert_true(blk.words[2].v.value == -6.789);
    assert_int_equal(blk.n_code, 0);
    assert_int_equal(blk.line, 42);
    assert_int_equal(blk.offset, 100);
    assert_int_equal(blk.length, 29);
    assert_int_equal(blk.err.code, NCP_OK);

    assert_int_equal(lex("g 0 1\tx 1"), NCP_OK);
    assert_int_equal(blk.words[0].letter, 'G');
    assert_true(blk.words[0].v.value == 1.0);
    assert_int_equal(blk.words[1].col, 7);

    /* G and M may repeat (the analyzer checks modal groups) */
    assert_int_equal(lex("G1 G90 M3 M8 S100"), NCP_OK);
    assert_int_equal(blk.n_words, 5);
    /* $ @ ^ are rs274 words too */
    assert_int_equal(lex("M3 $1 S100 @1 ^2"), NCP_OK);
    assert_int_equal(blk.words[1].letter, '$');
    assert_int_equal(blk.words[3].letter, '@');
    /* empty and blank lines */
    assert_int_equal(lex(""), NCP_OK);
    assert_int_equal(blk.n_words, 0);
    assert_int_equal(lex("  \t \r"), NCP_OK);
    assert_int_equal(blk.n_words, 0);
    assert_int_equal(lex("G1 X1\r"), NCP_OK);
    assert_int_equal(blk.n_words, 2);
}

static void test_line_number_and_delete(void **state)
{
    (void)state;
    assert_int_equal(lex("/N10.5 G1 X1"), NCP_OK);
    assert_true(blk.block_delete);
    assert_true(blk.has_n);
    assert_true(blk.n_number == 10.0);
    assert_int_equal(blk.n_words, 2);
    assert_int_equal(lex(" / g1"), NCP_OK);
    assert_true(blk.block_delete);
    assert_false(blk.has_n);
    assert_int_equal(lex("N 1 0 G1"), NCP_OK);
    assert_true(blk.n_number == 10.0);
    expect_error("G1 N10 X1", "Bad character 'n' used", 4);
    expect_error("N-1 G1", "Bad format unsigned integer", 2);
    expect_error("N10.X", "Bad format unsigned integer", 5);
    expect_error("N10 /G1", "Bad character '/' used", 5);
    expect_error("//G1", "Bad character '/' used", 2);
    expect_error("G1 X1 O", "Bad character 'o' used", 7);
}

static void test_duplicates(void **state)
{
    (void)state;
    expect_error("G1 X1 Y2 X3", "Multiple x words on one line", 10);
    expect_error("G1 F1 S1 S2", "Multiple s words on one line", 10);
    expect_error("M3 $1 $2", "Multiple spindle choice ($) words on one line", 7);
    expect_error("G4 P1 P2", "Multiple p words on one line", 7);
    expect_error("G1 U1", "Bad character 'u' used", 4); /* XYZABC only, as rs274 -g */
    assert_int_equal(lex("G1 @1 @2"), NCP_OK);
}

static void test_bad_characters(void **state)
{
    (void)state;
    expect_error("G1 X1 &", "Bad character '&' used", 7);
    expect_error("G1 X1 {", "Bad character '\\173' used", 7);
    expect_error("G1 X1 \x01", "Bad character '\\001' used", 7);
    expect_error("G1 X1 \xe9", "Bad character '\\351' used", 7);
    expect_error("G1 X1 )", "Bad character ')' used", 7);
    expect_error("G1 X1 %", "Bad character '%' used", 7);
    expect_error("G1 X1]", "Bad character ']' used", 6);
    expect_error("G1 X1 \x0b Y1", "Bad character '\\013' used", 7);
}

/* --------------------------------------------------------------- comments */

static const char *comment(void)
{
    return blk.pool + blk.comment_off;
}

static void test_comments(void **state)
{
    (void)state;
    assert_int_equal(lex("G1 X1 (first) Y2 (second)"), NCP_OK);
    assert_int_equal(blk.n_words, 3);
    assert_int_equal(blk.comment_kind, NCP_CMT_PLAIN);
    assert_string_equal(comment(), "second");
    assert_int_equal(lex("(MSG, hi)"), NCP_OK);
    assert_int_equal(blk.comment_kind, NCP_CMT_MSG);
    assert_string_equal(comment(), " hi");
    assert_int_equal(lex("( msg,Hi There )"), NCP_OK);
    assert_int_equal(blk.comment_kind, NCP_CMT_MSG);
    assert_string_equal(comment(), "Hi There ");
    assert_int_equal(lex("(MSG hi)"), NCP_OK);
    assert_int_equal(blk.comment_kind, NCP_CMT_PLAIN);
    assert_string_equal(comment(), "MSG hi");
    assert_int_equal(lex("(MSG,b)(a)"), NCP_OK);
    assert_string_equal(comment(), "a");
    assert_int_equal(lex("(Debug,x=#1)"), NCP_OK);
    assert_int_equal(blk.comment_kind, NCP_CMT_DEBUG);
    assert_string_equal(comment(), "x=#1");
    assert_int_equal(lex("(PRINT,p)"), NCP_OK);
    assert_int_equal(blk.comment_kind, NCP_CMT_PRINT);
    assert_int_equal(lex("(LOG,l)"), NCP_OK);
    assert_int_equal(blk.comment_kind, NCP_CMT_LOG);
    assert_int_equal(lex("(LOGOPEN,f.txt)"), NCP_OK);
    assert_int_equal(blk.comment_kind, NCP_CMT_LOGOPEN);
    assert_string_equal(comment(), "f.txt");
    assert_int_equal(lex("(logappend,f.txt)"), NCP_OK);
    assert_int_equal(blk.comment_kind, NCP_CMT_LOGAPPEND);
    assert_int_equal(lex("( LOGCLOSE)"), NCP_OK);
    assert_int_equal(blk.comment_kind, NCP_CMT_LOGCLOSE);
    assert_int_equal(lex("(logclose )"), NCP_OK);
    assert_int_equal(blk.comment_kind, NCP_CMT_PLAIN);
    assert_int_equal(lex("(ABORT,stop here)"), NCP_OK);
    assert_int_equal(blk.comment_kind, NCP_CMT_ABORT);
    assert_string_equal(comment(), "stop here");
    assert_int_equal(lex("(a)()"), NCP_OK);
    assert_int_equal(blk.comment_kind, NCP_CMT_NONE);
    assert_int_equal(lex("(   )"), NCP_OK);
    assert_int_equal(blk.comment_kind, NCP_CMT_PLAIN);
    assert_string_equal(comment(), "");
    assert_int_equal(lex("(MSG,a;b) ; (MSG,c"), NCP_OK);
    assert_string_equal(comment(), "a;b");
    assert_int_equal(lex("G1 X1 ; (MSG,x) G2 %%"), NCP_OK);
    assert_int_equal(blk.n_words, 2);
    assert_int_equal(blk.comment_kind, NCP_CMT_NONE);
    /* blanks inside comments are kept */
    assert_int_equal(lex("G1 (MSG, A  B)"), NCP_OK);
    assert_string_equal(comment(), " A  B");
    expect_error("(a(b))", "Nested comment found", 3);
    expect_error("G1 (abc", "Unclosed comment found", 4);
    expect_error("G1 X1 (MSG,a)(", "Unclosed comment found", 14);
    expect_error("G1 X(a)1", "bad number format (conversion failed) parsing ''", 5);
}

/* ------------------------------------------------------------ expressions */

static void test_operators(void **state)
{
    (void)state;
    expect_word("X[1+2*3]", 7.0);
    expect_word("X[2 - 3 - 4]", -5.0);
    expect_word("X[2**3**2]", 64.0);
    expect_word("X[8/2/2]", 2.0);
    expect_word("X[2*3**2]", 18.0);
    expect_word("X[-7 mod 3]", 2.0);
    expect_word("X[7 mod -3]", 1.0);
    expect_word("X[-7 mod -3]", 2.0);
    expect_word("X[7.5 mod 2]", 1.5);
    expect_word("X[-2**2]", 4.0);
    expect_word("X[1 eq 1.00009]", 1.0);
    expect_word("X[1 eq 1.0002]", 0.0);
    expect_word("X[1 ne 1.00009]", 0.0);
    expect_word("X[1 ne 2]", 1.0);
    expect_word("X[1 gt 0.99999]", 1.0);
    expect_word("X[1 ge 1.00001]", 0.0);
    expect_word("X[1 lt 1.00001]", 1.0);
    expect_word("X[1 le 0.99999]", 0.0);
    expect_word("X[2 ge 2]", 1.0);
    expect_word("X[2 le 2]", 1.0);
    expect_word("X[1 and 0]", 0.0);
    expect_word("X[1 and 2]", 1.0);
    expect_word("X[0 or 0]", 0.0);
    expect_word("X[0 or 3]", 1.0);
    expect_word("X[1 xor 1]", 0.0);
    expect_word("X[1 xor 0]", 1.0);
    /* precedence: ** > * / mod > + - > relational > logical */
    expect_word("X[1 + 1 gt 1]", 1.0);
    expect_word("X[1 gt 0 and 0 lt 1]", 1.0);
    expect_word("X[1 lt 2 eq 1]", 1.0);
    expect_word("X[0 le 1 eq 0]", 0.0);
    expect_word("X[1 eq 2 + 3]", 0.0);
    expect_word("X[2 lt 3 gt 0 + 1]", 0.0);
    expect_word("X[1 or 0 and 0]", 0.0);
    expect_word("X[9+8*7/6+5-4*3**2+1]", 9.0 + 8.0 * 7.0 / 6.0 + 5.0 - 36.0 + 1.0);
    expect_word("X[1 * * 2]", 1.0);
    expect_word("X[1 2]", 12.0);
    expect_word("X-[2]", -2.0);
    expect_word("X+[2]", 2.0);
    expect_word("X[1+-2]", -1.0);
    expect_word("X[1--2]", 3.0);
    expect_word("X[[[[1]]]]", 1.0);
    /* an overflowing intermediate is fine until a "real value" ends */
    expect_word("X[1/10**400]", 0.0);
    expect_word("X[10**400 gt 0]", 1.0);
}

static void test_functions(void **state)
{
    (void)state;
    expect_word("X[abs[-2]]", 2.0);
    assert_true(signbit(word_value("X[abs[-0]]")));
    expect_word("X[sqrt[16]]", 4.0);
    expect_word("X[fix[-1.5]]", -2.0);
    expect_word("X[fup[-1.5]]", -1.0);
    expect_word("X[round[2.5]]", 3.0);
    expect_word("X[round[-2.5]]", -3.0);
    expect_word("X[round[3000000000]]", -2147483648.0);
    expect_word("X[exp[0]]", 1.0);
    expect_word("X[ln[1]]", 0.0);
    expect_word("Xatan[1]/[1]", 45.0);
    expect_word("X[atan[0]/[-1]]", 180.0);
    expect_word("X[acos[1]]", 0.0);
    expect_word("X[asin[1]]", 90.0);
    expect_word("X[exists[#5]]", 1.0);
    expect_word("X[exists[#0]]", 0.0);
    expect_word("X[exists[#<x>]]", 1.0);
    expect_word("X[exists[#<y>]]", 0.0);
    assert_true(fabs(word_value("X[sin[30]]") - 0.5) < 1e-15);
    assert_true(fabs(word_value("X[cos[60]]") - 0.5) < 1e-15);
    assert_true(fabs(word_value("X[tan[45]]") - 1.0) < 1e-15);
    assert_true(fabs(word_value("X[cos[sin[10]]]") - cos(sin(M_PI / 18) * M_PI / 180)) < 1e-15);
}

/* A folded constant and the same expression computed by the bytecode at
 * run time must agree to the bit. #2 evaluates to 1.0 here. */
static void test_fold_matches_eval(void **state)
{
    static const char *const exprs[] = {
        "sin[%s*33.3]", "cos[%s*71.9]", "tan[%s*12.1]", "acos[%s*0.3]", "asin[%s*-0.7]",
        "atan[%s*3]/[7]", "exp[%s*1.7]", "ln[%s*7.7]", "sqrt[%s*2]", "[%s*0.1+0.2]",
        "[%s*10 mod 3.3]", "[%s*2**0.5]", "round[%s*-7.5]", "fix[%s*1.25]", "fup[%s*1.25]",
        "[%s/3]", "[%s*1.1 - 1.1]", "[%s*5 eq 5.00001]", "abs[%s*-3.3]",
    };
    size_t i;
    char line[120], expr[100];
    (void)state;
    for (i = 0; i < sizeof exprs / sizeof exprs[0]; i++) {
        double folded, run;
        snprintf(expr, sizeof expr, exprs[i], "1");
        snprintf(line, sizeof line, "X%s", expr);
        folded = word_value(line);
        assert_true(blk.words[0].v.is_const);
        snprintf(expr, sizeof expr, exprs[i], "#2");
        snprintf(line, sizeof line, "X%s", expr);
        run = word_value(line);
        assert_false(blk.words[0].v.is_const);
        if (memcmp(&folded, &run, sizeof run) != 0)
            fail_msg("%s: folded %.17g, run %.17g", exprs[i], folded, run);
    }
}

static void test_expression_errors(void **state)
{
    (void)state;
    expect_error("G1 X[1", "Unclosed expression", 5);
    expect_error("G1 X[[1]", "Unclosed expression", 5);
    expect_error("G1 X[1+", "No characters found in reading real value", 8);
    expect_error("G1 X[1+]", "bad number format (conversion failed) parsing ''", 8);
    expect_error("G1 X[]", "bad number format (conversion failed) parsing ''", 6);
    expect_error("G1 X[1 foo 2]", "Unknown operation", 8);
    expect_error("G1 X[1(a)+2]", "Unknown operation", 7);
    expect_error("G1 X[1 a 2]", "Unknown operation name starting with a", 8);
    expect_error("G1 X[1 m 2]", "Unknown operation name starting with m", 8);
    expect_error("G1 X[1 o 2]", "Unknown operation name starting with o", 8);
    expect_error("G1 X[1 x 2]", "Unknown operation name starting with x", 8);
    expect_error("G1 X[1 e 2]", "Unknown operation name starting with e", 8);
    expect_error("G1 X[1 n 2]", "Unknown operation name starting with n", 8);
    expect_error("G1 X[1 g 2]", "Unknown operation name starting with g", 8);
    expect_error("G1 X[1 l 2]", "Unknown operation name starting with l", 8);
    expect_error("G1 X[foo[1]]", "Unknown word starting with f", 6);
    expect_error("G1 X[abc[1]]", "Unknown word starting with a", 6);
    expect_error("G1 X[ex[1]]", "Unknown word starting with e", 6);
    expect_error("G1 X[cz[1]]", "Unknown word starting with c", 6);
    expect_error("G1 X[lx[1]]", "Unknown word starting with l", 6);
    expect_error("G1 X[rx[1]]", "Unknown word starting with r", 6);
    expect_error("G1 X[sx[1]]", "Unknown word starting with s", 6);
    expect_error("G1 X[tx[1]]", "Unknown word starting with t", 6);
    expect_error("G1 X[zz[1]]", "Unknown word where unary operation could be", 6);
    expect_error("G1 X[cosx[1]]", "Left bracket missing after unary operation name", 9);
    expect_error("G1 X[sin 1]", "Left bracket missing after unary operation name", 10);
    expect_error("G1 X[atan[1]]", "Slash missing after first atan argument", 13);
    expect_error("G1 X[atan[1]/1]", "Left bracket missing after slash with atan", 14);
    expect_error("G1 X-[2]**2", "Bad character '*' used", 9);
    expect_error("G1 X[1/0]", "Attempt to divide by zero", 7);
    expect_error("G1 X[1 mod 0]", "Calculation resulted in 'not a number'", 5);
    expect_error("G1 X[1/[10**400]]", "Calculation resulted in 'infinity'", 8);
    expect_error("G1 X[[10**400] gt 0]", "Calculation resulted in 'infinity'", 6);
    expect_error("G1 X[exp[1000]]", "Calculation resulted in 'infinity'", 6);
    expect_error("G1 X[-2**0.5]", "Attempt to raise negative to non integer power", 8);
    expect_error("G1 X[sqrt[-1]]", "Negative argument to sqrt", 6);
    expect_error("G1 X[ln[0]]", "Zero or negative argument to ln", 6);
    expect_error("G1 X[acos[2]]", "Argument to acos out of range", 6);
    expect_error("G1 X[asin[-2]]", "Argument to asin out of range", 6);
    expect_error("G1 X[round[1e10]]", "Unknown operation name starting with e", 13);
    expect_error("G1 X[exists[5]]", "Expected # reading parameter", 13);
    expect_error("G1 X[exists[#<x>+1]]", "Expected ] reading bracketed parameter", 17);
}

/* ------------------------------------------------------------- parameters */

static void test_parameters(void **state)
{
    (void)state;
    expect_word("X#3", 1.5);
    expect_word("X-#3", -1.5);
    expect_word("X##4", 1.0);
    expect_word("X#[1+3]", 2.0);
    expect_word("X#5.00001", 2.5);
    expect_word("X#4.99999", 2.5);
    expect_word("X#<x>", 1.5);
    expect_word("X#< X >", 1.5);
    expect_word("X[#<x> * 2 + #2]", 4.0);
    expect_word("X[1 + #<x>]", 2.5);
    expect_word("X[#<x> + 1]", 2.5);
    expect_word("X[2 ** #2 ** 3]", 8.0);
    expect_word("Xsin[#<zero>]", 0.0);
    expect_word("Xatan[#<zero>]/[#2]", 0.0);
    expect_word("X[exists[#<x>] + exists[#<nope>]]", 1.0);
    assert_false(blk.words[0].v.is_const);
    expect_error("G1 X#1.5", "Non integer value for integer", 6);
    expect_error("G1 X#-1", "Parameter number out of range", 5);
    expect_error("G1 X#0", "Parameter number out of range", 5);
    expect_error("G1 X#5602", "Parameter number out of range", 5);
    expect_error("G1 X#<abc", "Named parameter not terminated", 6);
    expect_error("G1 X## F1", "Unknown word starting with f", 8);
    expect_error("G1 X#(a)1", "bad number format (conversion failed) parsing ''", 6);
}

static void test_eval_errors(void **state)
{
    (void)state;
    expect_eval_error("G1 X[#2/0]", "Attempt to divide by zero", 8);
    expect_eval_error("G1 X[#<zero>/#<zero>]", "Attempt to divide by zero", 13);
    expect_eval_error("G1 X[sqrt[-#2]]", "Negative argument to sqrt", 6);
    expect_eval_error("G1 X[ln[#<zero>]]", "Zero or negative argument to ln", 6);
    expect_eval_error("G1 X[acos[#4]]", "Argument to acos out of range", 6);
    expect_eval_error("G1 X[asin[#4]]", "Argument to asin out of range", 6);
    expect_eval_error("G1 X[-#2**0.5]", "Attempt to raise negative to non integer power", 9);
    expect_eval_error("G1 X[#2 mod 0]", "Calculation resulted in 'not a number'", 9);
    expect_eval_error("G1 X[#2 * 10**400]", "Calculation resulted in 'infinity'", 9);
    expect_eval_error("G1 X#[#2/3]", "Non integer value for integer", 5);
    expect_eval_error("G1 X#[#2*0]", "Parameter number out of range", 5);
    expect_eval_error("G1 X#[#2*-7]", "Parameter number out of range", 5);
    expect_eval_error("G1 X[1+#<y>]", "Named parameter #<y> not defined", 8);
}

static void test_assignments(void **state)
{
    (void)state;
    assert_int_equal(lex("#1=5 #<A b>=[#1+1] #[1+#2]=3 #<_g>=#<x>"), NCP_OK);
    assert_int_equal(blk.n_assign, 4);
    assert_int_equal(blk.n_words, 0);
    assert_int_equal(blk.assign[0].kind, NCP_ASSIGN_NUMBERED);
    assert_true(blk.assign[0].index.is_const);
    assert_true(blk.assign[0].index.value == 1.0);
    assert_true(eval_ok(&blk.assign[0].value) == 5.0);
    assert_int_equal(blk.assign[0].col, 1);
    assert_int_equal(blk.assign[1].kind, NCP_ASSIGN_NAMED);
    assert_int_equal(blk.assign[1].name_len, 2);
    assert_string_equal(blk.pool + blk.assign[1].name_off, "ab");
    assert_true(eval_ok(&blk.assign[1].value) == 1.5);
    assert_false(blk.assign[2].index.is_const);
    assert_true(eval_ok(&blk.assign[2].index) == 2.0);
    assert_string_equal(blk.pool + blk.assign[3].name_off, "_g");
    assert_true(eval_ok(&blk.assign[3].value) == 1.5);
    assert_int_equal(lex("#1.00001=2 G1 X#1"), NCP_OK);
    assert_true(blk.assign[0].index.value == 1.0);
    assert_int_equal(lex("#<>=1"), NCP_OK);
    assert_int_equal(blk.assign[0].name_len, 0);
    expect_error("#1 5", "Equal sign missing in parameter setting", 5);
    expect_error("#<x>5", "Equal sign missing in parameter setting", 5);
    expect_error("G1 X#1#2", "Equal sign missing in parameter setting", 9);
    expect_error("#0=1", "Parameter number out of range", 1);
    expect_error("#1.5=1", "Non integer value for integer", 2);
    expect_error("#1=", "No characters found in reading real value", 4);
    expect_error("#1=[2", "Unclosed expression", 4);
    expect_error("G1 X[#1=2]", "Unknown operation", 8);
}

/* ---------------------------------------------------------------- O-words */

static const char *oname(void)
{
    return blk.pool + blk.oword.name_off;
}

static void test_owords(void **state)
{
    (void)state;
    assert_int_equal(lex("o0100 sub"), NCP_OK);
    assert_int_equal(blk.oword.kind, NCP_O_SUB);
    assert_string_equal(oname(), "100");
    assert_int_equal(blk.oword.col, 1);
    assert_int_equal(lex("O<Foo Bar> CALL [1] (x) [2+#3]"), NCP_OK);
    assert_int_equal(blk.oword.kind, NCP_O_CALL);
    assert_string_equal(oname(), "foobar");
    assert_int_equal(blk.oword.nargs, 2);
    assert_true(eval_ok(&blk.oword.args[0]) == 1.0);
    assert_true(eval_ok(&blk.oword.args[1]) == 3.5);
    assert_int_equal(blk.comment_kind, NCP_CMT_NONE);
    assert_int_equal(lex("N5 o100 if [#2 gt 0] (MSG,not shown)"), NCP_OK);
    assert_true(blk.has_n);
    assert_int_equal(blk.oword.kind, NCP_O_IF);
    assert_true(blk.oword.has_cond);
    assert_true(eval_ok(&blk.oword.cond) == 1.0);
    assert_int_equal(blk.comment_kind, NCP_CMT_NONE);
    /* a number from parameters is read when the line runs, as rs274 reads it */
    assert_int_equal(lex("o[#3*2] call"), NCP_OK);
    assert_int_equal(blk.oword.kind, NCP_O_CALL);
    assert_true(blk.oword.name_computed);
    assert_int_equal(blk.oword.name_len, 0);
    assert_true(eval_ok(&blk.oword.num) == 3.0);
    assert_int_equal(lex("o100 sub"), NCP_OK);
    assert_false(blk.oword.name_computed);
    assert_int_equal(lex("o100elseif[1]"), NCP_OK);
    assert_int_equal(blk.oword.kind, NCP_O_ELSEIF);
    assert_int_equal(lex("o100 else"), NCP_OK);
    assert_int_equal(blk.oword.kind, NCP_O_ELSE);
    assert_int_equal(lex("o100 endif ; done"), NCP_OK);
    assert_int_equal(blk.oword.kind, NCP_O_ENDIF);
    assert_int_equal(lex("o[50*2] while [#1 lt 3]"), NCP_OK);
    assert_int_equal(blk.oword.kind, NCP_O_WHILE);
    assert_string_equal(oname(), "100");
    assert_int_equal(lex("o100 endwhile"), NCP_OK);
    assert_int_equal(blk.oword.kind, NCP_O_ENDWHILE);
    assert_int_equal(lex("o100 do"), NCP_OK);
    assert_int_equal(blk.oword.kind, NCP_O_DO);
    assert_int_equal(lex("o-5 repeat [3]"), NCP_OK);
    assert_int_equal(blk.oword.kind, NCP_O_REPEAT);
    assert_string_equal(oname(), "-5");
    assert_true(blk.oword.cond.is_const && blk.oword.cond.value == 3.0);
    assert_int_equal(lex("o100 endrepeat"), NCP_OK);
    assert_int_equal(blk.oword.kind, NCP_O_ENDREPEAT);
    assert_int_equal(lex("o100 break"), NCP_OK);
    assert_int_equal(blk.oword.kind, NCP_O_BREAK);
    assert_int_equal(lex("o100 continue"), NCP_OK);
    assert_int_equal(blk.oword.kind, NCP_O_CONTINUE);
    assert_int_equal(lex("o100 return [#2*3]"), NCP_OK);
    assert_int_equal(blk.oword.kind, NCP_O_RETURN);
    assert_true(blk.oword.has_cond && eval_ok(&blk.oword.cond) == 3.0);
    assert_int_equal(lex("o100 return"), NCP_OK);
    assert_false(blk.oword.has_cond);
    assert_int_equal(lex("o100 endsub [2]"), NCP_OK);
    assert_int_equal(blk.oword.kind, NCP_O_ENDSUB);
    assert_true(blk.oword.has_cond);
    assert_int_equal(lex("o100 call"), NCP_OK);
    assert_int_equal(blk.oword.nargs, 0);
    /* O-line conditions are not "real values": no finite check (as rs274) */
    assert_int_equal(lex("o1 if [10**400]"), NCP_OK);
}

static void test_oword_errors(void **state)
{
    char line[200];
    int i, n = 0;
    (void)state;
    expect_error("o100 foo", "Unknown control command in o word", 6);
    expect_error("o100 if 1", "Left bracket missing after 'if'", 9);
    expect_error("o100 elseif 1", "Left bracket missing after 'elseif'", 13);
    expect_error("o100 while 1", "Left bracket missing after 'while'", 12);
    expect_error("o100 repeat 1", "Left bracket missing after 'repeat'", 13);
    expect_error("o100 if (a) [1]", "Left bracket missing after 'if'", 9);
    expect_error("o1.5 if [1]", "Non integer value for integer", 2);
    expect_error("o100 if [1] [2]", "Unexpected character after O-word", 13);
    expect_error("o100 if [1] G1", "Unexpected character after O-word", 13);
    expect_error("o100 (a) if [1]", "Unexpected character after O-word", 10);
    expect_error("o<abc sub", "Named parameter not terminated", 2);
    /* the kind is known even when the condition is bad */
    expect_error("o7 while [1/0]", "Attempt to divide by zero", 12);
    assert_int_equal(blk.oword.kind, NCP_O_WHILE);
    n += snprintf(line + n, sizeof line - (size_t)n, "o1 call");
    for (i = 0; i < 31; i++)
        n += snprintf(line + n, sizeof line - (size_t)n, "[%d]", i);
    expect_error(line, "Too many subroutine parameters", -1);
}

/* Fanuc-style subroutines: rs274 decides on the first item of the line */
static void test_fanuc_lines(void **state)
{
    (void)state;
    assert_int_equal(lex("O100 (sub)"), NCP_OK);
    assert_int_equal(blk.oword.kind, NCP_O_FANUC);
    assert_int_equal(blk.oword.name_len, 3);
    assert_memory_equal(blk.pool + blk.oword.name_off, "100", 3);
    /* M98: read from three characters on; the M itself is no word */
    assert_int_equal(lex("N10 M98 P100 L3"), NCP_OK);
    assert_int_equal(blk.oword.kind, NCP_O_M98);
    assert_int_equal(blk.oword.col, 5);
    assert_int_equal(blk.n_words, 2);
    assert_int_equal(blk.words[0].letter, 'P');
    assert_int_equal(blk.words[1].letter, 'L');
    assert_int_equal(lex("/M98 P#1 G1 X2"), NCP_OK);
    assert_int_equal(blk.oword.kind, NCP_O_M98);
    assert_int_equal(blk.n_words, 3);
    assert_false(blk.words[0].v.is_const);
    /* the fast reader hands these to the general one */
    assert_true(ncp_lex_fast("M98 P1", 6, 1, 0, &blk) == 0);
    assert_true(ncp_lex_fast("M99", 3, 1, 0, &blk) == 0);
    assert_true(ncp_lex_fast("G1 M99", 6, 1, 0, &blk) == 1);
    /* M99: lexed as usual, the first thing after it that is no comment noted */
    assert_int_equal(lex("M99 (back)"), NCP_OK);
    assert_int_equal(blk.oword.kind, NCP_O_M99);
    assert_int_equal(blk.oword.tail_col, 0);
    assert_int_equal(blk.n_words, 1);
    assert_int_equal(lex("M99 (a) G1 X3"), NCP_OK);
    assert_int_equal(blk.oword.kind, NCP_O_M99);
    assert_int_equal(blk.oword.tail_col, 9);
    assert_int_equal(lex("M99 ;G1"), NCP_OK);
    assert_int_equal(blk.oword.tail_col, 0);
    /* elsewhere on the line they are plain M words */
    assert_int_equal(lex("G1 X1 M98 P100"), NCP_OK);
    assert_int_equal(blk.oword.kind, NCP_O_NONE);
    assert_int_equal(lex("(c) M99"), NCP_OK);
    assert_int_equal(blk.oword.kind, NCP_O_NONE);
    assert_int_equal(lex("M3 S100"), NCP_OK);
    assert_int_equal(blk.oword.kind, NCP_O_NONE);
    /* an M value that is no integer leaves the line to the usual reader
     * (the analyzer rejects it there) */
    assert_int_equal(lex("M98.5 P1"), NCP_OK);
    assert_int_equal(blk.oword.kind, NCP_O_NONE);
    /* rs274 reads an M value first on the line with the parameters of the
     * moment, so "M#1 P100" with #1 = 98 is a call: the lexer marks the
     * line, lexed as usual, for the flow to decide; once decided, the line is
     * read again from three characters on ("m#1" happens to be three, "m#10"
     * leaves a bad character, as in rs274) */
    assert_int_equal(lex("M#1 P100"), NCP_OK);
    assert_int_equal(blk.oword.kind, NCP_O_M_VALUE);
    assert_int_equal(blk.oword.col, 1);
    assert_int_equal(blk.n_words, 2);
    assert_int_equal(blk.words[0].letter, 'M');
    assert_false(blk.words[0].v.is_const);
    assert_int_equal(lex("N5 M[#2 + 1]"), NCP_OK);
    assert_int_equal(blk.oword.kind, NCP_O_M_VALUE);
    assert_int_equal(blk.oword.col, 4);
    assert_int_equal(ncp_lex_block_fanuc("M#1 P100 L2", 11, 1, 0, 98, &blk), NCP_OK);
    assert_int_equal(blk.oword.kind, NCP_O_M98);
    assert_int_equal(blk.n_words, 2); /* P and L: the M is the call itself */
    assert_int_equal(ncp_lex_block_fanuc("M#10 P100", 9, 1, 0, 98, &blk), NCP_ERR_SYNTAX);
    assert_string_equal(blk.err.msg, "Bad character '0' used");
    assert_int_equal(ncp_lex_block_fanuc("M#3 (done)", 10, 1, 0, 99, &blk), NCP_OK);
    assert_int_equal(blk.oword.kind, NCP_O_M99);
    assert_int_equal(blk.oword.tail_col, 0);
    assert_int_equal(ncp_lex_block_fanuc("M#3 G1", 6, 1, 0, 99, &blk), NCP_OK);
    assert_int_equal(blk.oword.tail_col, 5);
    /* "m098" and "m98.0": three characters on is the rest of the number */
    expect_error("M098 P100", "Bad character '8' used", 4);
    assert_int_equal(blk.oword.kind, NCP_O_M98);
    expect_error("M98.0 P100", "Bad character '.' used", 4);
    expect_error("M98 P1 L2 L3", "Multiple l words on one line", 11);
}

/* ------------------------------------------------------- limits, garbage */

static void test_long_lines(void **state)
{
    char line[600];
    (void)state;
    memset(line, 'a', sizeof line);
    memcpy(line, "G1 X1 (", 7);
    line[251] = ')';
    assert_int_equal(ncp_lex_block(line, 252, 1, 0, &blk), NCP_OK);
    assert_int_equal(blk.comment_kind, NCP_CMT_PLAIN);
    line[252] = ')';
    assert_int_equal(ncp_lex_block(line, 253, 1, 0, &blk), NCP_ERR_SYNTAX);
    assert_string_equal(blk.err.msg, "Command too long");
    assert_int_equal(ncp_lex_block(line, sizeof line, 1, 0, &blk), NCP_ERR_SYNTAX);
    assert_string_equal(blk.err.msg, "Command too long");
    /* more words than a block holds */
    memset(line, 0, sizeof line);
    for (int i = 0; i < 70; i++)
        memcpy(line + 2 * i, "g1", 2);
    assert_int_equal(lex(line), NCP_ERR_SYNTAX);
    /* nesting is bounded (stack use), long operator chains fit the block */
    memset(line, 0, sizeof line);
    strcpy(line, "X");
    for (int i = 0; i < 38; i++)
        strcat(line, "[");
    strcat(line, "#1");
    for (int i = 0; i < 38; i++)
        strcat(line, "]");
    expect_word(line, 0.5);
    memset(line, 0, sizeof line);
    strcpy(line, "X");
    for (int i = 0; i < 60; i++)
        strcat(line, "-[");
    strcat(line, "1");
    for (int i = 0; i < 60; i++)
        strcat(line, "]");
    expect_error(line, "Expression nested too deeply (more than 40 levels)", -1);
    memset(line, 0, sizeof line);
    strcpy(line, "X[#1");
    for (int i = 0; i < 80; i++)
        strcat(line, "+#1");
    strcat(line, "]");
    expect_word(line, 40.5);
    memset(line, 0, sizeof line);
    /* the code array holds any line: at most one instruction per character */
    strcpy(line, "X[#1");
    for (int i = 0; i < 41; i++)
        strcat(line, "*#1+#1");
    strcat(line, "]");
    expect_word(line, 41 * 0.25 + 0.5);
    assert_true(blk.n_code <= 252);
}

static void test_nul_and_garbage(void **state)
{
    static const char with_nul[] = "G1 X1\0Y2";
    unsigned seed = 12345;
    char line[300];
    int round, i;
    (void)state;
    assert_int_equal(ncp_lex_block(with_nul, sizeof with_nul - 1, 3, 0, &blk), NCP_ERR_SYNTAX);
    assert_string_equal(blk.err.msg, "Bad character '\\000' used");
    assert_int_equal(blk.err.col, 6);
    assert_int_equal(ncp_lex_block("(a\0b)", 5, 3, 0, &blk), NCP_ERR_SYNTAX);
    assert_int_equal(ncp_lex_block("G1;\0", 4, 3, 0, &blk), NCP_ERR_SYNTAX);
    /* random bytes, and random mixes of G-code tokens: never crash, and every
     * error has a message and a column inside the line */
    for (round = 0; round < 20000; round++) {
        static const char *const tok[] = {
            "G1", "X", "[", "]", "#", "<a>", "1", ".", "-", "+", "*", "**", "/", "sin",
            "atan", "exists", "(", ")", ";", "o1", "if", "call", "=", " ", "mod",
            "eq", "#<x>", "#2", "n", "abs", "e", "2.5", "\xff", "\t", "$", "@"
        };
        int len = (int)((seed = seed * 1103515245u + 12345u) >> 16) % 280;
        if (round & 1) {
            for (i = 0; i < len; i++)
                line[i] = (char)((seed = seed * 1103515245u + 12345u) >> 16);
        } else {
            int n = 0;
            while (n < len) {
                const char *t = tok[((seed = seed * 1103515245u + 12345u) >> 16) %
                                    (sizeof tok / sizeof tok[0])];
                size_t tl = strlen(t);
                if (n + (int)tl > len)
                    break;
                memcpy(line + n, t, tl);
                n += (int)tl;
            }
            len = n;
        }
        if (ncp_lex_block(line, (size_t)len, 9, 0, &blk) != NCP_OK) {
            assert_int_equal(blk.err.code, NCP_ERR_SYNTAX);
            assert_true(blk.err.msg[0] != '\0');
            assert_true(blk.err.col <= len + 1);
        } else {
            double v;
            struct ncp_diag d;
            for (i = 0; i < blk.n_words; i++)
                ncp_expr_eval(&blk, &blk.words[i].v, &ops, &v, &d);
            for (i = 0; i < blk.n_assign; i++)
                ncp_expr_eval(&blk, &blk.assign[i].value, &ops, &v, &d);
        }
    }
}

/* ---- packed blocks: what the parallel pipeline passes between cores ------ */

static void assert_same_block(const struct ncp_block *a, const struct ncp_block *b)
{
    assert_int_equal(a->offset, b->offset);
    assert_int_equal(a->line, b->line);
    assert_int_equal(a->length, b->length);
    assert_int_equal(a->block_delete, b->block_delete);
    assert_int_equal(a->has_n, b->has_n);
    assert_memory_equal(&a->n_number, &b->n_number, sizeof a->n_number);
    assert_int_equal(a->n_words, b->n_words);
    assert_int_equal(a->n_assign, b->n_assign);
    assert_int_equal(a->n_code, b->n_code);
    assert_int_equal(a->pool_used, b->pool_used);
    assert_int_equal(a->comment_kind, b->comment_kind);
    assert_int_equal(a->comment_off, b->comment_off);
    assert_int_equal(a->comment_len, b->comment_len);
    assert_int_equal(a->err.code, b->err.code);
    assert_int_equal(a->err.line, b->err.line);
    assert_int_equal(a->err.col, b->err.col);
    assert_string_equal(a->err.msg, b->err.msg);
    for (unsigned k = 0; k < a->n_words; k++) { /* field by field: padding does not travel */
        assert_int_equal(a->words[k].letter, b->words[k].letter);
        assert_int_equal(a->words[k].col, b->words[k].col);
        assert_memory_equal(&a->words[k].v.value, &b->words[k].v.value, sizeof(double));
        assert_int_equal(a->words[k].v.start, b->words[k].v.start);
        assert_int_equal(a->words[k].v.len, b->words[k].v.len);
        assert_int_equal(a->words[k].v.is_const, b->words[k].v.is_const);
    }
    if (a->n_assign)
        assert_memory_equal(a->assign, b->assign, a->n_assign * sizeof a->assign[0]);
    assert_int_equal(a->oword.kind, b->oword.kind);
    if (a->oword.kind != NCP_O_NONE)
        assert_memory_equal(&a->oword, &b->oword,
                            offsetof(struct ncp_oword, args) +
                                a->oword.nargs * sizeof a->oword.args[0]);
    if (a->n_code)
        assert_memory_equal(a->code, b->code, a->n_code * sizeof a->code[0]);
    if (a->pool_used)
        assert_memory_equal(a->pool, b->pool, a->pool_used);
}

static void round_trip(const char *line, size_t len)
{
    static struct ncp_block back;
    static unsigned char buf[NCP_BLOCK_PACK_MAX + 64];
    ncp_lex_block(line, len, 7, 1234, &blk);
    size_t want = ncp_block_packed_size(&blk);
    memset(buf, 0xA5, sizeof buf);
    assert_int_equal(ncp_block_pack(&blk, buf), want);
    assert_true(want % NCP_PACK_UNIT == 0 && want <= NCP_BLOCK_PACK_MAX);
    assert_int_equal(buf[want], 0xA5); /* nothing written past the record */
    assert_int_equal(ncp_block_packed_units(buf) * NCP_PACK_UNIT, want);
    assert_false(ncp_block_packed_is_pad(buf));
    assert_false(ncp_block_packed_is_end_mark(buf));
    memset(&back, 0x5A, sizeof back);
    ncp_block_unpack(buf, &back);
    assert_same_block(&blk, &back);
}

/* The one-pass reader for plain lines against the general reader: every line
 * the fast path takes must come out as the very block the general reader
 * makes of it. Lines from an alphabet close to CAM output with the characters
 * that must make the fast path give up mixed in. */
static void expect_fast_like_general(const char *line, size_t len, int *taken)
{
    static struct ncp_block fast, general;
    memset(&fast, 0x5A, sizeof fast);
    int took = ncp_lex_fast(line, len, 11, 99, &fast);
    /* the same line inside a text, ended by its '\n' and more text behind it:
     * the reader's unbounded build, which must decide exactly as the bounded */
    static struct ncp_block in_text;
    char text[400];
    size_t next = 0;
    assert_true(len + 8 < sizeof text);
    memcpy(text, line, len);
    memcpy(text + len, "\nG1 X1\n", 8);
    memset(&in_text, 0x5A, sizeof in_text);
    int took_in_text = ncp_lex_fast_line(text, len + 8, 11, 99, &in_text, &next);
    /* (a line of the full limit is the reader's only when nothing follows it) */
    if (len < NCP_LEX_TOO_LONG && !memchr(line, '\n', len) && !memchr(line, '\r', len)) {
        assert_int_equal(took_in_text, took);
        if (took) {
            assert_int_equal(next, len + 1);
            assert_same_block(&fast, &in_text);
        }
    }
    if (!took)
        return;
    (*taken)++;
    if (ncp_lex_block_general(line, len, 11, 99, &general) != NCP_OK)
        fail_msg("fast path took '%.*s', the general reader says: %s", (int)len, line,
                 general.err.msg);
    assert_same_block(&general, &fast);
    /* the reader's words-only hint says what the packer would find itself */
    assert_int_equal(fast.words_only, 1);
    assert_int_equal(general.words_only, 0);
    assert_int_equal(ncp_block_packed_size(&fast), ncp_block_packed_size(&general));
}

static void test_fast_path_is_the_general_reader(void **state)
{
    (void)state;
    static const char *const lines[] = {
        "G1 X12.253 Y-3.7 Z-0.540 F600", "g0x1y2", "G1\tX1", "  G1 X1  ", "", "   ",
        "G2 X7.867 Y2.423 I0.000 J2.000", "X.5 Y-.5 Z+.5", "G1 X1.", "M3 S12000",
        "G1 G0 X1", "M3 M8", "X1.0000000000000000001", "X123456789012345678901",
        "A1 B2 C3 D4 E5 F6 H7 I8 J9 K10 L11 P12 Q13 R14 S15 T16 X17 Y18 Z19",
        "N10 G1 X1", "n20g1x1", "N10", "  N0010 G0 X1 ", "N123456789012345678901 G1 X1",
        "N7\tM3 S100",
    };
    int taken = 0;
    for (size_t i = 0; i < sizeof lines / sizeof lines[0]; i++)
        expect_fast_like_general(lines[i], strlen(lines[i]), &taken);
    /* all but the empty lines and those that start with M (M98, M99: the
     * general reader's, see test_fanuc_lines) */
    assert_true(taken >= 15);
    /* and what it must leave alone */
    static const char *const general_only[] = {
        "N10.5 G1 X1", "N 10 G1", "N10(c)", "N10 ;c", "G1 N10 X1", "N", "NX1", "N10 O100 sub",
        "N10 N20", "N10 2", "/N10 G1", "G1 X1 (c)", "G1 X1 ;c", "/G1 X1", "G1 X#1", "G1 X[1]", "G1 X1 X2",
        "G1 X1.2.3", "G1 X--1", "G1 X1 2", "G1 X", "o100 sub", "G1 U1", "G1 X1\r",
        "G1 X1\v", "#1=2", "G1 $1", "G1 X 1", "M98 P1", "N10 M99", "m3",
    };
    for (size_t i = 0; i < sizeof general_only / sizeof general_only[0]; i++) {
        static struct ncp_block b;
        if (ncp_lex_fast(general_only[i], strlen(general_only[i]), 1, 0, &b))
            fail_msg("fast path took '%s'", general_only[i]);
    }
    static const char alphabet[] = "GgXxYyZzMmFfIiJjNnOoUu0123456789..--+  \t(;#[/\r\v$";
    uint64_t seed = 99;
    char line[300];
    taken = 0;
    for (int iter = 0; iter < 300000; iter++) {
        seed = seed * 6364136223846793005u + 1442695040888963407u;
        size_t len = (size_t)(seed >> 33) % 40;
        if (iter % 1000 == 0)
            len = 240 + (size_t)(seed >> 40) % 20; /* around the too-long limit */
        for (size_t i = 0; i < len; i++) {
            seed = seed * 6364136223846793005u + 1442695040888963407u;
            /* mostly letter, digits, point, blank: the shapes the fast path takes */
            unsigned r = (unsigned)(seed >> 33);
            line[i] = r % 4 ? "GXYZ0123456789. "[r / 4 % 16] : alphabet[r / 4 % (sizeof alphabet - 1)];
        }
        if (iter % 3 == 0 && len > 2) { /* a leading N word, now and then a malformed one */
            line[0] = iter % 2 ? 'N' : 'n';
            for (size_t i = 1; i < len && i < 1 + (size_t)(seed >> 60); i++)
                line[i] = (char)('0' + (seed >> (4 * i)) % 10);
        }
        expect_fast_like_general(line, len, &taken);
    }
    assert_true(taken > 1000);
}

/* ncp_lex_line finds the line end while it reads: it must split a text exactly
 * as ncp_source_span does (\n, \r\n, a \r at the very end, blank lines, no
 * newline at the end, lines past the length limit) and lex every line as
 * ncp_lex_block lexes the span. */
static void expect_lines_like_spans(const char *text, size_t len)
{
    static struct ncp_block by_line, by_span;
    struct ncp_source src = {0};
    src.text = text;
    src.len = src.end = len;
    src.begin_line = 1;
    src.name = "t";
    uint64_t off = 0;
    uint32_t line = 1;
    struct ncp_span sp;
    while (ncp_source_span(&src, off, line, &sp) == 0) {
        size_t next = 0;
        memset(&by_line, 0x5A, sizeof by_line);
        int rc = ncp_lex_line(text + off, len - off, line, off, &by_line, &next);
        int want = ncp_lex_block(text + sp.off, sp.len, sp.line, sp.off, &by_span);
        assert_int_equal(rc, want);
        assert_int_equal(off + next, sp.next);
        assert_same_block(&by_span, &by_line);
        off = sp.next;
        line++;
    }
    assert_int_equal(off, len);
}

static void test_line_reader_splits_as_spans(void **state)
{
    (void)state;
    static const char *const texts[] = {
        "G1 X1\nG1 Y2\n", "G1 X1\r\nG1 Y2\r\n", "G1 X1", "G1 X1\r", "\n\n\r\n",
        "G1 X1\r\r\nG0 Y1", "G1 X1 \n(c)\nG1 X2\t\r\n", "G1 X1\rG1 X2\n", "X1\n\n",
    };
    for (size_t i = 0; i < sizeof texts / sizeof texts[0]; i++)
        expect_lines_like_spans(texts[i], strlen(texts[i]));
    static const char alphabet[] = "GgXxYyZzMmFf0123456789..--  \t(;#[\r\n\n\n";
    uint64_t seed = 5;
    static char text[4096];
    for (int iter = 0; iter < 20000; iter++) {
        seed = seed * 6364136223846793005u + 1442695040888963407u;
        size_t len = (size_t)(seed >> 33) % 200;
        if (iter % 100 == 0)
            len = 200 + (size_t)(seed >> 40) % 3000; /* lines past the limit too */
        for (size_t i = 0; i < len; i++) {
            seed = seed * 6364136223846793005u + 1442695040888963407u;
            unsigned r = (unsigned)(seed >> 33);
            text[i] = r % 3 ? "GXYZ0123456789. \n"[r / 4 % 17]
                            : alphabet[r / 4 % (sizeof alphabet - 1)];
            if (iter % 100 == 0 && text[i] == '\n' && r % 5)
                text[i] = '1'; /* long lines */
        }
        expect_lines_like_spans(text, len);
    }
}

/* Lexing straight into a packed record (the lexing-ahead helper's path) must
 * give the record ncp_lex_line + ncp_block_pack give, for lines either reader
 * takes, and say 0 when the record does not fit. */
static void expect_packed_like_lexed(const char *text, size_t avail)
{
    static struct ncp_block lexed, back, scratch;
    static unsigned char want[NCP_BLOCK_PACK_MAX + 64], got[NCP_BLOCK_PACK_MAX + 64];
    size_t next_lexed = 0, next_packed = 0;
    ncp_lex_line(text, avail, 0, 4321, &lexed, &next_lexed);
    size_t size = ncp_block_pack(&lexed, want);
    memset(got, 0xA5, sizeof got);
    size_t n = ncp_lex_line_packed(text, avail, 4321, got, sizeof got, &scratch, &next_packed);
    assert_int_equal(n, size);
    assert_int_equal(next_packed, next_lexed);
    assert_memory_equal(got, want, size);
    memset(&back, 0x5A, sizeof back);
    ncp_block_unpack(got, &back);
    assert_same_block(&lexed, &back);
    /* exactly the room it needs (the general reader then packs), and less */
    assert_int_equal(ncp_lex_line_packed(text, avail, 4321, got, size, &scratch, &next_packed),
                     size);
    assert_memory_equal(got, want, size);
    assert_int_equal(ncp_lex_line_packed(text, avail, 4321, got, size - 1, &scratch,
                                         &next_packed), 0);
}

static void test_lex_line_packed(void **state)
{
    (void)state;
    static const char *const texts[] = {
        "G1 X12.253 Y-3.7 Z-0.540 F600\nG1 X1\n", "N10 G1 X1\n", "G1 X1", "G1 X1\r\n",
        "G1 X1 (c)\n", "#1 = 2\n", "\n", "", "o100 sub\n", "N7\n", "G1 X1 X2\n", "/G1 X1\n",
    };
    for (size_t i = 0; i < sizeof texts / sizeof texts[0]; i++)
        expect_packed_like_lexed(texts[i], strlen(texts[i]));
    uint64_t seed = 17;
    char text[300];
    for (int iter = 0; iter < 50000; iter++) {
        seed = seed * 6364136223846793005u + 1442695040888963407u;
        size_t len = (size_t)(seed >> 33) % 60;
        for (size_t i = 0; i < len; i++) {
            seed = seed * 6364136223846793005u + 1442695040888963407u;
            unsigned r = (unsigned)(seed >> 33);
            text[i] = r % 5 ? "GXYZNM0123456789.- "[r / 5 % 19] : "\n\r(;#[/\tO"[r / 5 % 10];
        }
        expect_packed_like_lexed(text, len);
    }
}

/* One block unpacked over, record after record (the analyzer's block when
 * blocks are lexed ahead): plain records of more and fewer words and general
 * ones in any order, and the block lexed over in between, must each come out
 * as the block that was packed. */
static void test_unpack_over(void **state)
{
    (void)state;
    static const char *const lines[] = {
        "G1 X1.5 Y-2 Z0.25", "G0 X1", "/N10 G1 X1 Y2 Z3 A4 B5 C6 F7", "N20 G2 X1 Y1 I0 J1",
        "#1 = [#2 + 3]", "G1 X[#1]", "(just a comment)", "G1 X1 X2 Y", "M3 S1000",
        "o100 if [#1 LT 2]", "G1 X1 Y2 Z3 U4 V5 W6 A7 B8 C9 F10", "", "G1 X1 (c)",
    };
    static struct ncp_block lexed, over;
    static unsigned char buf[NCP_BLOCK_PACK_MAX + 64];
    unsigned plain = 0, seed = 3;
    memset(&over, 0x5A, sizeof over);
    for (int r = 0; r < 2000; r++) {
        seed = seed * 1103515245u + 12345u;
        const char *line = lines[(seed >> 16) % (sizeof lines / sizeof lines[0])];
        ncp_lex_block(line, strlen(line), (uint32_t)r + 1, (uint64_t)r * 40, &lexed);
        ncp_block_pack(&lexed, buf);
        if ((seed >> 8) % 17 == 0) { /* written by someone else in between */
            ncp_lex_block("#1=2 G1 X[#1] (MSG, x)", 22, 1, 0, &over);
            plain = 0;
        }
        assert_int_equal(ncp_block_unpack_over(buf, &over, &plain), ncp_block_packed_units(buf));
        assert_same_block(&lexed, &over);
    }
}

static void test_pack_round_trip(void **state)
{
    (void)state;
    static const char *const lines[] = {
        "G1 X1.5 Y-2 Z0.25 F600", "", "(just a comment)", "/N10 G0 X0 (MSG, hello)",
        "#1 = [#2 + sin[30]] #<name> = 2 #[1+2] = #<_global>",
        "o<sub> call [1] [#2*3] [exists[#<x>]] [4]", "o100 while [#1 LT 10]",
        "o100 endsub [#1 ** 2]", "G2 X1 Y1 I[#3/2] J0.5 ;rest of line", "G1 X1 X2",
        "G1 X[1 +", "(unclosed", "M3 S[1000 * #4] T[#5 MOD 3] (DEBUG, #1 and #<x>)",
        "o1 if [[#1 EQ 2] AND [#2 NE 3] OR [ATAN[1]/[2] GT 0]]", "%",
        "/N10 G1 X1 Y2", "N20 G0 X-1e", "/", "G1 X[1]", "G1 X1 (c)", "N7",
    };
    for (size_t i = 0; i < sizeof lines / sizeof lines[0]; i++)
        round_trip(lines[i], strlen(lines[i]));
    /* a CAM line travels in one cache line (the plain form) */
    ncp_lex_block("G1 X12.253 Y-3.7 Z-0.540", 24, 1, 0, &blk);
    assert_int_equal(ncp_block_packed_size(&blk), 64);
    /* the largest block: every word slot and a long comment */
    char big[256];
    size_t n = 0;
    while (n + 4 < 250) {
        memcpy(big + n, "G1X1", 4);
        n += 4;
    }
    round_trip(big, n);
    /* random text: error blocks carry partial contents, which must survive too */
    unsigned seed = 7;
    char line[300];
    for (int r = 0; r < 5000; r++) {
        size_t len = ((seed = seed * 1103515245u + 12345u) >> 16) % 280;
        for (size_t i = 0; i < len; i++)
            line[i] = "g1xyz#[]+-*/0123456789.<>o=( ),;amnif"[((seed = seed * 1103515245u +
                                                                12345u) >> 16) % 37];
        round_trip(line, len);
    }
    unsigned char pad[8];
    ncp_block_pack_pad(pad);
    assert_true(ncp_block_packed_is_pad(pad));
    assert_false(ncp_block_packed_is_end_mark(pad));
    ncp_block_pack_end_mark(pad);
    assert_true(ncp_block_packed_is_end_mark(pad));
    assert_false(ncp_block_packed_is_pad(pad));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_numbers),
        cmocka_unit_test(test_number_errors),
        cmocka_unit_test(test_words),
        cmocka_unit_test(test_line_number_and_delete),
        cmocka_unit_test(test_duplicates),
        cmocka_unit_test(test_bad_characters),
        cmocka_unit_test(test_comments),
        cmocka_unit_test(test_operators),
        cmocka_unit_test(test_functions),
        cmocka_unit_test(test_fold_matches_eval),
        cmocka_unit_test(test_expression_errors),
        cmocka_unit_test(test_parameters),
        cmocka_unit_test(test_eval_errors),
        cmocka_unit_test(test_assignments),
        cmocka_unit_test(test_owords),
        cmocka_unit_test(test_oword_errors),
        cmocka_unit_test(test_fanuc_lines),
        cmocka_unit_test(test_numbers_match_strtod),
        cmocka_unit_test(test_fast_path_is_the_general_reader),
        cmocka_unit_test(test_line_reader_splits_as_spans),
        cmocka_unit_test(test_long_lines),
        cmocka_unit_test(test_nul_and_garbage),
        cmocka_unit_test(test_pack_round_trip),
        cmocka_unit_test(test_unpack_over),
        cmocka_unit_test(test_lex_line_packed),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
