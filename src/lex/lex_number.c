/* Decimal literals as rs274's read_real_number() takes them: the longest run of
 * signs followed by the longest run of digits and dots, which must then be a
 * valid number ([sign] digits [. digits], at least one digit, no exponent).
 * Values are correctly rounded, like the C++ stream rs274 uses: exact
 * integer-mantissa arithmetic when that is exact, strtod otherwise. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "lex_internal.h"

static const double pow10_tab[23] = {
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11,
    1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22
};

static int is_digit(char c)
{
    return c >= '0' && c <= '9';
}

static double slow_convert(const char *s, int len)
{
    char tmp[NCP_LEX_TOO_LONG + 1];
    memcpy(tmp, s, (size_t)len);
    tmp[len] = '\0';
    return strtod(tmp, 0);
}

/* Error text: rs274 quotes the run of signs, digits and dots it tried. */
static int bad_number(struct ncp_lexer *lx, int start, const char *why)
{
    const char *s = lx->buf;
    int end = start;
    while (s[end] == '+' || s[end] == '-')
        end++;
    while (is_digit(s[end]) || s[end] == '.')
        end++;
    return ncp_lex_fail(lx, start, "bad number format (%s) parsing '%.*s'", why,
                        end - start, s + start);
}

/* Callers only come here with at most one leading sign (read_real_value
 * handles "+-1" and friends by recursion). */
int ncp_lex_number(struct ncp_lexer *lx, double *out)
{
    const char *s = lx->buf;
    int start = lx->pos, p = start, first, ndig, frac = 0, neg = 0;
    uint64_t m = 0;

    if (s[p] == '+' || s[p] == '-')
        neg = (s[p++] == '-');
    first = p;
    /* m wraps only past 19 digits, and then the slow path takes over */
    for (; is_digit(s[p]); p++)
        m = m * 10 + (uint64_t)(s[p] - '0');
    ndig = p - first;
    if (s[p] == '.') {
        for (p++; is_digit(s[p]); p++)
            m = m * 10 + (uint64_t)(s[p] - '0');
        frac = p - first - ndig - 1;
        ndig += frac;
    }
    if (ndig == 0)
        return bad_number(lx, start, "conversion failed");
    if (s[p] == '.')
        return bad_number(lx, start, "trailing characters");
    if (ndig <= 19 && m < ((uint64_t)1 << 53) && frac <= 22) {
        double v = (double)m / pow10_tab[frac];
        *out = neg ? -v : v;
    } else {
        *out = slow_convert(s + start, p - start);
    }
    lx->pos = p;
    return NCP_OK;
}
